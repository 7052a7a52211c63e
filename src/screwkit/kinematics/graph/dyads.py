"""Closed forms of the sub-chains of graph/subchains.py, every branch, batched over samples.

Every body moves in the plane normal to the dyad's n: its pose is a rotation about n and a
translation in the plane, found from the known world points of the placed bodies p1 and p2
(joint J1's centre A on p1, J2's centre C on p2; J3's centre B on the bodies of the dyad; a P
joint's slide direction u; subscript 0 for the drawing, ⟂ for the part in the plane):

- RRR, circle–circle: w = C − A, d = |w⟂|, a = (d² + r1² − r2²)/(2d), h² = r1² − a² (r1 = |B0 −
  A0|⟂, r2 = |B0 − C0|⟂); B = A + a ŵ + σ h (n × ŵ);
- RRP, circle–line: B on the line Q + t d (Q = p2's image of B0, d = p2's image of u), |B − A|⟂ =
  r1: t = −(Q − A)·d + σ √(r1² − |(Q − A)⟂ − ((Q − A)·d) d|²);
- RPR, the slide of a rotating slot: b2 = b1 moved by t u, so R_b1 (w0⟂ + t u) = w⟂, hence
  t² + 2t (u·w0) + |w0⟂|² − |w⟂|² = 0, t = −u·w0 + σ √((u·w0)² − |w0⟂|² + |w⟂|²);
- PRP, line–line: B = Q1 + s d1 = Q2 + t d2, one solution.

σ = ±1 is the branch; it is continuous in the inputs wherever the square root's argument (the
**discriminant**, reported per dyad over L²) stays positive; where it crosses zero the dyad folds
(its links in line): there the branch is born or dies. A body's rotation is the one about n that
takes its drawn in-plane link to the solved one. Joint variables follow from the relative poses
(:func:`joint_values`), so the closure Jacobian code gives rates and accelerations unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import matvec
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.subchains import Decomposition, Driven, Dyad
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Placement:
    """Body poses (K, B+1, 3, 3) and (K, B+1, 3), the ground last (graph/closure.py's
    layout), and each dyad's discriminant over L² (K, D): NaN poses where a dyad does not
    assemble (its discriminant negative)."""

    R: Array
    p: Array
    discriminant: Array

    @property
    def assembles(self) -> NDArray[np.bool_]:
        """Every discriminant non-negative (and every pose finite: an RSS leg's rod turned
        exactly end for end has no least rotation)."""
        return np.asarray(np.all(self.discriminant >= 0.0, axis=1)
                          & np.all(np.isfinite(self.p), axis=(1, 2)))


def rotation_about(n: Array, angle: Array) -> Array:
    """Rotations (K, 3, 3) by ``angle`` (K,) about the unit axis n (Rodrigues)."""
    return _rotation_cs(n, np.cos(angle), np.sin(angle))


def _rotation_cs(n: Array, c: Array, s: Array) -> Array:
    """Rodrigues' rotation about n from the angle's cosine and sine (K,): c I + s [n]× +
    (1 − c) n nᵀ."""
    nn = np.outer(n, n)
    out = np.multiply.outer(c, np.eye(3) - nn)
    out += np.multiply.outer(s, np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]],
                                          [-n[1], n[0], 0.0]]))
    out += nn
    return out


def rotation_each(u: Array, angle: Array) -> Array:
    """Rotations (K, 3, 3) by ``angle`` (K,) about unit axes ``u`` (K, 3) (Rodrigues)."""
    K = np.zeros((u.shape[0], 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -u[:, 2], u[:, 1], -u[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = u[:, 2], -u[:, 1], u[:, 0]
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.asarray(np.eye(3) + s * K + (1.0 - c) * (K @ K))


def _turn(n: Array, v0: Array, v: Array) -> Array:
    """The rotation about n taking the in-plane part of v0 (3,) to that of v (K, 3)."""
    v0 = v0 - (v0 @ n) * n
    cross = np.cross(v0, n)  # sin = n·(v0 × v) = v·(n × v0)
    c, s = v @ v0, -(v @ cross)
    size = np.hypot(c, s)
    return _rotation_cs(n, c / size, s / size)


def place(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array, signs: Array
          ) -> Placement:
    """Every body's pose at inputs ``X`` (K, n_in) on the branches ``signs`` (K, D), one ±1
    per dyad of ``dec`` in order (module docstring)."""
    poses: dict[str, Pose] = {GROUND: _ground(X.shape[0])}
    disc = np.empty((X.shape[0], len(dec.dyads)))
    d = 0
    for step in dec.steps:
        if isinstance(step, Driven):
            poses[step.body] = driven_pose(mech, lay, step, X, poses[step.parent])
        else:
            assert isinstance(step, Dyad), "a loop stage is placed by graph/loop_stage.py"
            b1, b2, disc[:, d] = dyad_poses(mech, step, signs[:, d], poses[step.placed[0]],
                                       poses[step.placed[1]])
            poses[step.bodies[0]], poses[step.bodies[1]] = b1, b2
            d += 1
    return _gathered(mech, lay, poses, disc)


def place_every(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array) -> Placement:
    """Every body's pose in every combination of dyad branches at every input row: M·N
    samples, mode-major, in graph/closed_modes.py's ``branch_combinations`` order (the first
    dyad's branch varies slowest, the drawing's branch first). Each dyad is solved once per
    combination of the branches before it: a body's pose is shared by the modes that differ
    only in later dyads."""
    N = X.shape[0]
    poses: dict[str, Pose] = {GROUND: _ground(N)}
    count: dict[str, int] = {GROUND: 1}  # how many branch prefixes a body's pose covers
    discs: list[tuple[Array, int]] = []
    m = 1
    for step in dec.steps:
        if isinstance(step, Driven):
            c = count[step.parent]
            poses[step.body] = driven_pose(mech, lay, step, np.tile(X, (c, 1)), poses[step.parent])
            count[step.body] = c
            continue
        assert isinstance(step, Dyad), "a loop stage is placed by graph/loop_stage.py"
        m_new = m * step.branches
        branch = [step.drawn_branch, -step.drawn_branch][:step.branches]
        sigma = np.repeat(np.tile(np.array(branch, dtype=float), m), N)
        ends = [_widened(poses[b], count[b], m, N) for b in step.placed]
        if step.kind == "RRR":  # the circles once per prefix, both branches from them
            b1, b2, dsc = _rrr(mech, step, sigma, ends[0], ends[1], (m, m_new, N))
            discs.append((dsc, m))
        else:
            if step.branches == 2:  # every prefix on both branches
                ends = [_widened(e, m, m_new, N) for e in ends]
            b1, b2, dsc = dyad_poses(mech, step, sigma, ends[0], ends[1])
            discs.append((dsc, m_new))
        poses[step.bodies[0]], poses[step.bodies[1]] = b1, b2
        count[step.bodies[0]] = count[step.bodies[1]] = m_new
        m = m_new
    disc = np.empty((m * N, len(discs)))
    for d, (dsc, have) in enumerate(discs):
        disc[:, d] = np.repeat(dsc.reshape(have, N), m // have, axis=0).reshape(-1)
    return _gathered(mech, lay, poses, disc, count, N)


Pose = tuple[Array, Array]


def _ground(K: int) -> Pose:
    return np.broadcast_to(np.eye(3), (K, 3, 3)), np.zeros((K, 3))


def _widened(pose: Pose, have: int, want: int, N: int) -> Pose:
    """A pose over ``have`` branch prefixes (have·N samples) repeated to ``want`` prefixes
    (a multiple of ``have``: each prefix followed by every branch of the dyads after it)."""
    if have == want:
        return pose
    r = want // have
    R, p = pose
    return (np.repeat(R.reshape(have, N, 3, 3), r, axis=0).reshape(want * N, 3, 3),
            np.repeat(p.reshape(have, N, 3), r, axis=0).reshape(want * N, 3))


def _gathered(mech: Mechanism, lay: GraphLayout, poses: dict[str, Pose], disc: Array,
              count: dict[str, int] | None = None, N: int = 0) -> Placement:
    """The poses in graph/closure.py's layout (K, B+1, …), written body by body (a body
    over fewer branch prefixes than K/N repeated to all: :func:`place_every`)."""
    K = disc.shape[0]
    B = len(mech.bodies) + 1
    R = np.empty((B, K, 3, 3))  # body-major: each body's write is contiguous
    p = np.empty((B, K, 3))
    for name, (Rb, pb) in poses.items():
        b = lay.body_of[name]
        have = 1 if count is None else count[name]
        if count is None or have * N == K:
            R[b], p[b] = Rb, pb
        else:
            R[b].reshape(have, -1, N, 3, 3)[:] = Rb.reshape(have, 1, -1, 3, 3)
            p[b].reshape(have, -1, N, 3)[:] = pb.reshape(have, 1, -1, 3)
    return Placement(R.transpose(1, 0, 2, 3), p.transpose(1, 0, 2), disc)


def driven_pose(mech: Mechanism, lay: GraphLayout, step: Driven, X: Array, parent: Pose) -> Pose:
    j = mech.joints[step.joint]
    x = X[:, lay.inputs.index(lay.first_freedom[step.joint])]
    if j.kind == "R":
        Mr = rotation_about(j.axis, x)
        Mp = j.at - matvec(Mr, j.at)
    else:
        Mr = np.broadcast_to(np.eye(3), (x.shape[0], 3, 3))
        Mp = x[:, None] * j.axis
    if j.bodies[0] != step.parent:  # the joint runs from the body to its parent: M⁻¹
        Mr = np.swapaxes(Mr, -1, -2)
        Mp = -np.einsum("nij,nj->ni", Mr, Mp)
    Ra, pa = parent
    return Ra @ Mr, np.einsum("nij,nj->ni", Ra, Mp) + pa


def _world(pose: Pose, x0: Array) -> Array:
    return matvec(pose[0], x0) + pose[1]


def dyad_poses(mech: Mechanism, dy: Dyad, sigma: Array, first: Pose, second: Pose
          ) -> tuple[Pose, Pose, Array]:
    """The poses of the dyad's two bodies from those of the placed bodies it joins (p1, p2)
    on branches ``sigma`` (K,), and its discriminant over L² (K,)."""
    if dy.kind == "RSS":
        from screwkit.kinematics.graph.legs import rss_leg

        return rss_leg(mech, dy.joints, sigma, first, second)
    if dy.kind == "PSS":
        from screwkit.kinematics.graph.legs import pss_leg

        return pss_leg(mech, dy.joints, sigma, first, second)
    if dy.kind == "SS":
        from screwkit.kinematics.graph.legs import spin_hold

        return spin_hold(mech, dy.joints, dy.normal, sigma, first, second)
    j1, j3, j2 = (mech.joints[k] for k in dy.joints)
    n = dy.normal
    L2 = mech.length_scale ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        if dy.kind == "RRR":
            return _rrr(mech, dy, sigma, first, second)
        if dy.kind == "RRP":
            A = _world(first, j1.at)
            Q = _world(second, j3.at)
            dirn = matvec(second[0], j2.axis)
            q = Q - A
            along = np.einsum("ki,ki->k", q, dirn)
            perp = q - along[:, None] * dirn
            perp -= np.outer(perp @ n, n)
            disc = _sq(j3.at - j1.at, n) - np.einsum("ki,ki->k", perp, perp)
            t = -along + sigma * np.sqrt(disc)
            Bw = Q + t[:, None] * dirn
            return (_rotating(n, j3.at - j1.at, Bw - A, A, j1.at),
                    (second[0], Bw - matvec(second[0], j3.at)), np.asarray(disc / L2))
        if dy.kind == "RPR":
            A, C = _world(first, j1.at), _world(second, j2.at)
            w0 = j2.at - j1.at
            uw = float(j3.axis @ w0)
            w = C - A
            disc = uw ** 2 - _sq(w0, n) + np.einsum("ki,ki->k", w, w) - (w @ n) ** 2
            t = -uw + sigma * np.sqrt(disc)
            slid = w0[None, :] + t[:, None] * j3.axis
            Rb = _turn_each(n, slid, w)
            return ((Rb, A - matvec(Rb, j1.at)), (Rb, C - matvec(Rb, j2.at)),
                    np.asarray(disc / L2))
        # PRP: line–line
        Q1, Q2 = _world(first, j3.at), _world(second, j3.at)
        d1, d2 = matvec(first[0], j1.axis), matvec(second[0], j2.axis)
        s = (np.cross(Q2 - Q1, d2) @ n) / (np.cross(d1, d2) @ n)
        Bw = Q1 + s[:, None] * d1
        return ((first[0], Bw - matvec(first[0], j3.at)),
                (second[0], Bw - matvec(second[0], j3.at)),
                np.asarray(np.where(np.isfinite(s), 1.0, np.nan)))


def _circles(mech: Mechanism, dy: Dyad, first: Pose, second: Pose
             ) -> tuple[Array, Array, Array, Array, Array, Array]:
    """An RRR dyad's circle–circle intersection up to the branch (module docstring): A, C, ŵ,
    a, h² and the discriminant h²/L² (NaN where A and C coincide in the plane)."""
    j1, j3, j2 = (mech.joints[k] for k in dy.joints)
    n = dy.normal
    with np.errstate(invalid="ignore", divide="ignore"):
        A, C = _world(first, j1.at), _world(second, j2.at)
        w = C - A
        w -= np.outer(w @ n, n)
        dist = np.linalg.norm(w, axis=1)
        e = w / dist[:, None]
        r1 = _sq(j3.at - j1.at, n)
        r2 = _sq(j3.at - j2.at, n)
        a = (dist ** 2 + r1 - r2) / (2.0 * dist)
        h2 = r1 - a ** 2
        disc = np.asarray(np.where(dist > 0.0, h2 / mech.length_scale ** 2, np.nan))
    return A, C, e, a, h2, disc


def _rrr(mech: Mechanism, dy: Dyad, sigma: Array, first: Pose, second: Pose,
         widen: tuple[int, int, int] | None = None) -> tuple[Pose, Pose, Array]:
    """:func:`dyad_poses` of an RRR dyad. With ``widen`` = (have, want, N) the placed poses
    cover ``have`` branch prefixes and ``sigma`` ``want`` (:func:`place_every`): the circles'
    intersection, which the branch does not change, is found once per prefix and repeated to
    every branch (the same operations on the same values); the discriminant stays per
    prefix."""
    j1, j3, j2 = (mech.joints[k] for k in dy.joints)
    n = dy.normal
    A, C, e, a, h2, disc = _circles(mech, dy, first, second)
    with np.errstate(invalid="ignore", divide="ignore"):
        base, root, side = A + a[:, None] * e, np.sqrt(h2), np.cross(n, e)
        if widen is not None and widen[0] != widen[1]:
            have, want, N = widen
            A, C, base, root, side = (
                np.repeat(x.reshape(have, N, *x.shape[1:]), want // have, axis=0)
                .reshape(want * N, *x.shape[1:]) for x in (A, C, base, root, side))
        Bw = base + (sigma * root)[:, None] * side
        return (_rotating(n, j3.at - j1.at, Bw - A, A, j1.at),
                _rotating(n, j3.at - j2.at, Bw - C, C, j2.at), disc)


def discriminants(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                  signs: Array) -> Array:
    """:func:`place`'s discriminants (K, D) alone, by the same operations: an RRR dyad whose
    bodies no later step is placed on is not posed (the slopes of graph/step_folds.py need
    the discriminants only)."""
    poses: dict[str, Pose] = {GROUND: _ground(X.shape[0])}
    disc = np.empty((X.shape[0], len(dec.dyads)))
    d = 0
    for i, step in enumerate(dec.steps):
        later = {b for st in dec.steps[i + 1:]
                 for b in (st.placed if isinstance(st, Dyad) else (st.parent,))}
        if isinstance(step, Driven):
            if step.body in later:
                poses[step.body] = driven_pose(mech, lay, step, X, poses[step.parent])
            continue
        assert isinstance(step, Dyad), "a loop stage is placed by graph/loop_stage.py"
        first, second = poses[step.placed[0]], poses[step.placed[1]]
        if step.kind == "RRR" and not later & set(step.bodies):
            disc[:, d] = _circles(mech, step, first, second)[-1]
        else:
            b1, b2, disc[:, d] = dyad_poses(mech, step, signs[:, d], first, second)
            poses[step.bodies[0]], poses[step.bodies[1]] = b1, b2
        d += 1
    return disc


def _sq(v: Array, n: Array) -> float:
    """|v⟂|²: the squared length of v's part in the plane normal to n."""
    v = v - (v @ n) * n
    return float(v @ v)


