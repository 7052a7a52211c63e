"""The CSSP rod's zero-spin pose: the turn φ about the rod axis u that carries Rahman's rod frame
{3} = Z(θ1 + θ2)·Y(η2) (SPEC §1.1) to the zero-spin frame along the branch
(:mod:`screwkit.kinematics.tracker.idle_spin`, the generic solver's convention), computed once per sweep
(:func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_sweep`) from u and its derivatives along each step
(the closed form at the steps' input rates) and applied by the block rows.

The transport of :func:`~screwkit.kinematics.tracker.idle_spin.transported_spin`, fused: in blocks
of samples (each with the sample before it), one (n,) array per component, the step's turn

    φ_k − φ_{k−1} = c_k − ∠_{u_k}(M x_{k−1}, x_k),    c_k = −(f(1)/2 − f′(1)/12),
    f(1) = (u_{k−1} × u_k)·u̇_k / (1 + u_{k−1}·u_k),
    f′(1) = (u_{k−1} × u_k)·ü_k / (1 + u_{k−1}·u_k) − f(1) (u_{k−1}·u̇_k) / (1 + u_{k−1}·u_k),

with M x = (u_{k−1}·u_k) x + k × x + (k·x) k/(1 + u_{k−1}·u_k), k = u_{k−1} × u_k (the least
rotation taking u_{k−1} to u_k) and x the rod frame's body vector e ⟂ u; the run starts (the
proximal ball a pure swing from rest) go through the (N, 3) functions of idle_spin at those
samples only. The same formulas as idle_spin's, so the same φ to round-off.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.cssp import CSSPDimensions
from screwkit.kinematics.closed_forms.cssp_compiled import rod_steps, use_compiled
from screwkit.kinematics.tracker.idle_spin import (
    minimal_rotation_apply,
    perpendicular,
    signed_angle,
)
from screwkit.kinematics.tracker.loop import Array

#: samples per block of the transport (its temporaries stay in the CPU caches)
BLOCK = 16384


def _frame_x(k: dict[str, Any], e_body: Array) -> tuple[Array, Array, Array]:
    """x = rod·e for Rahman's rod frame {3} = (u, y3, z3) (:func:`rahman_rod_axes`)."""
    from screwkit.kinematics.closed_forms.cssp_motion import rahman_rod_axes

    u = k["u"]
    y3, z3 = rahman_rod_axes(u)
    e0, e1, e2 = (float(x) for x in e_body)
    return (u[0] * e0 + y3[0] * e1 + z3[0] * e2, u[1] * e0 + y3[1] * e1 + z3[1] * e2,
            u[2] * e0 + y3[2] * e1 + z3[2] * e2)


