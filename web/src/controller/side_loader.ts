// Fetches what one side of the stage shows: the clip, its poses over the range, its labels and
// its motion curve in the space (in parallel). A curve the space cannot give (another skeleton)
// leaves the side without one rather than failing it.
import { api, type FrameRange } from "../api/routes";
import type { Clip } from "../api/types";
import { Curve } from "../model/curve";
import type { FrameMap } from "../model/frame_map";
import { decodePoses } from "../model/poses";
import type { Side } from "../player/stage_player";
import type { FrameSpan } from "../view/timeline";

/** Poses are fetched at this rate at most: smooth on screen, a fraction of a 120 fps capture. */
const POSE_RATE = 60;
/** The curve plot draws a space's first three dimensions. */
const CURVE_DIMS = 3;

export interface SideRequest {
  clip: Clip;
  range: FrameRange;
  frames: FrameMap;
  highlight: FrameSpan | null;
  role: string;
}

export async function loadSide(request: SideRequest, space: string | null): Promise<Side> {
  const [poses, labels, curve] = await Promise.all([
    api.poses(request.range, POSE_RATE),
    api.clipLabels(request.range.clipId),
    space ? api.curve(space, request.range, CURVE_DIMS).catch(() => null) : Promise.resolve(null),
  ]);
  return {
    ...request,
    poses: decodePoses(poses),
    labels: labels.labels,
    curve: curve ? new Curve(curve) : null,
  };
}

/** A whole clip's range. */
export function wholeClip(clip: Clip): FrameRange {
  return { clipId: clip.clip_id, first: 0, last: clip.frame_count - 1 };
}
