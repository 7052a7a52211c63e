// screwkit studio page (docs/studio.md): dimension sliders and number boxes, the input slider
// with play/pause, the mode picker, SVG plots, the numbers table; every change goes to the
// server over the WebSocket and the answer is redrawn. The 3-D view is the report's viewer in
// an iframe; each new scene of the same mechanism is handed to it and drawn in place.
// window.studio exposes the state for tests.
'use strict';
(function () {
  const boot = JSON.parse(document.getElementById('studio-boot').textContent);
  const $ = (id) => document.getElementById(id);
  const COLOURS = ['#2f6db5', '#d1495b', '#2a9d8f', '#8e6cc0', '#c9853a', '#4f8a3c'];
  const S = {
    state: null, result: null, frame: 0, mode: boot.mode, playing: false, seq: 0,
    inflight: null, pending: null, lastChange: 0, latencies: [], viewLatencies: [], errors: [],
    messages: [], viewReady: false,
    phases: [], // per timed change: ms from the input event to the answer, the scene, the view
  };
  window.studio = S;

  function el(tag, attrs = {}, text) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
    if (text !== undefined) e.textContent = text;
    return e;
  }
  const svgEl = (tag, attrs = {}) => {
    const e = document.createElementNS('http://www.w3.org/2000/svg', tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
    return e;
  };
  const fmt = (v) => {
    if (v === null || v === undefined) return '—';
    const t = (+v).toPrecision(6);
    return t.includes('.') ? t.replace(/\.?0+(e|$)/, '$1') : t; // 1.50000 → 1.5, 100000 stays
  };

  // ---- the WebSocket -------------------------------------------------------------------
  const wsUrl = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws?token=${encodeURIComponent(boot.token)}`;
  const ws = new WebSocket(wsUrl);
  S.send = (msg) => { msg.seq = ++S.seq; ws.send(JSON.stringify(msg)); return msg.seq; };
  S.sendRaw = (text) => ws.send(text);
  ws.onmessage = (ev) => {
    const t = performance.now();
    const msg = JSON.parse(ev.data);
    S.parsed = performance.now() - t; // ms to parse this message (timed answers keep it)
    receive(msg);
  };
  ws.onclose = () => say('the studio server has stopped; restart `screwkit studio` and reload', 'error');

  function say(text, kind) {
    const m = $('message');
    m.textContent = text;
    m.className = kind || '';
    S.messages.push({ text, kind });
  }

  // a dimension change: sent at once, or after the answer in flight (only the latest values)
  function change(values, mode) {
    const t0 = performance.now();
    clearTimeout(restTimer);
    if (S.inflight !== null) {
      S.pending = { values: { ...(S.pending ? S.pending.values : {}), ...values }, mode: mode ?? (S.pending ? S.pending.mode : null), t0 };
      return;
    }
    const msg = { type: 'set', values };
    if (mode !== null && mode !== undefined) msg.mode = mode;
    S.inflight = { seq: S.send(msg), t0 };
    S.lastChange = S.inflight.seq;
  }

  function receive(msg) {
    const timed = S.inflight && msg.seq === S.inflight.seq ? S.inflight : null;
    if (timed) { S.inflight = null; S.phases.push({ answer: performance.now() - timed.t0, parse: S.parsed }); }
    if (msg.type === 'state' && msg.unchanged) mergeUnchanged(msg);
    if (msg.type === 'state' && msg.scene) S.scene = msg.scene; // whole again (merged)
    if (msg.type === 'state') showState(msg, timed);
    else if (msg.type === 'error') { S.errors.push(msg.message); say(msg.message, 'error'); }
    else if (msg.type === 'saved') say(`saved ${msg.path}`, 'ok');
    else if (msg.type === 'checked') { S.checked = msg.seq; document.body.dataset.checked = String(msg.seq); }
    else if (msg.type === 'numbers') {
      if (msg.seq > S.lastChange) { // else asked for before a later change: stale
        S.numbers = msg.numbers; drawNumbers(msg.numbers); $('numbers').classList.remove('stale'); document.body.dataset.numbers = String(msg.seq);
      }
    }
    else if (msg.type === 'download') download(msg);
    if (S.inflight === null && S.pending) {
      const p = S.pending;
      S.pending = null;
      change(p.values, p.mode);
      if (S.inflight) S.inflight.t0 = p.t0;
    } else if (S.inflight === null && msg.type === 'state' && msg.result.ok) {
      numbersAtRest(); // the slower table, once the curves are drawn and the design rests
    }
  }

  // the parts of a state the server left out (each a path into its result or scene) are
  // those of the state before, as the page holds them
  function mergeUnchanged(msg) {
    for (const path of msg.unchanged) {
      let from = path[0] === 'result' ? S.result : S.scene;
      let to = msg;
      if (path.length === 1) { msg.sameScene = true; continue; } // ['scene']: the shown one
      for (let k = 0; k < path.length - 1; k++) {
        if (k) from = from[path[k]];
        to = to[path[k]];
      }
      to[path[path.length - 1]] = from[path[path.length - 1]];
    }
  }

  // the numbers table (limit positions: up to a few hundred ms on the server) is asked for
  // once no change has been made for REST ms, so a drag never queues it; the server computes
  // it beside later changes, which are answered without waiting for it
  const REST = 150;
  let restTimer = null;
  function numbersAtRest() {
    clearTimeout(restTimer);
    restTimer = setTimeout(() => { if (S.inflight === null && !S.pending) S.send({ type: 'numbers' }); }, REST);
  }

  function download(msg) {
    const a = el('a', { download: msg.name });
    a.href = URL.createObjectURL(new Blob([msg.text], { type: msg.mime }));
    document.body.appendChild(a);
    a.click();
    a.remove();
    say(`exported ${msg.name}`, 'ok');
  }

  // ---- dimensions ----------------------------------------------------------------------
  const dimInputs = {};
  for (const d of boot.dimensions) {
    const row = el('div', { class: 'dim', 'data-name': d.name });
    const slider = el('input', { type: 'range', min: d.low, max: d.high, step: d.step, value: d.value, 'aria-label': d.name });
    const box = el('input', { type: 'number', step: 'any', value: d.value, 'aria-label': `${d.name} value` });
    row.append(el('label', { title: d.name }, d.name.replace(/^dimensions\./, '')), slider, box, el('span', { class: 'unit' }, d.unit));
    $('dims').appendChild(row);
    dimInputs[d.name] = { slider, box };
    slider.addEventListener('input', () => { box.value = slider.value; change({ [d.name]: +slider.value }); });
    box.addEventListener('change', () => {
      const v = +box.value;
      if (box.value.trim() === '' || !Number.isFinite(v)) { say(`${d.name}: give a number`, 'error'); return; }
      if (v < +slider.min) slider.min = v;
      if (v > +slider.max) slider.max = v;
      slider.value = v;
      change({ [d.name]: v });
    });
  }

  // ---- controls ------------------------------------------------------------------------
  const step = (type) => { clearTimeout(restTimer); S.inflight = { seq: S.send({ type }), t0: performance.now() }; S.lastChange = S.inflight.seq; };
  $('undo').onclick = () => step('undo');
  $('redo').onclick = () => step('redo');
  $('save').onclick = () => S.send({ type: 'save' });
  $('export-report').onclick = () => S.send({ type: 'export', what: 'report' });
  $('export-csv').onclick = () => S.send({ type: 'export', what: 'csv' });
  $('export-spec').onclick = () => S.send({ type: 'export', what: 'spec' });
  $('mode').onchange = () => change({}, +$('mode').value);
  $('play').onclick = () => (S.playing ? pause() : play());
  $('frame').addEventListener('input', () => { pause(); setFrame(+$('frame').value); });

  function play() { S.playing = true; S.last = null; $('play').textContent = 'pause'; document.body.dataset.playing = 'true'; }
  function pause() { S.playing = false; $('play').textContent = 'play'; document.body.dataset.playing = 'false'; }
  S.play = play;
  S.pause = pause;

  function viewer() {
    const f = $('view'), w = f && f.contentWindow;
    return S.viewReady && w && w.screwkitViewer ? w.screwkitViewer : null;
  }

  function setFrame(i) {
    const r = S.result;
    if (!r || !r.ok) return;
    const n = r.input.values.length;
    S.frame = Math.max(0, Math.min(n - 1, Math.round(i)));
    $('frame').value = String(S.frame);
    const v = viewer();
    if (v) {
      const k = Math.min(S.mode, v.modeCount - 1);
      if (v.mode !== k) v.setMode(k);
      v.setFrame(S.frame);
    }
    $('input-readout').textContent = `${r.input.name} = ${fmt(r.input.values[S.frame])} ${r.input.unit}`;
    for (const c of document.querySelectorAll('#plots line.cursor')) {
      const x = c.sx(r.input.values[S.frame]);
      c.setAttribute('x1', x); c.setAttribute('x2', x);
    }
    document.body.dataset.frame = String(S.frame);
  }
  S.setFrame = setFrame;

  function tick(t) {
    const r = S.result;
    if (S.playing && r && r.ok) {
      const n = r.input.values.length;
      if (S.last !== null) {
        S.phase = (S.phase ?? S.frame) + ((t - S.last) / 1000) * (n / Math.max(4, n / 30));
        if (Math.floor(S.phase) % n !== S.frame) setFrame(Math.floor(S.phase) % n);
        S.phase %= n;
      }
      S.last = t;
    }
    requestAnimationFrame(tick);
  }
  requestAnimationFrame(tick);

  // ---- plots (SVG) ---------------------------------------------------------------------
  function ticks(lo, hi) {
    const span = hi - lo || 1, step0 = Math.pow(10, Math.floor(Math.log10(span / 5)));
    const step = [1, 2, 5, 10].map((m) => m * step0).find((s) => span / s <= 6);
    const out = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) out.push(+v.toPrecision(12));
    return out;
  }

  // series: [{name, x: [], y: [], colour, bold}]; linked: a cursor at the current input
  function plot(title, xLabel, series, { linked = false, square = false } = {}) {
    const W = 420, H = square ? 360 : 220, L = 58, R = 10, T = 24, B = 34;
    const svg = svgEl('svg', { viewBox: `0 0 ${W} ${H}`, class: 'plot', 'data-title': title });
    const xs = [], ys = [];
    for (const s of series) s.x.forEach((x, i) => { if (x !== null && s.y[i] !== null) { xs.push(x); ys.push(s.y[i]); } });
    const card = el('div', { class: 'card' });
    card.appendChild(svg);
    $('plots').appendChild(card);
    svg.appendChild(svgEl('text', { x: W / 2, y: 15, class: 'title', 'text-anchor': 'middle' })).textContent = title;
    if (!xs.length) {
      svg.appendChild(svgEl('text', { x: W / 2, y: H / 2, 'text-anchor': 'middle', class: 'empty' })).textContent = 'nothing to draw: no mode assembles';
      return svg;
    }
    let [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    if (x1 === x0) { x0 -= 1; x1 += 1; }
    if (y1 === y0) { y0 -= 1; y1 += 1; }
    if (square) { // equal scales (a path's true shape)
      const k = Math.max((x1 - x0) / (W - L - R), (y1 - y0) / (H - T - B));
      const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
      x0 = cx - k * (W - L - R) / 2; x1 = cx + k * (W - L - R) / 2; y0 = cy - k * (H - T - B) / 2; y1 = cy + k * (H - T - B) / 2;
    }
    const sx = (x) => L + ((x - x0) / (x1 - x0)) * (W - L - R), sy = (y) => H - B - ((y - y0) / (y1 - y0)) * (H - T - B);
    for (const v of ticks(x0, x1)) {
      svg.appendChild(svgEl('line', { x1: sx(v), x2: sx(v), y1: T, y2: H - B, class: 'grid' }));
      svg.appendChild(svgEl('text', { x: sx(v), y: H - B + 13, 'text-anchor': 'middle' })).textContent = fmt(v);
    }
    for (const v of ticks(y0, y1)) {
      svg.appendChild(svgEl('line', { x1: L, x2: W - R, y1: sy(v), y2: sy(v), class: 'grid' }));
      svg.appendChild(svgEl('text', { x: L - 4, y: sy(v) + 4, 'text-anchor': 'end' })).textContent = fmt(v);
    }
    svg.appendChild(svgEl('text', { x: (L + W - R) / 2, y: H - 4, 'text-anchor': 'middle', class: 'axis' })).textContent = xLabel;
    series.forEach((s, k) => {
      let d = '', pen = false;
      s.x.forEach((x, i) => {
        const y = s.y[i];
        if (x === null || y === null) { pen = false; return; }
        d += `${pen ? 'L' : 'M'}${sx(x).toFixed(2)},${sy(y).toFixed(2)}`;
        pen = true;
      });
      svg.appendChild(svgEl('path', { d, class: s.bold ? 'curve bold' : 'curve', stroke: s.colour || COLOURS[k % COLOURS.length], 'data-series': s.name }));
      svg.appendChild(svgEl('text', { x: L + 6 + 120 * (k % 3), y: T + 12 + 12 * Math.floor(k / 3), fill: s.colour || COLOURS[k % COLOURS.length], class: 'key' })).textContent = s.name;
    });
    if (linked) {
      const c = svgEl('line', { y1: T, y2: H - B, class: 'cursor' });
      c.sx = sx;
      svg.appendChild(c);
    }
    return svg;
  }

  // the coordinate plane on which the paths spread most (the sum of each path's bounding-box
  // area there), so a circle is seen as a circle rather than edge-on
  function widestPlane(paths) {
    const spans = paths.map((p) => [0, 1, 2].map((j) => {
      const v = p[j].filter((x) => x !== null);
      return v.length ? Math.max(...v) - Math.min(...v) : 0;
    }));
    const area = (pr) => spans.reduce((a, s) => a + s[pr[0]] * s[pr[1]], 0);
    return [[0, 1], [0, 2], [1, 2]].reduce((a, b) => (area(b) > area(a) ? b : a));
  }

  function drawPlots(r) {
    $('plots').textContent = '';
    const x = r.input.values, xl = `${r.input.name} [${r.input.unit}]`;
    const names = Object.keys(r.modes[0] ? r.modes[0].outputs : {});
    for (const name of names) {
      plot(`${name} against the input`, xl, r.modes.map((m, k) => ({
        name: m.label, x, y: m.outputs[name], colour: COLOURS[k % COLOURS.length], bold: k === S.mode,
      })), { linked: true });
    }
    const axes = 'xyz';
    const m = r.paths.modes[Math.min(S.mode, r.paths.modes.length - 1)] || {};
    const proj = S.projection || widestPlane(Object.values(m));
    const svg = plot(`${r.paths.title}, ${r.modes[S.mode] ? r.modes[S.mode].label : ''}, projected on ${axes[proj[0]]}${axes[proj[1]]}`,
      `${axes[proj[0]]} [${r.length_unit}]`, Object.entries(m).map(([n, p]) => ({ name: n, x: p[proj[0]], y: p[proj[1]] })), { square: true });
    const pick = el('select', { 'aria-label': 'projection', class: 'projection' });
    for (const pr of [[0, 1], [0, 2], [1, 2]]) pick.appendChild(el('option', { value: pr.join('') }, `${axes[pr[0]]}${axes[pr[1]]} plane`));
    pick.value = proj.join('');
    pick.onchange = () => { S.projection = pick.value.split('').map(Number); drawPlots(S.result); setFrame(S.frame); };
    svg.parentNode.appendChild(pick);
    if (r.transmission) {
      const t = r.transmission[Math.min(S.mode, r.transmission.length - 1)];
      const series = Object.entries(t.index).map(([n, y]) => ({ name: `index of ${n}`, x, y }));
      plot(`transmission index, ${r.modes[S.mode].label}`, xl, series, { linked: true });
      if (t.angle) plot('transmission angle [deg]', xl, [{ name: 'angle', x, y: t.angle }], { linked: true });
    }
    if (r.loads) {
      for (const [name, y] of Object.entries(r.loads.curves)) plot(`${name}, mode ${r.loads.mode}`, xl, [{ name, x, y }], { linked: true });
    }
  }

  function drawNumbers(rows) {
    const t = $('numbers');
    t.textContent = '';
    for (const [k, v] of rows) { const tr = el('tr'); tr.append(el('th', {}, k), el('td', {}, v)); t.appendChild(tr); }
  }

  function drawTables(r) {
    $('numbers').classList.add('stale'); // until the numbers of this state arrive
    const lt = $('loads-table');
    lt.textContent = r.loads_note || '';
    if (r.loads) {
      const tab = el('table', { id: 'loads' });
      const h = el('tr');
      h.append(el('th', {}, `load (mode ${r.loads.mode})`), el('th', {}, 'peak'), el('th', {}, 'RMS'));
      tab.appendChild(h);
      for (const [k, p, rms] of r.loads.summary) { const tr = el('tr'); tr.append(el('th', {}, k), el('td', {}, fmt(p)), el('td', {}, fmt(rms))); tab.appendChild(tr); }
      lt.appendChild(tab);
    }
  }

  // ---- the 3-D view (the report's viewer in an iframe) ---------------------------------
  // a scene of the same mechanism goes to the shown viewer, which replaces its frames in place
  // (screwkitViewer.update); another one (the first, or a new topology) loads in a second
  // iframe on top of the shown one (transparent until its viewer is up), which then takes the
  // id 'view': the picture never goes blank
  function loadView(scene, t0) {
    const shown = $('view');
    const viewer = shown && !document.getElementById('view-next') && shown.contentWindow.screwkitViewer;
    const t1 = performance.now();
    if (viewer && viewer.update && viewer.update(scene)) {
      viewer.pause();
      S.viewReady = true;
      setFrame(S.frame);
      viewer.renderNow();
      if (S.phases.length) S.phases[S.phases.length - 1].update = performance.now() - t1;
      S.viewUpdates = (S.viewUpdates || 0) + 1;
      requestAnimationFrame(() => { // the frame that shows the new view (the curves are drawn)
        S.viewLatencies.push(performance.now() - t0);
        if (S.phases.length) S.phases[S.phases.length - 1].view = performance.now() - t0;
        document.body.dataset.view = String(S.viewLatencies.length);
      });
      return;
    }
    const old = document.getElementById('view-next');
    if (old) old.remove();
    const frame = el('iframe', { id: 'view-next', title: '3-D view', class: 'loading' });
    $('view-box').appendChild(frame);
    S.viewReady = false;
    const json = JSON.stringify(scene).replace(/</g, '\\u003c');
    frame.onload = () => {
      const w = frame.contentWindow;
      const wait = () => {
        if (!frame.isConnected) return; // replaced by a newer scene
        if (!w.screwkitViewer) { setTimeout(wait, 10); return; }
        w.screwkitViewer.pause();
        const shown = $('view');
        if (shown) shown.remove();
        frame.id = 'view';
        frame.className = '';
        S.viewReady = true;
        setFrame(S.frame);
        S.viewLatencies.push(performance.now() - t0);
        document.body.dataset.view = String(S.viewLatencies.length);
      };
      wait();
    };
    frame.srcdoc = '<!doctype html><html><head><meta charset="utf-8"><style>body{margin:0;font:13px system-ui,sans-serif}' +
      '#sk-viewer{height:100vh;display:flex;flex-direction:column}.sk-canvas{position:relative;flex:1}.sk-canvas canvas{display:block}' +
      '.sk-controls,.sk-readout,.sk-events,#sk-plots{display:none}.sk-status{position:absolute;left:.5em;top:.4em;right:.5em;font-weight:600}' +
      '.sk-warn{color:#b71c1c}.sk-caution{color:#8a5300}.sk-legend{position:absolute;left:.5em;bottom:.4em;font-size:.8em;color:#444}</style></head>' +
      '<body><main><section id="sk-viewer"></section><div id="sk-plots"></div></main>' +
      `<script type="application/json" id="screwkit-scene">${json}<\/script>` +
      `<script src="/static/viewer.js?token=${encodeURIComponent(boot.token)}"><\/script></body></html>`;
  }

  function showState(msg, timed) {
    S.state = msg;
    for (const [name, v] of Object.entries(msg.values)) {
      const d = dimInputs[name];
      if (!d) continue;
      if (document.activeElement !== d.slider) d.slider.value = v;
      if (document.activeElement !== d.box) d.box.value = v;
    }
    $('undo').disabled = !msg.can_undo;
    $('redo').disabled = !msg.can_redo;
    const r = msg.result;
    S.mode = msg.mode;
    if (!r.ok) {
      say(r.error, 'error');
      $('assembly').textContent = r.where ? `${r.error}. ${r.where}.` : r.error;
      $('assembly').className = 'error';
      document.body.dataset.solved = 'error';
      S.result = r;
      document.body.dataset.drawn = String(msg.seq);
      return;
    }
    say('', '');
    const sel = $('mode');
    sel.textContent = '';
    const count = Math.max(r.modes.length, msg.mode + 1);
    for (let k = 0; k < count; k++) sel.appendChild(el('option', { value: String(k) }, r.modes[k] ? r.modes[k].label : `mode ${k} (none)`));
    sel.value = String(msg.mode);
    $('assembly').textContent = r.assembly.join('; ');
    $('assembly').className = r.assembly.length ? 'warn' : '';
    S.result = r;
    $('frame').max = String(r.input.values.length - 1);
    const t1 = performance.now();
    drawPlots(r);
    drawTables(r);
    if (timed && S.phases.length) S.phases[S.phases.length - 1].draw = performance.now() - t1;
    S.frame = Math.min(S.frame, r.input.values.length - 1);
    S.stateT0 = timed ? timed.t0 : performance.now();
    if (msg.scene) { // the 3-D scene comes in the same message: the view takes it now
      S.viewReady = false; // until it is loaded
      if (timed && S.phases.length) S.phases[S.phases.length - 1].scene = performance.now() - S.stateT0;
      loadView(msg.scene, S.stateT0);
    } else if (msg.sameScene) { // the view already shows this scene
      const t0 = S.stateT0;
      if (timed && S.phases.length) Object.assign(S.phases[S.phases.length - 1], { scene: performance.now() - t0, update: 0 });
      requestAnimationFrame(() => { S.viewLatencies.push(performance.now() - t0); document.body.dataset.view = String(S.viewLatencies.length); });
    }
    setFrame(S.frame);
    document.body.dataset.solved = String(msg.seq);
    requestAnimationFrame(() => {
      if (timed) S.latencies.push(performance.now() - timed.t0);
      document.body.dataset.drawn = String(msg.seq);
    });
  }
}());
