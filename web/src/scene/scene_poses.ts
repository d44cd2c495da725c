// An uploaded FBX or glTF query, shown from the file itself (it is not stored): three.js's
// loaders read it, and the nodes its animation moves, joined up to the smallest tree that holds
// them (the skeleton the server reads, core/scene/scene_reader.h), are sampled into joint
// positions. Loaded on first use, as the stage is.
import { AnimationMixer, PropertyBinding, Vector3, type AnimationClip, type Object3D } from "three";
import { FBXLoader } from "three/examples/jsm/loaders/FBXLoader.js";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { Poses } from "../model/poses";

export interface SceneTake {
  poses: Poses;
  /** The take's frames at its own rate: the spacing of its keys. */
  frameCount: number;
  fps: number;
  jointCount: number;
}

async function load(
  bytes: Uint8Array,
  format: "fbx" | "glb" | "gltf",
): Promise<{ root: Object3D; clips: AnimationClip[] }> {
  const buffer = bytes.slice().buffer;
  if (format === "fbx") {
    const group = new FBXLoader().parse(buffer, "");
    return { root: group, clips: group.animations };
  }
  const gltf = await new GLTFLoader().parseAsync(buffer, "");
  return { root: gltf.scene, clips: gltf.animations };
}

/** The nodes a clip's tracks move, in the order of their first track. */
function animatedNodes(root: Object3D, clip: AnimationClip): Object3D[] {
  const nodes = new Set<Object3D>();
  for (const track of clip.tracks) {
    const { nodeName } = PropertyBinding.parseTrackName(track.name);
    const node = PropertyBinding.findNode(root, nodeName) as Object3D | undefined;
    if (node) nodes.add(node);
  }
  return [...nodes];
}

function pathFromRoot(node: Object3D): Object3D[] {
  const path: Object3D[] = [];
  for (let n: Object3D | null = node; n; n = n.parent) path.unshift(n);
  return path;
}

/** The smallest tree holding every animated node: their common ancestor and the paths to them. */
function skeletonOf(animated: Object3D[]): { joints: Object3D[]; parents: number[] } {
  const paths = animated.map(pathFromRoot);
  let common = 0;
  while (paths.every((p) => common < p.length && p[common] === paths[0][common])) common++;
  const members = new Set<Object3D>();
  for (const path of paths)
    for (const node of path.slice(Math.max(common - 1, 0))) members.add(node);
  const joints: Object3D[] = [];
  const parents: number[] = [];
  const visit = (node: Object3D, parent: number) => {
    if (!members.has(node)) return;
    joints.push(node);
    const index = joints.length - 1;
    parents.push(parent);
    for (const child of node.children) visit(child, index);
  };
  visit(paths[0][Math.max(common - 1, 0)], -1);
  return { joints, parents };
}

/** The take's frame rate: the smallest spacing of its keys, as the server reads it. */
function keyRate(clip: AnimationClip): number {
  let step = Infinity;
  for (const track of clip.tracks) {
    for (let i = 1; i < track.times.length; i++) {
      const gap = track.times[i] - track.times[i - 1];
      if (gap > 1e-6) step = Math.min(step, gap);
    }
  }
  return Number.isFinite(step) ? 1 / step : 30;
}

/** The file's one take as poses sampled at `maxRate` at most. */
export async function scenePoses(
  fileName: string,
  bytes: Uint8Array,
  format: "fbx" | "glb" | "gltf",
  maxRate: number,
): Promise<SceneTake> {
  const { root, clips } = await load(bytes, format);
  if (!clips.length) throw new Error(`${fileName} holds no animation to search with`);
  if (clips.length > 1) {
    throw new Error(
      `${fileName} holds ${clips.length} takes; a search asks with one: add the file to the library and search with a range of a take`,
    );
  }
  const clip = clips[0];
  const animated = animatedNodes(root, clip);
  if (!animated.length) throw new Error(`${fileName}'s animation moves no node of the file`);
  const { joints, parents } = skeletonOf(animated);
  const fps = keyRate(clip);
  const frameCount = Math.round(clip.duration * fps) + 1;
  const sampleRate = Math.min(fps, maxRate);
  const samples = Math.floor(clip.duration * sampleRate + 1e-6) + 1;
  const positions = new Float32Array(samples * joints.length * 3);
  const mixer = new AnimationMixer(root);
  mixer.clipAction(clip).play();
  const at = new Vector3();
  for (let k = 0; k < samples; k++) {
    mixer.setTime(k / sampleRate);
    root.updateMatrixWorld(true);
    joints.forEach((joint, j) => {
      joint.getWorldPosition(at);
      positions.set([at.x, at.y, at.z], (k * joints.length + j) * 3);
    });
  }
  const poses = new Poses({
    jointNames: joints.map((j) => j.name),
    parents,
    sampleRate,
    frames: samples,
    firstFrame: 0,
    lastFrame: frameCount - 1,
    positions,
  });
  return { poses, frameCount, fps, jointCount: joints.length };
}
