"""Joint wrenches and input efforts of any mechanism graph from the loads on its bodies.

Unknowns: the wrench W_j = (f_j; m_j) (moment about the world origin) exerted through joint j by
its first body on its second (``between = [a, b]``: by a on b), for every joint.

Equations (Newton–Euler for every moving body b, B_b its applied inertia + weight wrench):

    Σ_{j: b second} W_j − Σ_{j: b first} W_j + B_b = 0          (6 per moving body)
    S_k · W_{j(k)} = 0                                           (1 per passive freedom k)

with S·W = ω·m + v·f the reciprocal product of a unit freedom screw with the wrench (no work
along a frictionless freedom; Bagci 1969 §3.4). A driven freedom's effort is τ_k = S_k·W_{j(k)}.

A system of full column rank (a statically determinate mechanism such as the Stewart platform
or an RSSR) is solved through the spanning tree, the chords' wrenches the only unknowns
(dynamics/graph_tree_statics.py); one of full row rank by LU of A·Aᵀ (y = Aᵀz); any other,
per sample, by the SVD (a sample the first two leave a residual at is solved again by the
full system). Either way the solution is the one of the wrenches that minimise Σ_j |f_j|² + |m_cj/ℓ|², moments
taken about each joint's centre c_j and divided by the length scale ℓ (as single loops do,
dynamics/loop_statics.py): the choice is independent of the reference point and of how the graph
is cut. Its null space — self-stress that rigid joints can carry without any load, three per
loop of a planar mechanism drawn in 3-D — is counted and named by the joints it loads. Idle
freedoms (a rod's spin) make the passive equations consistent only when the loads do no work
along them; the least-squares solution is returned and the residual reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dynamics.graph_tree_statics import tree_cut, tree_statics
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

RANK_RTOL = 1e-9
#: samples whose equations are built and solved together (their dense systems stay in cache)
CHUNK = 64


@dataclass(frozen=True)
class GraphStatics:
    """Solved joint wrenches (N, J, 6, K) by first body on second, moment about the world
    origin; efforts (N, n_in, K); the equations' residual (N, K) (relative to the loads); the
    count of statically indeterminate components and the joints that carry them."""

    wrenches: Array
    efforts: Array
    residual: Array
    indeterminate: int
    indeterminate_joints: list[str]
    #: (N, R, K) the scaled equations' residual A·y − b itself and the rank of A: loads along
    #: idle freedoms leave R − rank consistency conditions (dynamics/graph_regressor.py)
    equation_residual: Array
    rank: int


def _system(mech: Mechanism, screws: Array, centres: Array, passive: list[int],
            joint_of: tuple[int, ...], length: float) -> Array:
    """The scaled matrix (N, 6B + m_p, 6J) acting on y_j = (f_j; m_cj/ℓ)."""
    N = screws.shape[0]
    B, J = len(mech.bodies), len(mech.joints)
    index = {b: k for k, b in enumerate(mech.body_names)}
    A = np.zeros((N, 6 * B + len(passive), 6 * J))
    # W_j = T_j y_j: f = f, m_O = c_j × f + ℓ m_c/ℓ
    T = np.zeros((N, J, 6, 6))
    T[:, :, :3, :3] = np.eye(3)
    T[:, :, 3:, 3:] = length * np.eye(3)
    c = centres
    T[:, :, 3, 1], T[:, :, 3, 2] = -c[..., 2], c[..., 1]
    T[:, :, 4, 0], T[:, :, 4, 2] = c[..., 2], -c[..., 0]
    T[:, :, 5, 0], T[:, :, 5, 1] = -c[..., 1], c[..., 0]
    rows = np.ones(6)
    rows[3:] = 1.0 / length  # moment rows in force units
    for j, joint in enumerate(mech.joints):
        a, b = joint.bodies
        for body, sign in ((b, 1.0), (a, -1.0)):
            if body != GROUND:
                k = index[body]
                A[:, 6 * k:6 * k + 6, 6 * j:6 * j + 6] = sign * rows[:, None] * T[:, j]
    for r, f in enumerate(passive):
        j = joint_of[f]
        S = screws[:, :, f]  # (ω; v): S·W = ω·m + v·f
        SW = np.concatenate([S[:, 3:], S[:, :3]], -1)
        scale = 1.0 / length if np.any(S[:, :3] != 0.0) else 1.0
        A[:, 6 * B + r, 6 * j:6 * j + 6] = scale * np.einsum("nk,nkl->nl", SW, T[:, j])
    return A


def solve_graph_statics(mech: Mechanism, screws: Array, centres: Array, loads: Array,
                        passive: list[int], inputs: list[int], joint_of: tuple[int, ...],
                        length: float) -> GraphStatics:
    """Joint wrenches and efforts (module docstring) from the body loads ``loads``
    (N, B, 6, K): applied wrenches about the world origin, one column per load case."""
    N, _, _, K = loads.shape
    J = len(mech.joints)
    A0 = _system(mech, screws[:1], centres[:1], passive, joint_of, length)[0]
    s0, vt0 = np.linalg.svd(A0)[1:]  # the first sample: is the system of full rank?
    rank = int(np.sum(s0 > RANK_RTOL * max(float(s0[0]), 1e-300)))
    fast = rank in A0.shape  # full row or column rank: LU
    args = (mech, screws, centres, loads, passive, joint_of, length)
    if rank == A0.shape[1]:  # full column rank (determinate): through the spanning tree
        wrench, res, size = tree_statics(mech, tree_cut(mech), screws, loads, passive,
                                         joint_of, length)
        rel = np.linalg.norm(res, axis=1) / size
        bad = ~np.all(np.isfinite(wrench), axis=(1, 2, 3)) | np.any(~(rel <= LU_RESIDUAL),
                                                                     axis=1)
        if bad.any():
            wrench[bad], res[bad], size[bad], _ = _dense(*args, np.nonzero(bad)[0], fast)
    else:
        wrench, res, size, ranks = _dense(*args, np.arange(N), fast)
        if not fast:
            rank = int(np.median(ranks))
    indeterminate = 6 * J - rank
    named = _null_joints(mech, vt0[rank:]) if indeterminate else []
    residual = np.linalg.norm(res, axis=1) / size
    efforts = np.empty((N, len(inputs), K))
    for k, f in enumerate(inputs):
        j = joint_of[f]
        S = screws[:, :, f]
        efforts[:, k] = (np.einsum("nk,nkl->nl", S[:, :3], wrench[:, j, 3:])
                         + np.einsum("nk,nkl->nl", S[:, 3:], wrench[:, j, :3]))
    return GraphStatics(wrench, efforts, residual, indeterminate, named, res, rank)


def _dense(mech: Mechanism, screws: Array, centres: Array, loads: Array, passive: list[int],
           joint_of: tuple[int, ...], length: float, samples: NDArray[np.intp], fast: bool
           ) -> tuple[Array, Array, Array, NDArray[np.intp]]:
    """The full system at ``samples``, built and solved a chunk at a time (LU when ``fast``,
    else the SVD): wrenches about the origin (n, J, 6, K), the residual A·y − rhs, the norm of
    rhs (n, K) and the rank of each sample's A (``fast``: its column count)."""
    n, K, B, J = len(samples), loads.shape[3], len(mech.bodies), len(mech.joints)
    rows = np.ones(6)
    rows[3:] = 1.0 / length
    y = np.empty((n, 6 * J, K))
    res = np.empty((n, 6 * B + len(passive), K))
    size = np.empty((n, K))
    ranks = np.full(n, 6 * J, dtype=np.intp)
    for a in range(0, n, CHUNK):  # a chunk's dense system stays in cache
        sl, at = slice(a, min(a + CHUNK, n)), samples[a:a + CHUNK]
        A = _system(mech, screws[at], centres[at], passive, joint_of, length)
        rhs = np.zeros((A.shape[0], A.shape[1], K))
        rhs[:, :6 * B] = -(loads[at] * rows[None, None, :, None]).reshape(-1, 6 * B, K)
        if fast:
            y[sl], res[sl] = _lu_solve(A, rhs)
        else:
            y[sl], ranks[sl] = _least_norm(A, rhs)
            res[sl] = A @ y[sl] - rhs
        size[sl] = np.linalg.norm(rhs, axis=1) + 1e-300
    wrench = y.reshape(n, J, 6, K).copy()  # back to W_j about the origin
    c = centres[samples]
    wrench[:, :, 3:] = length * wrench[:, :, 3:] + np.cross(c[:, :, None, :],
                                                               wrench[:, :, :3].swapaxes(2, 3)
                                                               ).swapaxes(2, 3)
    return wrench, res, size, ranks


