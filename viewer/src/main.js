// screwkit report viewer: reads the scene from <script id="screwkit-scene">, builds the 3-D
// view, the controls and the linked plots, autoplays, and exposes window.screwkitViewer for
// tests: frameCount, frame, modeCount, mode, playing, play(), pause(), setFrame(i),
// setMode(k), setView(name), jointPositions(i) (the joint centres drawn at frame i, metres),
// and for a mechanism with loops: loopCount, loop, setLoop(k) (-1: all), fullJoints() (the
// joints drawn in full, not faint).
// plotAxes() (each plot's axis limits and tick labels), and update(scene) (show another
// packed scene of the same mechanism in place, keeping the camera; false when it is not one).
import { decode, value } from './data.js';
import { MechanismView } from './view3d.js';
import { buildPlots } from './plots.js';

function el(tag, attrs = {}, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

class ViewerApp {
  constructor(scene, viewRoot, plotRoot) {
    this.scene = scene;
    this.N = scene.input.values.length;
    this.frame = 0;
    this.mode = 0;
    this.playing = false;
    this.speed = 1;
    this.phase = 0;
    this.last = null;
    this.cycleSeconds = Math.max(4, this.N / 30);
    this.buildLayout(viewRoot);
    this.view = new MechanismView(this.canvasBox, scene);
    this.plotRoot = plotRoot;
    this.plots = buildPlots(plotRoot, scene, (i) => { this.pause(); this.setFrame(i); });
    this.setMode(scene.initial_mode || 0);
    document.body.dataset.frames = String(this.N);
    requestAnimationFrame((t) => this.tick(t));
  }

  buildLayout(root) {
    const box = el('div', { class: 'sk-canvas' });
    this.canvasBox = box;
    this.status = el('div', { class: 'sk-status', role: 'status' });
    this.legend = el('div', { class: 'sk-legend' });
    box.appendChild(this.status);
    box.appendChild(this.legend);
    root.appendChild(box);
    const bar = el('div', { class: 'sk-controls' });
    this.playButton = el('button', { type: 'button', class: 'sk-play', title: 'play / pause (space)' }, 'pause');
    this.playButton.addEventListener('click', () => (this.playing ? this.pause() : this.play()));
    this.slider = el('input', { type: 'range', min: '0', max: String(this.N - 1), step: '1', value: '0', 'aria-label': 'frame' });
    this.slider.addEventListener('input', () => { this.pause(); this.setFrame(+this.slider.value); });
    const speed = el('select', { 'aria-label': 'speed' });
    for (const s of [0.25, 0.5, 1, 2, 4]) {
      const o = el('option', { value: String(s) }, `${s}×`);
      if (s === 1) o.selected = true;
      speed.appendChild(o);
    }
    speed.addEventListener('change', () => { this.speed = +speed.value; });
    this.modeSelect = el('select', { 'aria-label': 'assembly mode' });
    this.fillModes();
    this.modeSelect.addEventListener('change', () => this.setMode(+this.modeSelect.value));
    bar.append(this.playButton, this.slider, el('span', { class: 'sk-label' }, 'speed'), speed);
    if (this.scene.modes.length > 1) bar.append(el('span', { class: 'sk-label' }, 'mode'), this.modeSelect);
    const loops = this.scene.loops || [];
    if (loops.length) {
      this.loopSelect = el('select', { 'aria-label': 'loop', class: 'sk-loop' });
      this.loopSelect.appendChild(el('option', { value: '-1' }, 'all loops'));
      loops.forEach((lp, k) => this.loopSelect.appendChild(el('option', { value: String(k) },
        `${lp.name}: ${lp.joint_names.join('–')}`)));
      this.loopSelect.addEventListener('change', () => this.setLoop(+this.loopSelect.value));
      bar.append(el('span', { class: 'sk-label' }, 'show'), this.loopSelect);
    }
    const views = el('span', { class: 'sk-views' });
    for (const v of ['front', 'top', 'side', 'iso']) {
      const b = el('button', { type: 'button' }, v);
      b.addEventListener('click', () => this.view.setView(v));
      views.appendChild(b);
    }
    bar.appendChild(views);
    const toggle = (label, on) => {
      const lab = el('label', { class: 'sk-toggle' });
      const cb = el('input', { type: 'checkbox' });
      cb.checked = true;
      cb.addEventListener('change', () => on(cb.checked));
      lab.append(cb, document.createTextNode(` ${label}`));
      return lab;
    };
    bar.appendChild(toggle('traces', (v) => { this.view.showTraces = v; this.view.applyVisibility(); }));
    if (this.scene.modes.some((m) => Object.keys(m.arrows || {}).length)) {
      bar.appendChild(toggle('arrows', (v) => { this.view.showArrows = v; this.view.applyVisibility(); this.updateLegend(); }));
    }
    root.appendChild(bar);
    this.readout = el('div', { class: 'sk-readout' });
    root.appendChild(this.readout);
    this.events = el('ul', { class: 'sk-events' });
    root.appendChild(this.events);
    document.addEventListener('keydown', (e) => {
      if (e.target && ['INPUT', 'SELECT', 'TEXTAREA'].includes(e.target.tagName)) return;
      if (e.key === ' ') { e.preventDefault(); this.playing ? this.pause() : this.play(); }
      if (e.key === 'ArrowRight') { this.pause(); this.setFrame((this.frame + 1) % this.N); }
      if (e.key === 'ArrowLeft') { this.pause(); this.setFrame((this.frame - 1 + this.N) % this.N); }
    });
  }

  fillModes() {
    this.modeSelect.textContent = '';
    this.scene.modes.forEach((m, k) => this.modeSelect.appendChild(el('option', { value: String(k) }, m.label)));
  }

  // Another scene of the same mechanism (a new design): its frames replace the shown ones in
  // place (no new page, the camera stays); false, and nothing changed, when it draws another
  // mechanism (other joints, links or samples).
  update(scene) {
    if (!this.view.sameShape(scene)) return false;
    this.scene = scene;
    this.view.update(scene);
    this.fillModes();
    for (const p of this.plots) if (p.chart) p.chart.destroy();
    this.plotRoot.textContent = '';
    this.plots = buildPlots(this.plotRoot, scene, (i) => { this.pause(); this.setFrame(i); });
    this.setMode(Math.min(this.mode, scene.modes.length - 1));
    return true;
  }

  inputText(i) {
    const inp = this.scene.input, u = this.scene.display_units;
    const v = value(inp.values, i);
    if (v === null) return '';
    return inp.kind === 'angle' ? `${inp.name} = ${(v * 180 / Math.PI).toFixed(2)} deg`
      : `${inp.name} = ${+(v * u.factor).toPrecision(6)} ${u.length}`;
  }

  updateLegend() {
    this.legend.textContent = '';
    const u = this.scene.display_units;
    this.legend.appendChild(el('div', {}, `lengths in ${u.length}; grid step ${this.view.gridStep}`));
    if (this.scene.ghost) this.legend.appendChild(el('div', {}, `grey lines: ${this.scene.ghost.label}`));
    if (this.view.showArrows && this.view.arrows && this.view.arrows.length && this.view.arrowScale > 0) {
      // forces in the spec's unit (display_units.force; N in older scenes)
      const per = (u.force_factor || 1) / (this.view.arrowScale * u.factor);
      this.legend.appendChild(el('div', {}, `arrows: 1 ${u.length} = ${+per.toPrecision(3)} ${u.force || 'N'}`));
      for (const a of this.view.arrows) {
        const row = el('div', { class: 'sk-arrow-key' });
        const sw = el('span', { class: 'sk-swatch' });
        sw.style.background = a.colour;
        row.append(sw, document.createTextNode(a.name));
        this.legend.appendChild(row);
      }
    }
  }

  setMode(k) {
    if (!(k >= 0 && k < this.scene.modes.length)) throw new RangeError(`mode ${k} out of range`);
    this.mode = k;
    this.modeSelect.value = String(k);
    this.view.setMode(k);
    this.events.textContent = '';
    for (const ev of this.scene.modes[k].events) this.events.appendChild(el('li', {}, ev));
    document.body.dataset.mode = String(k);
    this.updateLegend();
    this.setFrame(this.frame);
  }

  setLoop(k) {
    this.view.setLoop(k);
    if (this.loopSelect) this.loopSelect.value = String(k);
    document.body.dataset.loop = String(k);
  }

  setFrame(i) {
    i = Math.round(+i);
    if (!(i >= 0 && i < this.N)) throw new RangeError(`frame ${i} out of range 0..${this.N - 1}`);
    this.frame = i;
    this.phase = i;
    const mode = this.scene.modes[this.mode];
    const ok = this.view.setFrame(i);
    this.slider.value = String(i);
    this.readout.textContent = `${this.inputText(i)}   (frame ${i} of 0…${this.N - 1}, ${mode.label})`;
    if (!ok) {
      this.status.textContent = `${mode.label} does not assemble at ${this.inputText(i)}: nothing is drawn here.`;
      this.status.className = 'sk-status sk-warn';
    } else if (mode.singular[i]) {
      this.status.textContent = `singular configuration at ${this.inputText(i)} (rates undefined).`;
      this.status.className = 'sk-status sk-caution';
    } else {
      this.status.textContent = '';
      this.status.className = 'sk-status';
    }
    for (const p of this.plots) p.moveCursor(i, this.mode);
    document.body.dataset.frame = String(i);
  }

  play() {
    this.playing = true;
    this.last = null;
    this.playButton.textContent = 'pause';
    document.body.dataset.playing = 'true';
  }

  pause() {
    this.playing = false;
    this.playButton.textContent = 'play';
    document.body.dataset.playing = 'false';
  }

  tick(t) {
    if (this.playing) {
      if (this.last !== null) {
        this.phase += ((t - this.last) / 1000) * (this.N / this.cycleSeconds) * this.speed;
        const f = Math.floor(this.phase) % this.N;
        if (f !== this.frame) {
          const keep = this.phase % this.N;
          this.setFrame(f);
          this.phase = keep;
        }
      }
      this.last = t;
    }
    this.view.render();
    requestAnimationFrame((tt) => this.tick(tt));
  }

  api() {
    const app = this;
    return {
      get frameCount() { return app.N; },
      get frame() { return app.frame; },
      get modeCount() { return app.scene.modes.length; },
      get mode() { return app.mode; },
      get playing() { return app.playing; },
      play: () => app.play(),
      pause: () => app.pause(),
      setFrame: (i) => app.setFrame(i),
      setMode: (k) => app.setMode(k),
      setView: (name) => app.view.setView(name),
      // the joint centres drawn at frame i (shown first), metres; nulls where nothing is drawn
      jointPositions: (i) => {
        if (i !== undefined && i !== app.frame) app.setFrame(i);
        return app.view.drawnJointCentres();
      },
      renderNow: () => { app.view.dirty = true; app.view.render(); },
      get loopCount() { return (app.scene.loops || []).length; },
      get loop() { return app.view.loopIndex; },
      setLoop: (k) => app.setLoop(k),
      fullJoints: () => app.view.fullJoints(),
      // each plot's axes as drawn: {plot id: {x: {min, max, labels}, y: {…}}}
      plotAxes: () => Object.fromEntries(app.plots.map((p) => [p.plot.id, p.axes()])),
      // a packed scene (JSON text or its parsed object) of the same mechanism, shown in place
      update: (packed) => app.update(decode(typeof packed === 'string' ? JSON.parse(packed) : packed)),
    };
  }
}

function start() {
  const node = document.getElementById('screwkit-scene');
  const scene = decode(JSON.parse(node.textContent));
  const app = new ViewerApp(scene, document.getElementById('sk-viewer'), document.getElementById('sk-plots'));
  window.screwkitViewer = app.api();
  app.play();
}

if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', start);
else start();
