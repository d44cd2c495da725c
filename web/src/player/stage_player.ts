// Plays one or two sides on the shared clock: each side maps the clock to its clip's frame
// (straight, or through the hit's warp path), and its pane and curve marker follow.
import type { Curve } from "../model/curve";
import { sampleOf, type FrameMap } from "../model/frame_map";
import type { ClipPane, PaneContent } from "../view/clip_pane";
import type { CurvePlot } from "../view/curve_plot";
import type { Clock } from "./clock";

export interface Side extends PaneContent {
  frames: FrameMap;
  curve: Curve | null;
}

export const CURVE_COLORS = [0x4fb3ff, 0xff9f43];

export class StagePlayer {
  private sides: Side[] = [];

  constructor(
    private readonly clock: Clock,
    private readonly panes: ClipPane[],
    private readonly plot: CurvePlot,
  ) {
    clock.onTick((seconds) => this.showTime(seconds));
  }

  /** Shows the sides (one pane each; the rest hidden) and plays from the start. */
  play(sides: Side[], autoplay: boolean): void {
    this.clock.pause();
    this.sides = sides;
    this.panes.forEach((pane, i) => {
      pane.element.hidden = i >= sides.length;
      if (i < sides.length) pane.show(sides[i]);
      else pane.clear();
    });
    const drawn = sides.flatMap((side, i) =>
      side.curve ? [{ curve: side.curve, color: CURVE_COLORS[i] }] : [],
    );
    this.plot.show(drawn);
    this.clock.load(sides[0]?.frames.duration ?? 0);
    if (autoplay) this.clock.play();
  }

  /** Seeks the clock to clip frame `frame` of the first side. */
  seekFrame(frame: number): void {
    const side = this.sides[0];
    if (!side) return;
    this.clock.pause();
    const first = side.frames.frameAt(0);
    this.clock.seek((frame - first) / side.clip.fps);
  }

  private showTime(seconds: number): void {
    const samples: number[] = [];
    this.sides.forEach((side, i) => {
      const frame = side.frames.frameAt(seconds);
      this.panes[i].showFrame(frame);
      if (side.curve)
        samples.push(sampleOf(frame, side.curve.firstFrame, side.clip.fps, side.curve.sampleRate));
    });
    this.plot.mark(samples);
  }
}
