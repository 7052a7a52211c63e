// Linked 2-D plots (Chart.js): each plot of the scene in a card; a cursor follows the
// animation (a vertical line at the current input, dots on the current mode's curves), and a
// click on a plot moves the animation to the nearest frame.
import {
  Chart, ScatterController, LineElement, PointElement, LinearScale, Legend, Title, Tooltip,
} from 'chart.js';
import { value } from './data.js';
import { niceScale } from './axes.js';

Chart.register(ScatterController, LineElement, PointElement, LinearScale, Legend, Title, Tooltip);

const MODE_COLOURS = ['#2f6db5', '#d1495b', '#2a9d8f', '#8e6cc0', '#c9853a', '#4f8a3c'];
const COMPONENT_COLOURS = ['#212121', '#d32f2f', '#388e3c', '#1976d2'];

function colourOf(plot, series, k) {
  if (series.length === 4 && series[0].name.startsWith('|')) return COMPONENT_COLOURS[k];
  const s = series[k];
  if (s.mode !== null && s.mode !== undefined && plot.group === 'kinematics') return MODE_COLOURS[s.mode % MODE_COLOURS.length];
  return MODE_COLOURS[k % MODE_COLOURS.length];
}

function points(plot, s, input) {
  const xs = s.x || input;
  const out = [];
  for (let i = 0; i < s.y.length; i++) {
    const x = value(xs, i), y = value(s.y, i);
    out.push({ x: x === null ? null : x * plot.x_scale, y: y === null || x === null ? null : y * plot.y_scale });
  }
  return out;
}

class LinkedPlot {
  constructor(card, plot, scene, onPick) {
    this.plot = plot;
    this.scene = scene;
    this.input = scene.input.values;
    const wrap = document.createElement('div');
    wrap.className = 'sk-plot-canvas';
    card.appendChild(wrap);
    const canvas = document.createElement('canvas');
    wrap.appendChild(canvas);
    this.wrap = wrap;
    const datasets = plot.series.map((s, k) => {
      const colour = colourOf(plot, plot.series, k);
      const style = s.style || 'line';
      return {
        label: s.name,
        data: points(plot, s, this.input),
        showLine: style !== 'points',
        pointRadius: style === 'line' ? 0 : 3,
        pointHoverRadius: 3,
        borderWidth: k === 0 && plot.series.length === 4 ? 2.2 : 1.6,
        borderColor: colour,
        backgroundColor: colour,
        spanGaps: false,
      };
    });
    const square = plot.kind === 'xy';
    const [xs, ys] = this.extents(datasets);
    const [lo, hi] = [Math.min(xs[0], ys[0]), Math.max(xs[1], ys[1])];
    // an x–y plot (a hodograph) keeps one scale on both axes
    const xScale = square ? niceScale(lo, hi) : niceScale(xs[0], xs[1]);
    const yScale = square ? niceScale(lo, hi) : niceScale(ys[0], ys[1]);
    this.chart = new Chart(canvas, {
      type: 'scatter',
      data: { datasets },
      options: {
        animation: false,
        responsive: true,
        maintainAspectRatio: false,
        parsing: false,
        plugins: {
          title: { display: true, text: plot.title, font: { size: 13 } },
          legend: { display: plot.series.length > 1, labels: { boxWidth: 12, font: { size: 11 } } },
          tooltip: { enabled: true },
        },
        scales: {
          x: { type: 'linear', title: { display: true, text: plot.x_label }, ...xScale },
          y: { type: 'linear', title: { display: true, text: plot.y_label }, ...yScale },
        },
        onClick: (evt) => this.pick(evt, onPick),
        onResize: () => requestAnimationFrame(() => this.moveCursor(this.lastFrame, this.lastMode)),
      },
    });
    this.line = null;
    this.dots = [];
    if (plot.linked) {
      this.line = document.createElement('div');
      this.line.className = 'sk-cursor';
      wrap.appendChild(this.line);
      wrap.classList.add('sk-linked');
    }
  }

  // [[x min, x max], [y min, y max]] of the finite points (Infinity/-Infinity for none)
  extents(datasets) {
    const x = [Infinity, -Infinity], y = [Infinity, -Infinity];
    for (const d of datasets) for (const p of d.data) {
      if (p.x === null || p.y === null || !Number.isFinite(p.x) || !Number.isFinite(p.y)) continue;
      x[0] = Math.min(x[0], p.x); x[1] = Math.max(x[1], p.x);
      y[0] = Math.min(y[0], p.y); y[1] = Math.max(y[1], p.y);
    }
    return [x, y];
  }

