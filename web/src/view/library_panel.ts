// The library: clips filtered by name, tag, skeleton and label, sorted and paged, each with its
// duration, rate and tags. Choosing a clip opens it; files dropped on it are added to it.
import { api, type ClipFilter } from "../api/routes";
import type { Clip, Skeleton } from "../api/types";
import { duration, rate } from "../model/format";
import { h, fill } from "./dom";
import { dropZone, MOTION_FILES } from "./drop_zone";
import type { StatusLine } from "./status_line";

const PAGE_SIZE = 50;

export class LibraryPanel {
  onOpen: (clip: Clip) => void = () => {};
  onAdd: (files: File[]) => void = () => {};
  private readonly name = h("input", {
    type: "search",
    placeholder: "name contains",
    "data-testid": "filter-name",
  });
  private readonly tag = h("input", {
    type: "search",
    placeholder: "tag",
    "data-testid": "filter-tag",
  });
  private readonly label = h("input", {
    type: "search",
    placeholder: "has label",
    "data-testid": "filter-label",
  });
  private readonly skeleton = h("select", {
    "data-testid": "filter-skeleton",
    "aria-label": "Skeleton",
  });
  private readonly sort = h(
    "select",
    { "data-testid": "sort", "aria-label": "Sort" },
    h("option", { value: "id" }, "by id"),
    h("option", { value: "name" }, "by name"),
    h("option", { value: "created" }, "by date"),
  );
  private readonly list = h("ol", { class: "clip-list", "data-testid": "clip-list" });
  private readonly count = h("span", { class: "count", "data-testid": "clip-count" });
  private readonly previous = h("button", { class: "ghost", title: "Previous page" }, "‹");
  private readonly next = h("button", { class: "ghost", title: "Next page" }, "›");
  private readonly add = dropZone({
    text: "Add BVH, FBX or glTF files: drop them here",
    accept: MOTION_FILES,
    multiple: true,
    testId: "add-drop",
    inputTestId: "add-input",
    onFiles: (files) => this.onAdd(files),
  });
  /** The token of each page shown so far; the last is the current page's. */
  private tokens: string[] = [""];
  private nextToken = "";
  private selectedId = "";
  private generation = 0;

  constructor(
    element: HTMLElement,
    private readonly status: StatusLine,
  ) {
    fill(
      element,
      h("div", { class: "filters" }, this.name, this.tag, this.label, this.skeleton, this.sort),
      this.list,
      h("div", { class: "pager" }, this.previous, this.count, this.next),
      this.add,
    );
    let typing = 0;
    for (const input of [this.name, this.tag, this.label]) {
      input.addEventListener("input", () => {
        window.clearTimeout(typing);
        typing = window.setTimeout(() => this.reload(), 200);
      });
    }
    for (const select of [this.skeleton, this.sort])
      select.addEventListener("change", () => this.reload());
    this.previous.addEventListener("click", () => this.turn(-1));
    this.next.addEventListener("click", () => this.turn(1));
  }

  /** Whether the token may add files (the server refuses them all the same). */
  setWritable(writable: boolean): void {
    this.add.hidden = !writable;
  }

  showSkeletons(skeletons: Skeleton[]): void {
    fill(
      this.skeleton,
      h("option", { value: "" }, "any skeleton"),
      ...skeletons.map((s) =>
        h("option", { value: s.skeleton_id }, `${s.name} · ${s.clip_count} clips`),
      ),
    );
  }

  /** Marks the clip open on the stage. */
  highlight(clipId: string): void {
    this.selectedId = clipId;
    for (const row of this.list.children) {
      row.classList.toggle("open", (row as HTMLElement).dataset.clipId === clipId);
    }
  }

  reload(): Promise<void> {
    this.tokens = [""];
    return this.load();
  }

  private filter(): ClipFilter {
    return {
      name_contains: this.name.value.trim(),
      tag: this.tag.value.trim(),
      descriptor: this.label.value.trim(),
      skeleton_id: this.skeleton.value,
      sort: this.sort.value,
    };
  }

  private turn(direction: number): void {
    if (direction > 0 && this.nextToken) this.tokens.push(this.nextToken);
    else if (direction < 0 && this.tokens.length > 1) this.tokens.pop();
    else return;
    void this.load();
  }

  private async load(): Promise<void> {
    const generation = ++this.generation;
    const token = this.tokens[this.tokens.length - 1];
    try {
      const page = await api.listClips(this.filter(), PAGE_SIZE, token);
      if (generation !== this.generation) return;
      this.nextToken = page.next_page_token;
      fill(this.list, ...page.clips.map((clip) => this.row(clip)));
      const first = (this.tokens.length - 1) * PAGE_SIZE;
      const total = page.total_size === undefined ? "" : ` of ${page.total_size}`;
      this.count.textContent = page.clips.length
        ? `${first + 1}–${first + page.clips.length}${total}`
        : "no clips match";
      this.previous.disabled = this.tokens.length <= 1;
      this.next.disabled = !this.nextToken;
      this.highlight(this.selectedId);
    } catch (error) {
      this.status.error(error);
    }
  }

  private row(clip: Clip): HTMLElement {
    const row = h(
      "li",
      { class: "clip-row", "data-clip-id": clip.clip_id, tabindex: 0 },
      h("span", { class: "clip-name", title: clip.name }, clip.name),
      h(
        "span",
        { class: "clip-meta" },
        `${duration(clip.duration_s)} · ${rate(clip.fps)} · skeleton ${clip.skeleton_id}`,
      ),
      h("span", { class: "tags" }, ...clip.tags.map((tag) => h("span", { class: "tag" }, tag))),
    );
    row.addEventListener("click", () => this.onOpen(clip));
    row.addEventListener("keydown", (event) => {
      if (event.key === "Enter") this.onOpen(clip);
    });
    return row;
  }
}
