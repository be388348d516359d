// SPDX-License-Identifier: GPL-3.0-or-later
// The 3D view: the loaded program's toolpath (feeds solid, rapids dashed), the soft-limit box,
// the live tool position and the path already cut (the tool's trail).
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import type { Machine } from "./types";

export interface Preview {
  polylines: { rapid: boolean; points: number[] }[];
  moves: number;
  truncated: boolean;
  /** The tools the program puts in the spindle. */
  tools?: number[];
}

const kTrail = 20000;  // points of the path cut kept

export class View3d {
  private renderer: THREE.WebGLRenderer;
  private scene = new THREE.Scene();
  private camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100000);
  private controls: OrbitControls;
  private path = new THREE.Group();
  private tool: THREE.Mesh;
  private trail: THREE.Line;
  private trailPositions = new Float32Array(kTrail * 3);
  private trailCount = 0;
  private limits?: THREE.LineSegments;

  constructor(private host: HTMLElement) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setClearColor(0x101418);
    host.append(this.renderer.domElement);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(150, -200, 200);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.scene.add(this.path);
    this.scene.add(new THREE.AxesHelper(20));
    this.tool = new THREE.Mesh(new THREE.ConeGeometry(2, 8, 16), new THREE.MeshBasicMaterial({ color: 0xffcc00 }));
    this.tool.rotation.x = -Math.PI / 2;  // the cone's tip down, at the tool point
    this.tool.geometry.translate(0, -4, 0);
    this.scene.add(this.tool);
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(this.trailPositions, 3));
    g.setDrawRange(0, 0);
    this.trail = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0xff5533 }));
    this.scene.add(this.trail);
    new ResizeObserver(() => this.resize()).observe(host);
    const loop = () => {
      this.controls.update();
      this.renderer.render(this.scene, this.camera);
      requestAnimationFrame(loop);
    };
    loop();
  }

  private resize() {
    const w = this.host.clientWidth || 400, h = this.host.clientHeight || 300;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  /** The soft-limit box of the machine's X Y Z. */
  setMachine(m: Machine) {
    const lim = (a: string) => m.axes.find((x) => x.axis === a);
    const x = lim("X"), y = lim("Y"), z = lim("Z");
    if (!x || !y || !z) return;
    const box = new THREE.Box3(new THREE.Vector3(x.min_limit, y.min_limit, z.min_limit), new THREE.Vector3(x.max_limit, y.max_limit, z.max_limit));
    if (this.limits) this.scene.remove(this.limits);
    this.limits = new THREE.LineSegments(
      new THREE.EdgesGeometry(new THREE.BoxGeometry(...box.getSize(new THREE.Vector3()).toArray())),
      new THREE.LineBasicMaterial({ color: 0x446688 }),
    );
    this.limits.position.copy(box.getCenter(new THREE.Vector3()));
    this.scene.add(this.limits);
  }

  /** The program's toolpath; the camera frames it. */
  setPreview(p: Preview) {
    this.path.clear();
    const bounds = new THREE.Box3();
    for (const pl of p.polylines) {
      const g = new THREE.BufferGeometry();
      g.setAttribute("position", new THREE.Float32BufferAttribute(pl.points, 3));
      g.computeBoundingBox();
      if (g.boundingBox) bounds.union(g.boundingBox);
      const material = pl.rapid
        ? new THREE.LineDashedMaterial({ color: 0x55aa55, dashSize: 2, gapSize: 2 })
        : new THREE.LineBasicMaterial({ color: 0x55aaff });
      const line = new THREE.Line(g, material);
      if (pl.rapid) line.computeLineDistances();
      this.path.add(line);
    }
    this.clearTrail();
    if (!bounds.isEmpty()) {
      const c = bounds.getCenter(new THREE.Vector3());
      const size = Math.max(...bounds.getSize(new THREE.Vector3()).toArray(), 10);
      this.controls.target.copy(c);
      this.camera.position.set(c.x + size * 0.8, c.y - size * 1.2, c.z + size);
    }
  }

  /** The tool where the machine is; the trail grows while it cuts. */
  setTool(x: number, y: number, z: number, cutting: boolean) {
    this.tool.position.set(x, y, z);
    if (!cutting) return;
    const n = this.trailCount;
    if (n > 0) {
      const i = (n - 1) * 3, p = this.trailPositions;
      if (Math.abs(p[i] - x) + Math.abs(p[i + 1] - y) + Math.abs(p[i + 2] - z) < 0.01) return;
    }
    if (n >= kTrail) return;
    this.trailPositions.set([x, y, z], n * 3);
    this.trailCount = n + 1;
    this.trail.geometry.setDrawRange(0, this.trailCount);
    this.trail.geometry.attributes.position.needsUpdate = true;
  }

  clearTrail() {
    this.trailCount = 0;
    this.trail.geometry.setDrawRange(0, 0);
  }
}
