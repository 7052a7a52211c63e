"""Draw every bundled mechanism graph for docs/mechanisms.md, in the spec's length unit:

* every body in the drawn configuration as lines joining its joints (a colour per body);
* every joint by kind (R ○, P □, C ◇, H ⬡, U △, S ★) with its name, and the ground's joints black;
* the path of every ``[[points]]`` entry over the spec's motion (dashed), and the point itself.

    python docs/draw_mechanisms.py                     # writes docs/mechanisms/<example>.png
    python docs/draw_mechanisms.py OUT watt_sixbar     # one example into OUT
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples" / "mechanisms"
MARKERS = {"R": "o", "P": "s", "C": "D", "H": "h", "U": "^", "S": "*"}
#: examples drawn flat (seen along z): the planar ones
PLANAR = {"fourbar_graph", "watt_sixbar", "watt_sixbar_balance", "watt_sixbar_simulate",
          "stephenson3_sixbar",
          "jansen_leg"}


def draw(stem: str, out: Path) -> Path:
    """One example's figure (module docstring) written to ``out``; returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import screwkit as sk
    from screwkit.io.units import unit_factor

    spec = sk.load_spec(EXAMPLES / f"{stem}.toml")
    mech = spec.mechanism
    unit = spec.units.get("length", "m")
    scale = 1.0 / unit_factor(unit, "length")
    motion = sk.solve_mechanism(mech, spec.inputs, rates=spec.speed)
    md = motion.modes[0]
    planar = stem in PLANAR
    fig = plt.figure(figsize=(6.4, 5.2), dpi=110)
    ax = fig.add_subplot(111) if planar else fig.add_subplot(111, projection="3d")

    def plot(xyz: np.ndarray, *args: object, **kw: object) -> None:
        pts = np.atleast_2d(xyz) * scale
        if planar:
            ax.plot(pts[:, 0], pts[:, 1], *args, **kw)
        else:
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], *args, **kw)

    colours = plt.get_cmap("tab10")
    for k, body in enumerate(mech.bodies):
        at = [j.at for j in mech.joints if body.name in j.bodies]
        at += [p.at for p in mech.points if p.body == body.name]
        if len(at) >= 2:
            ring = np.array(at + [at[0]] if len(at) > 2 else at)
            plot(ring, "-", color=colours(k % 10), lw=2.5, label=body.name)
    for j in mech.joints:
        grounded = "ground" in j.bodies
        plot(j.at, MARKERS[j.kind], color="black" if grounded else "dimgray", ms=8,
             mfc="white" if not grounded else "black")
        pos = j.at * scale
        if planar:
            ax.annotate(j.name, pos[:2], textcoords="offset points", xytext=(5, 5), fontsize=8)
        else:
            ax.text(*pos, f" {j.name}", fontsize=7)
    for p in mech.points:
        plot(md.points[p.name][md.assembles], "--", color="crimson", lw=1.0)
        plot(p.at, "x", color="crimson", ms=8)
    title = f"{spec.name}: {len(mech.bodies)} bodies, {len(mech.joints)} joints, " \
            f"{len(mech.topology.loops)} loop(s)"
    ax.set_title(title, fontsize=10)
    if planar:
        ax.set_aspect("equal")
        ax.set_xlabel(f"x [{unit}]")
        ax.set_ylabel(f"y [{unit}]")
    else:
        ax.set_xlabel(f"x [{unit}]")
        ax.set_ylabel(f"y [{unit}]")
        ax.set_zlabel(f"z [{unit}]")  # type: ignore[attr-defined]
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out


def main(argv: list[str]) -> int:
    folder = Path(argv[0]) if argv else HERE / "mechanisms"
    stems = argv[1:] or sorted(p.stem for p in EXAMPLES.glob("*.toml"))
    for stem in stems:
        print(draw(stem, folder / f"{stem}.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
