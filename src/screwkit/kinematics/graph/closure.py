"""The stacked loop closure of a :class:`~screwkit.model.mechanism.Mechanism`, batched over samples.

Body poses come from the spanning tree by the product of exponentials (model/mechanism.py):
T_child = T_parent · M_j(q_j)^{±1}. Each chord j between bodies a and b closes one loop; its
closure is E_j = T_a · M_j(q_j) · T_b⁻¹ = I, and the exact SE(3) logarithm of E_j is the loop's
residual twist (world frame). Its derivative is Σ sign·S_f q̇_f round the loop, with S_f the unit
screw of freedom f in the world (Bagci 1969 eqs. 3.19–3.26 generalised to a loop basis): the rows
of the stacked screw Jacobian, six per loop.

Screws are 6-vectors (ω; v), v the velocity of the point at the world origin (as
kinematics/tracker/loop.py). A configuration is a :class:`~screwkit.kinematics.tracker.loop.Configuration`:
scalar freedoms in joint order and one rotation per spherical joint (body increments).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import MATVEC_FROM, cross, matvec
from screwkit.kinematics.graph.joint_motions import (
    MotionTable,
    joint_motions,
    motion_table,
    rotate,
    tree_poses,
)
from screwkit.kinematics.tracker.loop import (
    Configuration,
    closure_error,
    closure_twist,
    freedom_columns,
    lie_bracket,
)
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True)
class GraphLayout:
    """Where each freedom lives in a configuration and in the Jacobian, and the constants the
    hot paths need (joint points and axes as arrays, the loops as signed joint lists)."""

    names: tuple[str, ...]
    joint_of: tuple[int, ...]
    scalar_col: tuple[int, ...]  # column in Configuration.scalars, -1 for S freedoms
    first_freedom: tuple[int, ...]  # per joint: index of its first freedom
    spherical_of_joint: dict[int, int]
    is_translation: tuple[bool, ...]
    n_scalar: int
    n_spherical: int
    inputs: tuple[int, ...]  # freedom indices of the inputs, in input order
    passive: tuple[int, ...]
    body_of: dict[str, int]  # body name -> index into pose arrays (ground last)
    length: float

    @property
    def m(self) -> int:
        return len(self.names)


def graph_layout(mech: Mechanism) -> GraphLayout:
    fc = freedom_columns(mech.joints)
    inputs = tuple(fc.names.index(x) for x in mech.inputs)
    passive = tuple(k for k in range(len(fc.names)) if k not in inputs)
    body_of = {b: k for k, b in enumerate(mech.body_names)}
    body_of[GROUND] = len(mech.bodies)
    return GraphLayout(fc.names, fc.joint_of, fc.scalar_col, fc.first, fc.spherical_of_joint,
                       fc.is_translation, fc.n_scalar, len(fc.spherical_of_joint), inputs,
                       passive, body_of, mech.length_scale)


def zero_configuration(lay: GraphLayout, count: int = 1) -> Configuration:
    """The drawn configuration (every freedom 0), ``count`` times."""
    return Configuration(np.zeros((count, lay.n_scalar)),
                         np.broadcast_to(np.eye(3), (count, lay.n_spherical, 3, 3)).copy())


def axis_rotation(u: Array, th: Array) -> Array:
    """Rotations (N, 3, 3) by angles θ (N,) about the fixed unit axis u (Rodrigues:
    I + sin θ K + (1 − cos θ) K², K = [u]×, K² = u uᵀ − I)."""
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    K2 = np.outer(u, u) - np.eye(3)
    s, c = np.sin(th), np.cos(th)
    out = np.multiply.outer(s, K)
    out += np.multiply.outer(1.0 - c, K2)
    out += np.eye(3)
    return out


def joint_motion(mech: Mechanism, lay: GraphLayout, conf: Configuration, i: int
                 ) -> tuple[Array, Array]:
    """M_j(q) (R (N, 3, 3), p (N, 3)) of joint ``i`` in drawn world coordinates (times
    Trans(seat_offset) for a joint made off its drawing, model/mechanism.py): joint ``i``'s
    part of :func:`.joint_motions.joint_motions` (the same arithmetic as every joint's at
    once), computed for that joint alone."""
    R, p = joint_motions(joint_table(mech, lay).motion, conf, np.array([i], dtype=np.intp))
    return R[:, 0], p[:, 0]


@dataclass(frozen=True)
class GraphFrames:
    """Body poses (N, B+1, …; the ground last), the unit screws of every freedom in the world
    (N, 6, m), the loop residual twists (N, L, 6) and joint centres and axes (N, J, 3)."""

    R: Array
    p: Array
    screws: Array
    residual: Array
    centres: Array
    axes: Array


def graph_forward(mech: Mechanism, lay: GraphLayout, conf: Configuration, exact: bool = True
                  ) -> GraphFrames:
    """Body poses along the spanning tree, every freedom's world screw and every loop's
    closure twist (module docstring): the exact logarithm, or with ``exact=False`` its
    first-order form (loop.closure_error: the same zero and the same derivative there, for a
    corrector that starts close)."""
    t = joint_table(mech, lay).motion
    Mr, Mp = joint_motions(t, conf)
    R, p = tree_poses(t, Mr, Mp, len(mech.bodies) + 1, lay.body_of[GROUND])
    residual = loop_residuals(mech, lay, conf, R, p, exact, (Mr, Mp))
    screws, centres, axes = joint_screws(mech, lay, R, p)
    return GraphFrames(R, p, screws, residual, centres, axes)


def loop_residuals(mech: Mechanism, lay: GraphLayout, conf: Configuration, R: Array, p: Array,
                   exact: bool = True, motions: tuple[Array, Array] | None = None) -> Array:
    """Every loop's closure twist (N, L, 6) from the body poses: E_j = T_a M_j T_b⁻¹ at each
    chord j, by the exact logarithm or its first-order form (:func:`graph_forward`);
    ``motions``: every joint's M_j(q) at ``conf`` where already known
    (:func:`.joint_motions.joint_motions`)."""
    chords = list(mech.topology.chords)
    N, L = conf.size, len(chords)
    if L == 0:
        return np.empty((N, 0, 6))
    if motions is None:  # the chords' alone
        Mr, Mp = joint_motions(joint_table(mech, lay).motion, conf,
                               np.array(chords, dtype=np.intp))
    else:
        Mr, Mp = motions[0][:, chords], motions[1][:, chords]
    a = [lay.body_of[mech.joints[k].bodies[0]] for k in chords]
    b = [lay.body_of[mech.joints[k].bodies[1]] for k in chords]
    # every chord at once: per chord the same products as one chord at a time (bit for bit,
    # tests/kinematics/test_tracker_batched_balls.py)
    Ra = R[:, a] @ Mr
    pa = np.einsum("nlij,nlj->nli", R[:, a], Mp) + p[:, a]
    ER = Ra @ np.swapaxes(R[:, b], -1, -2)
    Ep = pa - np.einsum("nlij,nlj->nli", ER, p[:, b])
    return closure_twist(ER, Ep) if exact else closure_error(ER, Ep)


def joint_screws(mech: Mechanism, lay: GraphLayout, R: Array, p: Array
            ) -> tuple[Array, Array, Array]:
    """World screws of every freedom (N, 6, m), joint centres and first axes (N, J, 3)."""
    N = R.shape[0]
    S = np.empty((N, 6, lay.m))
    J = len(mech.joints)
    t = joint_table(mech, lay)
    if N < MATVEC_FROM:  # matvec's R @ x for every joint in one stacked product (bit for bit)
        Ra = R[:, t.first]
        centres = (Ra @ t.at[:, :, None])[..., 0] + p[:, t.first]
        axes = (Ra @ t.axis[:, :, None])[..., 0]
    else:  # matvec's one BLAS call per joint
        centres = np.empty((N, J, 3))
        axes = np.empty((N, J, 3))
        for i, j in enumerate(mech.joints):
            a = t.first[i]
            centres[:, i] = matvec(R[:, a], j.at) + p[:, a]
            axes[:, i] = matvec(R[:, a], j.axis)
    k = t.kinds
    if k.line.size:  # R, H, C and a U's first freedom: the line screw (u; c × u + pitch·u)
        u = axes[:, k.line]
        moment = cross(centres[:, k.line], u)
        if k.helical.size:
            moment[:, k.helical] += k.pitch[:, None] * u[:, k.helical]
        S[:, :3, k.line_col] = u.transpose(0, 2, 1)
        S[:, 3:, k.line_col] = moment.transpose(0, 2, 1)
    if k.slide.size:  # P and a C's second freedom: the free vector (0; u)
        S[:, :3, k.slide_col] = 0.0
        S[:, 3:, k.slide_col] = axes[:, k.slide].transpose(0, 2, 1)
    if k.second.size:  # a U's second axis, fixed in its second body
        u2 = rotate(R[:, k.second_body], k.axis2)
        S[:, :3, k.second_col] = u2.transpose(0, 2, 1)
        S[:, 3:, k.second_col] = cross(centres[:, k.second], u2).transpose(0, 2, 1)
    if t.balls.size:  # S: body increments about the child's own axes through the centre
        out = np.empty((N, t.balls.size, 6, 3))
        _put_ball_screws(out, R[:, t.ball_child], centres[:, t.balls])
        S[:, :, t.ball_cols] = out.transpose(0, 2, 1, 3)
    return S, centres, axes


@dataclass(frozen=True)
class JointTable:
    """Per joint of a mechanism, as arrays: its first body's pose index, drawn centre and axis;
    the ball joints, their second bodies and their freedom columns (n_balls, 3)."""

    first: NDArray[np.intp]
    at: Array
    axis: Array
    balls: NDArray[np.intp]
    ball_child: NDArray[np.intp]
    ball_cols: NDArray[np.intp]
    loop_signs: Array
    motion: MotionTable
    kinds: ScrewColumns


@dataclass(frozen=True)
class ScrewColumns:
    """Which joints' freedoms are line screws (R, H, C, a U's first axis: joints ``line``,
    columns ``line_col``; the H joints among them at ``helical`` with their ``pitch``), free
    vectors (P, a C's slide: ``slide``, ``slide_col``) and a U's second axis (``second``, its
    column, its second body and its drawn axis2)."""

    line: NDArray[np.intp]
    line_col: NDArray[np.intp]
    helical: NDArray[np.intp]
    pitch: Array
    slide: NDArray[np.intp]
    slide_col: NDArray[np.intp]
    second: NDArray[np.intp]
    second_col: NDArray[np.intp]
    second_body: NDArray[np.intp]
    axis2: Array


def _screw_columns(mech: Mechanism, lay: GraphLayout) -> ScrewColumns:
    joints, first = mech.joints, lay.first_freedom
    line = [i for i, j in enumerate(joints) if j.kind in "RHCU"]
    helical = [n for n, i in enumerate(line) if joints[i].kind == "H"]
    slide = [i for i, j in enumerate(joints) if j.kind in "PC"]
    second = [i for i, j in enumerate(joints) if j.kind == "U"]

    def ints(v: list[int]) -> NDArray[np.intp]:
        return np.array(v, dtype=np.intp)

    return ScrewColumns(
        ints(line), ints([first[i] for i in line]), ints(helical),
        np.array([joints[line[n]].pitch for n in helical], dtype=float),
        ints(slide), ints([first[i] + (joints[i].kind == "C") for i in slide]),
        ints(second), ints([first[i] + 1 for i in second]),
        ints([lay.body_of[joints[i].bodies[1]] for i in second]),
        np.array([joints[i].axis2 for i in second], dtype=float).reshape(-1, 3))


_TABLES: dict[tuple[int, int], tuple[Mechanism, GraphLayout, JointTable]] = {}


def joint_table(mech: Mechanism, lay: GraphLayout) -> JointTable:
    """The :class:`JointTable` of ``mech`` (the last few kept, as graph/follow.py's systems)."""
    key = (id(mech), id(lay))
    if key not in _TABLES:
        if len(_TABLES) >= 8:
            _TABLES.pop(next(iter(_TABLES)))
        balls = [i for i, j in enumerate(mech.joints) if j.kind == "S"]
        table = JointTable(
            np.array([lay.body_of[j.bodies[0]] for j in mech.joints], dtype=np.intp),
            np.array([j.at for j in mech.joints], dtype=float).reshape(-1, 3),
            np.array([j.axis for j in mech.joints], dtype=float).reshape(-1, 3),
            np.array(balls, dtype=np.intp),
            np.array([lay.body_of[mech.joints[i].bodies[1]] for i in balls], dtype=np.intp),
            np.array([[lay.first_freedom[i] + k for k in range(3)] for i in balls],
                     dtype=np.intp).reshape(-1, 3), _loop_signs(mech, lay),
            motion_table(mech, lay), _screw_columns(mech, lay))
        _TABLES[key] = (mech, lay, table)
    return _TABLES[key][2]


def _loop_signs(mech: Mechanism, lay: GraphLayout) -> Array:
    """(6L, m): the sign of each freedom in each loop's six rows of the stacked Jacobian (0
    where the loop does not hold it)."""
    signs = np.zeros((6 * len(mech.topology.loops), lay.m))
    for l, loop in enumerate(mech.topology.loops):
        for k, sign in loop:
            f0 = lay.first_freedom[k]
            signs[6 * l:6 * l + 6, f0:f0 + len(mech.joints[k].freedoms)] = sign
    return signs


def _put_ball_screws(out: Array, Rb: Array, c: Array) -> None:
    """The three line screws (u_k; c × u_k) of a ball's freedoms, u_k the columns of Rb
    (..., 3, 3), into ``out`` (..., 6, 3): :func:`joint_screws`' line screw for k = 0, 1, 2 at once, the same
    products and differences as ``cross`` (bit for bit), without a call per column."""
    out[..., :3, :] = Rb
    c0, c1, c2 = c[..., 0, None], c[..., 1, None], c[..., 2, None]
    out[..., 3, :] = c1 * Rb[..., 2, :] - c2 * Rb[..., 1, :]
    out[..., 4, :] = c2 * Rb[..., 0, :] - c0 * Rb[..., 2, :]
    out[..., 5, :] = c0 * Rb[..., 1, :] - c1 * Rb[..., 0, :]


def loop_jacobian(mech: Mechanism, lay: GraphLayout, screws: Array) -> Array:
    """The stacked loop-closure Jacobian (N, 6L, m): rows 6l…6l+5 hold sign·S_f for every
    freedom f of a joint of loop l (module docstring)."""
    signs = joint_table(mech, lay).loop_signs  # (6L, m): ±1 where a loop holds the freedom
    rows = screws[:, np.arange(signs.shape[0]) % 6]
    Jac = np.zeros((screws.shape[0],) + signs.shape)  # C order, as the solvers had it
    np.multiply(signs, rows, out=Jac, where=signs != 0.0)
    return Jac


def body_twists(mech: Mechanism, lay: GraphLayout, screws: Array, qd: Array
                ) -> tuple[Array, Array]:
    """World twists V (N, B+1, 6) of every body for freedom rates ``qd`` (N, m), and the
    velocity-product part of every joint's relative acceleration, bias_j (N, J, 6):
    A_second − A_first = Σ S q̈ + bias_j with bias_j = [V_first, Σ S q̇] (+ [S₁θ̇₁, S₂θ̇₂] for a U),
    since a screw fixed in a body moving with twist V changes at the rate [V, S]."""
    N = qd.shape[0]
    V = np.zeros((N, len(mech.bodies) + 1, 6))
    rel = np.empty((N, len(mech.joints), 6))
    for i, j in enumerate(mech.joints):
        f = lay.first_freedom[i]
        n = len(j.freedoms)
        rel[:, i] = np.einsum("nkf,nf->nk", screws[:, :, f:f + n], qd[:, f:f + n])
    for k, parent, child in mech.topology.tree:
        sign = 1.0 if mech.joints[k].bodies[0] == parent else -1.0
        V[:, lay.body_of[child]] = V[:, lay.body_of[parent]] + sign * rel[:, k]
    bias = lie_bracket(V[:, joint_table(mech, lay).first], rel)  # every joint at once
    for i, j in enumerate(mech.joints):
        if j.kind == "U":
            f = lay.first_freedom[i]
            bias[:, i] += lie_bracket(screws[:, :, f] * qd[:, f, None],
                                      screws[:, :, f + 1] * qd[:, f + 1, None])
    return V, bias


def loop_bias(mech: Mechanism, bias: Array) -> Array:
    """The velocity-product terms of the stacked closure's second derivative (N, 6L):
    J q̈ = −(this), from Σ sign·(S q̈ + bias_j) = 0 round each loop."""
    loops = mech.topology.loops
    out = np.zeros((bias.shape[0], 6 * len(loops)))
    for l, loop in enumerate(loops):
        for k, sign in loop:
            out[:, 6 * l:6 * l + 6] += sign * bias[:, k]
    return out


def body_accelerations(mech: Mechanism, lay: GraphLayout, screws: Array, qdd: Array,
                       bias: Array) -> Array:
    """World accelerations (N, B+1, 6): the time derivative of each body's world twist, along
    the tree A_child = A_parent ± (S q̈ + bias_j)."""
    N = qdd.shape[0]
    A = np.zeros((N, len(mech.bodies) + 1, 6))
    for k, parent, child in mech.topology.tree:
        j = mech.joints[k]
        f = lay.first_freedom[k]
        n = len(j.freedoms)
        rel = np.einsum("nkf,nf->nk", screws[:, :, f:f + n], qdd[:, f:f + n]) + bias[:, k]
        sign = 1.0 if j.bodies[0] == parent else -1.0
        A[:, lay.body_of[child]] = A[:, lay.body_of[parent]] + sign * rel
    return A
