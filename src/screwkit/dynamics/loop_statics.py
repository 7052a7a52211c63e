"""Joint wrenches of a single closed loop from the loads on its links (batched linear solve).

Unknowns: the wrench W_j = (f_j; m_j) (moment about a reference point r) exerted through joint j
by its proximal link on its distal link, j = 0 … n−1 (link −1 and link n−1 are the ground), and
the effort τ_k of every driven freedom.

Equations (Newton–Euler for every moving link l = 0 … n−2, with B_l the applied inertia, weight
and external wrench on link l):

    W_l − W_{l+1} + B_l = 0                              (6 per moving link)
    S_k · W_{j(k)} = τ_k  (driven),  0  (passive)          (1 per freedom k of joint j(k))

where S·W = ω·m + v·f is the reciprocal product of a unit freedom screw with the wrench (Ball's
virtual power; Bagci 1969 §3.4 uses the same "zero work along the free directions" for his joint
reactions). The link balances give W_j = W_0 + C_j with C_j = Σ_{l<j} B_l, so the whole
system reduces to the freedoms of the loop acting on the one unknown wrench W_0:

    S_k · W_0 = −S_k · C_{j(k)}        (passive k),     τ_k = S_k · (W_0 + C_{j(k)})  (driven k).

The passive matrix A = [S_k]ᵀ (m_p × 6, made unit-consistent with the length scale ℓ: moments
divided by ℓ) has a generic rank r over a mode:

* 6 − r > 0 components of W_0 are statically indeterminate (a planar 4R treated as a spatial
  loop has 3: the force normal to the plane and the two in-plane moments, a self-stress the
  rigid joints can carry without any load). screwkit returns the solution that minimises
  Σ_j |f_j|² + |m_j / ℓ|² over all joints (moments about the joint centres) — a choice
  independent of where the loop is cut and of the reference point — and reports 6 − r;
* m_p − r > 0 passive freedoms are idle (e.g. the spin of an S–S rod about its own axis): their
  equations are consistent only when the link loads do no work along the idle motion. The
  least-squares solution is returned and the unbalanced generalised force is the residual.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dynamics.screws import Array, FreedomScrews

RANK_RTOL = 1e-8  # relative singular-value threshold for the generic rank of the statics


@dataclass(frozen=True)
class LoopStatics:
    """Solved joint wrenches, batch-first, with a trailing load axis K (one column per load
    case: K = 1 for a direct solve, K = 10·L for the regressor).

    ``wrenches`` (N, n, 6, K): W_j, proximal on distal, moment about the reference point;
    ``efforts`` (N, n_driven, K); ``residual`` (N, m_p, K): unbalanced generalised force along
    the passive freedoms (N, moments divided by ℓ).
    """

    wrenches: Array
    efforts: Array
    residual: Array


@dataclass(frozen=True)
class StaticsStructure:
    """What the joints of a loop can and cannot determine (generic over the mode)."""

    rank: int
    passive_count: int
    indeterminate_count: int  # 6 − rank
    idle_count: int  # m_p − rank
    indeterminate_directions: Array  # (6 − r, 6) unit wrenches (f; m about the reference)


def _scaled_passive_matrix(
    fs: FreedomScrews, length: float
) -> tuple[Array, Array, NDArray[np.intp]]:
    """A (N, m_p, 6) with A y = S·W for W = (f; ℓ y_m), the row scales and the passive index."""
    passive = np.array([not d for d in fs.driven])
    rot = np.array(fs.is_rotation)
    row_scale = np.where(rot, 1.0 / length, 1.0)
    # swap (ω; v) → (v; ω) so that S·W is a plain dot product with W = (f; m)
    swapped = np.concatenate([fs.screws[..., 3:], fs.screws[..., :3]], -1)
    col_scale = np.array([1.0, 1.0, 1.0, length, length, length])
    A = swapped[:, passive] * row_scale[passive][None, :, None] * col_scale
    return A, row_scale, np.nonzero(passive)[0]


def statics_structure(fs: FreedomScrews, length: float, samples: int = 32) -> StaticsStructure:
    """Generic rank of the passive statics over (up to ``samples`` of) the given samples."""
    N = fs.screws.shape[0]
    take = np.unique(np.linspace(0, N - 1, min(samples, N)).astype(int))
    sub = FreedomScrews(fs.screws[take], fs.names, fs.joint_of, fs.is_rotation, fs.driven,
                        fs.reference)
    A, _, pidx = _scaled_passive_matrix(sub, length)
    _, sv, vt = np.linalg.svd(A)
    big = sv[:, :1] if sv.shape[1] else np.ones((A.shape[0], 1))
    ranks = np.sum(sv > RANK_RTOL * big, axis=-1)
    rank = int(np.max(ranks)) if len(ranks) else 0
    first = int(np.argmax(ranks == rank))
    null = vt[first, rank:]  # rows: scaled null directions of A
    null = null * np.array([1.0, 1.0, 1.0, length, length, length])
    null /= np.linalg.norm(null, axis=-1, keepdims=True)
    return StaticsStructure(
        rank=rank,
        passive_count=len(pidx),
        indeterminate_count=6 - rank,
        idle_count=len(pidx) - rank,
        indeterminate_directions=null,
    )


def _joint_metric(centres: Array, length: float) -> Array:
    """E_j (N, n, 6, 6): (f; m_ref/ℓ) ↦ (f; m_centre/ℓ), m_centre = m_ref − d_j × f."""
    d = centres / length
    N, n, _ = d.shape
    E = np.zeros((N, n, 6, 6))
    E[..., :3, :3] = np.eye(3)
    E[..., 3:, 3:] = np.eye(3)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    # −[d]× as a block acting on f
    E[..., 3, 1], E[..., 3, 2] = z, -y
    E[..., 4, 0], E[..., 4, 2] = -z, x
    E[..., 5, 0], E[..., 5, 1] = y, -x
    return E


def solve_loop_statics(
    fs: FreedomScrews,
    centres: Array,
    link_wrenches: Array,
    length: float,
    structure: StaticsStructure,
) -> LoopStatics:
    """Joint wrenches and efforts for link loads ``link_wrenches`` (N, L, 6, K) about the
    reference point of ``fs``; ``centres`` (N, n, 3) joint centres relative to it (module
    docstring for the equations and the indeterminate/idle rules)."""
    N, L, _, K = link_wrenches.shape
    n = L + 1
    cumulative = np.zeros((N, n, 6, K))
    np.cumsum(link_wrenches, axis=1, out=cumulative[:, 1:])
    A, row_scale, pidx = _scaled_passive_matrix(fs, length)
    col_scale = np.array([1.0, 1.0, 1.0, length, length, length])
    swapped = np.concatenate([fs.screws[..., 3:], fs.screws[..., :3]], -1)  # (N, m, 6)
    joint_of = np.array(fs.joint_of)
    # S_k · C_{j(k)} for every freedom: (N, m, K)
    on_cut = np.einsum("nmi,nmik->nmk", swapped, cumulative[:, joint_of])
    b = -(on_cut[:, pidx] * row_scale[pidx][None, :, None])  # (N, m_p, K)
    r = structure.rank
    At = np.swapaxes(A, -1, -2)
    if r == 6 and len(pidx) == 6:
        y = np.linalg.solve(A, b)
    elif r == 6:
        y = np.linalg.solve(At @ A, At @ b)
    else:
        E = _joint_metric(centres, length)
        EtE = np.swapaxes(E, -1, -2) @ E  # (N, n, 6, 6)
        G = EtE.sum(axis=1)
        z = cumulative / col_scale[:, None]  # (N, n, 6, K): C_j in scaled units
        g = np.einsum("njab,njbk->nak", EtE, z)
        Gi_rhs = np.linalg.solve(G, np.concatenate([At, g], -1))
        Gi_At, Gi_g = Gi_rhs[..., : len(pidx)], Gi_rhs[..., len(pidx):]
        rhs = b + A @ Gi_g
        if r == len(pidx):
            lam = np.linalg.solve(A @ Gi_At, rhs)
            y = Gi_At @ lam - Gi_g
        else:
            chol = np.linalg.cholesky(G)
            M = np.swapaxes(np.linalg.solve(chol, At), -1, -2)  # A L^{-T}
            x = np.linalg.pinv(M, rcond=1e-8) @ rhs
            y = np.linalg.solve(np.swapaxes(chol, -1, -2), x) - Gi_g
    residual = A @ y - b
    w0 = y * col_scale[:, None]
    wrenches = cumulative + w0[:, None]
    driven = [k for k, d in enumerate(fs.driven) if d]
    efforts = np.einsum(
        "nmi,nmik->nmk", swapped[:, driven], wrenches[:, joint_of[driven]]
    )
    return LoopStatics(wrenches=wrenches, efforts=efforts, residual=residual)
