"""One self-contained HTML file from a scene (:mod:`screwkit.report.scene`): the vendored
viewer bundle (three.js + Chart.js, built from ``viewer/`` by ``make viewer``) and the scene
data are inlined, so the page opens from a file:// URL and makes no network request.

Escaping: every text of the scene reaches the page either through :func:`html.escape` (the
text sections, rendered here) or as data the viewer writes with ``textContent`` / onto a
canvas; the JSON is written with ``<``, ``>``, ``&`` and the JavaScript line separators as
``\\uXXXX`` escapes, so no ``</script>`` can close its tag early.

Size: joint centres and the input values are kept as float64 (what is drawn matches the
solver to the last bit), every other array as float32, both base64-encoded: an RSRC with two
modes over 360 frames and full dynamics is about 1.3 MB (four modes, 1.5 MB), the viewer
bundle 0.8 MB of it.
"""

from __future__ import annotations

import base64
import html
import json
from functools import lru_cache
from importlib import resources
from typing import Any

import numpy as np

from screwkit import __version__
from screwkit.errors import InputError

#: scene keys (per mode) kept in float64; every other numeric array is sent as float32
FLOAT64_KEYS = {"joint_centres"}
#: per-mode keys that are arrays
MODE_ARRAYS = ("joint_centres", "joint_axes", "second_axes", "link_points")

_CSS = """
*{box-sizing:border-box} body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:0;color:#222;background:#fafafa}
header{padding:.4em 0 .2em}
header h1{font-size:1.35em;margin:0 0 .2em} .muted{color:#666;margin:.1em 0;font-size:.92em}
main{display:grid;grid-template-columns:minmax(0,1.15fr) minmax(0,1fr);gap:0}
#sk-viewer{position:sticky;top:0;height:100vh;display:flex;flex-direction:column;background:#fff;border-right:1px solid #ddd;padding:.5em}
.sk-canvas{position:relative;flex:1;min-height:260px;border:1px solid #e3e3e3}
.sk-canvas canvas{display:block}
.sk-status{position:absolute;left:.6em;top:.5em;right:.6em;font-weight:600;pointer-events:none}
.sk-warn{color:#b71c1c;background:rgba(255,235,238,.92);padding:.4em .6em;border-radius:4px}
.sk-caution{color:#8a5300;background:rgba(255,243,224,.92);padding:.3em .6em;border-radius:4px}
.sk-legend{position:absolute;left:.6em;bottom:.5em;font-size:.8em;color:#444;background:rgba(255,255,255,.85);padding:.2em .4em;pointer-events:none}
.sk-arrow-key{display:flex;align-items:center;gap:.35em} .sk-swatch{display:inline-block;width:.9em;height:.9em;border-radius:2px}
.sk-controls{display:flex;flex-wrap:wrap;align-items:center;gap:.45em;padding:.45em 0}
.sk-controls input[type=range]{flex:1;min-width:140px} .sk-label{color:#666;font-size:.85em}
.sk-controls button,.sk-controls select{font:inherit;font-size:.85em;padding:.15em .5em}
.sk-play{min-width:4.2em} .sk-views button{margin-left:.15em}
.sk-readout{font-family:ui-monospace,monospace;font-size:.85em;color:#333}
.sk-events{font-size:.8em;color:#8a5300;margin:.2em 0 0;padding-left:1.2em;max-height:5em;overflow:auto}
.sk-nogl{padding:1em;color:#b71c1c}
#sk-side{padding:.5em 1em 2em;min-width:0}
.sk-group h2,#sk-text h2{font-size:1.1em;border-bottom:1px solid #ccc;margin:1.2em 0 .3em}
.sk-note{font-size:.85em;color:#555;margin:.2em 0 .6em}
.sk-grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:.6em}
.sk-card{background:#fff;border:1px solid #e3e3e3;border-radius:4px;padding:.3em}
.sk-plot-canvas{position:relative;height:230px} .sk-square .sk-plot-canvas{height:300px}
.sk-linked canvas{cursor:crosshair}
.sk-cursor{position:absolute;width:0;border-left:1.5px solid rgba(224,112,32,.9);pointer-events:none;display:none}
.sk-dot{position:absolute;width:9px;height:9px;margin:-4.5px 0 0 -4.5px;border-radius:50%;border:1.5px solid #fff;box-shadow:0 0 0 1px #333;pointer-events:none;display:none}
#sk-text ul{font-size:.88em;padding-left:1.2em} #sk-text pre{font-size:.8em;background:#f4f4f4;padding:.6em;overflow:auto;max-height:28em}
footer{font-size:.78em;color:#777;padding:1em 0;margin-top:2em;border-top:1px solid #ddd}
@media (max-width:1000px){main{grid-template-columns:1fr} #sk-viewer{position:relative;height:78vh;border-right:0}}
"""


@lru_cache(maxsize=1)
def viewer_bundle() -> str:
    """The vendored viewer (one minified IIFE), from the package's static folder."""
    files = resources.files("screwkit.report") / "static"
    js = (files / "screwkit-viewer.min.js").read_text(encoding="utf-8")
    if "</script" in js.lower() or "<!--" in js:
        raise InputError("the viewer bundle contains '</script' or '<!--'; rebuild it with `make viewer`")
    return js


