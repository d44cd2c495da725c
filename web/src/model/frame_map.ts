// How the player's clock (seconds since the query's, or the clip's, first frame) maps to a frame
// of a clip at the clip's own rate, fractional. A clip plays straight; a hit plays through its
// warp path, so that it moves in step with the query.

export interface FrameMap {
  readonly duration: number;
  frameAt(seconds: number): number;
}

/** A clip range played at its own rate: `first` at 0 s. */
export function straightFrames(first: number, last: number, fps: number): FrameMap {
  return {
    duration: (last - first) / fps,
    frameAt: (seconds) => Math.min(first + seconds * fps, last),
  };
}

/**
 * A hit played in step with its query: `path[k]` is the hit's frame (at its rate) matched to
 * the query's sample k at the space's rate (SearchResult.path).
 */
export function warpedFrames(path: number[], spaceRate: number): FrameMap {
  if (path.length === 0) throw new Error("the search result has no warp path");
  return {
    duration: (path.length - 1) / spaceRate,
    frameAt: (seconds) => {
      const position = Math.min(Math.max(seconds * spaceRate, 0), path.length - 1);
      const k = Math.floor(position);
      const next = Math.min(k + 1, path.length - 1);
      return path[k] + (path[next] - path[k]) * (position - k);
    },
  };
}

/** The sample of a series that starts at clip frame `firstFrame` and runs at `rate` per second. */
export function sampleOf(frame: number, firstFrame: number, fps: number, rate: number): number {
  return Math.max(0, Math.round(((frame - firstFrame) / fps) * rate));
}