def _least_norm(A: Array, rhs: Array) -> tuple[Array, NDArray[np.intp]]:
    """Per sample, the least-squares solution of least norm of A·y = rhs (singular values
    below ``RANK_RTOL`` of the largest dropped), and the rank of each A."""
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    keep = s > RANK_RTOL * np.maximum(s[:, :1], 1e-300)
    inv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    # y = V·diag(1/s)·Uᵀ·rhs as two batched products (one einsum over all five indices costs
    # O(J²·R·K) per sample, which the regressor's K = 10·B right-hand sides make slow)
    y = np.swapaxes(Vt, 1, 2) @ (inv[..., None] * (np.swapaxes(U, 1, 2) @ rhs))
    return y, keep.sum(axis=1)


#: a square system whose LU solution leaves more than this residual (relative to the loads) at
#: a sample is solved there again by the SVD (a sample next to a singular configuration)
LU_RESIDUAL = 1e-10


def _lu_solve(A: Array, rhs: Array) -> tuple[Array, Array]:
    """The least-norm least-squares solution of A·y = rhs for A of full row or column rank, by
    batched LU: of A itself when it is square (a statically determinate mechanism: every joint
    wrench fixed by the loads); of A·Aᵀ for full row rank (y = Aᵀz, in A's row space: the
    least-norm solution); of AᵀA for full column rank (the unique least-squares solution; more
    equations than unknowns where a rod's idle spin makes one depend on the others). The same
    solution as :func:`_least_norm` at a fraction of the cost (about 25× for the Stewart
    platform's 108 × 108 system, 8× for a four-bar); a sample where LU fails or leaves a
    residual above ``LU_RESIDUAL`` (next to a singular configuration, or loads along an idle
    freedom; the residual bounds y's error by 1/σ_min) is solved by the SVD. Returns y and
    A·y − rhs."""
    R, C = A.shape[1:]
    At = np.swapaxes(A, 1, 2)
    try:
        if R == C:
            y = np.linalg.solve(A, rhs)
        elif C > R:
            y = At @ np.linalg.solve(A @ At, rhs)
        else:
            y = np.linalg.solve(At @ A, At @ rhs)
        bad = ~np.all(np.isfinite(y), axis=(1, 2))
    except np.linalg.LinAlgError:  # a singular sample: solve each one
        y = np.zeros((A.shape[0], C, rhs.shape[2]))
        bad = np.ones(A.shape[0], dtype=bool)
    y[bad] = 0.0
    res = A @ y - rhs
    rel = np.linalg.norm(res, axis=1) / (np.linalg.norm(rhs, axis=1) + 1e-300)
    bad |= np.any(rel > LU_RESIDUAL, axis=1)
    if bad.any():
        y[bad] = _least_norm(A[bad], rhs[bad])[0]
        res[bad] = A[bad] @ y[bad] - rhs[bad]
    return np.asarray(y, dtype=np.float64), np.asarray(res, dtype=np.float64)


def _null_joints(mech: Mechanism, null: Array) -> list[str]:
    """The joints the self-stress directions load (largest components first)."""
    weight = np.abs(null).reshape(null.shape[0], len(mech.joints), 6).max(axis=(0, 2))
    order = np.argsort(-weight)
    return [mech.joints[j].name for j in order if weight[j] > 1e-6 * weight.max()]
