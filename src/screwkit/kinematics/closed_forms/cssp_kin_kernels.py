"""The numba kernels of :mod:`screwkit.kinematics.closed_forms.cssp_compiled` (imported by it on
first use only, so that importing screwkit does not import numba; compiled on first use and
cached on disk by numba next to this module).

:func:`lean_rows` is :func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_block_rows`
(the closed form of Rahman 1996 §1.2, reference SPEC §1.2; the rod frame {3} of SPEC §1.1
turned by the zero-spin turn φ) and its stores, for a base at the world frame: the samples go
through in tiles of :data:`TILE`, each sample's rows computed into a local buffer and the
buffer's rows copied into the component-major storage. :func:`rod_steps` is the step loop of
:func:`~screwkit.kinematics.closed_forms.cssp_rod_pose.rod_turn` (the transport of
:mod:`screwkit.kinematics.tracker.idle_spin`, its module docstring's formulas). Every formula is
the numpy route's with its operations in the same order; no fastmath.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

#: samples per tile (its buffer stays in the first-level cache)
TILE = 64

# rows of the tile buffer: rotation, origin, velocity, acceleration, angular velocity and
# acceleration, joint centres, joint axes, s4 and its rates, closure
_ROT, _ORG, _VEL, _ACC, _W, _AL, _CEN, _AX, _S4, _CLO = 0, 27, 36, 45, 54, 63, 72, 84, 96, 99
# the tile's inputs: θ̇1, θ̈1, s1, ṡ1, s̈1, cos φ, sin φ
_IN = 100

njit = numba.njit(cache=True, nogil=True, error_model="numpy")


@numba.njit(inline="always")
def _closed(p: Any, root: float, ct: float, st: float, w: float, wd: float, s1: float,
            s1d: float, s1dd: float, disc: float) -> tuple[float, ...]:
    """:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_closed_form_block` at one
    sample: s4, ṡ4, s̈4, the pin's velocity and acceleration (x, y) and u, u̇, ü. ``p``: a4,
    sin α4, cos α4, a4² + a1² − a2², 1/a2, a1, a2."""
    a4, sa, ca, c0, inv_a2, a1 = p[0], p[1], p[2], p[3], p[4], p[5]
    a1c, a1s = a1 * ct, a1 * st
    b = sa * a1s + ca * s1
    c = (c0 + 2 * a4 * a1c) + s1 * s1
    radical = root * math.sqrt(disc)  # root is ±1.0: ±√disc exactly
    other = -b - radical
    cancels = (((b > 0) & (root > 0)) | ((b < 0) & (root < 0))) & (other != 0)
    s4 = c / other if cancels else radical - b
    w2 = w * w
    pv0, pv1 = -a1s * w, a1c * w
    pa0, pa1 = -(a1c * w2 + a1s * wd), a1c * wd - a1s * w2
    b_dot = sa * pv1 + ca * s1d
    b_ddot = sa * pa1 + ca * s1dd
    c_dot = 2 * (a4 * pv0 + s1 * s1d)
    c_ddot = 2 * ((a4 * pa0 + s1d * s1d) + s1 * s1dd)
    inv_root = 1.0 / radical
    s4_dot = -(b_dot * s4 + 0.5 * c_dot) * inv_root
    s4_ddot = -(((s4_dot * s4_dot + 2 * b_dot * s4_dot) + b_ddot * s4) + 0.5 * c_ddot) * inv_root
    ball1, ball2 = -sa * s4, -ca * s4
    u0, u1, u2 = (-a4 - a1c) * inv_a2, (ball1 - a1s) * inv_a2, (ball2 - s1) * inv_a2
    ud0, ud1, ud2 = (-pv0 * inv_a2, (-sa * s4_dot - pv1) * inv_a2,
                     (-ca * s4_dot - s1d) * inv_a2)
    udd0, udd1, udd2 = (-pa0 * inv_a2, (-sa * s4_ddot - pa1) * inv_a2,
                        (-ca * s4_ddot - s1dd) * inv_a2)
    return (s4, s4_dot, s4_ddot, pv0, pv1, pa0, pa1, u0, u1, u2, ud0, ud1, ud2, udd0, udd1,
            udd2)


@numba.njit(inline="always")
def _axes(u0: float, u1: float, u2: float, tol2: float) -> tuple[float, ...]:
    """y3, z3 of :func:`~screwkit.kinematics.closed_forms.cssp_motion.rahman_rod_axes`."""
    rho2 = u0 * u0 + u1 * u1
    defined = rho2 > tol2
    inv_rho = 1.0 / math.sqrt(rho2 if defined else 1.0)
    y0 = -u1 * inv_rho if defined else 0.0
    y1 = u0 * inv_rho if defined else 1.0
    y2 = 0.0
    return y0, y1, y2, -u2 * y1, u2 * y0, u0 * y1 - u1 * y0


@numba.njit(inline="always")
def _fill(buf: Any, row: int, src: Any, t0: int, m: int) -> None:
    """Row ``row`` of the tile buffer: ``src`` at the tile's samples, or its one entry."""
    if src.shape[0] > 1:
        for j in range(m):
            buf[row, j] = src[t0 + j]
    else:
        for j in range(m):
            buf[row, j] = src[0]


@njit
def lean_rows(ct: Any, st: Any, w: Any, wd: Any, s1: Any, s1d: Any, s1dd: Any, disc: Any,
              turn: Any, p: Any, root: float, tol2: float, slider: Any, k4: Any,
              driven: bool, write: Any, stores: Any) -> None:
    """The lean rows of every sample into ``stores`` (rotation (27, N), origin (9, N) or
    empty, velocity, acceleration, angular velocity and acceleration (9, N), centres and axes
    (12, N), s4 (3, N), closure (1, N)); ``write[r]`` is False for the rows the numpy route
    leaves unwritten (a constant zero). A rate or s1 of one entry is the same at every
    sample. Per tile: the inputs gathered and cos φ, sin φ taken, then one loop without
    calls (which the compiler vectorises), then the rows stored."""
    n = ct.shape[0]
    buf = np.zeros((_IN + 7, TILE))
    a4, a2, sa, ca, a1 = p[0], p[6], p[1], p[2], p[5]
    for tile in range((n + TILE - 1) // TILE):
        t0 = tile * TILE  # not range(0, n, TILE): numba's t0 could be negative to LLVM
        m = min(TILE, n - t0)
        _fill(buf, _IN, w, t0, m)
        _fill(buf, _IN + 1, wd, t0, m)
        _fill(buf, _IN + 2, s1, t0, m)
        _fill(buf, _IN + 3, s1d, t0, m)
        _fill(buf, _IN + 4, s1dd, t0, m)
        for j in range(m):
            buf[_IN + 5, j] = math.cos(turn[t0 + j])
            buf[_IN + 6, j] = math.sin(turn[t0 + j])
        for j in range(m):
            k = t0 + j
            wk, wdk, s1k = buf[_IN, j], buf[_IN + 1, j], buf[_IN + 2, j]
            s1dk, s1ddk = buf[_IN + 3, j], buf[_IN + 4, j]
            c_, s_ = ct[k], st[k]
            (s4, s4d, s4dd, pv0, pv1, pa0, pa1, u0, u1, u2, ud0, ud1, ud2, udd0, udd1,
             udd2) = _closed(p, root, c_, s_, wk, wdk, s1k, s1dk, s1ddk, disc[k])
            y0, y1, y2, z0, z1, z2 = _axes(u0, u1, u2, tol2)
            cph, sph = buf[_IN + 5, j], buf[_IN + 6, j]
            y0, y1, y2, z0, z1, z2 = (cph * y0 + sph * z0, cph * y1 + sph * z1,
                                      cph * y2 + sph * z2, cph * z0 - sph * y0,
                                      cph * z1 - sph * y1, cph * z2 - sph * y2)
            a1c, a1s = a1 * c_, a1 * s_
            ball1, ball2 = -sa * s4, -ca * s4
            buf[_ROT, j], buf[_ROT + 1, j], buf[_ROT + 3, j], buf[_ROT + 4, j] = c_, -s_, s_, c_
            buf[_ROT + 8, j] = 1.0
            buf[_ROT + 9, j], buf[_ROT + 10, j], buf[_ROT + 11, j] = u0, y0, z0
            buf[_ROT + 12, j], buf[_ROT + 13, j], buf[_ROT + 14, j] = u1, y1, z1
            buf[_ROT + 15, j], buf[_ROT + 16, j], buf[_ROT + 17, j] = u2, y2, z2
            for r in range(9):
                buf[_ROT + 18 + r, j] = slider[r]
            buf[_ORG + 2, j], buf[_ORG + 3, j], buf[_ORG + 4, j] = s1k, a1c, a1s
            buf[_ORG + 5, j], buf[_ORG + 6, j], buf[_ORG + 7, j] = s1k, -a4, ball1
            buf[_ORG + 8, j] = ball2
            buf[_VEL + 2, j], buf[_VEL + 3, j], buf[_VEL + 4, j] = s1dk, pv0, pv1
            buf[_VEL + 5, j], buf[_VEL + 7, j], buf[_VEL + 8, j] = (s1dk, -k4[1] * s4d,
                                                                    -k4[2] * s4d)
            buf[_ACC + 2, j], buf[_ACC + 3, j], buf[_ACC + 4, j] = s1ddk, pa0, pa1
            buf[_ACC + 5, j], buf[_ACC + 7, j], buf[_ACC + 8, j] = (s1ddk, -k4[1] * s4dd,
                                                                    -k4[2] * s4dd)
            buf[_W + 2, j] = wk
            buf[_W + 3, j] = u1 * ud2 - u2 * ud1
            buf[_W + 4, j] = u2 * ud0 - u0 * ud2
            buf[_W + 5, j] = u0 * ud1 - u1 * ud0
            buf[_AL + 2, j] = wdk
            buf[_AL + 3, j] = u1 * udd2 - u2 * udd1
            buf[_AL + 4, j] = u2 * udd0 - u0 * udd2
            buf[_AL + 5, j] = u0 * udd1 - u1 * udd0
            buf[_CEN + 2, j] = 0.0 if driven else s1k
            buf[_CEN + 3, j], buf[_CEN + 4, j], buf[_CEN + 5, j] = a1c, a1s, s1k
            buf[_CEN + 6, j], buf[_CEN + 7, j], buf[_CEN + 8, j] = -a4, ball1, ball2
            buf[_CEN + 9, j], buf[_CEN + 10, j], buf[_CEN + 11, j] = -a4, ball1, ball2
            buf[_AX + 2, j], buf[_AX + 5, j] = 1.0, 1.0
            buf[_AX + 6, j], buf[_AX + 7, j], buf[_AX + 8, j] = z0, z1, z2
            buf[_AX + 9, j], buf[_AX + 10, j], buf[_AX + 11, j] = k4[0], k4[1], k4[2]
            buf[_S4, j], buf[_S4 + 1, j], buf[_S4 + 2, j] = s4, s4d, s4dd
            span = math.sqrt((u0 * u0 + u1 * u1) + u2 * u2)
            buf[_CLO, j] = a2 * abs(span - 1.0)
        r0 = 0
        for store in stores:
            for r in range(store.shape[0]):
                if write[r0 + r]:
                    for j in range(m):
                        store[r, t0 + j] = buf[r0 + r, j]
            r0 += store.shape[0]


@njit
def rod_steps(ct: Any, st: Any, steps: Any, s1: Any, s1_steps: Any, disc: Any,
              continues: Any, p: Any, root: float, tol2: float, e: Any, out: Any,
              opposite: Any) -> int:
    """φ_i − φ_{i−1} of :func:`~screwkit.kinematics.closed_forms.cssp_rod_pose.rod_turn`'s
    steps into ``out`` (0 where ``continues`` is False); where u turns by a half turn in one
    step (``opposite`` set, their count returned) ``out`` holds only the step's correction
    c_k, for the numpy route to finish."""
    n = ct.shape[0]
    is1, is1s = s1.shape[0] > 1, s1_steps.shape[0] > 1
    count = 0
    ax = ay = az = vx = vy = vz = 0.0
    for i in range(n):
        r = _closed(p, root, ct[i], st[i], steps[i], 0.0, s1[i] if is1 else s1[0],
                    s1_steps[i] if is1s else s1_steps[0], 0.0, disc[i])
        bx, by, bz = r[7], r[8], r[9]
        y0, y1, y2, z0, z1, z2 = _axes(bx, by, bz, tol2)
        wx = (bx * e[0] + y0 * e[1]) + z0 * e[2]
        wy = (by * e[0] + y1 * e[1]) + z1 * e[2]
        wz = (bz * e[0] + y2 * e[1]) + z2 * e[2]
        out[i] = 0.0
        opposite[i] = False
        if i > 0 and continues[i]:
            kx, ky, kz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
            c = (ax * bx + ay * by) + az * bz
            inv = 1.0 / (1.0 + c)
            dx, dy, dz = r[10], r[11], r[12]
            f1 = ((kx * dx + ky * dy) + kz * dz) * inv
            f1_dot = (((kx * r[13] + ky * r[14]) + kz * r[15]) * inv
                      - f1 * ((ax * dx + ay * dy) + az * dz) * inv)
            corr = -(0.5 * f1 - f1_dot / 12.0)
            if not math.isfinite(corr):
                corr = 0.0
            if not 1.0 + c >= 1e-12:
                opposite[i] = True
                count += 1
                out[i] = corr
            else:
                kv = ((kx * vx + ky * vy) + kz * vz) * inv
                cx = (c * vx + (ky * vz - kz * vy)) + kv * kx
                cy = (c * vy + (kz * vx - kx * vz)) + kv * ky
                cz = (c * vz + (kx * vy - ky * vx)) + kv * kz
                turn = math.atan2((bx * (cy * wz - cz * wy) + by * (cz * wx - cx * wz))
                                  + bz * (cx * wy - cy * wx), (cx * wx + cy * wy) + cz * wz)
                out[i] = corr - turn
        ax, ay, az, vx, vy, vz = bx, by, bz, wx, wy, wz
    return count
