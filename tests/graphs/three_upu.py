"""The translational 3-UPU (Tsai 1996) of examples/mechanisms/three_upu.toml, rebuilt here
independently of screwkit: its geometry, inverse kinematics and a finite-difference closure
Jacobian. ``python tests/graphs/three_upu.py`` writes the example.

Base joints B_i = R r_i, platform joints P_i = r r_i + c (c the platform's centre offset, the
platform only translates), r_i = (cos θ_i, sin θ_i, 0) at θ_i = 0, 120, 240 deg. Leg i: a U on
the base with axes a_i (tangent, fixed in the ground) and b_i = a_i × d_i/|a_i × d_i| (d_i the
drawn leg), a P along the leg (the input: its extension), a U on the platform with axes b_i
(in the piston) and a_i (in the platform). Each leg's constraint is a couple along
c_i = a_i × b_i ∝ d_i − (a_i·d_i) a_i = u_i r_i + z e_z, u_i = r − R + c·r_i. The couples become
dependent, a constraint singularity (Zlatanov, Bonev & Gosselin 2002, "Constraint
singularities of parallel mechanisms", ICRA), where det[c_1 c_2 c_3] = z (√3/2)
(u_1u_2 + u_2u_3 + u_3u_1) vanishes; with Σ c·r_i = 0 and Σ (c·r_i)² = (3/2)|c_xy|²,
u_1u_2 + u_2u_3 + u_3u_1 = 3(r − R)² − (3/4)|c_xy|²: at every height, wherever the platform's
horizontal offset is |c_xy| = 2|R − r| (200 mm here).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

R_BASE, R_PLAT, HEIGHT = 200.0, 100.0, 300.0  # mm
SINGULAR_OFFSET = 2.0 * abs(R_BASE - R_PLAT)  # mm, the horizontal offset of the singularity
THETA = np.radians([0.0, 120.0, 240.0])
RADIAL = np.stack([np.cos(THETA), np.sin(THETA), np.zeros(3)], axis=1)
TANGENT = np.stack([-np.sin(THETA), np.cos(THETA), np.zeros(3)], axis=1)
BASE = R_BASE * RADIAL
PLATFORM = R_PLAT * RADIAL + [0.0, 0.0, HEIGHT]
LEG = PLATFORM - BASE
CROSS = np.cross(TANGENT, LEG)
CROSS /= np.linalg.norm(CROSS, axis=1, keepdims=True)
LENGTH = np.linalg.norm(LEG, axis=1)
PATH = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / "three_upu.toml"
#: steel bar 10 x 5 mm, kg/m (as the other bundled examples)
BAR = 0.39


def slides(offset: np.ndarray) -> np.ndarray:
    """Inverse kinematics: the leg extensions (N, 3) (mm, from the drawn lengths) that carry
    the platform by ``offset`` (N, 3) mm: |P_i + c − B_i| − |P_i − B_i|."""
    c = np.atleast_2d(offset)
    return np.linalg.norm(LEG[None] + c[:, None, :], axis=2) - LENGTH[None]


def couple_det(offset: np.ndarray) -> np.ndarray:
    """det[c_1 c_2 c_3] of the unit constraint couples (module docstring) at ``offset``."""
    c = np.atleast_2d(offset)
    d = LEG[None] + c[:, None, :]
    cc = d - np.einsum("nij,ij->ni", d, TANGENT)[..., None] * TANGENT[None]
    cc /= np.linalg.norm(cc, axis=2, keepdims=True)
    return np.asarray(np.linalg.det(cc))


def _rot(u: np.ndarray, th: float) -> np.ndarray:
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def _screw_motion(axis: np.ndarray, at: np.ndarray, th: float, slide: bool) -> np.ndarray:
    T = np.eye(4)
    if slide:
        T[:3, 3] = axis * th
    else:
        Rm = _rot(axis, th)
        T[:3, :3], T[:3, 3] = Rm, at - Rm @ at
    return T


def leg_pose(i: int, q: np.ndarray) -> np.ndarray:
    """The platform's pose (4 × 4, mm) reached through leg i at its five joint variables
    ``q`` (rad, rad, mm, rad, rad) from the drawing: a product of exponentials of the drawn
    joint screws (base U: a_i then b_i; P along d_i; platform U: b_i then a_i)."""
    a, b, d = TANGENT[i], CROSS[i], LEG[i] / LENGTH[i]
    T = np.eye(4)
    for axis, at, slide, th in [(a, BASE[i], False, q[0]), (b, BASE[i], False, q[1]),
                                (d, BASE[i], True, q[2]), (b, PLATFORM[i], False, q[3]),
                                (a, PLATFORM[i], False, q[4])]:
        T = T @ _screw_motion(axis, at, th, slide)
    return T


def leg_variables(offset: np.ndarray) -> np.ndarray:
    """Each leg's joint variables (3, 5) with the platform translated by ``offset`` (3,): the
    base U turns the leg onto its new direction (about a_i, then b_i), the slide stretches it,
    the platform U turns back (b_i, then a_i: the platform does not turn)."""
    q = np.zeros((3, 5))
    for i in range(3):
        a, b, d0 = TANGENT[i], CROSS[i], LEG[i] / LENGTH[i]
        v = LEG[i] + offset
        w = v / np.linalg.norm(v)
        # b = a × d0, so Rot(b, t2) d0 = cos t2 d0 − sin t2 a and Rot(a, t1) keeps w·a
        e = b
        t2 = np.arcsin(np.clip(-np.dot(w, a), -1.0, 1.0))
        inner = _rot(b, t2) @ d0
        x = [np.dot(inner, d0), np.dot(inner, e)]
        y = [np.dot(w, d0), np.dot(w, e)]
        t1 = np.arctan2(x[0] * y[1] - x[1] * y[0], x[0] * y[0] + x[1] * y[1])
        q[i] = [t1, t2, np.linalg.norm(v) - LENGTH[i], -t2, -t1]
    return q


def _twist(T1: np.ndarray, T0: np.ndarray) -> np.ndarray:
    """The spatial twist (ω, v at the origin) that moves T0 to T1, to first order."""
    dT = (T1 - T0) @ np.linalg.inv(T0)
    return np.array([dT[2, 1], dT[0, 2], dT[1, 0], *dT[:3, 3]])


def fd_closure_jacobian(offset: np.ndarray, loops: list[list[tuple[int, int]]],
                        joint_leg: dict[int, tuple[int, int]], freedoms: list[int],
                        length: float, h: float = 1e-6) -> np.ndarray:
    """The closure Jacobian at ``offset`` by central differences of :func:`leg_pose`, one loop
    per entry of ``loops`` (joint index, sign), scaled as screwkit scales it (rows: rad and
    mm/``length``; columns: rad and ``length`` mm per slide); ``joint_leg`` maps a joint to
    (leg, first variable), ``freedoms`` its number of variables."""
    q = leg_variables(offset)
    cols: dict[int, np.ndarray] = {}
    for k, (i, f0) in joint_leg.items():
        S = []
        for f in range(freedoms[k]):
            step = h * (length if f0 + f == 2 else 1.0)  # the slide in units of ``length``
            qp, qm = q[i].copy(), q[i].copy()
            qp[f0 + f] += step
            qm[f0 + f] -= step
            T0 = leg_pose(i, q[i])
            S.append((_twist(leg_pose(i, qp), T0) - _twist(leg_pose(i, qm), T0)) / (2 * h))
        cols[k] = np.array(S).T
    first = np.cumsum([0, *freedoms])
    J = np.zeros((6 * len(loops), first[-1]))
    for l, loop in enumerate(loops):
        for k, sign in loop:
            J[6 * l:6 * l + 6, first[k]:first[k + 1]] = sign * cols[k]
        J[6 * l + 3:6 * l + 6] /= length
    return J


def motion_offsets(n: int = 50) -> np.ndarray:
    """The example's platform path (n, 3) mm: x = 150 sin 2πs, y = 40 sin 4πs,
    z = 30 sin² πs, s = 0 … 1 (a horizontal offset of at most 160 mm < 200 mm)."""
    s = np.linspace(0.0, 1.0, n)
    return np.stack([150 * np.sin(2 * np.pi * s), 40 * np.sin(4 * np.pi * s),
                     30 * np.sin(np.pi * s) ** 2], axis=1)


def _bar(points: list[np.ndarray]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre (mm) and inertia (kg m², world axes, about the centre) of steel bars
    joining ``points`` (two: one bar; more: a closed ring), each a 10 × 5 mm section: m L²/12
    plus half the axial moment about its cross axes, m (a² + b²)/12 about its own axis."""
    pts = [np.asarray(p, float) / 1000 for p in points]
    segs = [(pts[0], pts[1])] if len(pts) == 2 else \
        [(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts))]
    ms, cs, Is = [], [], []
    for p, q in segs:
        L = float(np.linalg.norm(q - p))
        u = (q - p) / L
        m = BAR * L
        ms.append(m)
        cs.append((p + q) / 2)
        sec = m * (0.010 ** 2 + 0.005 ** 2) / 12  # about the bar's own axis
        Is.append((m * L ** 2 / 12 + sec / 2) * (np.eye(3) - np.outer(u, u))
                  + sec * np.outer(u, u))
    M = sum(ms)
    c = sum(m * x for m, x in zip(ms, cs, strict=True)) / M
    inertia = sum(I + m * (np.dot(x - c, x - c) * np.eye(3) - np.outer(x - c, x - c))
                  for m, x, I in zip(ms, cs, Is, strict=True))
    return M, c * 1000, inertia


