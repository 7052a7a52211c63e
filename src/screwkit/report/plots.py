"""Plots of an analysis document: every seed variable and its rates over the input, per
assembly mode, and the coupler curve in Bagci's three projections (App. C: X–Y, X–Z, Y–Z)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

ANGLE_NAMES = {"phi0", "chi0", "theta2", "eta2", "theta3", "eta3", "theta0", "theta1"}
LENGTH_NAMES = {"S", "s4"}


def _is_angle(name: str) -> bool:
    """Seed names by list; joint freedoms by kind (``.s`` is a translation, the rest angles)."""
    if "." in name:
        return not name.endswith(".s")
    return name in ANGLE_NAMES or name not in LENGTH_NAMES


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise ValueError(
            "plots need matplotlib: pip install 'screwkit[plot]' (or use --json and plot yourself)"
        ) from exc
    return plt


def save_figure(fig: Any, path: str | Path, inputs: Any = (), option: str | None = None) -> None:
    """Save through a temporary file and a rename (no half-written picture on error; links,
    FIFOs, folders and the command's inputs are refused: screwkit.io.outputs)."""
    from screwkit.io.outputs import atomic_path

    p = Path(path)
    fmt = p.suffix[1:].lower() or "png"
    with atomic_path(p, inputs, option) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format=fmt)


def plot_analysis(doc: dict[str, Any], path: str | Path) -> None:
    """One row per seed variable (position, velocity, acceleration columns), one line per
    assembly mode; plus the coupler curve projections when the document has a coupler point."""
    plt = _pyplot()
    x = np.degrees(np.asarray(doc["input"], dtype=float))
    modes = doc["modes"]
    names = [n for n in modes[0]["variables"] if "." not in n and n not in ("theta0", "theta1")]
    if not names:
        names = [n for n in modes[0]["variables"] if n != doc["input_name"]][:3]
    has_cp = any("coupler_point" in m for m in modes)
    rows = len(names) + (1 if has_cp else 0)
    fig, axes = plt.subplots(rows, 3, figsize=(13, 2.8 * rows), squeeze=False)
    for r, name in enumerate(names):
        angle = _is_angle(name)
        for c, (key, label) in enumerate((("variables", ""), ("velocities", "'"), ("accelerations", "''"))):
            ax = axes[r, c]
            for m in modes:
                y = np.asarray(m[key][name], dtype=float)
                if angle and key == "variables":
                    y = np.degrees(y)
                ax.plot(x, y, label=f"mode {m['mode']}")
            unit = "deg" if angle and key == "variables" else ("rad" if angle else "m")
            per = {"variables": "", "velocities": "/s", "accelerations": "/s²"}[key]
            ax.set_title(f"{name}{label} ({unit}{per})")
            ax.set_xlabel(f"{doc['input_name']} (deg)")
            ax.grid(True, alpha=0.3)
        axes[r, 0].legend(fontsize=8)
    if has_cp:
        for c, (i, j) in enumerate((("x", "y"), ("x", "z"), ("y", "z"))):
            ax = axes[-1, c]
            for m in modes:
                if "coupler_point" in m:
                    cp = m["coupler_point"]
                    xi = np.asarray(cp[i], dtype=float)
                    yj = np.asarray(cp[j], dtype=float)
                    if _full_turn(x):  # close the curve of a periodic sweep
                        xi, yj = np.append(xi, xi[0]), np.append(yj, yj[0])
                    ax.plot(xi, yj, label=f"mode {m['mode']}")
            ax.set_title(f"coupler curve, {i.upper()}–{j.upper()} projection (m)")
            ax.set_aspect("equal", adjustable="datalim")
            ax.grid(True, alpha=0.3)
    fig.suptitle(f"{doc['mechanism']} — {doc.get('method', '')} analysis", fontsize=12)
    fig.tight_layout()
    try:
        save_figure(fig, path)
    finally:
        plt.close(fig)


def _full_turn(x_deg: np.ndarray) -> bool:
    if len(x_deg) < 3:
        return False
    step = x_deg[1] - x_deg[0]
    return bool(abs(x_deg[-1] - x_deg[0] + step - 360.0) < 1e-6)
