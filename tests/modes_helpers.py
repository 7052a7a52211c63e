"""Helpers of the every-mode tests (kinematics/modes/): random loops of R joints, the relative
residual of a polynomial system and its Jacobians against central differences."""

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