@lru_cache(maxsize=1)
def third_party_notices() -> str:
    files = resources.files("screwkit.report") / "static"
    return (files / "THIRD_PARTY_LICENSES.txt").read_text(encoding="utf-8")


def _pack(values: Any, dtype: str) -> dict[str, Any]:
    """An array (lists with ``None`` for missing values allowed) as base64 little-endian
    floats; missing values become NaN. An infinite value is refused as :func:`~screwkit.io.
    results.jsonable` refuses it."""
    a = np.asarray(values, dtype=float)
    if np.isinf(a).any():
        from screwkit.io.results import NonFiniteResultError

        raise NonFiniteResultError(f"an infinite value in an array of shape {' × '.join(map(str, a.shape))} of "
                                   "the scene; strict JSON has no Infinity")
    raw = a.astype("<f8" if dtype == "f8" else "<f4").tobytes()
    return {"$b64": base64.b64encode(raw).decode("ascii"), "dtype": dtype, "shape": list(a.shape)}


def pack_scene(scene: dict[str, Any]) -> dict[str, Any]:
    """A copy of the scene with its large arrays packed for the page (see module doc)."""
    out = dict(scene)
    inp = dict(scene["input"])
    inp["values"] = _pack(inp["values"], "f8")
    out["input"] = inp
    modes = []
    for m in scene["modes"]:
        pm = dict(m)
        for key in MODE_ARRAYS:
            pm[key] = _pack(m[key], "f8" if key in FLOAT64_KEYS else "f4")
        if m.get("rail_ends") is not None:  # a mechanism's scene (report/graph_scene.py)
            pm["rail_ends"] = _pack(m["rail_ends"], "f4")
        pm["traces"] = {k: _pack(v, "f4") for k, v in m.get("traces", {}).items()}
        pm["arrows"] = {k: {**a, "vectors": _pack(a["vectors"], "f4"),
                            "points": _pack(a["points"], "f4")}
                        for k, a in m.get("arrows", {}).items()}
        pm.pop("closure_residual", None)
        modes.append(pm)
    out["modes"] = modes
    plots = []
    for p in scene["plots"]:
        pp = dict(p)
        pp["series"] = [{**s, **{k: _pack(s[k], "f4") for k in ("x", "y") if k in s}}
                        for s in p["series"]]
        plots.append(pp)
    out["plots"] = plots
    out["text"] = None  # rendered as HTML by the page itself
    return out


def script_json(doc: Any) -> str:
    """JSON that is safe inside ``<script type="application/json">``."""
    text = json.dumps(doc, allow_nan=False, separators=(",", ":"))
    return (text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
            .replace("\u2028", "\\u2028").replace("\u2029", "\\u2029"))


def _list(lines: list[str]) -> str:
    return "<ul>" + "".join(f"<li>{html.escape(str(x))}</li>" for x in lines) + "</ul>"


def text_section(text: dict[str, Any]) -> str:
    """The HTML of a scene's text sections (``<section id='sk-text'>``: units, solver,
    topology, validation, the spec file)."""
    parts = ["<section id='sk-text'>"]
    for key, title in (("units", "Units"), ("solver", "Solver"), ("topology", "Topology"),
                       ("validation", "Validation status")):
        if text.get(key):
            parts.append(f"<h2>{title}</h2>{_list(text[key])}")
    if text.get("spec"):
        parts.append(f"<h2>Spec file</h2><pre>{html.escape(text['spec'])}</pre>")
    parts.append("</section>")
    return "".join(parts)


def render_report_html(scene: dict[str, Any]) -> str:
    """The report page of a scene: one self-contained HTML document (string)."""
    e = html.escape
    n = len(scene["input"]["values"])
    src = str(scene.get("source") or "")
    source = f"<p class='muted'>source: {e(src)}</p>" if src and src not in str(scene.get("description")) else ""
    return "".join([
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width,initial-scale=1'>",
        f"<title>{e(scene['name'])} — screwkit report</title>",
        "<link rel='icon' href='data:,'>",
        f"<style>{_CSS}</style></head>",
        f"<body data-frames='{n}' data-frame='0'>",
        "<noscript><p>This report needs JavaScript for its 3-D view and plots.</p></noscript>",
        "<main><section id='sk-viewer' aria-label='3-D view'></section>",
        "<div id='sk-side'>", f"<header><h1>{e(scene['name'])}</h1>",
        f"<p class='muted'>{e(scene.get('description') or '')}</p>", source, "</header>",
        "<div id='sk-plots'></div>", text_section(scene["text"]),
        f"<footer>Made by screwkit {e(__version__)}. The viewer bundles three.js and Chart.js "
        "(MIT licences):<details><summary>third-party notices</summary><pre>",
        e(third_party_notices()), "</pre></details></footer></div></main>",
        "<script type='application/json' id='screwkit-scene'>", script_json(pack_scene(scene)),
        "</script><script>", viewer_bundle(), "</script></body></html>\n",
    ])
