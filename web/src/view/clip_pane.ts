// One side of the stage: a clip's name and the frame playing, its stick figure and its timeline.
import type { Clip, Label } from "../api/types";
import { duration, rate } from "../model/format";
import type { Poses } from "../model/poses";
import { sampleOf } from "../model/frame_map";
import { h, fill } from "./dom";
import { FigureView } from "./figure_view";
import { Timeline, type FrameSpan } from "./timeline";

export interface PaneContent {
  clip: Clip;
  poses: Poses;
  labels: Label[];
  /** The range shown highlighted on the timeline (the query or the hit). */
  highlight: FrameSpan | null;
  /** A word before the clip's name: "query", "hit 3". */
  role: string;
}

export class ClipPane {
  readonly timeline: Timeline;
  private readonly figure: FigureView;
  private readonly title = h("span", { class: "title" });
  private readonly counter = h("span", { class: "frame-counter", "data-testid": "frame-counter" });
  private content: PaneContent | null = null;

  constructor(
    readonly element: HTMLElement,
    color: number,
  ) {
    const viewport = h("div", { class: "viewport" });
    const timeline = h("div");
    fill(element, h("div", { class: "pane-head" }, this.title, this.counter), viewport, timeline);
    this.figure = new FigureView(viewport, color);
    this.timeline = new Timeline(timeline);
  }

  show(content: PaneContent): void {
    this.content = content;
    const { clip } = content;
    fill(
      this.title,
      h("b", { class: "role" }, content.role),
      ` ${clip.name} `,
      h(
        "small",
        {},
        `${clip.clip_id ? `#${clip.clip_id}` : "not stored"} · ${duration(clip.duration_s)} · ${rate(clip.fps)}`,
      ),
    );
    this.element.dataset.clipId = clip.clip_id;
    this.figure.show(content.poses);
    this.timeline.select(null);
    this.timeline.show({
      frameCount: clip.frame_count,
      fps: clip.fps,
      labels: content.labels,
      highlight: content.highlight,
    });
  }

  /** Shows the pose at clip frame `frame` (at the clip's rate, fractional). */
  showFrame(frame: number): void {
    if (!this.content) return;
    const { poses, clip } = this.content;
    this.figure.pose(
      Math.min(sampleOf(frame, poses.firstFrame, clip.fps, poses.sampleRate), poses.frames - 1),
    );
    this.timeline.setPlayhead(frame);
    const shown = Math.round(frame);
    this.counter.textContent = `frame ${shown}`;
    this.counter.dataset.frame = String(shown);
  }

  setLabels(labels: Label[]): void {
    if (!this.content) return;
    this.content = { ...this.content, labels };
    this.timeline.show({
      frameCount: this.content.clip.frame_count,
      fps: this.content.clip.fps,
      labels,
      highlight: this.content.highlight,
    });
  }

  clear(): void {
    this.content = null;
    this.figure.clear();
    fill(this.title);
    this.counter.textContent = "";
  }
}
