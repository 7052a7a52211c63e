"""A small picture of a mechanism for the demo's gallery (``index.html``): an inline SVG of the
loop at one frame in an isometric view — the links as the report draws them
(:func:`screwkit.report.scene.link_polylines`), the joints as dots, the input joint in orange —
over the paths its joint centres take through the cycle (light lines). No matplotlib: a few
kilobytes of text per example, drawn in milliseconds."""

from __future__ import annotations

import html
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.report.scene import link_polylines

Array = NDArray[np.float64]
#: the view: azimuth −60°, elevation 30° (matplotlib's default 3-D view), z up
AZIMUTH, ELEVATION = np.radians(-60.0), np.radians(30.0)
WIDTH, HEIGHT, PAD = 200, 140, 8


def view_rotation() -> Array:
    """(2, 3): world → picture (right, up) for the isometric view."""
    ca, sa, ce, se = np.cos(AZIMUTH), np.sin(AZIMUTH), np.cos(ELEVATION), np.sin(ELEVATION)
    right = np.array([-sa, ca, 0.0])
    up = np.array([-se * ca, -se * sa, ce])
    return np.stack([right, up])


def shown_mode_and_frame(motion: Any, preferred: int = 0) -> tuple[int, int] | None:
    """The mode drawn (``preferred`` when it assembles anywhere, else the mode assembling at the
    most samples) and its first assembling frame; None when no mode assembles."""
    counts = [int(np.sum(np.asarray(m.assembles, dtype=bool))) for m in motion.modes]
    if not counts or max(counts) == 0:
        return None
    k = preferred if 0 <= preferred < len(counts) and counts[preferred] else int(np.argmax(counts))
    return k, int(np.argmax(np.asarray(motion.modes[k].assembles, dtype=bool)))


def _fit(points: Array) -> tuple[float, float, float]:
    """Scale and offsets taking picture coordinates into the SVG box (y down)."""
    lo, hi = np.nanmin(points, axis=0), np.nanmax(points, axis=0)
    span = np.maximum(hi - lo, 1e-12)
    scale = float(min((WIDTH - 2 * PAD) / span[0], (HEIGHT - 2 * PAD) / span[1]))
    ox = PAD + ((WIDTH - 2 * PAD) - scale * span[0]) / 2 - scale * lo[0]
    oy = PAD + ((HEIGHT - 2 * PAD) - scale * span[1]) / 2 + scale * hi[1]
    return scale, float(ox), float(oy)


def _path(points: Array, fit: tuple[float, float, float]) -> str:
    """An SVG path through the finite points, a new sub-path after each gap."""
    scale, ox, oy = fit
    out, pen = [], "M"
    for x, y in points:
        if not (np.isfinite(x) and np.isfinite(y)):
            pen = "M"
            continue
        out.append(f"{pen}{ox + scale * x:.1f} {oy - scale * y:.1f}")
        pen = "L"
    return " ".join(out)


def _opening(title: str) -> tuple[str, str]:
    """The SVG element's opening tag and its title."""
    box = (f"<svg xmlns='http://www.w3.org/2000/svg' width='{WIDTH}' height='{HEIGHT}' "
           f"viewBox='0 0 {WIDTH} {HEIGHT}' role='img'>")
    return box, f"<title>{html.escape(title)}</title>" if title else ""


def _empty(box: str, label: str) -> str:
    """The picture of a mechanism that assembles nowhere: a frame saying so."""
    return (box + label + f"<text x='{WIDTH / 2}' y='{HEIGHT / 2}' text-anchor='middle' "
            "font-size='11' fill='#777'>does not assemble</text></svg>")


def mechanism_svg(linkage: Any, motion: Any, preferred_mode: int = 0, title: str = "") -> str:
    """The gallery picture (module docstring) of ``motion`` (a solved motion of ``linkage``);
    an empty frame saying so when no mode assembles."""
    box, label = _opening(title)
    chosen = shown_mode_and_frame(motion, preferred_mode)
    if chosen is None:
        return _empty(box, label)
    k, frame = chosen
    mode = motion.modes[k]
    view = view_rotation()
    centres = np.asarray(mode.joint_centres, dtype=float) @ view.T  # (N, n, 2)
    links = link_polylines(linkage, mode)[frame] @ view.T  # (n, 3, 2)
    fit = _fit(np.concatenate([centres.reshape(-1, 2), links.reshape(-1, 2)]))
    parts = [box, label]
    for j in range(centres.shape[1]):
        parts.append(f"<path d='{_path(centres[:, j], fit)}' fill='none' stroke='#9ec5e8' "
                     "stroke-width='1'/>")
    for i, pts in enumerate(links):
        ground = i == len(links) - 1
        colour, dash = ("#9e9e9e", " stroke-dasharray='4 3'") if ground else ("#2f4f6f", "")
        parts.append(f"<path d='{_path(pts, fit)}' fill='none' stroke='{colour}' "
                     f"stroke-width='2.2' stroke-linejoin='round'{dash}/>")
    inputs = {name.split(".")[0] for name in linkage.inputs}
    scale, ox, oy = fit
    for j, joint in enumerate(linkage.joints):
        x, y = centres[frame, j]
        colour = "#e07020" if joint.name in inputs else "#37474f"
        parts.append(f"<circle cx='{ox + scale * x:.1f}' cy='{oy - scale * y:.1f}' r='3.2' "
                     f"fill='{colour}'><title>{html.escape(joint.name)}</title></circle>")
    parts.append("</svg>")
    return "".join(parts)


def graph_svg(mechanism: Any, motion: Any, title: str = "") -> str:
    """The gallery picture of a mechanism graph's drawn mode: each body as the polygon of its
    joint centres at the first assembling frame, over the paths of the joint centres."""
    box, label = _opening(title)
    chosen = shown_mode_and_frame(motion, 0)
    if chosen is None:
        return _empty(box, label)
    k, frame = chosen
    mode = motion.modes[k]
    view = view_rotation()
    centres = np.asarray(mode.joint_centres, dtype=float) @ view.T  # (N, n, 2)
    fit = _fit(centres[np.isfinite(centres).all(axis=(1, 2))].reshape(-1, 2))
    parts = [box, label]
    for j in range(centres.shape[1]):
        ok = np.isfinite(centres[:, j]).all(axis=1)
        parts.append(f"<path d='{_path(centres[ok, j], fit)}' fill='none' stroke='#9ec5e8' "
                     "stroke-width='1'/>")
    for body in mechanism.body_names:
        idx = [j for j, joint in enumerate(mechanism.joints) if body in joint.bodies]
        pts = centres[frame, idx + idx[:1]] if len(idx) > 2 else centres[frame, idx]
        parts.append(f"<path d='{_path(pts, fit)}' fill='none' stroke='#2f4f6f' "
                     "stroke-width='2.2' stroke-linejoin='round'/>")
    inputs = {name.split(".")[0] for name in (*mechanism.inputs, *mechanism.actuated)}
    scale, ox, oy = fit
    for j, joint in enumerate(mechanism.joints):
        x, y = centres[frame, j]
        grounded = "ground" in joint.bodies
        colour = "#e07020" if joint.name in inputs else ("#000" if grounded else "#37474f")
        parts.append(f"<circle cx='{ox + scale * x:.1f}' cy='{oy - scale * y:.1f}' r='3.2' "
                     f"fill='{colour}'><title>{html.escape(joint.name)}</title></circle>")
    parts.append("</svg>")
    return "".join(parts)
