// What a search asks with: a stored clip's range, or an uploaded BVH file.
import type { FrameRange, SearchQuery } from "../api/routes";
import { bytesToBase64 } from "../api/packed";
import type { Clip } from "../api/types";

export type Query =
  | { kind: "range"; clip: Clip; range: FrameRange }
  | { kind: "file"; fileName: string; bvhBase64: string };

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

export async function fileQuery(file: File): Promise<Query> {
  const bytes = new Uint8Array(await file.arrayBuffer());
  return { kind: "file", fileName: file.name, bvhBase64: bytesToBase64(bytes) };
}
