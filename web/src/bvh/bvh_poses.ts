// Forward kinematics of a parsed BVH file, as the server's GetClipPoses computes it: each joint's
// rotation is the product of its rotation channels in file order, a joint's position channels
// replace its offset, and world positions chain from the root. Used to show an uploaded query.
import { Poses } from "../model/poses";
import type { BvhFile, BvhJoint } from "./bvh_file";

type Matrix = number[]; // 3x3, row-major

const IDENTITY: Matrix = [1, 0, 0, 0, 1, 0, 0, 0, 1];

function multiply(a: Matrix, b: Matrix): Matrix {
  const out = new Array<number>(9);
  for (let r = 0; r < 3; r++) {
    for (let c = 0; c < 3; c++) {
      out[r * 3 + c] = a[r * 3] * b[c] + a[r * 3 + 1] * b[3 + c] + a[r * 3 + 2] * b[6 + c];
    }
  }
  return out;
}

function axisRotation(axis: string, degrees: number): Matrix {
  const a = (degrees * Math.PI) / 180;
  const c = Math.cos(a);
  const s = Math.sin(a);
  if (axis === "X") return [1, 0, 0, 0, c, -s, 0, s, c];
  if (axis === "Y") return [c, 0, s, 0, 1, 0, -s, 0, c];
  return [c, -s, 0, s, c, 0, 0, 0, 1];
}

/** A joint's local rotation and translation in one motion row. */
function local(
  joint: BvhJoint,
  row: Float64Array,
  base: number,
): { rotation: Matrix; translation: number[] } {
  let rotation = IDENTITY;
  const translation = [...joint.offset];
  let positioned = false;
  joint.channels.forEach((channel, i) => {
    const value = row[base + joint.firstChannel + i];
    const axis = channel[0].toUpperCase();
    if (/rotation$/i.test(channel)) {
      rotation = multiply(rotation, axisRotation(axis, value));
    } else {
      if (!positioned) translation.fill(0);
      positioned = true;
      translation["XYZ".indexOf(axis)] = value;
    }
  });
  return { rotation, translation };
}

/** The file's poses at most `maxRate` samples a second (every n-th frame). */
export function bvhPoses(file: BvhFile, maxRate: number): Poses {
  const fps = 1 / file.frameTime;
  const step = Math.max(1, Math.ceil(fps / maxRate - 1e-9));
  const samples = Math.floor((file.frames - 1) / step) + 1;
  const joints = file.joints.length;
  const positions = new Float32Array(samples * joints * 3);
  const world: Matrix[] = new Array(joints);
  for (let k = 0; k < samples; k++) {
    const base = k * step * file.channelCount;
    file.joints.forEach((joint, j) => {
      const { rotation, translation } = local(joint, file.motion, base);
      const o = (k * joints + j) * 3;
      if (joint.parent < 0) {
        world[j] = rotation;
        positions.set(translation, o);
        return;
      }
      const parent = world[joint.parent];
      world[j] = multiply(parent, rotation);
      const p = (k * joints + joint.parent) * 3;
      for (let r = 0; r < 3; r++) {
        positions[o + r] =
          positions[p + r] +
          parent[r * 3] * translation[0] +
          parent[r * 3 + 1] * translation[1] +
          parent[r * 3 + 2] * translation[2];
      }
    });
  }
  return new Poses({
    jointNames: file.joints.map((j) => j.name),
    parents: file.joints.map((j) => j.parent),
    sampleRate: fps / step,
    frames: samples,
    firstFrame: 0,
    lastFrame: (samples - 1) * step,
    positions,
  });
}
