"""Writes examples/mechanisms/three_rps.toml: a 3-RPS parallel robot (Lee & Shah 1988), three
legs each an R joint on the base, a P joint along the leg (the input) and a ball joint (S) on
the platform (module text below); with a random generator, a general one (every joint moved,
every axis tilted) for the tests.

Run as a script to rewrite the example: ``python tests/graphs/three_rps.py [PATH]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

if __name__ == "__main__":  # run as a script: the repository root on the path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from tests.graphs.three_upu import body_lines  # noqa: E402

PATH = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / "three_rps.toml"
R_BASE, R_PLAT, HEIGHT = 200.0, 100.0, 300.0  # mm
THETA = np.radians([90.0, 210.0, 330.0])
#: the legs' extensions (mm) over the motion: 30 sin(2π t + 2π i / 3), t = 0 … 1
AMPLITUDE, SAMPLES = 30.0, 37


def geometry(rng: np.random.Generator | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The R joints' points and unit axes and the balls' centres (3, 3) each, mm: the R
    joints on a 200 mm circle with axes tangent to it, the balls on a 100 mm circle 300 mm up;
    with ``rng``, every joint moved by up to 20 mm and every axis tilted."""
    base = np.stack([R_BASE * np.cos(THETA), R_BASE * np.sin(THETA), 0 * THETA], 1)
    top = np.stack([R_PLAT * np.cos(THETA), R_PLAT * np.sin(THETA), 0 * THETA + HEIGHT], 1)
    tangent = np.stack([-np.sin(THETA), np.cos(THETA), 0 * THETA], 1)
    if rng is not None:
        base = base + rng.uniform(-20, 20, (3, 3))
        top = top + rng.uniform(-20, 20, (3, 3))
        tangent = tangent + rng.uniform(-0.2, 0.2, (3, 3))
        tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    return base, tangent, top


def extensions(n: int = SAMPLES) -> np.ndarray:
    """The example's rows (n, 3): each leg's extension (mm) from its drawn length."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    return AMPLITUDE * np.sin(2 * np.pi * t + 2 * np.pi * np.arange(3)[None, :] / 3)


def write_spec(path: Path = PATH, rng: np.random.Generator | None = None,
               reversed_leg: int | None = None) -> str:
    """The spec's TOML text (written to ``path``); ``rng``: a general 3-RPS
    (:func:`geometry`); ``reversed_leg``: that leg's P joint drawn the other way (the piston
    first, the axis reversed)."""
    vec = lambda v: "[" + ", ".join(f"{float(x):.12g}" for x in v) + "]"  # noqa: E731
    base, tangent, top = geometry(rng)
    mid = (base + top) / 2
    out = [HEADER]
    for i in range(3):
        out += body_lines(f"cylinder{i + 1}", [base[i], mid[i]])
        out += body_lines(f"piston{i + 1}", [mid[i], top[i]])
    out += body_lines("platform", list(top))
    for i in range(3):
        d = (top[i] - base[i]) / np.linalg.norm(top[i] - base[i])
        pair = [f"cylinder{i + 1}", f"piston{i + 1}"]
        if i == reversed_leg:
            pair, d = pair[::-1], -d
        out += [f"# leg {i + 1}", "[[joints]]", f'name = "R{i + 1}"', 'kind = "R"',
                f'between = ["ground", "cylinder{i + 1}"]', f"at = {vec(base[i])}",
                f"axis = {vec(tangent[i])}", "",
                "[[joints]]", f'name = "P{i + 1}"', 'kind = "P"',
                f'between = ["{pair[0]}", "{pair[1]}"]', f"at = {vec(mid[i])}",
                f"axis = {vec(d)}", "input = true", "",
                "[[joints]]", f'name = "S{i + 1}"', 'kind = "S"',
                f'between = ["piston{i + 1}", "platform"]', f"at = {vec(top[i])}", ""]
    out += ["[[points]]", 'name = "centre"', 'body = "platform"',
            f"at = {vec(top.mean(0))}", "", "[motion]",
            "# three leg extensions per row (mm), in the order P1, P2, P3", "rows = ["]
    out += ["  [" + ", ".join(f"{x:.10f}" if abs(x) > 5e-11 else "0" for x in row) + "],"
            for row in extensions()]
    out += ["]", 'speed = "10 mm/s"', ""]
    text = "\n".join(out)
    path.write_text(text, encoding="utf-8")
    return text


HEADER = """\
# A 3-RPS parallel robot (Lee & Shah 1988): three legs, each a revolute joint (R) on the
# base, a prismatic joint (P) along the leg, whose extension is the input, and a ball joint
# (S) on the platform. Each R axis is tangent to the base circle, so each leg swings in a
# vertical plane through the centre; the platform has three freedoms (heave, two tilts) and
# the forward kinematics 16 solutions. Dimensions chosen for this example (no source): R
# joints on a 200 mm circle at 90, 210, 330 deg, balls on a 100 mm circle at the same angles,
# 300 mm above the base. The rows are the three leg extensions (mm, from the drawn lengths),
# 30 sin(2pi t + 2pi i/3) for leg i = 0, 1, 2 and t = 0, 1/36, ..., 1: the platform wobbles.
# tests/graphs/three_rps.py writes this file.
# Mass properties: each body is a 10 x 5 mm steel bar (0.39 kg/m) along the lines joining
# its joints (the platform a ring through its balls), its centre of mass and inertia
# (kg*m^2, about the centre of mass, world axes) computed from those bars.
[mechanism]
name = "3-RPS parallel robot"

[units]
length = "mm"
angle = "deg"
"""

if __name__ == "__main__":
    write_spec(Path(sys.argv[1]) if len(sys.argv) > 1 else PATH)
