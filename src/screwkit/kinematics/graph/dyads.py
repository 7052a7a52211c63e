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
        return np.asarray(np.all(self.discriminant >= 0.0, axis=1))


def rotation_about(n: Array, angle: Array) -> Array:
    """Rotations (K, 3, 3) by ``angle`` (K,) about the unit axis n (Rodrigues)."""
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    s, c = np.sin(angle), np.cos(angle)
    return (np.eye(3) + np.multiply.outer(s, K) + np.multiply.outer(1.0 - c, K @ K))


def _turn(n: Array, v0: Array, v: Array) -> Array:
    """The rotation about n taking the in-plane part of v0 (3,) to that of v (K, 3)."""
    v0 = v0 - (v0 @ n) * n
    v = v - np.outer(v @ n, n)
    angle = np.arctan2(np.cross(v0, v) @ n, v @ v0)
    return rotation_about(n, angle)


def _world(R: Array, p: Array, b: int, x0: Array) -> Array:
    return R[:, b] @ x0 + p[:, b]


def place(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array, signs: Array
          ) -> Placement:
    """Every body's pose at inputs ``X`` (K, n_in) on the branches ``signs`` (K, D), one ±1
    per dyad of ``dec`` in order (module docstring)."""
    K = X.shape[0]
    B = len(mech.bodies) + 1
    R = np.full((K, B, 3, 3), np.nan)
    p = np.full((K, B, 3), np.nan)
    g = lay.body_of[GROUND]
    R[:, g] = np.eye(3)
    p[:, g] = 0.0
    disc = np.empty((K, len(dec.dyads)))
    d = 0
    for step in dec.steps:
        if isinstance(step, Driven):
            _driven(mech, lay, step, X, R, p)
        else:
            disc[:, d] = _dyad(mech, lay, step, signs[:, d], R, p)
            d += 1
    return Placement(R, p, disc)


def _driven(mech: Mechanism, lay: GraphLayout, step: Driven, X: Array, R: Array, p: Array
            ) -> None:
    j = mech.joints[step.joint]
    x = X[:, lay.inputs.index(lay.first_freedom[step.joint])]
    if j.kind == "R":
        Mr = rotation_about(j.axis, x)
        Mp = j.at - Mr @ j.at
    else:
        Mr = np.broadcast_to(np.eye(3), (x.shape[0], 3, 3))
        Mp = x[:, None] * j.axis
    a, b = lay.body_of[step.parent], lay.body_of[step.body]
    if j.bodies[0] != step.parent:  # the joint runs from the body to its parent: M⁻¹
        Mr = np.swapaxes(Mr, -1, -2)
        Mp = -np.einsum("nij,nj->ni", Mr, Mp)
    R[:, b] = R[:, a] @ Mr
    p[:, b] = np.einsum("nij,nj->ni", R[:, a], Mp) + p[:, a]


