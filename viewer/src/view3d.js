// The 3-D view: links between their joints, joints drawn by type, the fixed frame and the
// world axes, traces and load arrows, with three.js and its OrbitControls. The scene graph is
// built even where WebGL is missing (then only the picture is absent, with a message).
// Each link is a polyline of link_points.shape[2] points (3 for a loop; a body of a graph
// goes round all its joints and points); a mechanism's scene also lists its loops, and
// setLoop(k) draws the joints and bodies outside loop k faint.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { point } from './data.js';

const Y = new THREE.Vector3(0, 1, 0);
const LINK_COLOURS = [0x2f6db5, 0x2a9d8f, 0x8e6cc0, 0xc9853a, 0x4f8a3c, 0xb5485d, 0x5c7c99];
const JOINT_COLOUR = 0x37474f;
const INPUT_COLOUR = 0xe07020;
const GROUND_COLOUR = 0x9e9e9e;
const TRACE_COLOURS = [0x6fa8dc, 0x76c7b7, 0xb4a7d6, 0xf6b26b, 0x93c47d, 0xe06666];
const ARROW_COLOURS = [0xd32f2f, 0xf57c00, 0x388e3c, 0x7b1fa2, 0x0288d1, 0x5d4037, 0xc2185b];
const FAINT = 0.12;

// Opacity of every material under obj: its own (as built, kept in material.userData) times
// `factor`; materials shared by several meshes are set once per call, to the same value.
function fade(obj, factor) {
  obj.traverse((o) => {
    const m = o.material;
    if (!m) return;
    if (m.userData.opacity === undefined) {
      m.userData.opacity = m.opacity;
      m.userData.transparent = m.transparent;
    }
    m.opacity = m.userData.opacity * factor;
    m.transparent = m.userData.transparent || factor < 1;
    m.needsUpdate = true;
  });
}

// Free the geometries and materials of a group's children, then remove them.
function clearGroup(group) {
  group.traverse((o) => {
    if (o === group) return;
    if (o.geometry) o.geometry.dispose();
    if (o.material) o.material.dispose();
  });
  group.clear();
}

function niceStep(x) {
  const p = Math.pow(10, Math.floor(Math.log10(x)));
  const m = x / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

function textSprite(text, size, colour) {
  const canvas = document.createElement('canvas');
  const ctx = canvas.getContext('2d');
  const font = 'bold 40px sans-serif';
  ctx.font = font;
  const w = Math.ceil(ctx.measureText(text).width) + 16;
  canvas.width = w;
  canvas.height = 56;
  ctx.font = font;
  ctx.fillStyle = colour;
  ctx.textBaseline = 'middle';
  ctx.fillText(text, 8, 28);
  const tex = new THREE.CanvasTexture(canvas);
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: tex, depthTest: false, transparent: true }));
  sprite.scale.set((size * w) / 56, size, 1);
  sprite.renderOrder = 10;
  return sprite;
}

