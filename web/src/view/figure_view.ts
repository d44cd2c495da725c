// A pane's 3-D stick figure: the skeleton on a ground grid, the camera orbiting it (drag to
// turn, wheel to zoom) and following the root across the floor.
import * as THREE from "three";
import type { Poses } from "../model/poses";
import { StickFigure } from "./stick_figure";
import { ThreeStage } from "./three_stage";

export class FigureView {
  private readonly stage: ThreeStage;
  private figure: StickFigure | null = null;
  private grid: THREE.GridHelper | null = null;
  private shownSample = -1;
  private followed = new THREE.Vector3();

  constructor(
    container: HTMLElement,
    private readonly color: number,
  ) {
    this.stage = new ThreeStage(container);
    this.stage.scene.add(new THREE.AmbientLight(0xffffff, 1));
  }

  show(poses: Poses): void {
    this.clear();
    const height = poses.height();
    const [min, max] = poses.bounds();
    this.figure = new StickFigure(poses, this.color, height / 45);
    this.stage.scene.add(this.figure.object);
    // Cells a third of the figure's height, over the whole floor the motion covers.
    const cell = height / 3;
    const cells = Math.min(
      400,
      Math.ceil((Math.max(max[0] - min[0], max[2] - min[2]) + 4 * height) / cell),
    );
    this.grid = new THREE.GridHelper(cells * cell, cells, 0x3a4350, 0x262c35);
    this.grid.position.set((min[0] + max[0]) / 2, min[1], (min[2] + max[2]) / 2);
    this.stage.scene.add(this.grid);
    this.shownSample = -1;
    this.pose(0);
    this.followed = this.figure.root(0);
    const target = this.followed.clone();
    target.y = min[1] + height / 2;
    this.stage.frame(target, height * 1.9);
  }

  /** Shows sample k of the poses last shown. */
  pose(k: number): void {
    if (!this.figure || k === this.shownSample) return;
    this.figure.pose(k);
    this.shownSample = k;
    const root = this.figure.root(k);
    const delta = new THREE.Vector3(root.x - this.followed.x, 0, root.z - this.followed.z);
    if (delta.lengthSq() > 0) {
      this.stage.follow(delta);
      this.followed.add(delta);
    }
    this.stage.requestRender();
  }

  clear(): void {
    if (this.figure) {
      this.stage.scene.remove(this.figure.object);
      this.figure.dispose();
      this.figure = null;
    }
    if (this.grid) {
      this.stage.scene.remove(this.grid);
      this.grid.dispose();
      this.grid = null;
    }
    this.stage.requestRender();
  }

  dispose(): void {
    this.clear();
    this.stage.dispose();
  }
}
