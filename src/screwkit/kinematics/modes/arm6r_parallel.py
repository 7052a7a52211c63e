"""Inverse kinematics of 6R arms with (nearly) parallel consecutive axes, by a generic perturbation.

Real industrial arms have parallel consecutive joints: J2 ∥ J3 on a PUMA, KUKA, ABB or Fanuc
arm, J2 ∥ J3 ∥ J4 on a UR arm. There the 6R loop's parameters k_i = a_i / sin α_i are
infinite and :mod:`.loop6r` cannot be set up. :func:`solve_parallel_arm` finds every real
solution by a generic perturbation and continuation (the "perturbed system" argument of
Sommese & Wampler 2005, §7.1 and ch. 10: a nearby generic instance's solutions are continued to
the special one; those that stay finite end at its isolated solutions):

1. every joint axis u_i is tilted by ε·δ_i (δ_i ⊥ u_i, random, seeded), and the tilted arm, a
   general 6R arm, is solved by :func:`.arm6r.arm6r_instance` and :func:`.loop6r_solve.solve_loop6r`
   (all 16 complex solutions), each read as complex joint values (:func:`complex_joint_values`);
2. the tilt is taken to zero along s = 1 → 0 with the axes u_i + s ε δ_i + i s (1 − s) ε δ'_i
   (complex in between, the "gamma trick" that keeps the paths from meeting along the way),
   Newton's method on the forward kinematics' residual (position, and the skew part of
   R·R_target^T; the analytic spatial Jacobian) correcting every path at every step, batched over
   paths;
3. at s = 0 each path is polished on the exact arm; paths whose Newton steps do not settle
   (those going to infinity: a parallel pair drops the generic 16 to 8 for a PUMA or a UR arm)
   are dropped, and the real ones are deduplicated (angles mod 2π).

What is checked: every returned solution closes the exact forward kinematics
(:func:`.arm6r.arm_forward`, position and rotation) to its ``residual``, and is certified by
Smale's α-test on the arm's forward kinematics as polynomials in (cos q_i, sin q_i)
(:mod:`.arm6r_certify`): a true real solution lies within ``radius``, one per ball. The tests
compare the set with dense random Newton starts. What is not: completeness rests on the
perturbation argument (every isolated solution of the exact arm is the end of a path, with
probability one in the random tilt, for paths tracked without jumping), not on a proof per
target.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.errors import CapabilityError
from screwkit.kinematics.modes.arm6r_certify import arm_fk_system, certify_arm_solutions

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

#: a link whose two axes have sin α below this goes to the perturbation route
PARALLEL_SIN = 1e-2
#: the tilt of each axis in the perturbed arm (radians) and the continuation's steps
EPSILON = 0.02
#: the continuation drops a path whose step falls below this or whose joint values' imaginary
#: part passes MAX_IMAG (it goes to infinity), and stops after MAX_TRACK_ITERATIONS steps
MIN_STEP = 1e-7
MAX_IMAG = 25.0
MAX_TRACK_ITERATIONS = 400
ROUTE = ("generic perturbation: axes tilted by ε, the 16 solutions of the tilted arm "
         "continued to ε = 0 by Newton on the forward kinematics")


def parallel_links(axes: Array, points: Array) -> list[tuple[int, int]]:
    """The consecutive joints (1-based pairs) whose axes are within :data:`PARALLEL_SIN`
    of parallel. Raises :class:`CapabilityError` for two consecutive joints on one line (a
    continuum of solutions: the two turn as one)."""
    U = axes / np.linalg.norm(axes, axis=1)[:, None]
    out = []
    for i in range(5):
        if np.linalg.norm(np.cross(U[i], U[i + 1])) < PARALLEL_SIN:
            out.append((i + 1, i + 2))
            off = points[i + 1] - points[i]
            if np.linalg.norm(off - (off @ U[i]) * U[i]) < 1e-9 * (1.0 + np.linalg.norm(off)):
                raise CapabilityError(
                    f"joints {i + 1} and {i + 2} of the arm turn about one line, so its inverse "
                    f"kinematics has a continuum of solutions (their sum is fixed, not each); "
                    f"merge them into one joint")
    return out


def ground_parallel(axes: Array, tool_home: tuple[ArrayLike, ArrayLike],
                    target: tuple[ArrayLike, ArrayLike]) -> bool:
    """Whether joint 6, moved with the tool to ``target``, is within :data:`PARALLEL_SIN` of
    parallel to joint 1 (the loop's ground link, :mod:`.arm6r`)."""
    U = axes / np.linalg.norm(axes, axis=1)[:, None]
    move = np.asarray(target[0], dtype=float) @ np.asarray(tool_home[0], dtype=float).T
    return bool(np.linalg.norm(np.cross(U[0], move @ U[5])) < PARALLEL_SIN)


def _skew(w: NDArray) -> NDArray:
    out = np.zeros(w.shape + (3,), dtype=w.dtype)
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    return out


def _vee_skew(M: NDArray) -> NDArray:
    """The axial vector of the skew part of M (…, 3, 3)."""
    return 0.5 * np.stack([M[..., 2, 1] - M[..., 1, 2], M[..., 0, 2] - M[..., 2, 0],
                           M[..., 1, 0] - M[..., 0, 1]], -1)


def forward_batch(points: NDArray, axes: NDArray, tool_home: tuple[Array, Array], q: NDArray
                  ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Batched product of exponentials (Murray, Li & Sastry 1994, §3.2) at joint values q
    (N, 6), real or complex, with axes (6, 3) or (N, 6, 3) (normalised bilinearly, u·u = 1):
    the tool's R (N, 3, 3) and p (N, 3), and each joint's current axis (N, 6, 3) and point."""
    N = q.shape[0]
    A = np.broadcast_to(axes, (N, 6, 3))
    A = A / np.sqrt(np.sum(A * A, -1))[..., None]
    dtype = np.result_type(q, A, float)
    R = np.broadcast_to(np.eye(3, dtype=dtype), (N, 3, 3)).copy()
    p = np.zeros((N, 3), dtype=dtype)
    W, P = [], []
    for i in range(6):
        u, c = A[:, i], points[i]
        W.append(np.einsum("nij,nj->ni", R, u))
        P.append(np.einsum("nij,j->ni", R, c) + p)
        K = _skew(u)
        s, co = np.sin(q[:, i])[:, None, None], np.cos(q[:, i])[:, None, None]
        Ri = np.eye(3) + s * K + (1.0 - co) * (K @ K)
        p = np.einsum("nij,nj->ni", R, c - np.einsum("nij,j->ni", Ri, c)) + p
        R = R @ Ri
    return (R @ tool_home[0], np.einsum("nij,j->ni", R, tool_home[1]) + p, np.stack(W, 1),
            np.stack(P, 1))


def fk_residual(points: NDArray, axes: NDArray, tool_home: tuple[Array, Array],
                target: tuple[Array, Array], q: NDArray) -> tuple[NDArray, NDArray]:
    """The residual (N, 6) of joint values q at the target, p(q) − p_t and the axial vector of
    the skew part of R(q)·R_t^T, and its Jacobian (N, 6, 6) (spatial twists: dp = ω × (p − c),
    dR = [ω] R)."""
    R, p, W, P = forward_batch(points, axes, tool_home, q)
    M = R @ target[0].T
    r = np.concatenate([p - target[1], _vee_skew(M)], -1)
    Jp = np.cross(W, p[:, None, :] - P)
    Wk = _skew(W)
    Je = 0.5 * _vee_skew(Wk @ M[:, None] + np.swapaxes(M, -1, -2)[:, None] @ Wk)
    return r, np.swapaxes(np.concatenate([Jp, Je], -1), -1, -2)


def _newton(points: NDArray, axes: NDArray, tool_home: tuple[Array, Array],
            target: tuple[Array, Array], q: NDArray, iterations: int
            ) -> tuple[NDArray, NDArray, NDArray]:
    """Newton's method on :func:`fk_residual`: q, the last residual and last step (∞-norms)."""
    r = step = np.full(len(q), np.inf)
    for _ in range(iterations):
        with np.errstate(all="ignore"):  # paths going to infinity overflow, and are dropped
            res, J = fk_residual(points, axes, tool_home, target, q)
            r = np.abs(res).max(-1)
            ok = np.isfinite(J).all(axis=(1, 2)) & (np.abs(np.linalg.det(J)) > 1e-300)
            dq = np.zeros_like(q)
            if ok.any():
                dq[ok] = np.linalg.solve(J[ok], res[ok][..., None])[..., 0]
            dq[~ok] = np.nan
        q = q - dq
        step = np.abs(dq).max(-1)
    return q, r, step


def _track(points: NDArray, tool_home: tuple[Array, Array], target: tuple[Array, Array],
           q: Complex, arm_at: Callable[[NDArray], NDArray]) -> Complex:
    """Continue the solutions q (N, 6) of the arm ``arm_at(1)`` to ``arm_at(0)``, batched, with
    an adaptive step: predict along the tangent dq/dt = −J⁻¹ ∂r/∂t (∂r/∂t by a difference), correct
    by three Newton steps, accept when they contract and end below 1e-8, else halve the step.
    A path whose step falls below :data:`MIN_STEP` or whose imaginary part passes
    :data:`MAX_IMAG` goes to infinity (a solution the parallel axes remove) and is dropped
    (rows of NaN)."""
    q = q.copy()
    t = np.ones(len(q))
    h = np.full(len(q), 0.05)
    active: NDArray[np.bool_] = np.asarray(np.isfinite(q).all(-1))
    q[~active] = np.nan
    for _ in range(MAX_TRACK_ITERATIONS):
        if not active.any():
            break
        i = np.flatnonzero(active)
        qi, ti, hi = q[i], t[i], np.minimum(h[i], t[i])
        with np.errstate(all="ignore"):
            r0, J = fk_residual(points, arm_at(ti), tool_home, target, qi)
            dt = 1e-7
            r1, _ = fk_residual(points, arm_at(ti - dt), tool_home, target, qi)
            tangent = np.linalg.solve(J, ((r1 - r0) / dt)[..., None])[..., 0]
            tn = ti - hi
            qn = qi - hi[:, None] * tangent
            Un = arm_at(tn)
            steps = []
            for _ in range(3):
                r, Jn = fk_residual(points, Un, tool_home, target, qn)
                dq = np.linalg.solve(Jn, r[..., None])[..., 0]
                qn = qn - dq
                steps.append(np.abs(dq).max(-1))
        ok = (np.isfinite(qn).all(-1) & (steps[1] <= 0.5 * steps[0] + 1e-12)
              & (steps[2] <= 0.5 * steps[1] + 1e-12) & (steps[2] < 1e-8)
              & (steps[0] < 0.1))
        q[i[ok]], t[i[ok]] = qn[ok], tn[ok]
        h[i] = np.where(ok, np.minimum(1.5 * hi, 0.1), 0.5 * hi)
        lost = (h[i] < MIN_STEP) | (np.abs(q[i].imag).max(-1) > MAX_IMAG)
        q[i[lost]] = np.nan
        active[i[lost | (t[i] <= 0.0)]] = False
    q[active] = np.nan  # not finished in the iteration budget
    return q


def complex_joint_values(params: ArrayLike, x: ArrayLike, base_ref: Array, tool_ref: Array,
                         home_angles: Array) -> Complex:
    """Joint values (N, 6) from home of complex 6R solutions x (N, 12) of one arm instance:
    θ = −i log(cos θ + i sin θ) with cos and sin rational in the axes (the common normals
    z_i × z_{i+1} have length sin α_i, real), so complex solutions get joint values too."""
    from screwkit.kinematics.modes.loop6r import loop6r_axes

    params = np.asarray(params)
    z = loop6r_axes(x, params)
    cos_a = np.real(params[6:11])
    sin_a = np.sqrt(np.maximum(1.0 - cos_a * cos_a, 0.0))
    w = np.cross(z[:, :5], z[:, 1:])
    b = base_ref / np.linalg.norm(base_ref)
    t = tool_ref / np.linalg.norm(tool_ref)
    before = np.concatenate([np.broadcast_to(b, w[:, :1].shape), w], 1)
    after = np.concatenate([w, np.broadcast_to(t.astype(complex), w[:, :1].shape)], 1)
    scale = np.concatenate([[1.0], sin_a]) * np.concatenate([sin_a, [1.0]])
    cos = np.einsum("nij,nij->ni", before, after) / scale
    sin = np.einsum("nij,nij->ni", np.cross(before, after), z) / scale
    with np.errstate(all="ignore"):
        q = -1j * np.log(cos + 1j * sin) - home_angles
    return np.mod(q.real + np.pi, 2 * np.pi) - np.pi + 1j * q.imag


@dataclass(frozen=True)
class ArmContinuation:
    """The result of :func:`solve_parallel_arm` for one target. Per real solution (N,):
    ``residual`` (‖FK residual‖∞ on the exact arm), ``step`` (the last Newton step, ∞-norm),
    ``condition`` (the FK Jacobian's condition number), ``certified`` (a certified real zero of
    the (cos, sin) system by Smale's α-test, :mod:`.arm6r_certify`), ``alpha`` and ``radius``
    (a true zero within it, in (cos, sin) coordinates). Per target: ``paths`` tracked (16), ``converged`` (paths
    ending at a finite solution, complex ones included), ``found`` (distinct finite solutions:
    fewer than ``converged`` means two paths ended at one point, a double root or a jumped
    path) and ``real_count``, ``parallel`` (the joint pairs that sent the arm here; (6, 1) is
    joint 6 at the target parallel to joint 1), ``route``."""

    residual: Array
    step: Array
    condition: Array
    certified: NDArray[np.bool_]
    alpha: Array
    radius: Array
    paths: int
    converged: int
    found: int
    real_count: int
    parallel: tuple[tuple[int, int], ...]
    route: tuple[str, ...] = (ROUTE,)
    note: str = ""


@lru_cache(maxsize=8)
def _fk_system_of(key: bytes) -> PolynomialSystem:
    a = np.frombuffer(key, dtype=float)
    return arm_fk_system(a[:18].reshape(6, 3), a[18:36].reshape(6, 3),
                         (a[36:45].reshape(3, 3), a[45:48]))


def _fk_system(C: Array, U: Array, home: tuple[Array, Array]) -> PolynomialSystem:
    """The arm's (cos, sin) system, cached per arm (a few hundredths of a second to build)."""
    return _fk_system_of(np.concatenate([C.ravel(), U.ravel(), home[0].ravel(),
                                         home[1].ravel()]).astype(float).tobytes())


def _distinct(q: Complex, tol: float) -> NDArray[np.intp]:
    """Indices of the first of each group of joint values equal mod 2π within tol."""
    keep: list[int] = []
    for i in range(len(q)):
        d = q[i] - q[keep]
        d = np.mod(d.real + np.pi, 2 * np.pi) - np.pi + 1j * d.imag
        if not keep or np.abs(d).max(-1).min() > tol:
            keep.append(i)
    return np.asarray(keep, dtype=np.intp)


def solve_parallel_arm(centres: ArrayLike, axes: ArrayLike,
                       tool_home: tuple[ArrayLike, ArrayLike],
                       target: tuple[ArrayLike, ArrayLike], seed: int = 0,
                       epsilon: float = EPSILON) -> tuple[Array, ArmContinuation]:
    """Every real inverse-kinematics solution (N, 6), from home, of a 6R arm with nearly
    parallel consecutive axes, by the generic perturbation of the module docstring."""
    from screwkit.kinematics.modes.arm6r import arm6r_instance, arm_lines
    from screwkit.kinematics.modes.loop6r_solve import solve_loop6r

    C, U = arm_lines(centres, axes)
    home = (np.asarray(tool_home[0], dtype=float), np.asarray(tool_home[1], dtype=float))
    tgt = (np.asarray(target[0], dtype=float), np.asarray(target[1], dtype=float))
    pairs = parallel_links(U, C) + ([(6, 1)] if ground_parallel(U, home, tgt) else [])
    rng = np.random.default_rng(seed)

    def tilt() -> Array:
        d = rng.normal(size=(6, 3))
        d -= np.sum(d * U, 1)[:, None] * U
        return d / np.linalg.norm(d, axis=1)[:, None]

    D, D2 = tilt(), tilt()
    inst = arm6r_instance(C, U + epsilon * D, home, tgt)
    sol = solve_loop6r(inst.params)
    q = complex_joint_values(inst.params, sol.x, inst.base_ref, inst.tool_ref, inst.home_angles)
    q = q[np.isfinite(q).all(-1)]
    paths = len(q)

    def arm_at(t: NDArray) -> NDArray:
        """The axes (n, 6, 3) at continuation times t (n,): complex between 1 and 0."""
        t = t[:, None, None]
        return U + t * epsilon * D + 1j * t * (1.0 - t) * epsilon * D2

    q = _track(C, home, tgt, q, arm_at)
    q, r, step = _newton(C, U.astype(complex), home, tgt, q, 6)
    settled = np.isfinite(q).all(-1) & (r < 1e-9) & (step < 1e-9)
    q = q[settled]
    q = q[_distinct(q, 1e-6)]
    real = np.abs(q.imag).max(-1, initial=0.0) < 1e-8
    qr = np.mod(q[real].real + np.pi, 2 * np.pi) - np.pi
    qr, _, last = _newton(C, U, home, tgt, qr, 1)  # one real step: its size is reported
    res, J = fk_residual(C, U, home, tgt, qr)
    cond = np.linalg.cond(J) if len(qr) else np.zeros(0)
    cert = certify_arm_solutions(_fk_system(C, U, home), qr, tgt)
    certified = cert.certified & cert.real
    note = ("every real solution certified (α-test)" if certified.all() else
            f"{int((~certified).sum())} of {len(qr)} real solutions converged, not certified")
    result = ArmContinuation(np.abs(res).max(-1, initial=0.0), last, cond, certified,
                             cert.alpha, cert.radius, paths, int(settled.sum()), len(q),
                             len(qr), tuple(pairs), note=note)
    return qr, result
