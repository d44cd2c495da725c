// The proto3 JSON of the motiondb.v1 messages the page reads (field names as in the .proto
// files; int64 values arrive as strings, bytes as base64, enums by name). Only the fields the
// page uses are listed.

export type Int64 = string;

export interface Clip {
  clip_id: Int64;
  name: string;
  tags: string[];
  skeleton_id: Int64;
  created_unix_ms: Int64;
  frame_count: number;
  fps: number;
  duration_s: number;
  joint_count: number;
}

export interface IngestClipResponse {
  clip: Clip;
  warnings?: string[];
  /** "INGEST_RESULT_STORED", "INGEST_RESULT_SKIPPED", ... */
  result: string;
  /** A file's second and later takes, each as the first. */
  more_takes?: IngestClipResponse[];
  file?: { format: string; unit_m?: number; up_axis?: string; generator?: string };
}

export interface ListClipsResponse {
  clips: Clip[];
  next_page_token: string;
  total_size?: number | Int64;
}

export interface Skeleton {
  skeleton_id: Int64;
  name: string;
  joint_count: number;
  clip_count: Int64;
}

export interface HumanoidSlot {
  slot: string;
  joint: number;
  joint_name: string;
  overridden?: boolean;
  required?: boolean;
}

export interface SkeletonDetail {
  skeleton: Skeleton;
  joints: { name: string; parent: number }[];
  humanoid_map: {
    slots?: HumanoidSlot[];
    missing_slots?: string[];
    complete?: boolean;
    mirror_pairs?: { left_name: string; right_name: string }[];
  };
}

export interface Space {
  space_id: Int64;
  name: string;
  skeleton_id: Int64;
  /** A space over several skeletons: all of them, skeleton_id first; absent for one. */
  skeleton_ids?: Int64[];
  report?: { dims: number; sample_rate: number };
  index?: { clips: Int64; frames: Int64; dims: number };
}

export interface ClipPosesJson {
  clip_id: Int64;
  joint_names: string[];
  parents: number[];
  sample_rate: number;
  frames: number;
  first_frame: number;
  last_frame: number;
  positions: string;
}

export interface CurveJson {
  dims: number;
  frames: number;
  sample_rate: number;
  coordinates: string;
  first_frame: number;
  last_frame: number;
}

export interface SearchResult {
  clip_id: Int64;
  clip_name: string;
  start_s: number;
  end_s: number;
  start_frame: number;
  end_frame: number;
  score: number;
  seed_frame: number;
  path: number[];
}

export interface SearchResponse {
  results: SearchResult[];
  timings?: { total_ms: number; request_ms: number };
}

export interface Label {
  label_id: Int64;
  clip_id: Int64;
  first_frame: number;
  last_frame: number;
  descriptor_name: string;
  value: number;
  origin: string;
}

export interface ClipLabels {
  clip_id: Int64;
  frame_count: number;
  fps: number;
  labels: Label[];
  next_page_token: string; // empty on the last page
}

export type JobState =
  | "JOB_STATE_UNSPECIFIED"
  | "JOB_STATE_QUEUED"
  | "JOB_STATE_RUNNING"
  | "JOB_STATE_SUCCEEDED"
  | "JOB_STATE_FAILED"
  | "JOB_STATE_CANCELLED"
  | "JOB_STATE_INTERRUPTED";

export interface Job {
  job_id: string;
  state: JobState;
  space: string;
  descriptor_names: string[];
  done: Int64;
  total: Int64;
  labels_written: Int64;
  error: string;
}

export interface ServerInfo {
  version: string;
  counts?: { clips: Int64; spaces: Int64; labels: Int64 };
  auth_required: boolean;
  /** What the caller's token holds: "read", "write" or "admin". */
  scope: string;
}
