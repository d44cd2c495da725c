// A clip's timeline: a ruler in seconds, the labels as bars in a row per descriptor, the
// selected range, the highlighted range (a query or a hit) and the playhead. Drag on the ruler
// to select a range, click to seek, click a label to select its range.
import type { Label } from "../api/types";
import { h, fill } from "./dom";

export interface FrameSpan {
  first: number;
  last: number;
}

export interface TimelineModel {
  frameCount: number;
  fps: number;
  labels: Label[];
  highlight: FrameSpan | null;
}

export class Timeline {
  onSelect: (span: FrameSpan) => void = () => {};
  onSeek: (frame: number) => void = () => {};
  private model: TimelineModel = { frameCount: 1, fps: 30, labels: [], highlight: null };
  private selected: FrameSpan | null = null;
  private readonly ruler = h("div", { class: "ruler" });
  private readonly highlight = h("div", { class: "span highlight" });
  private readonly selection = h("div", { class: "span selection" });
  private readonly playhead = h("div", { class: "playhead" });
  private readonly rows = h("div", { class: "label-rows" });

  constructor(private readonly element: HTMLElement) {
    const track = h(
      "div",
      { class: "track" },
      this.ruler,
      this.highlight,
      this.selection,
      this.playhead,
    );
    fill(element, track, this.rows);
    element.classList.add("timeline");
    this.listenForDrag(track);
  }

  show(model: TimelineModel): void {
    this.model = model;
    this.drawRuler();
    this.drawLabels();
    this.place(this.highlight, model.highlight);
    this.place(this.selection, this.selected);
  }

  select(span: FrameSpan | null): void {
    this.selected = span;
    this.place(this.selection, span);
    this.element.dataset.selection = span ? `${span.first}-${span.last}` : "";
  }

  setPlayhead(frame: number): void {
    this.playhead.style.left = `${this.percent(frame)}%`;
  }

  private percent(frame: number): number {
    return (100 * frame) / Math.max(1, this.model.frameCount - 1);
  }

  private place(element: HTMLElement, span: FrameSpan | null): void {
    element.hidden = !span;
    if (!span) return;
    element.style.left = `${this.percent(span.first)}%`;
    element.style.width = `${Math.max(0.3, this.percent(span.last) - this.percent(span.first))}%`;
  }

  private drawRuler(): void {
    const seconds = (this.model.frameCount - 1) / this.model.fps;
    const step = [0.5, 1, 2, 5, 10, 30, 60, 120, 300].find((s) => seconds / s <= 12) ?? 600;
    const ticks: HTMLElement[] = [];
    for (let t = 0; t <= seconds; t += step) {
      ticks.push(
        h("span", { class: "tick", style: `left:${this.percent(t * this.model.fps)}%` }, `${t}s`),
      );
    }
    fill(this.ruler, ...ticks);
  }

  private drawLabels(): void {
    const byDescriptor = new Map<string, Label[]>();
    for (const label of this.model.labels) {
      const list = byDescriptor.get(label.descriptor_name) ?? [];
      list.push(label);
      byDescriptor.set(label.descriptor_name, list);
    }
    const rows = [...byDescriptor.entries()].sort(([a], [b]) => a.localeCompare(b));
    fill(
      this.rows,
      ...rows.map(([descriptor, labels]) =>
        h(
          "div",
          { class: "label-row" },
          h("span", { class: "descriptor", title: descriptor }, descriptor),
          h("div", { class: "bars" }, ...labels.map((label) => this.bar(label))),
        ),
      ),
    );
  }

  private bar(label: Label): HTMLElement {
    const origin = label.origin === "LABEL_ORIGIN_PROPAGATED" ? "propagated" : "manual";
    const bar = h("div", {
      class: `label-bar ${origin}`,
      title: `${label.descriptor_name} ${label.value.toFixed(2)} (${origin}) frames ${label.first_frame}-${label.last_frame}`,
      style: `opacity:${0.35 + 0.65 * label.value}`,
    });
    this.place(bar, { first: label.first_frame, last: label.last_frame });
    bar.addEventListener("click", () => {
      const span = { first: label.first_frame, last: label.last_frame };
      this.select(span);
      this.onSelect(span);
    });
    return bar;
  }

  private frameAt(track: HTMLElement, clientX: number): number {
    const box = track.getBoundingClientRect();
    const fraction = Math.min(Math.max((clientX - box.left) / box.width, 0), 1);
    return Math.round(fraction * (this.model.frameCount - 1));
  }

  private listenForDrag(track: HTMLElement): void {
    track.addEventListener("pointerdown", (down) => {
      track.setPointerCapture(down.pointerId);
      const start = this.frameAt(track, down.clientX);
      let span: FrameSpan | null = null;
      const move = (event: PointerEvent) => {
        const here = this.frameAt(track, event.clientX);
        if (Math.abs(here - start) < 2 && !span) return;
        span = { first: Math.min(start, here), last: Math.max(start, here) };
        this.select(span);
      };
      const up = () => {
        track.removeEventListener("pointermove", move);
        track.removeEventListener("pointerup", up);
        if (span) this.onSelect(span);
        else this.onSeek(start);
      };
      track.addEventListener("pointermove", move);
      track.addEventListener("pointerup", up);
    });
  }
}
