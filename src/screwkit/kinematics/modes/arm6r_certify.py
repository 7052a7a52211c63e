"""Smale's α-test for a 6R arm's inverse-kinematics solutions, on its forward kinematics written
as polynomials in (cos q_i, sin q_i).

With c_i = cos q_i and s_i = sin q_i, each joint's rotation is I + s_i K_i + (1 − c_i) K_i²
(Rodrigues) and the product of exponentials (Murray, Li & Sastry 1994, §3.2) is polynomial in
(c, s). The square system in these 12 unknowns, with the target (R_t, p_t) as its 12 parameters,
is

    c_i² + s_i² − 1 = 0 (i = 1..6),   p(c, s) − p_t = 0,   skew part of R(c, s)·R_t^T = 0,

and :func:`certify_arm_solutions` runs :func:`screwkit.algebraic.certify.certify` (Smale's
α-test; Hauenstein & Sottile 2012) on it at each solution's (cos q, sin q). A certified point
has a true zero within its radius; that zero's R(c, s)·R_t^T is a rotation with no skew part,
so it is I or a half-turn, and it is I because it is within the radius of a point where it is
≈ I: the certified zero is an inverse-kinematics solution of the exact arm, unique in that
ball, and real when ``real`` says so.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.certify import Certificate, certify
from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system

Array = NDArray[np.float64]


def _matmul(A: list[list[Poly]], B: list[list[Poly]]) -> list[list[Poly]]:
    return [[sum((A[i][k] * B[k][j] for k in range(3)), Poly()) for j in range(3)]
            for i in range(3)]


def _matvec(A: list[list[Poly]], v: list[Poly]) -> list[Poly]:
    return [sum((A[i][k] * v[k] for k in range(3)), Poly()) for i in range(3)]


def arm_fk_system(points: Array, axes: Array, tool_home: tuple[Array, Array]
                  ) -> PolynomialSystem:
    """The square (cos, sin) forward-kinematics system of the arm (module docstring): unknowns
    c1, s1, …, c6, s6; parameters the target's rotation (row by row) and position."""
    U = axes / np.linalg.norm(axes, axis=1)[:, None]
    var = [Poly.variable(k) for k in range(24)]
    Rt = [[var[12 + 3 * i + j] for j in range(3)] for i in range(3)]
    pt = var[21:24]
    R = [[Poly.constant(float(i == j)) for j in range(3)] for i in range(3)]
    p = [Poly(), Poly(), Poly()]
    for i in range(6):
        c, s = var[2 * i], var[2 * i + 1]
        u = U[i]
        K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        K2 = K @ K
        Ri = [[Poly.constant(float(i == j)) + s * float(K[i, j]) + (1.0 - c) * float(K2[i, j])
               for j in range(3)] for i in range(3)]
        ci = [Poly.constant(float(v)) for v in points[i]]
        moved = _matvec(Ri, ci)
        p = [p[r] + _matvec(R, [ci[k] - moved[k] for k in range(3)])[r] for r in range(3)]
        R = _matmul(R, Ri)
    tool_R = [[Poly.constant(float(v)) for v in row] for row in tool_home[0]]
    R_tool = _matmul(R, tool_R)
    p_tool = [p[r] + _matvec(R, [Poly.constant(float(v)) for v in tool_home[1]])[r]
              for r in range(3)]
    M = [[sum((R_tool[i][k] * Rt[j][k] for k in range(3)), Poly()) for j in range(3)]
         for i in range(3)]
    eqs = [var[2 * i] * var[2 * i] + var[2 * i + 1] * var[2 * i + 1] - 1.0 for i in range(6)]
    eqs += [p_tool[r] - pt[r] for r in range(3)]
    eqs += [M[2][1] - M[1][2], M[0][2] - M[2][0], M[1][0] - M[0][1]]
    names = [f"{f}{i}" for i in range(1, 7) for f in "cs"]
    params = [f"R{i}{j}" for i in range(1, 4) for j in range(1, 4)] + ["px", "py", "pz"]
    return compile_system(eqs, names, params)


def certify_arm_solutions(system: PolynomialSystem, q: Array,
                          target: tuple[Array, Array]) -> Certificate:
    """The α-test of joint values q (N, 6) on :func:`arm_fk_system` at the target (R, p)."""
    x = np.stack([np.cos(q), np.sin(q)], -1).reshape(len(q), 12).astype(complex)
    p = np.concatenate([np.asarray(target[0], dtype=float).ravel(),
                        np.asarray(target[1], dtype=float)]).astype(complex)
    return certify(system, x, p)
