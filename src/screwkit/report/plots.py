"""Plots of an analysis document: every seed variable and its rates over the input, per
assembly mode, and the coupler curve in Bagci's three projections (App. C: X–Y, X–Z, Y–Z)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError


def pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise InputError(
            "plots need matplotlib: pip install 'screwkit[plot]' (or use --json and plot yourself)"
        ) from exc
    return plt


def tidy_axes(fig: Any) -> None:
    """Axes a person can read, on every linear 2-D axes of ``fig``: limits rounded outward to
    the tick step where matplotlib chose them (no margin past a round number), tick labels
    without an offset ("90", not "+9e1" and "0.000003") and with a ×10ⁿ multiplier outside
    10⁻³…10⁵ (2×10⁶ deg/s², not 2000000). Equal-aspect axes (coupler curves) keep their
    limits."""
    import matplotlib as mpl
    from matplotlib.ticker import ScalarFormatter

    with mpl.rc_context({"axes.autolimit_mode": "round_numbers"}):
        for ax in fig.axes:
            if hasattr(ax, "zaxis") or ax.name != "rectilinear":
                continue
            for axis, auto, margin in ((ax.xaxis, ax.get_autoscalex_on(), ax.set_xmargin),
                                       (ax.yaxis, ax.get_autoscaley_on(), ax.set_ymargin)):
                if axis.get_scale() != "linear":
                    continue
                fmt = ScalarFormatter(useOffset=False, useMathText=True)
                fmt.set_powerlimits((-3, 5))
                axis.set_major_formatter(fmt)
                if auto and ax.get_aspect() == "auto":
                    margin(0)
            if ax.get_aspect() == "auto":
                ax.relim()
                ax.autoscale_view()


def save_figure(fig: Any, path: str | Path, inputs: Any = (), option: str | None = None) -> None:
    """Save through a temporary file and a rename (no half-written picture on error; links,
    FIFOs, folders and the command's inputs are refused: screwkit.io.outputs), the axes tidied
    (:func:`tidy_axes`)."""
    from screwkit.io.outputs import atomic_path

    p = Path(path)
    fmt = p.suffix[1:].lower() or "png"
    tidy_axes(fig)
    with atomic_path(p, inputs, option) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format=fmt)


def continuous_rotation_vectors(rv: np.ndarray) -> np.ndarray:
    """Rotation vectors (N, 3) made continuous along the sweep. ``as_rotvec`` keeps |r| ≤ π,
    so a rotation passing through π jumps to the antipodal vector (−(2π − |r|) r̂, the same
    rotation); here each sample keeps the axis sign of the one before and the angle is
    unwrapped, which gives back a smooth curve (|r| may then exceed π). NaN rows (samples that
    do not assemble) are kept and restart the chain."""
    out = np.array(rv, dtype=float)
    ok = np.isfinite(out).all(axis=1)
    angle = np.linalg.norm(out, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = out / angle[:, None]
    tiny = ~(angle > 1e-9)
    start = 0
    for stop in [*np.nonzero(~ok)[0].tolist(), len(out)]:  # runs between non-assembling samples
        run = np.arange(start, stop)
        start = stop + 1
        if run.size < 2:
            continue
        a, th = axis[run], angle[run]
        dots = np.einsum("ij,ij->i", a[1:], a[:-1])
        flip = np.where((dots < 0) & ~tiny[run][1:] & ~tiny[run][:-1], -1.0, 1.0)
        sign = np.concatenate([[1.0], np.cumprod(flip)])
        th_signed = np.unwrap(sign * th, period=2 * np.pi)
        a = a * sign[:, None]
        out[run] = np.where(tiny[run][:, None], out[run], a * th_signed[:, None])
    return out


def flatten_constant_axis(ax: Any, ys: list[np.ndarray]) -> None:
    """No offset notation, and a curve that is constant to round-off is shown as a flat line
    (a constant rate was drawn as noise on a 1e-10 axis offset by 6.283185307)."""
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")
    finite = np.concatenate([y[np.isfinite(y)] for y in ys]) if ys else np.array([])
    if finite.size == 0:
        return
    lo, hi = float(finite.min()), float(finite.max())
    scale = max(abs(lo), abs(hi), 1.0)
    if hi - lo <= 1e-9 * scale:
        mid = 0.5 * (lo + hi)
        half = max(0.05 * abs(mid), 1e-3)
        ax.set_ylim(mid - half, mid + half)


def _smoothed(mode: dict[str, Any], key: str) -> dict[str, np.ndarray]:
    """A mode's table with every spherical joint's rotation vector made continuous."""
    table = {k: np.asarray(v, dtype=float) for k, v in mode[key].items()}
    if key != "variables":
        return table
    for name in [k for k in table if k.endswith(".rx")]:
        joint = name[:-3]
        parts = [f"{joint}.r{a}" for a in "xyz"]
        if all(p in table for p in parts):
            rv = continuous_rotation_vectors(np.stack([table[p] for p in parts], axis=1))
            for a, p in enumerate(parts):
                table[p] = rv[:, a]
    return table


def plot_analysis(doc: dict[str, Any], path: str | Path, units: Any = None) -> None:
    """One row per seed variable (position, velocity, acceleration columns), one line per
    assembly mode; plus the coupler curve projections when the document has a coupler point.
    In ``units`` (a :class:`~screwkit.io.display_units.DisplayUnits`, e.g. the spec's; default
    deg and m): angles and their rates share the angle unit (deg, deg/s, deg/s²), lengths and
    theirs the length unit."""
    from screwkit.io.display_units import display_units
    from screwkit.kinematics.motion_table import ACCELERATION_KIND, RATE_KIND, variable_kind

    du = units if units is not None else display_units({"angle": "deg"})
    plt = pyplot()
    input_kind = variable_kind(doc["input_name"])
    x = du.show(input_kind, np.asarray(doc["input"], dtype=float))
    modes = doc["modes"]
    names = [n for n in modes[0]["variables"] if "." not in n and n not in ("theta0", "theta1")]
    if not names:
        names = [n for n in modes[0]["variables"] if n != doc["input_name"]][:3]
    curves = [_curves(m) for m in modes]
    periodic = _full_turn(np.degrees(np.asarray(doc["input"], dtype=float)))
    has_cp = any(curves)
    has_tr = any("transmission" in m for m in modes)
    rows = len(names) + (1 if has_cp else 0) + (1 if has_cp or has_tr else 0)
    fig, axes = plt.subplots(rows, 3, figsize=(13, 2.8 * rows), squeeze=False)
    tables = [{key: _smoothed(m, key) for key in ("variables", "velocities", "accelerations")}
              for m in modes]
    for r, name in enumerate(names):
        base = variable_kind(name)
        kinds = {"variables": base, "velocities": RATE_KIND[base],
                 "accelerations": ACCELERATION_KIND[base]}
        for c, (key, label) in enumerate((("variables", ""), ("velocities", "'"), ("accelerations", "''"))):
            ax = axes[r, c]
            ys = []
            for m, t in zip(modes, tables, strict=True):
                y = du.show(kinds[key], t[key][name])
                ys.append(y)
                ax.plot(x, y, label=f"mode {m['mode']}")
            ax.set_title(f"{name}{label} ({du.pretty(kinds[key])})")
            ax.set_xlabel(f"{doc['input_name']} ({du.pretty(input_kind)})")
            ax.grid(True, alpha=0.3)
            flatten_constant_axis(ax, ys)
        axes[r, 0].legend(fontsize=8)
    if has_cp:
        _coupler_projections(axes[len(names)], modes, curves, du, periodic)
    if has_cp or has_tr:
        _last_row(fig, axes[-1], modes, curves, x, du, periodic,
                  f"{doc['input_name']} ({du.pretty(input_kind)})")
    fig.suptitle(f"{doc['mechanism']} — {doc.get('method', '')} analysis", fontsize=12)
    fig.tight_layout()
    try:
        save_figure(fig, path)
    finally:
        plt.close(fig)


def _curves(mode: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """The mode's coupler curves by name (a lone ``coupler_point`` as "coupler point")."""
    if "coupler_points" in mode:
        return dict(mode["coupler_points"])
    return {"coupler point": mode["coupler_point"]} if "coupler_point" in mode else {}


def _closed(periodic: bool, *arrays: Any) -> list[np.ndarray]:
    """The arrays with their first sample appended when the sweep is a full turn."""
    arrs = [np.asarray(a, dtype=float) for a in arrays]
    return [np.append(a, a[0]) for a in arrs] if periodic else arrs


def _coupler_projections(row: Any, modes: list[dict[str, Any]], curves: list[dict[str, Any]],
                         du: Any, periodic: bool) -> None:
    for c, (i, j) in enumerate((("x", "y"), ("x", "z"), ("y", "z"))):
        ax = row[c]
        for m, cv in zip(modes, curves, strict=True):
            for name, cp in cv.items():
                xi, yj = _closed(periodic, du.show("length", np.asarray(cp[i], dtype=float)),
                                 du.show("length", np.asarray(cp[j], dtype=float)))
                ax.plot(xi, yj, label=f"{name}, mode {m['mode']}")
        ax.set_title(f"coupler curves, {i.upper()}–{j.upper()} projection "
                     f"({du.pretty('length')})")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    row[0].legend(fontsize=7)


def _last_row(fig: Any, row: Any, modes: list[dict[str, Any]], curves: list[dict[str, Any]],
              x: np.ndarray, du: Any, periodic: bool, x_label: str) -> None:
    """The coupler curves in 3-D, the transmission index and the transmission angle (planar
    loops) or the ball-joint cone angles, over the input."""
    if any(curves):
        pos = row[0].get_subplotspec()
        row[0].remove()
        ax3 = fig.add_subplot(pos, projection="3d")
        for m, cv in zip(modes, curves, strict=True):
            for name, cp in cv.items():
                ax3.plot(*_closed(periodic, *(du.show("length", np.asarray(cp[k], dtype=float))
                                              for k in "xyz")), label=f"{name}, mode {m['mode']}")
        ax3.set_title(f"coupler curves in 3-D ({du.pretty('length')})")
    else:
        row[0].axis("off")
    tr = [(m["mode"], m["transmission"]) for m in modes if "transmission" in m]
    for col in (1, 2):
        ax = row[col]
        if not tr:
            ax.axis("off")
            continue
        title = "transmission index"
        for k, t in tr:
            if col == 1:
                for name, ti in t["index"].items():
                    ax.plot(x, np.asarray(ti, dtype=float), label=f"{name}, mode {k}")
            elif "angle" in t:
                title = f"transmission angle μ ({du.pretty('angle')})"
                ax.plot(x, du.show("angle", np.asarray(t["angle"], dtype=float)),
                        label=f"mode {k}")
            else:
                title = f"ball-joint cone angles ({du.pretty('angle')})"
                for joint, a in t["cone_angle"].items():
                    ax.plot(x, du.show("angle", np.asarray(a, dtype=float)),
                            label=f"{joint}, mode {k}")
        ax.set_title(title)
        ax.set_xlabel(x_label)
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)


def _full_turn(x_deg: np.ndarray) -> bool:
    if len(x_deg) < 3:
        return False
    step = x_deg[1] - x_deg[0]
    return bool(abs(x_deg[-1] - x_deg[0] + step - 360.0) < 1e-6)
