// Decoding of the scene embedded in the page (see screwkit/report/scene.py for its keys).
// Large arrays arrive as {"$b64": base64 of little-endian floats, "dtype": "f8"|"f4",
// "shape": [...]}: joint centres as float64 so that what is drawn matches the solver to the
// last bit; the rest as float32.

function typedArray(node) {
  const bin = atob(node.$b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  const arr = node.dtype === 'f8' ? new Float64Array(bytes.buffer) : new Float32Array(bytes.buffer);
  arr.shape = node.shape;
  return arr;
}

export function decode(node) {
  if (Array.isArray(node)) return node.map(decode);
  if (node && typeof node === 'object') {
    if (Object.prototype.hasOwnProperty.call(node, '$b64')) return typedArray(node);
    const out = {};
    for (const key of Object.keys(node)) out[key] = decode(node[key]);
    return out;
  }
  return node;
}

// Row `i` of an array with shape [N, ...rest], as a view.
export function row(arr, i) {
  const size = arr.length / arr.shape[0];
  return arr.subarray(i * size, (i + 1) * size);
}

// Point j of frame i of an [N, n, 3] array, or null when it holds NaN.
export function point(arr, i, j) {
  const n = arr.shape[1];
  const k = (i * n + j) * 3;
  const x = arr[k], y = arr[k + 1], z = arr[k + 2];
  return Number.isFinite(x) && Number.isFinite(y) && Number.isFinite(z) ? [x, y, z] : null;
}

// Value i of a 1-D series (a typed array or a list), or null when it is missing.
export function value(arr, i) {
  const v = arr[i];
  return v === null || v === undefined || !Number.isFinite(v) ? null : v;
}