def _dyad(mech: Mechanism, lay: GraphLayout, dy: Dyad, sigma: Array, R: Array, p: Array
          ) -> Array:
    """Place the dyad's two bodies in ``R``, ``p``; its discriminant over L² (K,)."""
    j1, j3, j2 = (mech.joints[k] for k in dy.joints)
    p1, p2 = (lay.body_of[b] for b in dy.placed)
    b1, b2 = (lay.body_of[b] for b in dy.bodies)
    n = dy.normal
    L2 = mech.length_scale ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        if dy.kind == "RRR":
            A, C = _world(R, p, p1, j1.at), _world(R, p, p2, j2.at)
            w = C - A
            w -= np.outer(w @ n, n)
            dist = np.linalg.norm(w, axis=1)
            e = w / dist[:, None]
            r1 = _sq(j3.at - j1.at, n)
            r2 = _sq(j3.at - j2.at, n)
            a = (dist ** 2 + r1 - r2) / (2.0 * dist)
            h2 = r1 - a ** 2
            Bp = A + a[:, None] * e + (sigma * np.sqrt(h2))[:, None] * np.cross(n, e)
            Bw = Bp + ((j3.at - j1.at) @ n) * n  # B keeps its drawn height along n
            _rotating(R, p, b1, n, j3.at - j1.at, Bw - A, A, j1.at)
            _rotating(R, p, b2, n, j3.at - j2.at, Bw - C, C, j2.at)
            return np.asarray(np.where(dist > 0.0, h2 / L2, np.nan))
        if dy.kind == "RRP":
            A = _world(R, p, p1, j1.at)
            Q = _world(R, p, p2, j3.at)
            dirn = R[:, p2] @ j2.axis
            q = Q - A
            along = np.einsum("ki,ki->k", q, dirn)
            perp = q - along[:, None] * dirn
            perp -= np.outer(perp @ n, n)
            disc = _sq(j3.at - j1.at, n) - np.einsum("ki,ki->k", perp, perp)
            t = -along + sigma * np.sqrt(disc)
            Bw = Q + t[:, None] * dirn
            _rotating(R, p, b1, n, j3.at - j1.at, Bw - A, A, j1.at)
            R[:, b2] = R[:, p2]
            p[:, b2] = Bw - R[:, p2] @ j3.at
            return np.asarray(disc / L2)
        if dy.kind == "RPR":
            A, C = _world(R, p, p1, j1.at), _world(R, p, p2, j2.at)
            w0 = j2.at - j1.at
            uw = float(j3.axis @ w0)
            disc = uw ** 2 - _sq(w0, n) + np.einsum("ki,ki->k", C - A, C - A) - ((C - A) @ n) ** 2
            t = -uw + sigma * np.sqrt(disc)
            slid = w0[None, :] + t[:, None] * j3.axis
            Rb = _turn_each(n, slid, C - A)
            R[:, b1] = Rb
            p[:, b1] = A - Rb @ j1.at
            R[:, b2] = Rb
            p[:, b2] = C - Rb @ j2.at
            return np.asarray(disc / L2)
        # PRP
        Q1, Q2 = _world(R, p, p1, j3.at), _world(R, p, p2, j3.at)
        d1, d2 = R[:, p1] @ j1.axis, R[:, p2] @ j2.axis
        s = (np.cross(Q2 - Q1, d2) @ n) / (np.cross(d1, d2) @ n)
        Bw = Q1 + s[:, None] * d1
        for b, par in ((b1, p1), (b2, p2)):
            R[:, b] = R[:, par]
            p[:, b] = Bw - R[:, par] @ j3.at
        return np.asarray(np.where(np.isfinite(s), 1.0, np.nan))


def _sq(v: Array, n: Array) -> float:
    """|v⟂|²: the squared length of v's part in the plane normal to n."""
    v = v - (v @ n) * n
    return float(v @ v)


def _rotating(R: Array, p: Array, b: int, n: Array, link0: Array, link: Array, pivot: Array,
              pivot0: Array) -> None:
    """Body ``b`` turned about n so its drawn link (pivot0 → …) lies along ``link``, with its
    pivot at ``pivot``."""
    Rb = _turn(n, link0, link)
    R[:, b] = Rb
    p[:, b] = pivot - Rb @ pivot0


def _turn_each(n: Array, v0: Array, v: Array) -> Array:
    """As :func:`_turn` with one drawn vector per sample (K, 3)."""
    v0 = v0 - np.outer(v0 @ n, n)
    v = v - np.outer(v @ n, n)
    angle = np.arctan2(np.cross(v0, v) @ n, np.einsum("ki,ki->k", v, v0))
    return rotation_about(n, angle)


def joint_values(mech: Mechanism, lay: GraphLayout, R: Array, p: Array) -> Array:
    """Every scalar freedom (K, n_scalar) from the body poses: an R joint's angle from the
    relative rotation R_aᵀR_b = exp(θ[u]×) (sin θ = ½ u·vee(R − Rᵀ), cos θ = ½(tr R − 1)),
    a P joint's slide s = u·R_aᵀ(p_b − p_a). Angles are principal values (−π, π]."""
    out = np.zeros((R.shape[0], lay.n_scalar))
    for i, j in enumerate(mech.joints):
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
    """The configuration of closed-form poses (only R and P joints take part in them)."""
    return Configuration(joint_values(mech, lay, R, p), np.zeros((R.shape[0], 0, 3, 3)))