  // the tick labels and limits drawn on each axis (for tests)
  axes() {
    const out = {};
    for (const k of ['x', 'y']) {
      const sc = this.chart.scales[k];
      out[k] = { min: sc.min, max: sc.max, labels: sc.ticks.map((t) => t.label) };
    }
    return out;
  }

  dot(k) {
    while (this.dots.length <= k) {
      const d = document.createElement('div');
      d.className = 'sk-dot';
      this.wrap.appendChild(d);
      this.dots.push(d);
    }
    return this.dots[k];
  }

  moveCursor(frame, mode) {
    this.lastFrame = frame;
    this.lastMode = mode;
    if (!this.plot.linked || frame === undefined) return;
    const chart = this.chart, area = chart.chartArea;
    if (!area) return;
    const xs = chart.scales.x, ys = chart.scales.y;
    const inside = (px, py) => px >= area.left - 0.5 && px <= area.right + 0.5 && py >= area.top - 0.5 && py <= area.bottom + 0.5;
    let used = 0;
    if (this.plot.kind === 'line') {
      const x = value(this.input, frame);
      const px = x === null ? NaN : xs.getPixelForValue(x * this.plot.x_scale);
      if (Number.isFinite(px) && px >= area.left - 0.5 && px <= area.right + 0.5) {
        this.line.style.display = 'block';
        this.line.style.left = `${px}px`;
        this.line.style.top = `${area.top}px`;
        this.line.style.height = `${area.bottom - area.top}px`;
      } else {
        this.line.style.display = 'none';
      }
    } else if (this.line) {
      this.line.style.display = 'none';
    }
    this.plot.series.forEach((s, k) => {
      if (s.mode !== null && s.mode !== undefined && s.mode !== mode) return;
      const p = chart.data.datasets[k].data[frame];
      if (!p || p.x === null || p.y === null) return;
      const px = xs.getPixelForValue(p.x), py = ys.getPixelForValue(p.y);
      if (!inside(px, py)) return;
      const d = this.dot(used++);
      d.style.display = 'block';
      d.style.left = `${px}px`;
      d.style.top = `${py}px`;
      d.style.background = chart.data.datasets[k].borderColor;
    });
    for (let k = used; k < this.dots.length; k++) this.dots[k].style.display = 'none';
  }

  pick(evt, onPick) {
    if (!this.plot.linked) return;
    const chart = this.chart;
    const px = evt.x, py = evt.y;
    const N = this.input.length;
    let best = -1, bestD = Infinity;
    if (this.plot.kind === 'line') {
      const xv = chart.scales.x.getValueForPixel(px) / this.plot.x_scale;
      for (let i = 0; i < N; i++) {
        const d = Math.abs(this.input[i] - xv);
        if (d < bestD) { bestD = d; best = i; }
      }
    } else {
      chart.data.datasets.forEach((ds, k) => {
        const s = this.plot.series[k];
        if (s.mode !== null && s.mode !== undefined && s.mode !== this.lastMode) return;
        ds.data.forEach((p, i) => {
          if (p.x === null || p.y === null) return;
          const d = Math.hypot(chart.scales.x.getPixelForValue(p.x) - px, chart.scales.y.getPixelForValue(p.y) - py);
          if (d < bestD) { bestD = d; best = i; }
        });
      });
    }
    if (best >= 0) onPick(best);
  }
}

// Build every plot group of the scene inside `root`; returns the plots (for the cursor).
export function buildPlots(root, scene, onPick) {
  const plots = [];
  for (const group of scene.plot_groups) {
    const members = scene.plots.filter((p) => p.group === group.id);
    if (!members.length) continue;
    const section = document.createElement('section');
    section.className = 'sk-group';
    section.id = `sk-group-${group.id}`;
    const h = document.createElement('h2');
    h.textContent = group.title;
    section.appendChild(h);
    if (group.note) {
      const p = document.createElement('p');
      p.className = 'sk-note';
      p.textContent = group.note;
      section.appendChild(p);
    }
    const grid = document.createElement('div');
    grid.className = 'sk-grid';
    section.appendChild(grid);
    root.appendChild(section);
    for (const plot of members) {
      const card = document.createElement('div');
      card.className = plot.kind === 'xy' ? 'sk-card sk-square' : 'sk-card';
      card.dataset.plot = plot.id;
      grid.appendChild(card);
      plots.push(new LinkedPlot(card, plot, scene, onPick));
    }
  }
  return plots;
}