// A unit cylinder along +Y, stretched between two points.
function placeSegment(mesh, a, b) {
  if (!a || !b) { mesh.visible = false; return; }
  const d = new THREE.Vector3(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
  const len = d.length();
  if (len < 1e-12) { mesh.visible = false; return; }
  mesh.visible = true;
  mesh.position.set((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
  mesh.quaternion.setFromUnitVectors(Y, d.divideScalar(len));
  mesh.scale.set(1, len, 1);
}

function orient(obj, axis) {
  if (!axis) return;
  const v = new THREE.Vector3(axis[0], axis[1], axis[2]);
  if (v.lengthSq() < 1e-24) return;
  obj.quaternion.setFromUnitVectors(Y, v.normalize());
}

export class MechanismView {
  constructor(container, scene) {
    this.sceneData = scene;
    this.container = container;
    this.dirty = true;
    this.showTraces = true;
    this.showArrows = true;
    this.modeIndex = 0;
    this.frame = 0;
    this.loopIndex = -1;
    this.three = new THREE.Scene();
    this.three.background = new THREE.Color(0xffffff);
    this.measure();
    this.camera = new THREE.PerspectiveCamera(40, 1, this.size / 200, this.size * 200);
    this.camera.up.set(0, 0, 1);
    this.renderer = null;
    try {
      this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
      this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
      container.appendChild(this.renderer.domElement);
    } catch (err) {
      const msg = document.createElement('p');
      msg.className = 'sk-nogl';
      msg.textContent = 'This browser cannot draw WebGL, so the 3-D view is not shown; the plots and the controls still work.';
      container.appendChild(msg);
      console.warn('screwkit viewer: no WebGL', err);
    }
    this.controls = this.renderer ? new OrbitControls(this.camera, this.renderer.domElement) : null;
    if (this.controls) this.controls.addEventListener('change', () => { this.dirty = true; });
    this.three.add(new THREE.AmbientLight(0xffffff, 0.65));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(1, -2, 3);
    this.camera.add(sun);
    this.three.add(this.camera);
    this.buildStatic();
    this.buildMechanism();
    this.setView('iso');
    this.resize();
    if (typeof ResizeObserver !== 'undefined') new ResizeObserver(() => this.resize()).observe(container);
  }

  // Size and centre of everything drawn, over every mode and frame.
  measure() {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const m of this.sceneData.modes) {
      const c = m.joint_centres;
      for (let k = 0; k < c.length; k++) {
        const v = c[k];
        if (Number.isFinite(v)) { lo[k % 3] = Math.min(lo[k % 3], v); hi[k % 3] = Math.max(hi[k % 3], v); }
      }
    }
    for (const link of (this.sceneData.ghost ? this.sceneData.ghost.link_points : [])) {
      for (const p of link) {
        if (p) for (let a = 0; a < 3; a++) if (Number.isFinite(p[a])) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
      }
    }
    for (let a = 0; a < 3; a++) if (!(hi[a] >= lo[a])) { lo[a] = -0.5; hi[a] = 0.5; }
    this.centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
    this.size = Math.max(Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), 1e-6);
    // joints are drawn in proportion to the links (the median joint-to-joint distance of the
    // first assembled frame), not to the whole sweep, which long slides can make large
    const m0 = this.sceneData.modes[0];
    const i0 = Math.max(0, m0.assembles.indexOf(true));
    const n = this.sceneData.joints.length;
    const spans = [];
    for (let j = 0; j < n; j++) {
      const a = point(m0.joint_centres, i0, j), b = point(m0.joint_centres, i0, (j + 1) % n);
      if (a && b) { const d = Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]); if (d > 1e-9 * this.size) spans.push(d); }
    }
    spans.sort((a, b) => a - b);
    const typical = spans.length ? spans[Math.floor(spans.length / 2)] : this.size / 4;
    this.jointSize = Math.min(typical / 3.5, 0.1 * this.size);
  }

  material(colour, opts = {}) {
    return new THREE.MeshStandardMaterial({ color: colour, metalness: 0.15, roughness: 0.55, ...opts });
  }

  buildStatic() {
    const s = this.size;
    const units = this.sceneData.display_units;
    const stepDisplay = niceStep((s * units.factor) / 6);
    const step = stepDisplay / units.factor;
    const grid = new THREE.GridHelper(step * 12, 12, 0xbdbdbd, 0xe6e6e6);
    grid.rotation.x = Math.PI / 2;  // the XY plane (z is up)
    grid.position.set(Math.round(this.centre.x / step) * step, Math.round(this.centre.y / step) * step, 0);
    this.three.add(grid);
    this.gridStep = `${+stepDisplay.toPrecision(3)} ${units.length}`;
    // world axes at the origin, labelled
    const L = 0.35 * s;
    const world = new THREE.AxesHelper(L);
    world.material.depthTest = false;
    world.renderOrder = 5;
    this.three.add(world);
    const names = ['x', 'y', 'z'], colours = ['#d32f2f', '#388e3c', '#1976d2'];
    for (let a = 0; a < 3; a++) {
      const sp = textSprite(names[a], 0.05 * s, colours[a]);
      const p = [0, 0, 0]; p[a] = 1.08 * L;
      sp.position.set(p[0], p[1], p[2]);
      this.three.add(sp);
    }
    // the fixed (ground) frame of the loop: a smaller triad with a base plate
    const ff = this.sceneData.fixed_frame;
    const R = ff.rotation, o = ff.origin;
    const m = new THREE.Matrix4().set(R[0][0], R[0][1], R[0][2], o[0], R[1][0], R[1][1], R[1][2], o[1],
      R[2][0], R[2][1], R[2][2], o[2], 0, 0, 0, 1);
    const fixed = new THREE.Group();
    fixed.applyMatrix4(m);
    const triad = new THREE.AxesHelper(0.18 * s);
    fixed.add(triad);
    const plate = new THREE.Mesh(new THREE.BoxGeometry(1.6 * this.jointSize, 1.6 * this.jointSize, 0.08 * this.jointSize),
      this.material(GROUND_COLOUR, { transparent: true, opacity: 0.5 }));
    fixed.add(plate);
    const label = textSprite('fixed frame', 0.035 * s, '#616161');
    label.position.set(0.02 * s, -0.06 * s, 0);
    fixed.add(label);
    this.three.add(fixed);
    // a still ghost of another mechanism (a synthesis's start): thin faded lines
    const ghost = this.sceneData.ghost;
    if (ghost) {
      const mat = new THREE.LineBasicMaterial({ color: 0x8d8d8d, transparent: true, opacity: 0.6 });
      for (const link of ghost.link_points) {
        const pts = link.filter((p) => p && p.every(Number.isFinite)).map((p) => new THREE.Vector3(p[0], p[1], p[2]));
        if (pts.length > 1) this.three.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), mat));
      }
    }
  }

  jointObject(joint) {
    const s = this.size;
    const r = 0.25 * this.jointSize, h = this.jointSize;
    const mat = this.material(joint.input ? INPUT_COLOUR : JOINT_COLOUR);
    const g = new THREE.Group();
    const parts = { group: g, second: null, rail: null };
    const cyl = (radius, height, m = mat, open = false) =>
      new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, height, 28, 1, open), m);
    switch (joint.kind) {
      case 'R': g.add(cyl(r, h)); break;
      case 'P':
        g.add(new THREE.Mesh(new THREE.BoxGeometry(2.2 * r, 1.3 * h, 2.2 * r), mat));
        break;
      case 'C': {
        g.add(cyl(1.5 * r, 1.1 * h, this.material(joint.input ? INPUT_COLOUR : JOINT_COLOUR,
          { side: THREE.DoubleSide, transparent: true, opacity: 0.85 }), true));
        g.add(cyl(0.7 * r, 1.5 * h));
        break;
      }
      case 'H': {
        g.add(cyl(0.8 * r, 1.4 * h));
        const turns = 3, radius = 1.25 * r;
        const pts = [];
        for (let k = 0; k <= 96; k++) {
          const t = (k / 96) * turns * 2 * Math.PI;
          pts.push(new THREE.Vector3(radius * Math.cos(t), (k / 96 - 0.5) * 1.2 * h, radius * Math.sin(t)));
        }
        const helix = new THREE.Mesh(new THREE.TubeGeometry(new THREE.CatmullRomCurve3(pts), 192, 0.18 * r, 8, false),
          this.material(0xb71c1c));
        g.add(helix);
        const u = this.sceneData.display_units;
        const sp = textSprite(`H pitch ${+(joint.pitch * u.factor).toPrecision(3)} ${u.length}/rad`, 0.03 * s, '#b71c1c');
        sp.position.set(2 * r, 0.8 * h, 0);
        g.add(sp);
        break;
      }
      case 'U': {
        g.add(cyl(0.8 * r, 1.2 * h));
        parts.second = cyl(0.8 * r, 1.2 * h, this.material(0x5d6d7e));
        break;
      }
      default:  // S
        g.add(new THREE.Mesh(new THREE.SphereGeometry(1.5 * r, 32, 16), mat));
    }
    if (joint.kind === 'P' || joint.kind === 'C' || joint.kind === 'H') {
      // the joint's travel: from its centre (proximal side) to where the next link leaves it
      parts.rail = cyl(0.45 * r, 1, this.material(joint.input ? INPUT_COLOUR : 0x78909c));
    }
    return parts;
  }

  buildMechanism() {
    this.mechanism = new THREE.Group();
    this.three.add(this.mechanism);
    this.joints = this.sceneData.joints.map((j) => {
      const parts = this.jointObject(j);
      this.mechanism.add(parts.group);
      if (parts.second) this.mechanism.add(parts.second);
      if (parts.rail) this.mechanism.add(parts.rail);
      return parts;
    });
    const seg = new THREE.CylinderGeometry(1, 1, 1, 16);
    const nSegments = this.sceneData.modes[0].link_points.shape[2] - 1;
    this.links = this.sceneData.links.map((link, k) => {
      const radius = (link.ground ? 0.06 : 0.1) * this.jointSize;
      // one material per link, so that a link can be drawn faint on its own
      const mat = this.material(link.ground ? GROUND_COLOUR : LINK_COLOURS[k % LINK_COLOURS.length]);
      const parts = [];
      for (let q = 0; q < nSegments; q++) {
        const m = new THREE.Mesh(seg, mat);
        m.scale.set(radius, 1, radius);
        m.userData.radius = radius;
        this.mechanism.add(m);
        parts.push(m);
      }
      return parts;
    });
    this.traceGroup = new THREE.Group();
    this.three.add(this.traceGroup);
    this.arrowGroup = new THREE.Group();
    this.three.add(this.arrowGroup);
  }

  setMode(k) {
    this.modeIndex = k;
    const mode = this.sceneData.modes[k];
    // traces: every joint centre and every extra point, split where the mode does not assemble
    clearGroup(this.traceGroup);
    const N = this.sceneData.input.values.length;
    const closed = this.sceneData.input.periodic;
    const addTrace = (get, colour, opacity) => {
      let pts = [];
      const flush = () => {
        if (pts.length > 1) {
          const geom = new THREE.BufferGeometry().setFromPoints(pts);
          this.traceGroup.add(new THREE.Line(geom, new THREE.LineBasicMaterial({ color: colour, transparent: true, opacity })));
        }
        pts = [];
      };
      for (let i = 0; i < N + (closed ? 1 : 0); i++) {
        const p = get(i % N);
        if (p) pts.push(new THREE.Vector3(p[0], p[1], p[2])); else flush();
      }
      flush();
    };
    this.sceneData.joints.forEach((j, jj) => addTrace((i) => point(mode.joint_centres, i, jj),
      TRACE_COLOURS[jj % TRACE_COLOURS.length], 0.8));
    for (const name of Object.keys(mode.traces || {})) {
      const arr = mode.traces[name];
      arr.shape = [arr.shape[0], 1, 3];
      addTrace((i) => point(arr, i, 0), 0xc2185b, 1.0);
    }
    // arrows: one per load, scaled together so that the largest force over the cycle is half
    // the mechanism's size
    clearGroup(this.arrowGroup);
    this.arrows = [];
    let fmax = 0;
    const names = Object.keys(mode.arrows || {});
    for (const name of names) {
      const v = mode.arrows[name].vectors;
      for (let i = 0; i < v.length / 3; i++) {
        const m = Math.hypot(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        if (Number.isFinite(m)) fmax = Math.max(fmax, m);
      }
    }
    this.arrowScale = fmax > 0 ? (0.5 * this.size) / fmax : 0;
    names.forEach((name, q) => {
      const colour = ARROW_COLOURS[q % ARROW_COLOURS.length];
      const helper = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 1, colour);
      helper.line.material.depthTest = false;
      helper.cone.material.depthTest = false;
      helper.renderOrder = 6;
      this.arrowGroup.add(helper);
      const data = mode.arrows[name];
      data.vectors.shape = [data.vectors.length / 3, 1, 3];
      data.points.shape = [data.points.length / 3, 1, 3];
      this.arrows.push({ name, helper, data, colour: '#' + colour.toString(16).padStart(6, '0') });
    });
    this.applyVisibility();
    this.dirty = true;
  }

  applyVisibility() {
    this.traceGroup.visible = this.showTraces;
    this.arrowGroup.visible = this.showArrows;
    this.dirty = true;
  }

  // Place everything at frame i of the current mode; returns whether the mode assembles there.
  setFrame(i) {
    this.frame = i;
    const mode = this.sceneData.modes[this.modeIndex];
    const ok = mode.assembles[i];
    this.mechanism.visible = ok;  // never draw a loop that does not close
    if (ok) {
      this.sceneData.joints.forEach((j, jj) => {
        const parts = this.joints[jj];
        const c = point(mode.joint_centres, i, jj);
        const axis = point(mode.joint_axes, i, jj);
        parts.group.position.set(c[0], c[1], c[2]);
        orient(parts.group, axis);
        if (parts.second) {
          parts.second.position.set(c[0], c[1], c[2]);
          orient(parts.second, point(mode.second_axes, i, jj));
        }
        if (parts.rail) {
          // the travel ends where the distal link leaves the joint: rail_ends when the scene
          // has them (a graph), else the first point of link jj (a loop)
          let end;
          if (mode.rail_ends) end = point(mode.rail_ends, i, jj);
          else {
            const lp = mode.link_points;
            const k = ((i * lp.shape[1] + jj) * lp.shape[2]) * 3;
            end = [lp[k], lp[k + 1], lp[k + 2]];
          }
          placeSegment(parts.rail, c, end);
          const rr = 0.45 * 0.25 * this.jointSize;
          parts.rail.scale.x = rr; parts.rail.scale.z = rr;
        }
      });
      const lp = mode.link_points;
      const n = lp.shape[1], P = lp.shape[2];
      this.links.forEach((parts, k) => {
        const base = ((i * n + k) * P) * 3;
        const p = (q) => [lp[base + 3 * q], lp[base + 3 * q + 1], lp[base + 3 * q + 2]];
        parts.forEach((m, q) => {
          placeSegment(m, p(q), p(q + 1));
          m.scale.x = m.userData.radius; m.scale.z = m.userData.radius;
        });
      });
    }
    for (const arrow of this.arrows || []) {
      const v = point(arrow.data.vectors, i, 0), p = point(arrow.data.points, i, 0);
      const mag = v ? Math.hypot(v[0], v[1], v[2]) : 0;
      if (!ok || !v || !p || !(mag > 0) || !(this.arrowScale > 0)) { arrow.helper.visible = false; continue; }
      arrow.helper.visible = true;
      arrow.helper.position.set(p[0], p[1], p[2]);
      arrow.helper.setDirection(new THREE.Vector3(v[0] / mag, v[1] / mag, v[2] / mag));
      const len = Math.max(mag * this.arrowScale, 1e-9);
      arrow.helper.setLength(len, Math.min(0.2 * len, 0.05 * this.size), Math.min(0.1 * len, 0.025 * this.size));
    }
    this.dirty = true;
    return ok;
  }

  // Whether `scene` draws the same mechanism (joints, links, link polylines, samples) as the
  // shown one, so that update(scene) can replace its frames in place.
  sameShape(scene) {
    const a = this.sceneData, b = scene;
    return a.joints.length === b.joints.length && a.links.length === b.links.length
      && a.joints.every((j, k) => j.kind === b.joints[k].kind && j.input === b.joints[k].input)
      && a.input.values.length === b.input.values.length && b.modes.length > 0
      && b.modes.every((m) => m.link_points.shape[2] === a.modes[0].link_points.shape[2]);
  }

  // Take the frames of another scene of the same mechanism (sameShape) without rebuilding the
  // view: the camera, the grid and the joint sizes stay; setMode then redraws the traces and
  // arrows.
  update(scene) {
    this.sceneData = scene;
    if (this.loopIndex >= (scene.loops || []).length) this.setLoop(-1);
  }

  // Draw the joints and links outside loop k faint (k = -1: every part in full).
  setLoop(k) {
    const loops = this.sceneData.loops || [];
    if (!(k === -1 || (k >= 0 && k < loops.length))) throw new RangeError(`loop ${k} out of range`);
    this.loopIndex = k;
    const joints = k < 0 ? null : new Set(loops[k].joints);
    const links = k < 0 ? null : new Set(loops[k].links);
    this.joints.forEach((parts, jj) => {
      const f = !joints || joints.has(jj) ? 1 : FAINT;
      for (const o of [parts.group, parts.second, parts.rail]) if (o) fade(o, f);
    });
    this.links.forEach((parts, kk) => {
      const f = !links || links.has(kk) ? 1 : FAINT;
      for (const m of parts) fade(m, f);
    });
    this.dirty = true;
  }

  // Indices of the joints drawn in full (not faint).
  fullJoints() {
    const out = [];
    this.joints.forEach((parts, jj) => {
      let full = true;
      parts.group.traverse((o) => { const m = o.material; if (m && m.userData.opacity !== undefined && m.opacity < m.userData.opacity) full = false; });
      if (full) out.push(jj);
    });
    return out;
  }

  // Joint centres as drawn (metres), or nulls where the mode does not assemble.
  drawnJointCentres() {
    return this.joints.map((parts) => (this.mechanism.visible
      ? [parts.group.position.x, parts.group.position.y, parts.group.position.z] : null));
  }

  setView(name) {
    const d = 1.75 * this.size;
    const dirs = { front: [0, -1, 0], side: [1, 0, 0], top: [0, -1e-3, 1], iso: [1, -1, 0.8] };
    const v = new THREE.Vector3(...(dirs[name] || dirs.iso)).normalize().multiplyScalar(d);
    this.camera.position.copy(this.centre).add(v);
    this.camera.lookAt(this.centre);
    if (this.controls) { this.controls.target.copy(this.centre); this.controls.update(); }
    this.dirty = true;
  }

  resize() {
    if (!this.renderer) return;
    const w = Math.max(this.container.clientWidth, 50), h = Math.max(this.container.clientHeight, 50);
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  render() {
    if (!this.renderer || !this.dirty) return;
    this.dirty = false;
    this.renderer.render(this.three, this.camera);
  }
}