def _rotating(n: Array, link0: Array, link: Array, pivot: Array, pivot0: Array) -> Pose:
    """A body turned about n so its drawn link (from pivot0) lies along ``link`` (K, 3), with
    its pivot at ``pivot``."""
    Rb = _turn(n, link0, link)
    return Rb, pivot - matvec(Rb, pivot0)


def _turn_each(n: Array, v0: Array, v: Array) -> Array:
    """As :func:`_turn` with one drawn vector per sample (K, 3)."""
    v0 = v0 - np.outer(v0 @ n, n)
    c = np.einsum("ki,ki->k", v, v0)
    s = np.cross(v0, v) @ n
    size = np.hypot(c, s)
    return _rotation_cs(n, c / size, s / size)


def joint_values(mech: Mechanism, lay: GraphLayout, R: Array, p: Array) -> Array:
    """Every scalar freedom (K, n_scalar) from the body poses: an R joint's angle from the
    relative rotation R_aᵀR_b = exp(θ[u]×) (sin θ = ½ u·vee(R − Rᵀ), cos θ = ½(tr R − 1)),
    a P joint's slide s = u·R_aᵀ(p_b − p_a). Angles are principal values (−π, π]."""
    out = np.zeros((R.shape[0], lay.n_scalar))
    for i, j in enumerate(mech.joints):
        if j.kind == "S":
            continue
        a, b = (lay.body_of[x] for x in j.bodies)
        col = lay.scalar_col[lay.first_freedom[i]]
        Ra = R[:, a]
        if j.kind == "P":
            out[:, col] = np.einsum("kji,kj->ki", Ra, p[:, b] - p[:, a]) @ j.axis
            continue
        Rr = np.swapaxes(Ra, -1, -2) @ R[:, b]
        vee = np.stack([Rr[:, 2, 1] - Rr[:, 1, 2], Rr[:, 0, 2] - Rr[:, 2, 0],
                        Rr[:, 1, 0] - Rr[:, 0, 1]], axis=1)
        out[:, col] = np.arctan2(0.5 * (vee @ j.axis), 0.5 * (np.trace(Rr, axis1=1, axis2=2)
                                                               - 1.0))
    return out


def configuration(mech: Mechanism, lay: GraphLayout, R: Array, p: Array) -> Configuration:
    """The configuration of closed-form poses: R and P joints' values (:func:`joint_values`),
    an S joint's relative rotation R_aᵀR_b (its M_j, graph/closure.py)."""
    balls = np.empty((R.shape[0], lay.n_spherical, 3, 3))
    for i, k in lay.spherical_of_joint.items():
        a, b = (lay.body_of[x] for x in mech.joints[i].bodies)
        balls[:, k] = np.swapaxes(R[:, a], -1, -2) @ R[:, b]
    return Configuration(joint_values(mech, lay, R, p), balls)
