// Play/pause, the scrub bar, the speed and the time: the controls of the shared Clock.
import type { Clock } from "../player/clock";
import { h, fill } from "./dom";

const SPEEDS = [0.25, 0.5, 1, 1.5, 2];

export class Transport {
  private readonly button = h("button", {
    class: "play",
    "data-testid": "play",
    title: "Play/pause (space)",
  });
  private readonly scrub = h("input", {
    type: "range",
    min: 0,
    max: 1000,
    value: 0,
    class: "scrub",
    "aria-label": "Time",
  });
  private readonly time = h("span", { class: "time", "data-testid": "time" });
  private readonly speed = h(
    "select",
    { class: "speed", "aria-label": "Speed" },
    ...SPEEDS.map((s) => h("option", { value: s, selected: s === 1 }, `${s}x`)),
  );

  constructor(
    element: HTMLElement,
    private readonly clock: Clock,
  ) {
    fill(element, this.button, this.scrub, this.time, this.speed);
    this.button.addEventListener("click", () => clock.toggle());
    this.scrub.addEventListener("input", () => {
      clock.pause();
      clock.seek((Number(this.scrub.value) / 1000) * clock.duration);
    });
    this.speed.addEventListener("change", () => clock.setSpeed(Number(this.speed.value)));
    document.addEventListener("keydown", (event) => {
      const target = event.target as HTMLElement;
      if (event.code !== "Space" || /INPUT|SELECT|TEXTAREA|BUTTON/.test(target.tagName)) return;
      event.preventDefault();
      clock.toggle();
    });
    clock.onTick((seconds) => this.showTime(seconds));
    clock.onState(() => this.showState());
    this.showState();
  }

  private showTime(seconds: number): void {
    const duration = this.clock.duration;
    this.scrub.value = String(duration > 0 ? Math.round((seconds / duration) * 1000) : 0);
    this.time.textContent = `${seconds.toFixed(2)} / ${duration.toFixed(2)} s`;
  }

  private showState(): void {
    this.button.textContent = this.clock.playing ? "❚❚" : "▶";
    this.button.dataset.state = this.clock.playing ? "playing" : "paused";
    this.button.disabled = this.clock.duration <= 0;
    this.scrub.disabled = this.clock.duration <= 0;
    this.showTime(this.clock.seconds);
  }
}
