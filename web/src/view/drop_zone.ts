// A place to drop files on or click to choose them from: a label around a hidden file input.
import { h } from "./dom";

export interface DropZoneOptions {
  text: string;
  /** The file input's `accept`: extensions the chooser offers. */
  accept: string;
  multiple: boolean;
  testId: string;
  inputTestId: string;
  onFiles: (files: File[]) => void;
}

export function dropZone(options: DropZoneOptions): HTMLElement {
  const input = h("input", {
    type: "file",
    accept: options.accept,
    multiple: options.multiple,
    hidden: true,
    "data-testid": options.inputTestId,
  });
  const zone = h(
    "label",
    { class: "drop", "data-testid": options.testId },
    `${options.text}, or `,
    h("u", {}, "choose"),
    input,
  );
  const take = (list: FileList | null | undefined) => {
    const files = [...(list ?? [])].slice(0, options.multiple ? undefined : 1);
    if (files.length) options.onFiles(files);
  };
  input.addEventListener("change", () => {
    take(input.files);
    input.value = "";
  });
  zone.addEventListener("dragover", (event) => {
    event.preventDefault();
    zone.classList.add("over");
  });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (event) => {
    event.preventDefault();
    zone.classList.remove("over");
    take(event.dataTransfer?.files);
  });
  return zone;
}

/** The extensions of the files motiondb reads. */
export const MOTION_FILES = ".bvh,.fbx,.glb,.gltf";
