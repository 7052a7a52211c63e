"""Hand-built screw Jacobians for the mobility tests, from explicit geometry only (no other part
of screwkit): unit screws (ω; v) = (u; r × u) for a revolute through r, (0; u) for a prism.

Any placement of the joint elements is a closed configuration of *some* linkage (the links are
whatever rigid bodies carry those elements), so generic mechanisms need no loop solve. Special
linkages (Bennett, parallelograms) are built from their defining geometry and their closure is
checked in the tests.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def unit(v: Array | list[float]) -> Array:
    a = np.asarray(v, dtype=float)
    return a / np.linalg.norm(a)


def revolute(point: Array | list[float], direction: Array | list[float]) -> Array:
    u = unit(direction)
    return np.concatenate([u, np.cross(np.asarray(point, float), u)])[:, None]


def prism(direction: Array | list[float]) -> Array:
    return np.concatenate([np.zeros(3), unit(direction)])[:, None]


def helical(point: Array | list[float], direction: Array | list[float], pitch: float) -> Array:
    u = unit(direction)
    return np.concatenate([u, pitch * u + np.cross(np.asarray(point, float), u)])[:, None]


def cylinder(point: Array | list[float], direction: Array | list[float]) -> Array:
    return np.hstack([revolute(point, direction), prism(direction)])


def spherical(point: Array | list[float]) -> Array:
    return np.hstack([revolute(point, e) for e in np.eye(3)])


def spherical_centre(columns: Array) -> Array:
    """Centre c of a spherical pair from its three columns (rotations about x, y, z through c):
    the moments are c × e_x = (0, c_z, −c_y), c × e_y = (−c_z, 0, c_x), c × e_z = (c_y, −c_x, 0)."""
    m = columns[3:]
    return np.array([m[2, 1], m[0, 2], m[1, 0]])


def random_direction(rng: np.random.Generator) -> Array:
    return unit(rng.normal(size=3))


# --- generic single loops (any placement closes) ------------------------------------------


def rssr(rng: np.random.Generator) -> tuple[Array, list[str]]:
    a0, a, b, b0 = rng.normal(size=(4, 3))
    jac = np.hstack(
        [
            revolute(a0, random_direction(rng)),
            spherical(a),
            spherical(b),
            revolute(b0, random_direction(rng)),
        ]
    )
    names = ["A0.rz", "A.rx", "A.ry", "A.rz", "B.rx", "B.ry", "B.rz", "B0.rz"]
    return jac, names


def rsrc(rng: np.random.Generator, delta0_zero: bool = False) -> tuple[Array, list[str]]:
    """R (input, ground) – S – R (coupler/output) – C (output, ground).

    ``delta0_zero``: the coupler–output R axis parallel to the output C axis (Bagci's δ0 = 0,
    the skew angle between coupler and output link)."""
    p_in, s_centre, p_r, p_c = rng.normal(size=(4, 3))
    u_in, u_c = random_direction(rng), random_direction(rng)
    u_r = u_c if delta0_zero else random_direction(rng)
    jac = np.hstack(
        [
            revolute(p_in, u_in),
            spherical(s_centre),
            revolute(p_r, u_r),
            cylinder(p_c, u_c),
        ]
    )
    names = ["R1.rz", "S.rx", "S.ry", "S.rz", "R2.rz", "C.rz", "C.tz"]
    return jac, names


def cssp(rng: np.random.Generator) -> tuple[Array, list[str]]:
    p_c, a, b = rng.normal(size=(3, 3))
    jac = np.hstack(
        [
            cylinder(p_c, random_direction(rng)),
            spherical(a),
            spherical(b),
            prism(random_direction(rng)),
        ]
    )
    names = ["C.rz", "C.tz", "A.rx", "A.ry", "A.rz", "B.rx", "B.ry", "B.rz", "P.tz"]
    return jac, names


def rccc(rng: np.random.Generator, parallel_outputs: bool = False) -> tuple[Array, list[str]]:
    """R – C – C – C; ``parallel_outputs``: the last two C axes parallel (Bagci: RCCC with
    δ0 = 0, a redundant translation)."""
    p = rng.normal(size=(4, 3))
    u = [random_direction(rng) for _ in range(4)]
    if parallel_outputs:
        u[3] = u[2]
    jac = np.hstack(
        [revolute(p[0], u[0]), cylinder(p[1], u[1]), cylinder(p[2], u[2]), cylinder(p[3], u[3])]
    )
    names = ["R.rz", "C1.rz", "C1.tz", "C2.rz", "C2.tz", "C3.rz", "C3.tz"]
    return jac, names


def plane_4r(rng: np.random.Generator) -> tuple[Array, list[str]]:
    pts = np.column_stack([rng.normal(size=(4, 2)), np.full(4, 0.3)])
    jac = np.hstack([revolute(p, [0.0, 0.0, 1.0]) for p in pts])
    return jac, ["A0.rz", "A.rz", "B.rz", "B0.rz"]


def spherical_4r(rng: np.random.Generator) -> tuple[Array, list[str]]:
    centre = rng.normal(size=3)
    jac = np.hstack([revolute(centre, random_direction(rng)) for _ in range(4)])
    return jac, ["A0.rz", "A.rz", "B.rz", "B0.rz"]


# --- Bennett linkage ------------------------------------------------------------------------


def _rz(t: float) -> Array:
    c, s = np.cos(t), np.sin(t)
    out = np.eye(4)
    out[:2, :2] = [[c, -s], [s, c]]
    return out


def _rx(t: float) -> Array:
    c, s = np.cos(t), np.sin(t)
    out = np.eye(4)
    out[1:3, 1:3] = [[c, -s], [s, c]]
    return out


def _tx(a: float) -> Array:
    out = np.eye(4)
    out[0, 3] = a
    return out


def bennett_frames(a: float, alpha: float, beta: float, theta1: float) -> tuple[list[Array], Array]:
    """Joint frames of a Bennett linkage (Hartenberg–Denavit: Rz(θ_i) Tx(a_i) Rx(α_i), zero
    offsets) and the loop product (identity when closed).

    Links a, b, a, b with twists α, β, α, β and a / sin α = b / sin β; closure
    θ3 = −θ1, θ4 = −θ2, tan(θ1/2) tan(θ2/2) = sin((β + α)/2) / sin((β − α)/2).
    """
    b = a * np.sin(beta) / np.sin(alpha)
    theta2 = 2.0 * np.arctan(
        np.sin((beta + alpha) / 2) / np.sin((beta - alpha) / 2) / np.tan(theta1 / 2)
    )
    frames, g = [], np.eye(4)
    for theta, length, twist in (
        (theta1, a, alpha),
        (theta2, b, beta),
        (-theta1, a, alpha),
        (-theta2, b, beta),
    ):
        frames.append(g.copy())
        g = g @ _rz(theta) @ _tx(length) @ _rx(twist)
    return frames, g


def bennett(
    a: float = 1.0,
    alpha: float = np.radians(40.0),
    beta: float = np.radians(70.0),
    theta1: float = np.radians(50.0),
) -> tuple[Array, list[str], Array]:
    frames, closure = bennett_frames(a, alpha, beta, theta1)
    jac = np.hstack([revolute(f[:3, 3], f[:3, 2]) for f in frames])
    return jac, ["J1.rz", "J2.rz", "J3.rz", "J4.rz"], closure


# --- Fig. 32: three-loop plane parallelogram ------------------------------------------------


def parallelogram_chain(
    crank: Array | tuple[float, ...] = (0.4, 0.9, 0.0),
    ground_x: tuple[float, ...] = (0.0, 1.0, 2.5, 3.1),
    last_pin_shift: Array | tuple[float, ...] | list[float] = (0.0, 0.0, 0.0),
) -> tuple[Array, list[str]]:
    """Ground and coupler bars joined by four equal parallel cranks: n = 6 links, 8 R pairs,
    k = 3 loops (loop j: crank j and crank j + 1). Loop j block: the coupler twist reached
    through crank j minus the one reached through crank j + 1. ``last_pin_shift`` moves the
    last coupler pin in the plane (the last crank is then no longer parallel)."""
    c = np.asarray(crank, float)
    ez = [0.0, 0.0, 1.0]
    ground = [np.array([x, 0.0, 0.0]) for x in ground_x]
    g = [revolute(p, ez) for p in ground]
    kpl = [revolute(p + c, ez) for p in ground]
    kpl[-1] = revolute(ground[-1] + c + np.asarray(last_pin_shift, float), ez)
    n_cranks = len(ground)
    names = [f"G{i}.rz" for i in range(n_cranks)] + [f"K{i}.rz" for i in range(n_cranks)]
    jac = np.zeros((6 * (n_cranks - 1), 2 * n_cranks))
    for j in range(n_cranks - 1):
        rows = slice(6 * j, 6 * j + 6)
        jac[rows, j] = g[j][:, 0]
        jac[rows, n_cranks + j] = kpl[j][:, 0]
        jac[rows, j + 1] = -g[j + 1][:, 0]
        jac[rows, n_cranks + j + 1] = -kpl[j + 1][:, 0]
    return jac, names
