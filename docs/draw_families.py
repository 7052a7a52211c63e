"""Draw every mechanism family's frames for docs/families.md: from the family constructors (through
a bundled example spec) and the solved motion at one input, in the spec's units —

* the world (ground) axes X, Y, Z at the origin;
* every joint centre (the point reaction moments are taken about; ``ModeMotion.joint_centres``)
  with its name and kind, and its axis;
* every moving link's body frame (``link_origin``, ``link_rotation``: x red, y green, z blue) — the
  frame its ``com`` and ``inertia`` are given in;
* each link's centre of mass from the example's ``[links.<name>] com`` (a ring, joined to the
  frame origin it is measured from).

    python docs/draw_families.py              # writes docs/families/<family>.png
    python docs/draw_families.py OUT RSRC     # one family into OUT
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
#: family -> (example spec, input angle drawn in degrees, view elevation, view azimuth)
FIGURES = {
    "RSRC": ("rsrc_fig7_dynamics.toml", 60.0, 22, -58),
    "CSSP": ("rahman_cssp.toml", 60.0, 20, -60),
    "4R": ("fourbar_dynamics.toml", 60.0, 90, -90),
    "RSSR": ("rssr_spatial.toml", 60.0, 22, -58),
    "LOOP": ("rccc_loop.toml", 60.0, 25, -50),
}
MARKERS = {"R": "o", "P": "s", "C": "D", "H": "h", "U": "^", "S": "*"}


def draw(family: str, out: Path) -> Path:
    """One family's figure (module docstring) written to ``out`` (PNG); returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import screwkit as sk

    name, angle, elev, azim = FIGURES[family]
    spec = sk.load_spec(EXAMPLES / name)
    du = spec.display_units()
    unit = du.label("length")
    k = 1.0 / du.unit_of("length")[1]
    lk = spec.linkage
    motion = sk.solve_motion(lk, np.radians([angle]), rates=1.0)
    md = motion.mode(0)
    centres = md.joint_centres[0] * k
    axes = md.joint_axes[0]
    scale = float(np.max(np.ptp(centres, axis=0))) or 1.0
    arrow = 0.22 * scale
    fig = plt.figure(figsize=(7.5, 6.2))
    ax = fig.add_subplot(projection="3d")
    for v, label in zip(np.eye(3), "XYZ", strict=True):
        ax.quiver(0, 0, 0, *(v * 0.35 * scale), color="black", lw=0.8, arrow_length_ratio=0.08)
        ax.text(*(v * 0.4 * scale), label, color="black")
    loop = np.vstack([centres, centres[:1]])
    ax.plot(loop[:, 0], loop[:, 1], loop[:, 2], color="0.55", lw=3, alpha=0.6)
    for j, joint in enumerate(lk.joints):
        c, u = centres[j], axes[j]
        ax.scatter(*c, marker=MARKERS[joint.kind], s=70, color="black", depthshade=False)
        ax.plot(*np.stack([c - 0.18 * scale * u, c + 0.18 * scale * u]).T, color="black",
                lw=1, ls="--")
        ax.text(*(c + 0.04 * scale), f"{joint.name} ({joint.kind})", fontsize=8)
    for i, link in enumerate(lk.links):
        o = md.link_origin[0, i] * k
        R = md.link_rotation[0, i]
        for a, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
            ax.quiver(*o, *(R[:, a] * arrow), color=colour, lw=1.6, arrow_length_ratio=0.15)
        ax.text(*(o - 0.08 * scale), f"{{{link.name}}}", color="tab:purple", fontsize=9)
        if link.mass is not None:
            com = o + R @ (np.asarray(link.mass.com) * k)
            ax.scatter(*com, s=90, facecolors="none", edgecolors="tab:purple", depthshade=False)
            ax.plot(*np.stack([o, com]).T, color="tab:purple", lw=0.8, ls=":")
    lo, hi = np.min(np.vstack([centres, [0, 0, 0]]), axis=0), np.max(
        np.vstack([centres, [0, 0, 0]]), axis=0)
    mid, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1e-9) * 1.15
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel(f"X ({unit})")
    ax.set_ylabel(f"Y ({unit})")
    ax.set_zlabel(f"Z ({unit})")
    ax.set_title(f"{family} ({name}) at input {angle:g}°: link frames x/y/z = red/green/blue,\n"
                 "joint centres (markers by kind), centres of mass (purple rings)", fontsize=9)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def main(argv: list[str]) -> int:
    folder = Path(argv[0]) if argv else HERE / "families"
    for family in argv[1:] or list(FIGURES):
        print(draw(family, folder / f"{family.lower()}.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
