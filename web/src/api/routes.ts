// Typed calls of the /v1 routes (the HTTP transcoding of the gRPC methods).
import { call } from "./http";
import type {
  Clip,
  ClipLabels,
  IngestClipResponse,
  ClipPosesJson,
  CurveJson,
  Job,
  Label,
  ListClipsResponse,
  SearchResponse,
  ServerInfo,
  Skeleton,
  SkeletonDetail,
  Space,
} from "./types";

export interface ClipFilter {
  name_contains?: string;
  tag?: string;
  skeleton_id?: string;
  descriptor?: string;
  sort?: string;
}

export interface FrameRange {
  clipId: string;
  first: number;
  last: number;
}

/** A search's query: a stored clip range or an uploaded BVH, FBX or glTF file (base64). */
export type SearchQuery = { range: FrameRange } | { fileBase64: string; fileName: string };

// The server's largest page (fewer when its answer limit is below 2 MiB; the pages then follow).
const LABEL_PAGE_SIZE = 1000;

export const api = {
  info: () => call<ServerInfo>("GET", "/v1/info"),

  listClips: (filter: ClipFilter, pageSize: number, pageToken: string) =>
    call<ListClipsResponse>("GET", "/v1/clips", {
      query: { ...filter, page_size: pageSize, page_token: pageToken },
    }),

  clip: (id: string) => call<Clip>("GET", `/v1/clips/${id}`),

  /** Adds a BVH, FBX or glTF file to the library: a clip a take. */
  ingest: (fileName: string, fileBase64: string) =>
    call<IngestClipResponse>("POST", "/v1/clips", {
      body: { file_name: fileName, bvh: fileBase64 },
    }),

  skeleton: (id: string) => call<SkeletonDetail>("GET", `/v1/skeletons/${id}`),

  skeletons: async () => (await call<{ skeletons: Skeleton[] }>("GET", "/v1/skeletons")).skeletons,

  spaces: async () =>
    (await call<{ spaces: Space[] }>("GET", "/v1/spaces", { query: { page_size: 1000 } })).spaces,

  poses: (range: FrameRange, maxRate: number) =>
    call<ClipPosesJson>("GET", `/v1/clips/${range.clipId}/poses`, {
      query: { from: range.first, to: range.last, max_rate: maxRate },
    }),

  curve: (space: string, range: FrameRange, dims: number) =>
    call<CurveJson>("GET", `/v1/spaces/${encodeURIComponent(space)}/curve`, {
      query: { clip: range.clipId, from: range.first, to: range.last, dims },
    }),

  /** A clip's label timeline, every page of it. */
  clipLabels: async (clipId: string): Promise<ClipLabels> => {
    const page = (pageToken: string) =>
      call<ClipLabels>("GET", `/v1/clips/${clipId}/labels`, {
        query: { page_size: LABEL_PAGE_SIZE, page_token: pageToken },
      });
    const first = await page("");
    const labels = [...first.labels];
    for (let token = first.next_page_token; token;) {
      const next = await page(token);
      labels.push(...next.labels);
      token = next.next_page_token;
    }
    return { ...first, labels, next_page_token: "" };
  },

  search: (space: string, query: SearchQuery, maxResults: number) =>
    call<SearchResponse>("POST", "/v1/search", {
      body: {
        space,
        max_results: maxResults,
        return_path: true,
        ...("range" in query
          ? {
              clip: {
                clip_id: query.range.clipId,
                first_frame: query.range.first,
                last_frame: query.range.last,
              },
            }
          : { bvh: { bvh: query.fileBase64 } }),
      },
    }),

  addLabel: async (range: FrameRange, descriptor: string, value: number) =>
    (
      await call<{ labels: Label[] }>("POST", "/v1/labels", {
        body: {
          labels: [
            {
              clip_id: range.clipId,
              first_frame: range.first,
              last_frame: range.last,
              descriptor_name: descriptor,
              value,
            },
          ],
        },
      })
    ).labels,

  startPropagation: (space: string, descriptor: string, maxResults: number) =>
    call<Job>("POST", "/v1/jobs", {
      body: { space, descriptor_names: [descriptor], search: { max_results: maxResults } },
    }),

  job: (id: string) => call<Job>("GET", `/v1/jobs/${encodeURIComponent(id)}`),
};
