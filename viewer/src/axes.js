// Plot axes a person can read: limits rounded outward to a nice step (no "0.209739" at an
// axis end) and tick labels written to the precision of the tick step (no "90.000003"), large
// and small values as a mantissa times a power of ten (2×10⁶, not 2000000).

// The smallest of 1, 2, 2.5, 5 × 10^k at or above x > 0.
export function niceStep(x) {
  const p = Math.pow(10, Math.floor(Math.log10(x)));
  const m = x / p;
  return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 2.5 ? 2.5 : m <= 5 ? 5 : 10) * p;
}

// {min, max, step}: [lo, hi] widened to multiples of a nice tick step (4 to 7 intervals, the
// tightest fit) (a constant gets a span of its own size, or ±1 at 0); null for no finite data.
export function niceLimits(lo, hi) {
  if (!Number.isFinite(lo) || !Number.isFinite(hi)) return null;
  if (!(hi > lo)) {
    const half = lo === 0 ? 1 : Math.abs(lo) / 2;
    lo -= half;
    hi += half;
  }
  // round before floor/ceil: a limit that is a multiple of the step to round-off stays put
  const q = (v, step) => Math.round((v / step) * 1e9) / 1e9;
  let best = null;
  for (let k = 4; k <= 7; k++) {  // 4 to 7 intervals: the one wasting least of the axis
    const step = niceStep((hi - lo) / k);
    const min = Math.floor(q(lo, step)) * step, max = Math.ceil(q(hi, step)) * step;
    if (best === null || max - min < best.max - best.min - 1e-9 * step) best = { min, max, step };
  }
  return best;
}

const SUPERSCRIPT = { '-': '⁻', 0: '⁰', 1: '¹', 2: '²', 3: '³', 4: '⁴', 5: '⁵', 6: '⁶', 7: '⁷', 8: '⁸', 9: '⁹' };

function decimalsFor(step) {
  if (!(step > 0)) return 0;
  for (let d = 0; d < 12; d++) {
    if (Math.abs(Math.round(step * 10 ** d) - step * 10 ** d) < 1e-6 * step * 10 ** d) return d;
  }
  return 12;
}

// The label of tick value v on an axis whose ticks are `values` (evenly spaced).
export function tickLabel(v, values) {
  const finite = values.filter(Number.isFinite);
  const step = finite.length > 1 ? Math.abs(finite[1] - finite[0]) : Math.abs(v) || 1;
  const big = Math.max(...finite.map(Math.abs), Math.abs(v));
  if (Math.abs(v) < step * 1e-9) return '0';
  if (big >= 1e5 || big < 1e-3) {
    const e = Math.floor(Math.log10(big));
    const d = decimalsFor(step / 10 ** e);
    const m = (v / 10 ** e).toFixed(d);
    const exp = String(e).split('').map((c) => SUPERSCRIPT[c]).join('');
    return `${m}×10${exp}`;
  }
  return v.toFixed(decimalsFor(step));
}

// Chart.js scale options: nice limits of the data extent, ticks at every multiple of the nice
// step, labels by tickLabel.
export function niceScale(lo, hi) {
  const nice = niceLimits(lo, hi);
  const ticks = { callback: (v, i, all) => tickLabel(+v, all.map((t) => t.value)) };
  if (nice === null) return { ticks };
  return { min: nice.min, max: nice.max, ticks: { ...ticks, stepSize: nice.step } };
}
