// Fetches what one side of the stage shows: the clip, its poses over the range, its labels and
// its motion curve in the space (in parallel). A clip of a skeleton the space does not hold has
// no curve there: the side shows none, and the page does not ask for one.
import { api, type FrameRange } from "../api/routes";
import type { Clip, Int64, Space } from "../api/types";
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

/** The skeletons whose clips `space` holds. */
export function skeletonsOf(space: Space): Int64[] {
  return space.skeleton_ids?.length ? space.skeleton_ids : [space.skeleton_id];
}

/** Whether `space` holds clips of `clip`'s skeleton. */
export function holds(space: Space | null, clip: Clip): space is Space {
  return space !== null && skeletonsOf(space).includes(clip.skeleton_id);
}

export async function loadSide(request: SideRequest, space: Space | null): Promise<Side> {
  const [poses, labels, curve] = await Promise.all([
    api.poses(request.range, POSE_RATE),
    api.clipLabels(request.range.clipId),
    holds(space, request.clip)
      ? api.curve(space.name, request.range, CURVE_DIMS)
      : Promise.resolve(null),
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
