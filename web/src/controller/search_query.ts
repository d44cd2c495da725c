// What a search asks with: a stored clip's range, or an uploaded BVH file (shown from the
// file itself, since it is not stored).
import type { FrameRange, SearchQuery } from "../api/routes";
import { bytesToBase64 } from "../api/packed";
import type { Clip } from "../api/types";
import { parseBvh } from "../bvh/bvh_file";
import { bvhPoses } from "../bvh/bvh_poses";
import type { Poses } from "../model/poses";

/** An uploaded file is shown at this rate at most, as stored clips are. */
const UPLOAD_POSE_RATE = 60;

export type Query =
  | { kind: "range"; clip: Clip; range: FrameRange }
  | { kind: "file"; fileName: string; bvhBase64: string; clip: Clip; poses: Poses };

export function describe(query: Query): string {
  if (query.kind === "file") return `uploaded ${query.fileName}`;
  const seconds = (query.range.last - query.range.first) / query.clip.fps;
  return `${query.clip.name}, frames ${query.range.first}–${query.range.last} (${seconds.toFixed(2)} s)`;
}

export function toSearchQuery(query: Query): SearchQuery {
  return query.kind === "range"
    ? { range: query.range }
    : { bvhBase64: query.bvhBase64, fileName: query.fileName };
}

/** Reads a dropped or chosen file; refuses what is not BVH before asking the server. */
export async function fileQuery(file: File): Promise<Query> {
  const bytes = new Uint8Array(await file.arrayBuffer());
  const bvh = parseBvh(new TextDecoder().decode(bytes));
  const fps = 1 / bvh.frameTime;
  const clip: Clip = {
    clip_id: "",
    name: file.name,
    tags: [],
    skeleton_id: "",
    created_unix_ms: "0",
    frame_count: bvh.frames,
    fps,
    duration_s: (bvh.frames - 1) / fps,
    joint_count: bvh.joints.length,
  };
  return {
    kind: "file",
    fileName: file.name,
    bvhBase64: bytesToBase64(bytes),
    clip,
    poses: bvhPoses(bvh, UPLOAD_POSE_RATE),
  };
}