def _steps(u: tuple[Array, Array, Array], ud: tuple[Array, Array, Array],
           udd: tuple[Array, Array, Array], x: tuple[Array, Array, Array],
           cont: NDArray[np.bool_]) -> Array:
    """φ_i − φ_{i−1} (module docstring) for the steps between consecutive samples of a block
    (u, its derivatives along the step arriving at each sample, the body vector x; ``cont``
    the steps that stay on a run), by components."""
    # step from sample i−1 (p) to i (q) for every i of the block after the first
    m = u[0].shape[0]
    p, q = slice(0, m - 1), slice(1, m)
    ax, ay, az = u[0][p], u[1][p], u[2][p]
    bx, by, bz = u[0][q], u[1][q], u[2][q]
    kx, ky, kz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    c = ax * bx + ay * by + az * bz
    inv = 1.0 / (1.0 + c)
    dx, dy, dz = ud[0][q], ud[1][q], ud[2][q]
    f1 = (kx * dx + ky * dy + kz * dz) * inv
    f1_dot = ((kx * udd[0][q] + ky * udd[1][q] + kz * udd[2][q]) * inv
              - f1 * (ax * dx + ay * dy + az * dz) * inv)
    corr = -(0.5 * f1 - f1_dot / 12.0)
    corr[~np.isfinite(corr)] = 0.0
    # carried = M x_{i−1}: the least rotation taking u_{i−1} to u_i
    vx, vy, vz = x[0][p], x[1][p], x[2][p]
    kv = (kx * vx + ky * vy + kz * vz) * inv
    cx = c * vx + (ky * vz - kz * vy) + kv * kx
    cy = c * vy + (kz * vx - kx * vz) + kv * ky
    cz = c * vz + (kx * vy - ky * vx) + kv * kz
    wx, wy, wz = x[0][q], x[1][q], x[2][q]
    turn = np.arctan2(bx * (cy * wz - cz * wy) + by * (cz * wx - cx * wz)
                      + bz * (cx * wy - cy * wx), cx * wx + cy * wy + cz * wz)
    step = corr - turn
    opposite = cont & ~(1.0 + c >= 1e-12)  # u turned by a half turn in one step
    if opposite.any():
        r = np.flatnonzero(opposite)
        moved = minimal_rotation_apply(
            np.stack([ax[r], ay[r], az[r]], -1), np.stack([bx[r], by[r], bz[r]], -1),
            np.stack([vx[r], vy[r], vz[r]], -1))
        bq = np.stack([bx[r], by[r], bz[r]], -1)
        step[r] = corr[r] - signed_angle(moved, np.stack([wx[r], wy[r], wz[r]], -1), bq)
    return step


def rod_turn(dims: CSSPDimensions, root: int, theta1: Array, ct: Array, st: Array,
             given: dict[str, Any], disc: Array, ok: NDArray[np.bool_]) -> Array:
    """φ (N,) for a sweep (module docstring): 0 where the CSSP does not assemble."""
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_closed_form_block

    n = theta1.shape[0]
    if not ok.any():
        return np.zeros(n)
    s1 = given["s1"]
    steps = np.empty(n)
    steps[0] = 0.0
    np.subtract(theta1[1:], theta1[:-1], out=steps[1:])
    if isinstance(s1, float):
        s1_steps: Any = 0.0
    else:
        s1_steps = np.empty(n)
        s1_steps[0] = 0.0
        np.subtract(s1[1:], s1[:-1], out=s1_steps[1:])

    def closed(sel: slice | NDArray[np.intp]) -> dict[str, Any]:
        return cssp_closed_form_block(
            dims, root, ct[sel], st[sel], steps[sel], 0.0,
            s1 if isinstance(s1, float) else s1[sel], s1_steps if isinstance(s1_steps, float)
            else s1_steps[sel], 0.0, disc[sel])

    # the rod's body vector e ⟂ its axis, taken at the first sample where it assembles
    first = int(np.argmax(ok))
    k0 = closed(slice(first, first + 1))
    u0 = np.array([float(c[0]) for c in k0["u"]])
    from screwkit.kinematics.closed_forms.cssp_motion import rahman_rod_axes

    y30, z30 = rahman_rod_axes(k0["u"])
    rod_first = np.array([[float(k0["u"][i][0]), float(y30[i][0]), float(z30[i][0])]
                          for i in range(3)])
    u_body = rod_first.T @ u0
    e_body = perpendicular(u_body)

    continues = np.zeros(n, dtype=bool)
    np.logical_and(ok[1:], ok[:-1], out=continues[1:])
    phi_step = np.zeros(n)
    starts = np.flatnonzero(ok & ~continues)
    frame_start = np.empty((starts.size, 3))
    u_start = np.empty((starts.size, 3))
    if use_compiled(n):
        _compiled_steps(dims, root, ct, st, steps, s1, s1_steps, disc, continues, e_body,
                        starts, closed, phi_step, frame_start, u_start)
    else:
        _blocked_steps(n, closed, e_body, starts, continues, phi_step, frame_start, u_start)
    # the wanted frame at a run's start: the proximal ball is a pure swing from rest
    start_phi = np.zeros(n)
    if starts.size:
        cs, ss = ct[starts], st[starts]
        ux, uy, uz = u_start[:, 0], u_start[:, 1], u_start[:, 2]
        u_in_crank = np.stack([cs * ux + ss * uy, cs * uy - ss * ux, uz], -1)  # Z(θ1)ᵀ·u
        sw = minimal_rotation_apply(np.broadcast_to(u_body, (starts.size, 3)), u_in_crank,
                                    np.broadcast_to(e_body, (starts.size, 3)))
        start_x = np.stack([cs * sw[:, 0] - ss * sw[:, 1], ss * sw[:, 0] + cs * sw[:, 1],
                            sw[:, 2]], -1)  # Z(θ1)·x
        start_phi[starts] = signed_angle(frame_start, start_x, u_start)
    # φ_k = φ_{k−1} + step_k along a run, φ = start_phi at its first sample
    total = np.cumsum(phi_step, out=phi_step)
    if starts.size == 1 and ok.all():  # one run: the whole sweep
        total += start_phi[starts[0]] - total[starts[0]]
        return total
    is_start = np.zeros(n, dtype=bool)
    is_start[starts] = True
    run_id = np.maximum(np.cumsum(is_start) - 1, 0)
    base = (start_phi[starts] - total[starts]) if starts.size else np.zeros(1)
    phi = total + base[run_id]
    return np.where(ok, phi, 0.0)


