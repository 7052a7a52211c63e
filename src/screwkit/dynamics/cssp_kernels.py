"""The numba kernel of :mod:`screwkit.dynamics.cssp_compiled` (imported by it on first use
only, so that importing screwkit does not import numba; compiled on first use for the layouts
it is given and cached on disk by numba next to this module).

The samples go through in tiles of :data:`TILE`: a tile's motion rows are gathered into a local
buffer row by row, its loads computed sample by sample — each sample's link loads (Newton–Euler
in the world frame, :mod:`screwkit.dynamics.inertia`), the CSSP's closed-form statics (Rahman
1996 §2.2; :mod:`screwkit.dynamics.cssp_statics`, the least-squares solution of its module
docstring) and the reported loads (:func:`screwkit.dynamics.cssp_fused_dynamics.cssp_rows_block`)
— in a loop the compiler vectorises, and scattered into the outputs row by row. Every formula
is the numpy route's with its operations in the same order; the numpy route only skips products
with a constant zero and sums with one, which change nothing but the sign of a zero. No
fastmath: the loads are the numpy route's bit for bit (tests/dynamics/test_cssp_compiled.py).

The tiles are counted, ``start = tile * TILE``: stepped by ``range(0, n, TILE)``, numba's
wraparound of negative indices left LLVM unable to prove ``start + k`` non-negative, and every
row's gather and scatter became masked vector gathers and scatters (the whole call 2× slower;
the test checks the optimised IR for them).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

#: samples per tile (its buffers stay in the first-level cache)
TILE = 128

# rows of the tile's input buffer: the motion rows as gathered (the crank and slider axes only)
_ROT, _ORG, _W, _AL, _ACC, _CEN, _AX = 0, 27, 36, 45, 54, 63, 75
_IN_ROWS = 81
# rows of the tile's output buffer
_SF, _SM, _RF, _RM, _ET, _ES, _RES = 0, 3, 6, 18, 30, 31, 32
_OUT_ROWS = 33

njit = numba.njit(cache=True, nogil=True, error_model="numpy")


@numba.njit(inline="always")
def _cross(a0: float, a1: float, a2: float, b0: float, b1: float,
           b2: float) -> tuple[float, float, float]:
    """a × b, as :func:`screwkit.dynamics.component_arrays.cross`."""
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


@numba.njit(inline="always")
def _dot(a0: float, a1: float, a2: float, b0: float, b1: float, b2: float) -> float:
    """a·b, summed as :func:`screwkit.dynamics.component_arrays.dot`."""
    return (a0 * b0 + a1 * b1) + a2 * b2


@numba.njit(inline="always")
def _gather(rows: Any, first: int, count: int, start: int, m: int, buf: Any) -> None:
    for r in range(count):
        for k in range(m):
            buf[first + r, k] = rows[r, start + k]


@numba.njit(inline="always")
def _link(x: Any, k: int, l: int, com: Any, inertia: Any, m: float, g0: float, g1: float,
          g2: float, ref0: float, ref1: float, ref2: float) -> tuple[float, ...]:
    """Link ``l``'s applied force and moment about the reference at sample ``k``
    (:func:`screwkit.dynamics.inertia.inertia_wrenches_soa`)."""
    b = _ROT + 9 * l
    R0, R1, R2 = x[b, k], x[b + 1, k], x[b + 2, k]
    R3, R4, R5 = x[b + 3, k], x[b + 4, k], x[b + 5, k]
    R6, R7, R8 = x[b + 6, k], x[b + 7, k], x[b + 8, k]
    v = 3 * l
    w0, w1, w2 = x[_W + v, k], x[_W + v + 1, k], x[_W + v + 2, k]
    al0, al1, al2 = x[_AL + v, k], x[_AL + v + 1, k], x[_AL + v + 2, k]
    c0, c1, c2 = com[l, 0], com[l, 1], com[l, 2]
    rc0 = _dot(R0, R1, R2, c0, c1, c2)
    rc1 = _dot(R3, R4, R5, c0, c1, c2)
    rc2 = _dot(R6, R7, R8, c0, c1, c2)
    p0 = (x[_ORG + v, k] + rc0) - ref0
    p1 = (x[_ORG + v + 1, k] + rc1) - ref1
    p2 = (x[_ORG + v + 2, k] + rc2) - ref2
    x0, x1, x2 = _cross(al0, al1, al2, rc0, rc1, rc2)
    y0, y1, y2 = _cross(w0, w1, w2, rc0, rc1, rc2)
    z0, z1, z2 = _cross(w0, w1, w2, y0, y1, y2)
    a0 = x[_ACC + v, k] + (x0 + z0)
    a1 = x[_ACC + v + 1, k] + (x1 + z1)
    a2 = x[_ACC + v + 2, k] + (x2 + z2)
    f0, f1, f2 = m * (g0 - a0), m * (g1 - a1), m * (g2 - a2)
    wb0 = _dot(R0, R3, R6, w0, w1, w2)
    wb1 = _dot(R1, R4, R7, w0, w1, w2)
    wb2 = _dot(R2, R5, R8, w0, w1, w2)
    ab0 = _dot(R0, R3, R6, al0, al1, al2)
    ab1 = _dot(R1, R4, R7, al0, al1, al2)
    ab2 = _dot(R2, R5, R8, al0, al1, al2)
    ia0 = _dot(inertia[l, 0, 0], inertia[l, 0, 1], inertia[l, 0, 2], ab0, ab1, ab2)
    ia1 = _dot(inertia[l, 1, 0], inertia[l, 1, 1], inertia[l, 1, 2], ab0, ab1, ab2)
    ia2 = _dot(inertia[l, 2, 0], inertia[l, 2, 1], inertia[l, 2, 2], ab0, ab1, ab2)
    iw0 = _dot(inertia[l, 0, 0], inertia[l, 0, 1], inertia[l, 0, 2], wb0, wb1, wb2)
    iw1 = _dot(inertia[l, 1, 0], inertia[l, 1, 1], inertia[l, 1, 2], wb0, wb1, wb2)
    iw2 = _dot(inertia[l, 2, 0], inertia[l, 2, 1], inertia[l, 2, 2], wb0, wb1, wb2)
    q0, q1, q2 = _cross(wb0, wb1, wb2, iw0, iw1, iw2)
    bd0, bd1, bd2 = ia0 + q0, ia1 + q1, ia2 + q2
    k0, k1, k2 = _cross(p0, p1, p2, f0, f1, f2)
    return (f0, f1, f2, k0 - _dot(R0, R1, R2, bd0, bd1, bd2), k1 - _dot(R3, R4, R5, bd0, bd1, bd2),
            k2 - _dot(R6, R7, R8, bd0, bd1, bd2))


@numba.njit(inline="always")
def _sample(x: Any, k: int, mass: Any, com: Any, inertia: Any, gravity: Any, reference: Any,
            arm: Any, residual_unit: float, y: Any) -> None:
    """The loads of sample ``k`` of the tile ``x`` (rows as gathered) into ``y``: the
    closed-form statics (:func:`screwkit.dynamics.cssp_statics.cssp_block_statics`) and
    the reported loads (:func:`screwkit.dynamics.cssp_fused_dynamics.cssp_rows_block`)."""
    g0, g1, g2 = gravity[0], gravity[1], gravity[2]
    ref0, ref1, ref2 = reference[0], reference[1], reference[2]
    F00, F01, F02, M00, M01, M02 = _link(x, k, 0, com, inertia, mass[0], g0, g1, g2, ref0, ref1, ref2)
    F10, F11, F12, M10, M11, M12 = _link(x, k, 1, com, inertia, mass[1], g0, g1, g2, ref0, ref1, ref2)
    F20, F21, F22, M20, M21, M22 = _link(x, k, 2, com, inertia, mass[2], g0, g1, g2, ref0, ref1, ref2)
    C00, C01, C02 = x[_CEN, k] - ref0, x[_CEN + 1, k] - ref1, x[_CEN + 2, k] - ref2
    C10, C11, C12 = x[_CEN + 3, k] - ref0, x[_CEN + 4, k] - ref1, x[_CEN + 5, k] - ref2
    C20, C21, C22 = x[_CEN + 6, k] - ref0, x[_CEN + 7, k] - ref1, x[_CEN + 8, k] - ref2
    C30, C31, C32 = x[_CEN + 9, k] - ref0, x[_CEN + 10, k] - ref1, x[_CEN + 11, k] - ref2
    e0, e1, e2 = x[_AX, k], x[_AX + 1, k], x[_AX + 2, k]
    k40, k41, k42 = x[_AX + 3, k], x[_AX + 4, k], x[_AX + 5, k]
    s0, s1, s2 = C20 - C10, C21 - C11, C22 - C12
    inv_d = 1.0 / np.sqrt(_dot(s0, s1, s2, s0, s1, s2))
    u0, u1, u2 = inv_d * s0, inv_d * s1, inv_d * s2
    t0, t1, t2 = _cross(C20, C21, C22, F10, F11, F12)
    mp0, mp1, mp2 = M10 - t0, M11 - t1, M12 - t2
    mu = _dot(u0, u1, u2, mp0, mp1, mp2)
    t0, t1, t2 = _cross(mp0, mp1, mp2, u0, u1, u2)
    fp0, fp1, fp2 = inv_d * t0, inv_d * t1, inv_d * t2
    lam = -_dot(k40, k41, k42, fp0 + (F10 + F20), fp1 + (F11 + F21),
                fp2 + (F12 + F22)) / _dot(k40, k41, k42, u0, u1, u2)
    fa0, fa1, fa2 = fp0 + lam * u0, fp1 + lam * u1, fp2 + lam * u2
    h = -0.5 * mu
    mq0, mq1, mq2 = h * u0, h * u1, h * u2
    t0, t1, t2 = _cross(C10, C11, C12, fa0, fa1, fa2)
    ma0, ma1, ma2 = mq0 + t0, mq1 + t1, mq2 + t2
    f00, f01, f02 = fa0 - F00, fa1 - F01, fa2 - F02
    m00, m01, m02 = ma0 - M00, ma1 - M01, ma2 - M02
    f20, f21, f22 = fa0 + F10, fa1 + F11, fa2 + F12
    m20, m21, m22 = ma0 + M10, ma1 + M11, ma2 + M12
    f30, f31, f32 = f20 + F20, f21 + F21, f22 + F22
    m30, m31, m32 = m20 + M20, m21 + M21, m22 + M22
    t0, t1, t2 = _cross(C00, C01, C02, f00, f01, f02)
    mc0, mc1, mc2 = m00 - t0, m01 - t1, m02 - t2
    y[_ET, k] = _dot(e0, e1, e2, mc0, mc1, mc2)
    y[_ES, k] = _dot(e0, e1, e2, f00, f01, f02)
    t0, t1, t2 = _cross(C30, C31, C32, f30, f31, f32)
    m3c0, m3c1, m3c2 = m30 - t0, m31 - t1, m32 - t2
    t0, t1, t2 = _cross(C20, C21, C22, f20, f21, f22)
    y[_RF, k], y[_RF + 1, k], y[_RF + 2, k] = f00, f01, f02
    y[_RF + 3, k], y[_RF + 4, k], y[_RF + 5, k] = fa0, fa1, fa2
    y[_RF + 6, k], y[_RF + 7, k], y[_RF + 8, k] = f20, f21, f22
    y[_RF + 9, k], y[_RF + 10, k], y[_RF + 11, k] = -1.0 * f30, -1.0 * f31, -1.0 * f32
    y[_RM, k], y[_RM + 1, k], y[_RM + 2, k] = mc0, mc1, mc2
    y[_RM + 3, k], y[_RM + 4, k], y[_RM + 5, k] = mq0, mq1, mq2
    y[_RM + 6, k], y[_RM + 7, k], y[_RM + 8, k] = m20 - t0, m21 - t1, m22 - t2
    y[_RM + 9, k], y[_RM + 10, k], y[_RM + 11, k] = -1.0 * m3c0, -1.0 * m3c1, -1.0 * m3c2
    y[_RES, k] = abs(mu) / residual_unit
    tf0 = (F00 + F10) + F20
    tf1 = (F01 + F11) + F21
    tf2 = (F02 + F12) + F22
    t0, t1, t2 = _cross(arm[0], arm[1], arm[2], tf0, tf1, tf2)
    y[_SF, k], y[_SF + 1, k], y[_SF + 2, k] = tf0, tf1, tf2
    y[_SM, k] = ((M00 + M10) + M20) + t0
    y[_SM + 1, k] = ((M01 + M11) + M21) + t1
    y[_SM + 2, k] = ((M02 + M12) + M22) + t2


@njit
def _fold(block_max: Any, block_nan: Any, scale2: float) -> float:
    """A block's largest joint load squared into the running one, as the numpy route's
    ``max(scale2, float(np.max(size2)))`` per joint and ``max(scale, part.scale)`` per block
    (a joint whose loads in the block hold a NaN is left out; Python's max keeps the first of
    unordered values)."""
    for j in range(4):
        if not block_nan[j] and block_max[j] > scale2:
            scale2 = block_max[j]
        block_max[j] = -np.inf
        block_nan[j] = False
    return scale2


@njit
def cssp_loads(rot: Any, org: Any, angvel: Any, angacc: Any, acc: Any, cen: Any, axes: Any,
               vel: Any, valid: Any, block: int, mass: Any, com: Any, inertia: Any,
               gravity: Any, reference: Any, arm: Any, inv_ell2: float, residual_unit: float,
               check: bool, shaking_force: Any, shaking_moment: Any, reaction_force: Any,
               reaction_moment: Any, effort_theta: Any, effort_s: Any, has_theta: bool,
               has_s: bool, residual: Any) -> float:
    """Loads of every sample of a CSSP mode (module docstring).

    Motion rows (component, sample), world frame: ``rot`` (27, N) R[9l + 3i + j], ``org``,
    ``angvel``, ``angacc``, ``acc`` (link origins) (9, N), ``cen`` joint centres and ``axes``
    (12, N); ``vel`` is only checked. ``valid`` (N,): the samples whose loads are wanted (the
    others are computed too, and overwritten by the caller); ``block``: the numpy route's
    samples per block, over which it takes its largest joint load. Constants: the links'
    ``mass`` (3,), ``com`` (3, 3), ``inertia`` (3, 3, 3) in their body frames, ``gravity``, the
    ``reference`` point, ``arm`` = reference − moment point, 1/ℓ² and √2·ℓ. Outputs by rows:
    ``shaking_force``, ``shaking_moment`` (3, N), ``reaction_force``, ``reaction_moment``
    (12, N: joint j at 3j + i), the efforts (N,) (when ``has_theta``, ``has_s``), ``residual``
    (N,). With ``check``, returns −1 if the motion of a valid sample is not finite (the outputs
    are then to be discarded); else the largest joint load squared over the valid samples,
    max |f|² + |m|²/ℓ²."""
    n = rot.shape[1]
    x = np.empty((_IN_ROWS, TILE))
    y = np.empty((_OUT_ROWS, TILE))
    probe = np.empty(TILE)
    block_max = np.full(4, -np.inf)
    block_nan = np.zeros(4, dtype=np.bool_)
    scale2 = 0.0
    counted = 0
    for tile in range((n + TILE - 1) // TILE):
        start = tile * TILE  # not range(0, n, TILE): numba's start could be negative to LLVM
        m = min(TILE, n - start)
        _gather(rot, _ROT, 27, start, m, x)
        _gather(org, _ORG, 9, start, m, x)
        _gather(angvel, _W, 9, start, m, x)
        _gather(angacc, _AL, 9, start, m, x)
        _gather(acc, _ACC, 9, start, m, x)
        _gather(cen, _CEN, 12, start, m, x)
        for r in range(3):
            for k in range(m):
                x[_AX + r, k] = axes[r, start + k]
                x[_AX + 3 + r, k] = axes[9 + r, start + k]
        if check:
            for k in range(m):
                probe[k] = 0.0
            for r in range(_IN_ROWS):
                for k in range(m):
                    probe[k] += x[r, k] * 0.0
            for r in range(vel.shape[0]):
                for k in range(m):
                    probe[k] += vel[r, start + k] * 0.0
            for r in range(6):  # the axes' rows not gathered
                for k in range(m):
                    probe[k] += axes[3 + r, start + k] * 0.0
            for k in range(m):
                if valid[start + k] and probe[k] != 0.0:
                    return -1.0
        for k in range(m):
            _sample(x, k, mass, com, inertia, gravity, reference, arm, residual_unit, y)
        for c in range(3):
            for k in range(m):
                shaking_force[c, start + k] = y[_SF + c, k]
            for k in range(m):
                shaking_moment[c, start + k] = y[_SM + c, k]
        for c in range(12):
            for k in range(m):
                reaction_force[c, start + k] = y[_RF + c, k]
            for k in range(m):
                reaction_moment[c, start + k] = y[_RM + c, k]
        for k in range(m):
            residual[start + k] = y[_RES, k]
        if has_theta:
            for k in range(m):
                effort_theta[start + k] = y[_ET, k]
        if has_s:
            for k in range(m):
                effort_s[start + k] = y[_ES, k]
        # the largest joint load, block by block of valid samples as the numpy route
        for k in range(m):
            if not valid[start + k]:
                continue
            for j in range(4):
                f, q = _RF + 3 * j, _RM + 3 * j
                s2 = (_dot(y[f, k], y[f + 1, k], y[f + 2, k], y[f, k], y[f + 1, k], y[f + 2, k])
                      + inv_ell2 * _dot(y[q, k], y[q + 1, k], y[q + 2, k],
                                        y[q, k], y[q + 1, k], y[q + 2, k]))
                if math.isnan(s2):
                    block_nan[j] = True
                elif s2 > block_max[j]:
                    block_max[j] = s2
            counted += 1
            if counted == block:
                scale2 = _fold(block_max, block_nan, scale2)
                counted = 0
    if counted:
        scale2 = _fold(block_max, block_nan, scale2)
    return scale2
