// Motion curves in a space's first three dimensions (thesis 3.3.3), drawn as 3-D lines in one
// plot, each with a marker at the sample playing. Every curve of one plot is in the same space,
// so they share the axes; the plot is scaled to fit them all.
import * as THREE from "three";
import type { Curve } from "../model/curve";
import { ThreeStage } from "./three_stage";

interface Drawn {
  curve: Curve;
  line: THREE.Line;
  marker: THREE.Mesh;
}

export class CurvePlot {
  private readonly stage: ThreeStage;
  private readonly group = new THREE.Group();
  private drawn: Drawn[] = [];
  /** From the space's coordinates to the plot's cube [-1, 1]^3. */
  private toPlot = (p: THREE.Vector3) => p;

  constructor(container: HTMLElement) {
    this.stage = new ThreeStage(container);
    this.stage.scene.add(this.group, axes());
  }

  show(curves: { curve: Curve; color: number }[]): void {
    this.clear();
    const box = new THREE.Box3();
    for (const { curve } of curves) {
      for (let k = 0; k < curve.frames; k++) box.expandByPoint(pointOf(curve, k));
    }
    // Each dimension stretched to the plot's cube: the space's later dimensions carry less
    // variance, and would otherwise look flat.
    const size = box.getSize(new THREE.Vector3()).max(new THREE.Vector3(1e-6, 1e-6, 1e-6));
    this.toPlot = (p) => p.sub(box.getCenter(new THREE.Vector3())).divide(size).multiplyScalar(2);
    for (const { curve, color } of curves) {
      const points: THREE.Vector3[] = [];
      for (let k = 0; k < curve.frames; k++) points.push(this.toPlot(pointOf(curve, k)));
      const line = new THREE.Line(
        new THREE.BufferGeometry().setFromPoints(points),
        new THREE.LineBasicMaterial({ color }),
      );
      const marker = new THREE.Mesh(
        new THREE.SphereGeometry(0.05, 12, 8),
        new THREE.MeshBasicMaterial({ color: 0xffffff }),
      );
      this.group.add(line, marker);
      this.drawn.push({ curve, line, marker });
    }
    this.stage.frame(new THREE.Vector3(), 3.6, new THREE.Vector3(1.4, 0.9, 1.6));
    this.mark(this.drawn.map(() => 0));
  }

  /** Puts curve i's marker on its sample samples[i]. */
  mark(samples: number[]): void {
    this.drawn.forEach(({ curve, marker }, i) => {
      const k = Math.min(Math.max(samples[i] ?? 0, 0), curve.frames - 1);
      marker.position.copy(this.toPlot(pointOf(curve, k)));
    });
    this.stage.requestRender();
  }

  clear(): void {
    for (const { line, marker } of this.drawn) {
      this.group.remove(line, marker);
      line.geometry.dispose();
      (line.material as THREE.Material).dispose();
      marker.geometry.dispose();
      (marker.material as THREE.Material).dispose();
    }
    this.drawn = [];
    this.stage.requestRender();
  }
}

function pointOf(curve: Curve, k: number): THREE.Vector3 {
  return new THREE.Vector3(curve.at(k, 0), curve.at(k, 1), curve.at(k, 2));
}

/** The first three dimensions as red, green and blue axes through the plot's centre. */
function axes(): THREE.Object3D {
  const helper = new THREE.AxesHelper(1.2);
  (helper.material as THREE.Material).transparent = true;
  (helper.material as THREE.Material).opacity = 0.5;
  return helper;
}
