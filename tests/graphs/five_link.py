"""Writes examples/mechanisms/five_link_suspension.toml: a five-link rear suspension whose
upright is held by five S–S links and a pushrod from a rocker, the input (module text below).

Run as a script to rewrite the example: ``python tests/graphs/five_link.py [PATH]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

if __name__ == "__main__":  # run as a script: the repository root on the path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from tests.graphs.three_upu import body_lines  # noqa: E402

PATH = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / \
    "five_link_suspension.toml"
#: (name, chassis ball, upright ball), mm
LINKS = (
    ("upper_front", (150.0, 420.0, 430.0), (20.0, 690.0, 460.0)),
    ("upper_rear", (-200.0, 440.0, 420.0), (-30.0, 690.0, 455.0)),
    ("lower_front", (250.0, 380.0, 160.0), (60.0, 730.0, 140.0)),
    ("lower_rear", (-220.0, 390.0, 150.0), (-70.0, 735.0, 135.0)),
    ("toe_link", (-250.0, 400.0, 250.0), (-150.0, 720.0, 220.0)),
)
ROCKER_PIVOT = (0.0, 380.0, 460.0)
ROCKER_AXIS = (1.0, 0.0, 0.0)
ROCKER_BALL = (0.0, 420.0, 520.0)
PUSHROD_FOOT = (0.0, 700.0, 170.0)
WHEEL_CENTRE = (0.0, 760.0, 300.0)
CONTACT_PATCH = (0.0, 765.0, 0.0)


def write_spec(path: Path = PATH) -> str:
    """The example's TOML text (written to ``path``)."""
    vec = lambda v: "[" + ", ".join(f"{float(x):.12g}" for x in v) + "]"  # noqa: E731
    out = [HEADER]
    bodies = [(name, [np.array(a), np.array(b)]) for name, a, b in LINKS]
    bodies.append(("rocker", [np.array(ROCKER_PIVOT), np.array(ROCKER_BALL)]))
    bodies.append(("pushrod", [np.array(ROCKER_BALL), np.array(PUSHROD_FOOT)]))
    bodies.append(("upright", [np.array(b) for _, _, b in LINKS] + [np.array(PUSHROD_FOOT)]))
    for name, pts in bodies:
        out += body_lines(name, pts)
    out += ["# the rocker turns on the chassis; its angle is the input (positive: bump)",
            "[[joints]]", 'name = "rocker_pivot"', 'kind = "R"',
            'between = ["ground", "rocker"]', f"at = {vec(ROCKER_PIVOT)}",
            f"axis = {vec(ROCKER_AXIS)}", "input = true", "",
            "[[joints]]", 'name = "pushrod_top"', 'kind = "S"',
            'between = ["rocker", "pushrod"]', f"at = {vec(ROCKER_BALL)}", "",
            "[[joints]]", 'name = "pushrod_foot"', 'kind = "S"',
            'between = ["pushrod", "upright"]', f"at = {vec(PUSHROD_FOOT)}", ""]
    for name, a, b in LINKS:
        out += [f"# {name.replace('_', ' ')} link", "[[joints]]", f'name = "{name}_in"',
                'kind = "S"', f'between = ["ground", "{name}"]', f"at = {vec(a)}", "",
                "[[joints]]", f'name = "{name}_out"', 'kind = "S"',
                f'between = ["{name}", "upright"]', f"at = {vec(b)}", ""]
    out += ["[[points]]", 'name = "wheel_centre"', 'body = "upright"',
            f"at = {vec(WHEEL_CENTRE)}", "",
            "[[points]]", 'name = "contact_patch"', 'body = "upright"',
            f"at = {vec(CONTACT_PATCH)}", "", FOOTER]
    text = "\n".join(out)
    path.write_text(text, encoding="utf-8")
    return text


HEADER = """\
# A five-link rear suspension (left corner; x forward, y outboard, z up, mm): the upright is
# held by five links, each an S-S rod from the chassis (upper front and rear, lower front and
# rear, and a toe link), and a pushrod from a rocker on the chassis, as on a racing car's
# pushrod suspension. The rocker's angle is the input; the wheel's travel, camber, toe and
# track change follow from the upright's pose. The upright, held by six rods at once, is a
# platform, not a chain of dyads: no closed form takes it, so every assembly mode comes from
# the homotopy on the point formulation (docs/kinematics.md), whose generic count is that of
# a general Stewart-Gough platform, 40. Hardpoints chosen for this example (no source).
# tests/graphs/five_link.py writes this file.
# Mass properties: each body is a 10 x 5 mm steel bar (0.39 kg/m) along the lines joining
# its joints (the upright a ring through its six balls), its centre of mass and inertia
# (kg*m^2, about the centre of mass, world axes) computed from those bars.
[mechanism]
name = "five-link suspension"

[units]
length = "mm"
angle = "deg"
"""

FOOTER = """\
[[outputs]]
name = "camber"
body = "upright"
vector = [0, 1, 0]
about = [1, 0, 0]

[[outputs]]
name = "toe"
body = "upright"
vector = [0, 1, 0]
about = [0, 0, 1]

[[outputs]]
name = "wheel_travel"
point = "wheel_centre"
along = [0, 0, 1]

[[outputs]]
name = "track_change"
point = "contact_patch"
along = [0, 1, 0]

[motion]
start = -12
stop = 12
step = 0.5
speed = "10 deg/s"
"""

if __name__ == "__main__":
    write_spec(Path(sys.argv[1]) if len(sys.argv) > 1 else PATH)
