"""Every joint's motion M_j(q) at once, and the spanning tree's body poses by levels: the
table-driven form of :func:`.closure.graph_forward`'s per-joint loop (model/mechanism.py's
product of exponentials, T_child = T_parent · M_j(q)^{±1}).

A graph's tracker, fold searches and every-mode decoding evaluate the closure at one or a few
samples thousands of times, where a loop over joints spends its time in numpy's per-call
overhead, not in arithmetic (a 3-UPU: 0.47 ms per evaluation at one sample, flat up to 40).
Here the joints' constants are laid out once per mechanism as arrays (:class:`MotionTable`),
every joint's rotation is one Rodrigues formula over all joints (the U joints' second
rotation one more product), and the tree is composed level by level: the edges whose parents
are placed are one stacked product. Each joint's arithmetic is :func:`.closure.axis_rotation`'s
and the per-joint form's (the same products and sums, element by element).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

if TYPE_CHECKING:
    from screwkit.kinematics.graph.closure import GraphLayout

Array = NDArray[np.float64]
Index = NDArray[np.intp]


@dataclass(frozen=True)
class MotionTable:
    """Per joint of a mechanism (J joints), as arrays.

    ``K``/``K2`` are [u]× and u uᵀ − I of the first axis, ``L``/``L2`` of a U joint's second
    axis; ``angle``, ``angle2`` and ``slide`` are columns of the scalars padded with one zero
    column (index ``n_scalar``: a joint without that freedom), ``gain`` the slide per unit of
    its column (1 for P and C, the pitch for H). ``levels`` holds the tree, level by level:
    (tree joints, parent body, child body, whether the tree runs against the joint)."""

    at: Array
    axis: Array
    K: Array
    K2: Array
    L: Array
    L2: Array
    angle: Index
    angle2: Index
    slide: Index
    gain: Array
    prismatic: Index
    universal: Index
    balls: Index
    ball_index: Index
    seated: Index
    seat: Array
    levels: tuple[tuple[Index, Index, Index, NDArray[np.bool_]], ...]


def _skew(u: Array) -> Array:
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


def motion_table(mech: Mechanism, lay: GraphLayout) -> MotionTable:
    """:class:`MotionTable` of ``mech`` with the layout ``lay``."""
    joints = mech.joints
    J = len(joints)
    pad, col, first = lay.n_scalar, lay.scalar_col, lay.first_freedom
    angle = np.full(J, pad, dtype=np.intp)
    angle2 = np.full(J, pad, dtype=np.intp)
    slide = np.full(J, pad, dtype=np.intp)
    gain = np.zeros(J)
    second = []
    for i, j in enumerate(joints):
        f0 = first[i]
        if j.kind in "RCHU":
            angle[i] = col[f0]
        if j.kind == "U":
            angle2[i] = col[f0 + 1]
        if j.kind in "PH":
            slide[i], gain[i] = col[f0], (1.0 if j.kind == "P" else j.pitch)
        elif j.kind == "C":
            slide[i], gain[i] = col[f0 + 1], 1.0
        second.append(j.axis2 if j.kind == "U" and j.axis2 is not None else j.axis)
    axis = np.array([j.axis for j in joints], dtype=float).reshape(J, 3)
    sec = np.array(second, dtype=float).reshape(J, 3)
    K = np.array([_skew(u) for u in axis]).reshape(J, 3, 3)
    L = np.array([_skew(u) for u in sec]).reshape(J, 3, 3)
    K2 = np.einsum("ji,jk->jik", axis, axis) - np.eye(3)
    L2 = np.einsum("ji,jk->jik", sec, sec) - np.eye(3)
    kinds = [j.kind for j in joints]
    balls = [i for i, k in enumerate(kinds) if k == "S"]
    seated = [i for i, j in enumerate(joints) if j.seat_offset is not None]
    return MotionTable(
        np.array([j.at for j in joints], dtype=float).reshape(J, 3), axis, K, K2, L, L2,
        angle, angle2, slide, gain,
        np.array([i for i, k in enumerate(kinds) if k == "P"], dtype=np.intp),
        np.array([i for i, k in enumerate(kinds) if k == "U"], dtype=np.intp),
        np.array(balls, dtype=np.intp),
        np.array([lay.spherical_of_joint[i] for i in balls], dtype=np.intp),
        np.array(seated, dtype=np.intp),
        np.array([joints[i].seat_offset for i in seated], dtype=float).reshape(-1, 3),
        _levels(mech, lay))


def _levels(mech: Mechanism, lay: GraphLayout
            ) -> tuple[tuple[Index, Index, Index, NDArray[np.bool_]], ...]:
    """The tree's edges grouped by the depth of their child (every parent placed by an earlier
    level), each group as (joints, parent bodies, child bodies, against the joint)."""
    body_of = lay.body_of
    depth = {GROUND: 0}
    groups: dict[int, list[tuple[int, int, int, bool]]] = {}
    for k, parent, child in mech.topology.tree:
        depth[child] = depth[parent] + 1
        groups.setdefault(depth[child], []).append(
            (k, body_of[parent], body_of[child], mech.joints[k].bodies[0] != parent))
    out = []
    for d in sorted(groups):
        cols = list(zip(*groups[d], strict=True))
        out.append((np.array(cols[0], dtype=np.intp), np.array(cols[1], dtype=np.intp),
                    np.array(cols[2], dtype=np.intp), np.array(cols[3], dtype=bool)))
    return tuple(out)


def rotate(R: Array, v: Array) -> Array:
    """R v for stacks of 3 × 3 matrices R (..., 3, 3) and vectors v (..., 3) broadcast
    against them, by columns (R's columns times v's entries, summed): a few array
    operations whatever the stack, where numpy's matmul calls BLAS once per small matrix."""
    return np.asarray(R[..., :, 0] * v[..., 0, None] + R[..., :, 1] * v[..., 1, None]
                      + R[..., :, 2] * v[..., 2, None])


