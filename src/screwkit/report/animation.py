"""The 3-D scene of a report (:mod:`screwkit.report.scene`) with matplotlib, for papers and
slides: :func:`render_still` draws one frame (PNG, SVG, PDF), :func:`render_animation` the
whole cycle (GIF through Pillow, MP4 through ffmpeg where it is installed). The picture is the
one the HTML viewer draws: links as polylines between their joints, joints by type, traces,
the world axes and the load arrows, lengths in the report's display unit."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.report.plots import pyplot

JOINT_MARKERS = {"R": "o", "P": "s", "C": "D", "H": "*", "U": "X", "S": "o"}
JOINT_SIZES = {"R": 60, "P": 70, "C": 70, "H": 140, "U": 80, "S": 130}
LINK_COLOURS = ["#2f6db5", "#2a9d8f", "#8e6cc0", "#c9853a", "#4f8a3c", "#b5485d"]
ARROW_COLOURS = ["#d32f2f", "#f57c00", "#388e3c", "#7b1fa2", "#0288d1", "#5d4037"]


def _arr(x: Any) -> np.ndarray:
    return np.asarray(x, dtype=float)


def _check(scene: dict[str, Any], mode: int, frame: int | None = None) -> None:
    modes = scene["modes"]
    if not 0 <= mode < len(modes):
        raise InputError(f"--mode {mode}: this mechanism has {len(modes)} assembly mode(s) "
                         f"(0…{len(modes) - 1})")
    n = len(scene["input"]["values"])
    if frame is not None and not 0 <= frame < n:
        raise InputError(f"--frame {frame}: the sweep has {n} frames (0…{n - 1})")


def check_plots(scene: dict[str, Any], paths: list[Path], *, mode: int, frame: int) -> None:
    """Refuse, before anything is written, ``--plot`` files that :func:`render_still` or
    :func:`render_animation` would refuse: the mode, the frame of a still, ffmpeg for an
    .mp4."""
    for p in paths:
        still = p.suffix.lower() in (".png", ".svg", ".pdf")
        _check(scene, mode, frame if still else None)
        if p.suffix.lower() == ".mp4":
            from matplotlib import animation

            if not animation.writers.is_available("ffmpeg"):
                raise InputError(f"{p}: an .mp4 needs ffmpeg, which is not installed; install "
                                 "it (e.g. apt-get install ffmpeg) or write a .gif")


class _Painter:
    """Draws frame i of one mode on a 3-D axes; everything in display units."""

    def __init__(self, scene: dict[str, Any], mode: int, fig: Any) -> None:
        self.scene = scene
        self.m = scene["modes"][mode]
        self.f = scene["display_units"]["factor"]
        self.unit = scene["display_units"]["length"]
        self.centres = _arr(self.m["joint_centres"]) * self.f
        self.links = _arr(self.m["link_points"]) * self.f
        self.ax = fig.add_subplot(projection="3d")
        pts = self.links.reshape(-1, 3)
        pts = pts[np.isfinite(pts).all(axis=1)]
        if pts.size == 0:
            pts = np.zeros((1, 3))
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        mid, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1e-9) * 1.1
        self.limits = [(c - half, c + half) for c in mid]
        self.size = 2 * half
        vec = [(k, a) for k, a in self.m["arrows"].items()]
        fmax = max((np.nanmax(np.linalg.norm(_arr(a["vectors"]), axis=-1), initial=0.0)
                    for _, a in vec), default=0.0)
        self.arrows = vec
        self.arrow_scale = 0.4 * self.size / fmax if fmax > 0 else 0.0

    def draw(self, i: int) -> None:
        ax, s = self.ax, self.scene
        ax.cla()
        for (a, b), c in zip(self.limits, "xyz", strict=True):
            getattr(ax, f"set_{c}lim")(a, b)
            getattr(ax, f"set_{c}label")(f"{c} ({self.unit})")
        ax.set_box_aspect((1, 1, 1))
        L = 0.3 * self.size
        for k, col in enumerate(("#d32f2f", "#388e3c", "#1976d2")):
            d = np.zeros(3)
            d[k] = L
            ax.quiver(0, 0, 0, *d, color=col, linewidth=1.2, arrow_length_ratio=0.08)
        closed = s["input"]["periodic"]
        for j in range(self.centres.shape[1]):
            tr = self.centres[:, j]
            if closed:
                tr = np.vstack([tr, tr[:1]])
            ax.plot(tr[:, 0], tr[:, 1], tr[:, 2], lw=0.6, alpha=0.5, color="#90a4ae")
        for tr in self.m["traces"].values():
            t = _arr(tr) * self.f
            ax.plot(t[:, 0], t[:, 1], t[:, 2], lw=1.2, color="#c2185b")
        title = f"{s['name']} — mode {self.m['index']}, {self._input_text(i)}"
        if not self.m["assembles"][i]:
            ax.set_title(title + "\n(does not assemble here: nothing drawn)", fontsize=10,
                         color="#b71c1c")
            return
        ax.set_title(title, fontsize=10)
        for k, link in enumerate(s["links"]):
            p = self.links[i, k]
            ax.plot(p[:, 0], p[:, 1], p[:, 2], lw=2.0 if link["ground"] else 3.5,
                    color="#9e9e9e" if link["ground"] else LINK_COLOURS[k % len(LINK_COLOURS)],
                    solid_capstyle="round")
        for j, joint in enumerate(s["joints"]):
            c = self.centres[i, j]
            ax.scatter(*c, marker=JOINT_MARKERS[joint["kind"]], s=JOINT_SIZES[joint["kind"]],
                       color="#e07020" if joint["input"] else "#37474f", depthshade=False,
                       zorder=5)
        for q, (name, a) in enumerate(self.arrows):
            v, p = _arr(a["vectors"])[i] * self.arrow_scale, _arr(a["points"])[i] * self.f
            if np.isfinite(v).all() and np.isfinite(p).all():
                ax.quiver(*p, *v, color=ARROW_COLOURS[q % len(ARROW_COLOURS)], linewidth=1.5,
                          arrow_length_ratio=0.15, label=name)
        if self.arrows:
            ax.legend(loc="upper left", fontsize=7)

    def _input_text(self, i: int) -> str:
        inp = self.scene["input"]
        v = float(inp["values"][i])
        if inp["kind"] == "angle":
            return f"{inp['name']} = {np.degrees(v):.1f} deg"
        return f"{inp['name']} = {v * self.f:.4g} {self.unit}"


def _atomic(path: Path, write: Any) -> None:
    if not path.parent.is_dir():
        raise InputError(f"cannot write {path}: folder {path.parent} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=str(path.parent))
    os.close(fd)
    try:
        write(tmp)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def render_still(scene: dict[str, Any], path: str | Path, *, mode: int = 0, frame: int = 0,
                 dpi: int = 120) -> None:
    """One frame of the 3-D scene to a picture file (format from the suffix)."""
    _check(scene, mode, frame)
    plt = pyplot()
    fig = plt.figure(figsize=(7, 6))
    try:
        _Painter(scene, mode, fig).draw(frame)
        _atomic(Path(path), lambda tmp: fig.savefig(tmp, dpi=dpi))
    finally:
        plt.close(fig)


def render_animation(scene: dict[str, Any], path: str | Path, *, mode: int = 0,
                     fps: int | None = None, dpi: int = 80) -> None:
    """The whole cycle of one mode as an animation: ``.gif`` (Pillow, always there with
    matplotlib) or ``.mp4`` (needs ffmpeg on the PATH)."""
    p = Path(path)
    check_plots(scene, [p], mode=mode, frame=0)
    plt = pyplot()
    from matplotlib import animation

    if p.suffix.lower() == ".mp4":
        writer: Any = animation.FFMpegWriter(fps=fps or 12)
    elif p.suffix.lower() == ".gif":
        writer = animation.PillowWriter(fps=fps or 12)
    else:
        raise InputError(f"{p}: an animation is a .gif or an .mp4; got {p.suffix or 'no suffix'!r}")
    n = len(scene["input"]["values"])
    fig = plt.figure(figsize=(6, 5.2))
    try:
        painter = _Painter(scene, mode, fig)
        anim = animation.FuncAnimation(fig, painter.draw, frames=n, repeat=False)
        _atomic(p, lambda tmp: anim.save(tmp, writer=writer, dpi=dpi))
    finally:
        plt.close(fig)
