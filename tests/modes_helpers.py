"""Helpers of the every-mode tests (kinematics/modes/): random loops of R joints, the relative
residual of a polynomial system and its Jacobians against central differences, and the RSSR
island (:data:`ISLAND_RSSR`)."""

from __future__ import annotations

import numpy as np

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.model.mechanism import GROUND, Body, Mechanism, MechanismJoint


def relative_residual(system: PolynomialSystem, x: np.ndarray, p: np.ndarray) -> float:
    """max |F| over the size of the terms it sums (|Jx|·|x| + |Jp|·|p|, Euler's bound for
    the homogeneous parts), so that a root of a large instance is judged like a small one."""
    F, Jx, Jp = system.evaluate(x, p)
    assert Jp is not None
    scale = (np.abs(Jx) @ np.abs(x)[..., None])[..., 0] + np.abs(
        Jp @ np.broadcast_to(p, (x.shape[0], system.k))[..., None])[..., 0]
    return float(np.max(np.abs(F) / (1.0 + scale)))


def check_jacobians(system: PolynomialSystem, x: np.ndarray, p: np.ndarray) -> None:
    """∂F/∂x and ∂F/∂p against central differences (the system is polynomial, so h = 1e-6
    leaves an error of order h² times the third derivatives)."""
    _, Jx, Jp = system.evaluate(x, p)
    assert Jp is not None
    h = 1e-6
    for i in range(system.n):
        e = np.zeros(system.n)
        e[i] = h
        d = (system.evaluate(x + e, p, False)[0] - system.evaluate(x - e, p, False)[0]) / (2 * h)
        assert np.allclose(d, Jx[:, :, i], rtol=1e-6, atol=1e-6), f"∂F/∂{system.variables[i]}"
    P = np.broadcast_to(p, (x.shape[0], system.k))
    for i in range(system.k):
        e = np.zeros(system.k)
        e[i] = h
        d = (system.evaluate(x, P + e, False)[0] - system.evaluate(x, P - e, False)[0]) / (2 * h)
        assert np.allclose(d, Jp[:, :, i], rtol=1e-6, atol=1e-6), f"∂F/∂{system.parameters[i]}"


def random_loop(rng: np.random.Generator, kinds: str, inputs: list[str]) -> Mechanism:
    """A loop of joints of ``kinds`` (R, P, C, U) on random lines (a U joint with a random
    second axis), some joints' bodies listed against the walk, driven at the freedoms
    ``inputs`` (e.g. "j0.theta")."""
    bodies = [Body(f"l{i}") for i in range(1, len(kinds))]
    names = [GROUND, *(b.name for b in bodies), GROUND]
    joints = []
    for i, kind in enumerate(kinds):
        a, b = (names[i], names[i + 1]) if rng.random() < 0.6 else (names[i + 1], names[i])
        joints.append(MechanismJoint(f"j{i}", kind, (a, b), rng.normal(size=3),
                                     rng.normal(size=3),
                                     axis2=rng.normal(size=3) if kind == "U" else None))
    return Mechanism("loop", tuple(bodies), tuple(joints), tuple(inputs))


def random_r_loop(rng: np.random.Generator, n: int, inputs: list[int]) -> Mechanism:
    """A loop of n R joints on random lines, some joints' bodies listed against the walk."""
    bodies = [Body(f"l{i}") for i in range(1, n)]
    names = [GROUND, *(b.name for b in bodies), GROUND]
    joints = []
    for i in range(n):
        a, b = (names[i], names[i + 1]) if rng.random() < 0.6 else (names[i + 1], names[i])
        joints.append(MechanismJoint(f"j{i}", "R", (a, b), rng.normal(size=3),
                                     rng.normal(size=3)))
    return Mechanism("loop", tuple(bodies), tuple(joints), tuple(f"j{k}.theta" for k in inputs))


#: An RSSR (model.families.rssr's parameters d1, d2, d3, a, b, λ0, output offset) that
#: assembles only over an island of two modes, input 168.04° … 176.39° (8.4°): on a 5° grid
#: (72 samples from 0°) two samples, 170° and 175° (indices 34, 35), lie on it, neither a
#: multiple of 15° (the loop solver's root-search anchors) nor of 40° (the graph route's every
#: 8th sample). Found by scanning 200,000 random RSSRs of test_never_miss_a_mode's draws with
#: the distance test of :func:`rssr_reach` (tests/kinematics/test_rssr_island.py).
ISLAND_RSSR = (0.58878, 4.30529, 1.55105, 2.07143, -0.93211, 0.74000, 0.29829)
#: the island's ends (deg), to 0.01°, and its samples on the 72-sample 5° grid
ISLAND_DEG = (168.04, 176.39)
ISLAND_SAMPLES = (34, 35)


def rssr_reach(params: tuple[float, ...], theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nearest and farthest distance (N,) from the input crank's ball to the circle the
    output crank's ball runs on, at input angles ``theta`` (rad), in the family's frame (input
    axis x through the origin, output axis u3 = (cos λ0, 0, −sin λ0) through (b, a, 0), the
    circle's centre ``output_offset`` along u3): the loop closes where the coupler's length d2
    lies between them. Independent of the closed form (plain geometry of a point and a
    circle), up to the input angle's origin."""
    d1, _, d3, a, b, lam, off = params
    P = d1 * np.stack([np.zeros_like(theta), np.cos(theta), np.sin(theta)], axis=1)
    u3 = np.array([np.cos(lam), 0.0, -np.sin(lam)])
    w = P - (np.array([b, a, 0.0]) + off * u3)
    along = w @ u3
    across = np.linalg.norm(w - along[:, None] * u3, axis=1)
    return np.hypot(along, across - d3), np.hypot(along, across + d3)


def tilted(mech: Mechanism, k: int, to: int, twist: float) -> Mechanism:
    """``mech`` with joint k's axis joint ``to``'s turned by ``twist`` rad (Rodrigues, about a
    fixed direction normal to it): a nearly parallel pair for ``twist`` ≪ 1."""
    joints = list(mech.joints)
    a = joints[to].axis / np.linalg.norm(joints[to].axis)
    n = np.cross(a, [0.3, 0.5, 0.8])
    n /= np.linalg.norm(n)
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    turn = np.eye(3) + np.sin(twist) * K + (1.0 - np.cos(twist)) * (K @ K)
    j = joints[k]
    joints[k] = MechanismJoint(j.name, j.kind, j.bodies, j.at, turn @ a)
    return Mechanism(mech.name, mech.bodies, tuple(joints), mech.inputs)