def body_lines(name: str, points: list[np.ndarray]) -> list[str]:
    """A spec's [[bodies]] block for a body of steel bars joining ``points`` (:func:`_bar`)."""
    m, c, inertia = _bar(points)
    return ["[[bodies]]", f'name = "{name}"', f'mass = "{m * 1000:.4f} g"',
            f"com = [{', '.join(f'{x:.6f}' for x in c)}]",
            "inertia = [" + ", ".join("[" + ", ".join(f"{x:.6e}" for x in row) + "]"
                                      for row in inertia) + "]", ""]


def write_spec(path: Path = PATH) -> str:
    """The example's TOML text (written to ``path``)."""
    vec = lambda v: "[" + ", ".join(f"{float(x):.12g}" for x in v) + "]"  # noqa: E731
    mid = (BASE + PLATFORM) / 2
    out = [__doc_header__]
    bodies = []
    for i in range(3):
        bodies.append((f"cylinder{i + 1}", [BASE[i], mid[i]]))
        bodies.append((f"piston{i + 1}", [mid[i], PLATFORM[i]]))
    bodies.append(("platform", list(PLATFORM) + [np.array([0.0, 0.0, HEIGHT])]))
    for name, pts in bodies:
        out += body_lines(name, pts if name != "platform" else pts[:3])
    for i in range(3):
        d = LEG[i] / LENGTH[i]
        out += [f"# leg {i + 1}", "[[joints]]", f'name = "Ub{i + 1}"', 'kind = "U"',
                f'between = ["ground", "cylinder{i + 1}"]', f"at = {vec(BASE[i])}",
                f"axis = {vec(TANGENT[i])}", f"axis2 = {vec(CROSS[i])}", "",
                "[[joints]]", f'name = "P{i + 1}"', 'kind = "P"',
                f'between = ["cylinder{i + 1}", "piston{i + 1}"]', f"at = {vec(mid[i])}",
                f"axis = {vec(d)}", "input = true", "",
                "[[joints]]", f'name = "Up{i + 1}"', 'kind = "U"',
                f'between = ["piston{i + 1}", "platform"]', f"at = {vec(PLATFORM[i])}",
                f"axis = {vec(CROSS[i])}", f"axis2 = {vec(TANGENT[i])}", ""]
    out += ["[[points]]", 'name = "centre"', 'body = "platform"',
            f"at = [0.0, 0.0, {HEIGHT}]", "", "[motion]",
            "# three leg extensions per row (mm), in the order P1, P2, P3", "rows = ["]
    out += ["  [" + ", ".join(f"{x:.10f}" if abs(x) > 5e-11 else "0" for x in row) + "],"
            for row in slides(motion_offsets())]
    out += ["]", 'speed = "10 mm/s"', ""]
    text = "\n".join(out)
    path.write_text(text, encoding="utf-8")
    return text


