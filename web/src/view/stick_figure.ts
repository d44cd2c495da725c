// A skeleton drawn as bones (a line from each joint to its parent) and joints (points),
// updated in place from one sample of a Poses.
import * as THREE from "three";
import type { Poses } from "../model/poses";

export class StickFigure {
  readonly object = new THREE.Group();
  private readonly bonePositions: Float32Array;
  private readonly jointPositions: Float32Array;
  private readonly bones: THREE.LineSegments;
  private readonly joints: THREE.Points;
  private readonly pairs: [number, number][] = [];

  constructor(
    private readonly poses: Poses,
    color: number,
    jointSize: number,
  ) {
    poses.parents.forEach((parent, joint) => {
      if (parent >= 0) this.pairs.push([joint, parent]);
    });
    this.bonePositions = new Float32Array(this.pairs.length * 6);
    this.jointPositions = new Float32Array(poses.joints * 3);
    this.bones = new THREE.LineSegments(
      geometryOf(this.bonePositions),
      new THREE.LineBasicMaterial({ color }),
    );
    this.joints = new THREE.Points(
      geometryOf(this.jointPositions),
      new THREE.PointsMaterial({ color: 0xffffff, size: jointSize, sizeAttenuation: true }),
    );
    this.bones.frustumCulled = false;
    this.joints.frustumCulled = false;
    this.object.add(this.bones, this.joints);
  }

  /** Shows sample k. */
  pose(k: number): void {
    const source = this.poses.positions;
    this.jointPositions.set(source.subarray(this.poses.offset(k, 0), this.poses.offset(k + 1, 0)));
    this.pairs.forEach(([joint, parent], i) => {
      this.bonePositions.set(
        source.subarray(this.poses.offset(k, joint), this.poses.offset(k, joint) + 3),
        i * 6,
      );
      this.bonePositions.set(
        source.subarray(this.poses.offset(k, parent), this.poses.offset(k, parent) + 3),
        i * 6 + 3,
      );
    });
    this.bones.geometry.attributes.position.needsUpdate = true;
    this.joints.geometry.attributes.position.needsUpdate = true;
  }

  /** The root joint's position in sample k. */
  root(k: number): THREE.Vector3 {
    const o = this.poses.offset(k, 0);
    const p = this.poses.positions;
    return new THREE.Vector3(p[o], p[o + 1], p[o + 2]);
  }

  dispose(): void {
    this.bones.geometry.dispose();
    this.joints.geometry.dispose();
    (this.bones.material as THREE.Material).dispose();
    (this.joints.material as THREE.Material).dispose();
  }
}

function geometryOf(positions: Float32Array): THREE.BufferGeometry {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(positions, 3));
  return geometry;
}