def _rodrigues(s: Array, c: Array, K: Array, K2: Array) -> Array:
    """I + sin θ K + (1 − cos θ) K² for every sample and joint (N, J, 3, 3), in
    :func:`.closure.axis_rotation`'s order of operations."""
    out = s[..., None, None] * K
    out += (1.0 - c)[..., None, None] * K2
    out += np.eye(3)
    return out


def joint_motions(t: MotionTable, conf: Configuration, joints: Index | None = None
                  ) -> tuple[Array, Array]:
    """M_j(q) of every joint (R (N, J, 3, 3), p (N, J, 3)) in drawn world coordinates (times
    Trans(seat_offset) for a joint made off its drawing), or of the joints ``joints`` only
    (in that order; each joint's the same arithmetic): a rotation about the joint's axis
    through its point (R, C, H; a U's two in turn; an S's own rotation), p = c − R c, plus the
    slide along the axis (P, C, H); a P joint's R = I and p its slide alone."""
    if joints is not None:
        t = _subset(t, np.asarray(joints, dtype=np.intp))
    N = conf.size
    q = np.concatenate([conf.scalars, np.zeros((N, 1))], axis=1)
    th = q[:, t.angle]
    R = _rodrigues(np.sin(th), np.cos(th), t.K, t.K2)
    if t.universal.size:
        th2 = q[:, t.angle2[t.universal]]
        R[:, t.universal] = R[:, t.universal] @ _rodrigues(np.sin(th2), np.cos(th2),
                                                           t.L[t.universal], t.L2[t.universal])
    if t.balls.size:
        R[:, t.balls] = conf.spherical[:, t.ball_index]
    if t.prismatic.size:
        R[:, t.prismatic] = np.eye(3)
    p = t.at - rotate(R, t.at)
    p += (q[:, t.slide] * t.gain)[..., None] * t.axis
    if t.prismatic.size:  # c − I c is 0: the slide alone
        p[:, t.prismatic] = (q[:, t.slide[t.prismatic]])[..., None] * t.axis[t.prismatic]
    if t.seated.size:  # M_j(q) · Trans(δ): the second body's seat is off by δ
        p[:, t.seated] += rotate(R[:, t.seated], t.seat)
    return R, p


def _subset(t: MotionTable, joints: Index) -> MotionTable:
    """The table of the joints ``joints`` alone (their rows, renumbered in that order)."""
    where = np.full(len(t.at), -1, dtype=np.intp)
    where[joints] = np.arange(len(joints))

    def renumbered(idx: Index, rows: Array | Index | None = None
                   ) -> tuple[Index, Array | Index | None]:
        keep = where[idx] >= 0
        return where[idx][keep], (None if rows is None else rows[keep])

    universal, _ = renumbered(t.universal)
    balls, ball_index = renumbered(t.balls, t.ball_index)
    prismatic, _ = renumbered(t.prismatic)
    seated, seat = renumbered(t.seated, t.seat)
    return MotionTable(t.at[joints], t.axis[joints], t.K[joints], t.K2[joints], t.L[joints],
                       t.L2[joints], t.angle[joints], t.angle2[joints], t.slide[joints],
                       t.gain[joints], prismatic, universal, balls,
                       np.asarray(ball_index, dtype=np.intp), seated,
                       np.asarray(seat, dtype=float).reshape(-1, 3), ())


def tree_poses(t: MotionTable, Mr: Array, Mp: Array, bodies: int, ground: int
               ) -> tuple[Array, Array]:
    """Every body's pose (R (N, B, 3, 3), p (N, B, 3); ``bodies`` B with the ground, at index
    ``ground``) along the spanning tree, one level of edges at a time: T_child = T_parent · M
    (M⁻¹ = (Rᵀ, −Rᵀp) where the tree runs against the joint)."""
    N = Mr.shape[0]
    R = np.empty((N, bodies, 3, 3))
    p = np.empty((N, bodies, 3))
    R[:, ground] = np.eye(3)
    p[:, ground] = 0.0
    for k, a, b, rev in t.levels:
        Rk, pk = Mr[:, k], Mp[:, k]
        if rev.any():
            Rk[:, rev] = np.swapaxes(Rk[:, rev], -1, -2)
            pk[:, rev] = -rotate(Rk[:, rev], pk[:, rev])
        Ra = R[:, a]
        R[:, b] = Ra @ Rk
        p[:, b] = rotate(Ra, pk) + p[:, a]
    return R, p