def _blocked_steps(n: int, closed: Any, e_body: Array, starts: NDArray[np.intp],
                   continues: NDArray[np.bool_], phi_step: Array, frame_start: Array,
                   u_start: Array) -> None:
    """The steps of :func:`rod_turn` block by block (numpy), into ``phi_step``; the rod's
    body vector x and u at the runs' starts into ``frame_start``, ``u_start``."""
    with np.errstate(divide="ignore", invalid="ignore"):  # placeholders off the runs
        for a in range(0, n, BLOCK):
            b = min(a + BLOCK, n)
            lo = max(a - 1, 0)  # with the sample before the block
            k = closed(slice(lo, b))
            u, ud, udd = k["u"], k["u_dot"], k["u_ddot"]
            x = _frame_x(k, e_body)
            here = [s - lo for s in starts[(starts >= a) & (starts < b)].tolist()]
            if here:
                j = np.searchsorted(starts, a)
                frame_start[j:j + len(here)] = np.stack([c[here] for c in x], -1)
                u_start[j:j + len(here)] = np.stack([c[here] for c in u], -1)
            if b - lo < 2:
                continue
            cont = continues[lo + 1:b]
            phi_step[lo + 1:b] = np.where(cont, _steps(u, ud, udd, x, cont), 0.0)


def _compiled_steps(dims: CSSPDimensions, root: int, ct: Array, st: Array, steps: Array,
                    s1: Any, s1_steps: Any, disc: Array, continues: NDArray[np.bool_],
                    e_body: Array, starts: NDArray[np.intp], closed: Any, phi_step: Array,
                    frame_start: Array, u_start: Array) -> None:
    """The steps of :func:`rod_turn` by the compiled loop (the same formulas: cssp_compiled),
    x and u at the runs' starts and the half-turn steps by the numpy functions."""
    opposite = rod_steps(dims, root, ct, st, steps, s1, s1_steps, disc, continues, e_body,
                         phi_step)
    with np.errstate(divide="ignore", invalid="ignore"):
        if starts.size:
            k = closed(starts)
            frame_start[:] = np.stack(_frame_x(k, e_body), -1)
            u_start[:] = np.stack(k["u"], -1)
        if opposite.size:  # u turned by a half turn in one step: as _steps finishes them
            kp, kq = closed(opposite - 1), closed(opposite)
            a, b = np.stack(kp["u"], -1), np.stack(kq["u"], -1)
            moved = minimal_rotation_apply(a, b, np.stack(_frame_x(kp, e_body), -1))
            phi_step[opposite] = phi_step[opposite] - signed_angle(
                moved, np.stack(_frame_x(kq, e_body), -1), b)
