// Reads a BVH file far enough to show it: the joint hierarchy (names, parents, offsets, channel
// lists) and the motion rows. The server's reader is the one that validates; this one only
// needs the files the server accepts for a search, and says where it gives up.

export interface BvhJoint {
  name: string;
  parent: number;
  offset: [number, number, number];
  /** Channel names in file order, e.g. Xposition ... Zrotation Xrotation Yrotation. */
  channels: string[];
  /** Index of this joint's first channel in a motion row. */
  firstChannel: number;
}

export interface BvhFile {
  joints: BvhJoint[];
  frames: number;
  frameTime: number;
  /** frames x channels. */
  motion: Float64Array;
  channelCount: number;
}

export function parseBvh(text: string): BvhFile {
  const lines = text.split(/\r?\n/);
  const joints: BvhJoint[] = [];
  const stack: number[] = [];
  let channelCount = 0;
  let inEndSite = false;
  let line = 0;
  for (; line < lines.length; line++) {
    const words = lines[line].trim().split(/\s+/);
    const keyword = words[0].toUpperCase();
    if (keyword === "MOTION") break;
    if (keyword === "ROOT" || keyword === "JOINT") {
      const name = lines[line].trim().slice(words[0].length).trim();
      joints.push({
        name,
        parent: stack.length ? stack[stack.length - 1] : -1,
        offset: [0, 0, 0],
        channels: [],
        firstChannel: channelCount,
      });
    } else if (keyword === "END") {
      inEndSite = true;
    } else if (keyword === "{") {
      if (!inEndSite) stack.push(joints.length - 1);
    } else if (keyword === "}") {
      if (inEndSite) inEndSite = false;
      else stack.pop();
    } else if (keyword === "OFFSET" && !inEndSite && joints.length) {
      joints[joints.length - 1].offset = [Number(words[1]), Number(words[2]), Number(words[3])];
    } else if (keyword === "CHANNELS" && joints.length) {
      const joint = joints[joints.length - 1];
      joint.channels = words.slice(2, 2 + Number(words[1]));
      joint.firstChannel = channelCount;
      channelCount += joint.channels.length;
    }
  }
  if (!joints.length || line >= lines.length)
    throw new Error("not a BVH file: no HIERARCHY joints and MOTION section");
  return { joints, channelCount, ...readMotion(lines.slice(line + 1), channelCount) };
}

function readMotion(
  lines: string[],
  channelCount: number,
): { frames: number; frameTime: number; motion: Float64Array } {
  const timeLine = lines.findIndex((l) => /^\s*frame\s+time\s*:/i.test(l));
  if (timeLine < 0) throw new Error("BVH: no 'Frame Time:' line");
  const frameTime = Number(lines[timeLine].split(":")[1]);
  if (!(frameTime > 0)) throw new Error("BVH: the frame time is not a positive number");
  const values = lines
    .slice(timeLine + 1)
    .join(" ")
    .trim()
    .split(/\s+/)
    .filter(Boolean)
    .map(Number);
  const frames = channelCount ? Math.floor(values.length / channelCount) : 0;
  if (frames < 1) throw new Error("BVH: no motion rows");
  return { frames, frameTime, motion: Float64Array.from(values.slice(0, frames * channelCount)) };
}