__doc_header__ = """\
# A translational 3-UPU parallel mechanism (Tsai 1996): three legs, each a universal joint
# (U) on the base, a prismatic joint (P) along the leg, whose extension is the input, and a
# U on the platform. Each leg's outer axes (the base U's first, the platform U's second) are
# parallel and tangent to the joint circles, its inner axes parallel and square to the leg,
# so the platform only translates, but it has a constraint singularity (Zlatanov, Bonev &
# Gosselin 2002): where its horizontal offset reaches 2 |R - r| = 200 mm, the legs'
# constraint couples become dependent and the platform gains a rotation about z.
# Dimensions chosen for this example (no source): base joints on a 200 mm circle, platform
# joints on a 100 mm circle, both at 0, 120, 240 deg, the platform 300 mm above the base.
# The rows are the three leg extensions (mm, from the drawn lengths) that carry the
# platform's centre along x = 150 sin 2pi s, y = 40 sin 4pi s, z = 30 sin^2 pi s for
# s = 0, 1/49, ..., 1 (at most 160 mm off centre: regular throughout): inverse kinematics,
# |P_i + c - B_i| - |P_i - B_i|. tests/graphs/three_upu.py writes this file.
# Mass properties: each body is a 10 x 5 mm steel bar (0.39 kg/m) along the lines joining
# its joints, its centre of mass and inertia (kg*m^2, about the centre of mass, world axes)
# computed from those bars (axial moment m (a^2 + b^2)/12 of the 10 x 5 mm section).
[mechanism]
name = "3-UPU translational platform"

[units]
length = "mm"
angle = "deg"
"""

#: each leg's platform U axis as the example draws it
_PLATFORM_AXES = {1: "[-0, 1, 0]", 2: "[-0.866025403784, -0.5, 0]", 3: "[0.866025403784, -0.5, 0]"}


def write_tilted(path: Path, legs: tuple[int, ...]) -> Path:
    """The example with the platform U axes of ``legs`` tipped up by 0.1 (unit vectors again),
    so that those legs' axes are not square (written to ``path``)."""
    text = PATH.read_text(encoding="utf-8")
    for i in legs:
        line = _PLATFORM_AXES[i]
        a = np.array([float(x) for x in line.strip("[]").split(",")]) + [0.0, 0.0, 0.1]
        a /= np.linalg.norm(a)
        text = text.replace(f"axis2 = {line}", f"axis2 = [{a[0]:.15g}, {a[1]:.15g}, {a[2]:.15g}]")
    path.write_text(text, encoding="utf-8")
    return path


if __name__ == "__main__":
    write_spec(Path(sys.argv[1]) if len(sys.argv) > 1 else PATH)
