// What a search asks with: a stored clip's range, or an uploaded BVH, FBX or glTF file (shown
// from the file itself, since it is not stored).
import type { FrameRange, SearchQuery } from "../api/routes";
import { bytesToBase64 } from "../api/packed";
import type { Clip } from "../api/types";
import { parseBvh } from "../bvh/bvh_file";
import { bvhPoses } from "../bvh/bvh_poses";
import type { Poses } from "../model/poses";
import { motionFormat } from "../scene/file_format";

/** An uploaded file is shown at this rate at most, as stored clips are. */
const UPLOAD_POSE_RATE = 60;

export type Query =
  | { kind: "range"; clip: Clip; range: FrameRange }
  | { kind: "file"; fileName: string; fileBase64: string; clip: Clip; poses: Poses };

export function describe(query: Query): string {
  if (query.kind === "file") return `uploaded ${query.fileName}`;
  const seconds = (query.range.last - query.range.first) / query.clip.fps;
  return `${query.clip.name}, frames ${query.range.first}–${query.range.last} (${seconds.toFixed(2)} s)`;
}

export function toSearchQuery(query: Query): SearchQuery {
  return query.kind === "range"
    ? { range: query.range }
    : { fileBase64: query.fileBase64, fileName: query.fileName };
}

/** The figure of an uploaded file: a BVH read here, an FBX or glTF by three.js's loaders. */
async function filePoses(
  file: File,
  bytes: Uint8Array,
): Promise<{ poses: Poses; frameCount: number; fps: number; jointCount: number }> {
  const format = motionFormat(bytes);
  if (format === null) throw new Error(`${file.name} is not a BVH, FBX or glTF file`);
  if (format !== "bvh") {
    const { scenePoses } = await import("../scene/scene_poses");
    return scenePoses(file.name, bytes, format, UPLOAD_POSE_RATE);
  }
  const bvh = parseBvh(new TextDecoder().decode(bytes));
  return {
    poses: bvhPoses(bvh, UPLOAD_POSE_RATE),
    frameCount: bvh.frames,
    fps: 1 / bvh.frameTime,
    jointCount: bvh.joints.length,
  };
}

/** Reads a dropped or chosen file; refuses what no reader takes before asking the server. */
export async function fileQuery(file: File): Promise<Query> {
  const bytes = new Uint8Array(await file.arrayBuffer());
  const { poses, frameCount, fps, jointCount } = await filePoses(file, bytes);
  const clip: Clip = {
    clip_id: "",
    name: file.name,
    tags: [],
    skeleton_id: "",
    created_unix_ms: "0",
    frame_count: frameCount,
    fps,
    duration_s: (frameCount - 1) / fps,
    joint_count: jointCount,
  };
  return { kind: "file", fileName: file.name, fileBase64: bytesToBase64(bytes), clip, poses };
}
