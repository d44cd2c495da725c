// A clip range's joint positions (GetClipPoses), decoded once: frames x joints x 3 floats.
import { base64ToFloat32 } from "../api/packed";
import type { ClipPosesJson } from "../api/types";

/** Joint positions of consecutive samples of a clip range. */
export interface PoseData {
  jointNames: string[];
  parents: number[];
  sampleRate: number;
  frames: number;
  /** The range covered, at the clip's own rate, inclusive. */
  firstFrame: number;
  lastFrame: number;
  /** frames x joints x 3, world positions in the clip's units. */
  positions: Float32Array;
}

export function decodePoses(json: ClipPosesJson): Poses {
  return new Poses({
    jointNames: json.joint_names,
    parents: json.parents,
    sampleRate: json.sample_rate,
    frames: json.frames,
    firstFrame: json.first_frame,
    lastFrame: json.last_frame,
    positions: base64ToFloat32(json.positions),
  });
}

export class Poses implements PoseData {
  readonly jointNames: string[];
  readonly parents: number[];
  readonly sampleRate: number;
  readonly frames: number;
  readonly firstFrame: number;
  readonly lastFrame: number;
  readonly positions: Float32Array;

  constructor(data: PoseData) {
    this.jointNames = data.jointNames;
    this.parents = data.parents;
    this.sampleRate = data.sampleRate;
    this.frames = data.frames;
    this.firstFrame = data.firstFrame;
    this.lastFrame = data.lastFrame;
    this.positions = data.positions;
    const expected = this.frames * this.joints * 3;
    if (this.positions.length !== expected) {
      throw new Error(`poses: ${this.positions.length} floats, expected ${expected}`);
    }
  }

  get joints(): number {
    return this.parents.length;
  }

  /** Seconds from the first to the last sample. */
  get duration(): number {
    return this.frames > 1 ? (this.frames - 1) / this.sampleRate : 0;
  }

  /** The sample shown at `seconds` after the range's start (clamped). */
  sampleAt(seconds: number): number {
    const k = Math.round(seconds * this.sampleRate);
    return Math.min(Math.max(k, 0), this.frames - 1);
  }

  /** Offset of joint j of sample k in `positions`. */
  offset(k: number, j: number): number {
    return (k * this.joints + j) * 3;
  }

  /** The extent of every joint over every frame: [min xyz, max xyz]. */
  bounds(): [number[], number[]] {
    const min = [Infinity, Infinity, Infinity];
    const max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < this.positions.length; i++) {
      const axis = i % 3;
      min[axis] = Math.min(min[axis], this.positions[i]);
      max[axis] = Math.max(max[axis], this.positions[i]);
    }
    return [min, max];
  }

  /**
   * The figure's size, for framing it (units of the BVH): the largest extent of a single pose,
   * upwards or across, over a sample of the poses, so that a crouch does not zoom in.
   */
  height(): number {
    let largest = 0;
    for (let k = 0; k < this.frames; k += Math.max(1, Math.floor(this.frames / 50))) {
      const min = [Infinity, Infinity, Infinity];
      const max = [-Infinity, -Infinity, -Infinity];
      for (let j = 0; j < this.joints; j++) {
        for (let axis = 0; axis < 3; axis++) {
          const value = this.positions[this.offset(k, j) + axis];
          min[axis] = Math.min(min[axis], value);
          max[axis] = Math.max(max[axis], value);
        }
      }
      const across = Math.hypot(max[0] - min[0], max[2] - min[2]);
      largest = Math.max(largest, max[1] - min[1], across);
    }
    return largest || 1;
  }
}
