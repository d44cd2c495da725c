// The player's clock: seconds since the start of what plays, advanced by animation frames
// while playing (times the speed), looping at the end. Every pane reads the same clock, which
// is what keeps a hit in step with its query.

export class Clock {
  private time = 0;
  private length = 0;
  private rate = 1;
  private running = false;
  private last = 0;
  private readonly listeners: ((seconds: number) => void)[] = [];
  private readonly stateListeners: (() => void)[] = [];

  get seconds(): number {
    return this.time;
  }

  get duration(): number {
    return this.length;
  }

  get playing(): boolean {
    return this.running;
  }

  get speed(): number {
    return this.rate;
  }

  onTick(listener: (seconds: number) => void): void {
    this.listeners.push(listener);
  }

  onState(listener: () => void): void {
    this.stateListeners.push(listener);
  }

  /** Starts over on something new to play, `duration` seconds long. */
  load(duration: number): void {
    this.length = Math.max(0, duration);
    this.seek(0);
    this.notifyState();
  }

  seek(seconds: number): void {
    this.time = Math.min(Math.max(seconds, 0), this.length);
    for (const listener of this.listeners) listener(this.time);
  }

  setSpeed(speed: number): void {
    this.rate = speed;
    this.notifyState();
  }

  play(): void {
    if (this.running || this.length <= 0) return;
    this.running = true;
    this.last = performance.now();
    requestAnimationFrame((now) => this.tick(now));
    this.notifyState();
  }

  pause(): void {
    this.running = false;
    this.notifyState();
  }

  toggle(): void {
    if (this.running) this.pause();
    else this.play();
  }

  private tick(now: number): void {
    if (!this.running) return;
    const elapsed = Math.max(0, now - this.last) / 1000;
    this.last = now;
    let next = this.time + elapsed * this.rate;
    if (next > this.length) next = 0;
    this.seek(next);
    requestAnimationFrame((t) => this.tick(t));
  }

  private notifyState(): void {
    for (const listener of this.stateListeners) listener();
  }
}
