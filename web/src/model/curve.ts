// A clip range's motion curve in a space (GetCurve): frames x dims coordinates at the space's
// sample rate.
import { base64ToFloat32 } from "../api/packed";
import type { CurveJson } from "../api/types";

export class Curve {
  readonly dims: number;
  readonly frames: number;
  readonly sampleRate: number;
  readonly firstFrame: number;
  readonly coordinates: Float32Array;

  constructor(json: CurveJson) {
    this.dims = json.dims;
    this.frames = json.frames;
    this.sampleRate = json.sample_rate;
    this.firstFrame = json.first_frame;
    this.coordinates = base64ToFloat32(json.coordinates);
    if (this.coordinates.length !== this.frames * this.dims) {
      throw new Error(`curve: ${this.coordinates.length} floats for ${this.frames}x${this.dims}`);
    }
  }

  /** Coordinate d of sample k (0 past the curve's dimensions). */
  at(k: number, d: number): number {
    return d < this.dims ? this.coordinates[k * this.dims + d] : 0;
  }

  /** The sample at `seconds` after the range's start (clamped). */
  sampleAt(seconds: number): number {
    return Math.min(Math.max(Math.round(seconds * this.sampleRate), 0), this.frames - 1);
  }
}
