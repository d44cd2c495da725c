// What an uploaded motion file is, told by its first bytes as the server tells it
// (core/scene/scene_format.h), so that the page refuses what no reader takes before uploading it.

export type MotionFormat = "bvh" | "fbx" | "glb" | "gltf";

const FBX_BINARY = "Kaydara FBX Binary";

export function motionFormat(bytes: Uint8Array): MotionFormat | null {
  const head = new TextDecoder().decode(bytes.subarray(0, 256));
  if (head.startsWith("glTF")) return "glb";
  if (head.startsWith(FBX_BINARY)) return "fbx";
  const text = head.replace(/^\uFEFF/, "").trimStart();
  if (text.startsWith("HIERARCHY")) return "bvh";
  if (text.startsWith("{")) return "gltf";
  if (text.startsWith(";") || text.startsWith("FBXHeaderExtension")) return "fbx";
  return null;
}
