"""The closed forms of spatial legs (graph/subchains.py). An RSS leg: a body b turning on an R joint
(point c, axis u) of a placed body p1 and carrying the ball C of a rod whose other ball B sits
on a placed body; the rod is held by those two balls alone.

In p1's frame (the drawing's coordinates), with v = C0 − c split along u (v∥) and across it
(v⟂), the ball on b is C(φ) = c + v∥ + cos φ v⟂ + sin φ (u × v⟂), and the rod's length
l = |C0 − B0| holds when (d = c + v∥ − B, B in p1's frame)

    P cos φ + Q sin φ = S,  P = 2 d·v⟂,  Q = 2 d·(u × v⟂),  S = l² − |d|² − |v⟂|²,

so φ = atan2(Q, P) + σ arccos(S/ρ), ρ = √(P² + Q²): two branches σ = ±1, continuous while the
discriminant ρ² − S² stays positive (it folds where the rod's line meets the circle of C
tangentially). The rod's rotation is the least rotation taking its drawn direction C0 − B0 to
C − B: its spin about its own axis is idle (nothing drives it; graph/idle.py holds its rate
at zero), so any choice is a pose of the mechanism, and this one is defined at every sample
without a path. A PSS leg is the same with the body sliding on a P joint (a quadratic in the
slide); an SS step turns a body about the line through two of its balls until a tie rod fits.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
Pose = tuple[Array, Array]


def circle_sphere(c: Array, u: Array, v: Array, B: Array, length2: float
                  ) -> tuple[Array, Array, Array]:
    """P, Q, S of P cos φ + Q sin φ = S: the point c + v turned by φ about the line (c, u)
    keeps the squared distance ``length2`` from B (c, u, v, B (K, 3) or (3,))."""
    v_par = np.sum(v * u, axis=-1)[..., None] * u
    v_perp = v - v_par
    d = c + v_par - B
    P = 2.0 * np.sum(d * v_perp, axis=-1)
    Q = 2.0 * np.sum(d * np.cross(u, v_perp), axis=-1)
    S = length2 - np.sum(d * d, axis=-1) - np.sum(v_perp * v_perp, axis=-1)
    return P, Q, S


def leg_terms(mech: Mechanism, joints: tuple[int, int, int], B: Array
              ) -> tuple[Array, Array, Array]:
    """P, Q, S of the leg's equation for the far ball at ``B`` (K, 3) in p1's frame."""
    jr, jc, jb = (mech.joints[k] for k in joints)
    return circle_sphere(jr.at, jr.axis, jc.at - jr.at, B,
                         float(np.sum((jc.at - jb.at) ** 2)))


def _drawn_root_branch(P: Array, Q: Array, L: float) -> int | None:
    """The branch σ whose root atan2(Q, P) + σ arccos(S/ρ) is φ = 0 (the drawing), None on a
    fold or a degenerate equation."""
    rho = float(np.hypot(P, Q))
    if rho <= 1e-9 * L ** 2:
        return None
    alpha = float(np.arctan2(Q, P))
    if abs(alpha) <= 1e-9:  # φ = 0 is a double root: the fold
        return None
    return -1 if alpha > 0.0 else 1


def drawn_leg_branch(mech: Mechanism, joints: tuple[int, int, int]) -> int | None:
    """The branch of the drawing (φ = 0 is a root), None where it is drawn on its fold or
    the equation is degenerate (the ball on the axis, or the far ball's distance to the
    circle not changing with φ)."""
    P, Q, _ = leg_terms(mech, joints, mech.joints[joints[2]].at)
    return _drawn_root_branch(P, Q, mech.length_scale)


def drawn_slide_branch(mech: Mechanism, joints: tuple[int, int, int]) -> int | None:
    """The branch of a PSS leg's drawing (s = 0 is a root of s² + 2s (u·d) + |d|² − l² = 0,
    d = C0 − B0; the other root is −2 u·d), None on its fold (u·d = 0)."""
    jp, jc, jb = (mech.joints[k] for k in joints)
    ud = float(jp.axis @ (jc.at - jb.at))
    if abs(ud) <= 1e-9 * mech.length_scale:
        return None
    return 1 if ud > 0.0 else -1


def pss_leg(mech: Mechanism, joints: tuple[int, int, int], sigma: Array, first: Pose,
            second: Pose) -> tuple[Pose, Pose, Array]:
    """A PSS leg: the body slides by s along the P joint's u (in p1's frame) until its ball
    C0 + s u is the rod's length l from the far ball B: s = −u·d + σ √((u·d)² − |d|² + l²),
    d = C0 − B; the rod by its least rotation; the discriminant over L²."""
    jp, jc, jb = (mech.joints[k] for k in joints)
    R1, p1 = first
    B_world = second[0] @ jb.at + second[1]
    d = jc.at - np.einsum("kji,kj->ki", R1, B_world - p1)
    ud = d @ jp.axis
    disc = ud ** 2 - np.einsum("ki,ki->k", d, d) + float(np.sum((jc.at - jb.at) ** 2))
    with np.errstate(invalid="ignore"):
        slide = -ud + sigma * np.sqrt(disc)
    Rb = R1
    pb = p1 + np.einsum("kij,kj->ki", R1, slide[:, None] * jp.axis)
    rod = _least_rotation(jc.at - jb.at, Rb @ jc.at + pb - B_world)
    return (Rb, pb), (rod, B_world - rod @ jb.at), disc / mech.length_scale ** 2


def drawn_spin_branch(mech: Mechanism, joints: tuple[int, int, int], axis: Array
                      ) -> int | None:
    """As :func:`drawn_leg_branch` for the spin of a body about the line through its ball
    joints[0] along ``axis``, held by the S–S rod joints[1]–joints[2]."""
    jl, jt, ja = (mech.joints[k] for k in joints)
    P, Q, _ = circle_sphere(jl.at, axis, jt.at - jl.at, ja.at,
                            float(np.sum((jt.at - ja.at) ** 2)))
    return _drawn_root_branch(P, Q, mech.length_scale)


def spin_hold(mech: Mechanism, joints: tuple[int, int, int], axis: Array, sigma: Array,
              body: Pose, anchor: Pose) -> tuple[Pose, Pose, Array]:
    """The body (provisionally placed with its first two balls right) turned by ψ about the
    line through its ball joints[0] along its drawn ``axis`` until the S–S rod joints[1]–
    joints[2] (anchored on ``anchor``) fits, on branches ``sigma``; the rod by its least
    rotation; the discriminant (ρ² − S²)/L⁴."""
    from screwkit.kinematics.graph.dyads import rotation_each

    jl, jt, ja = (mech.joints[k] for k in joints)
    R, p = body
    c = R @ jl.at + p
    u = R @ axis
    T = R @ jt.at + p
    G = anchor[0] @ ja.at + anchor[1]
    P, Q, S = circle_sphere(c, u, T - c, G, float(np.sum((jt.at - ja.at) ** 2)))
    disc = P ** 2 + Q ** 2 - S ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        psi = np.arctan2(Q, P) + sigma * np.arccos(np.clip(S / np.hypot(P, Q), -1.0, 1.0))
    psi = np.where(disc >= 0.0, psi, np.nan)
    turn = rotation_each(u, psi)
    Rb = turn @ R
    pb = c + np.einsum("kij,kj->ki", turn, p - c)
    rod = _least_rotation(jt.at - ja.at, Rb @ jt.at + pb - G)
    return (Rb, pb), (rod, G - rod @ ja.at), disc / mech.length_scale ** 4


def rss_leg(mech: Mechanism, joints: tuple[int, int, int], sigma: Array, first: Pose,
            second: Pose) -> tuple[Pose, Pose, Array]:
    """Poses of the turning body and the rod from the placed bodies' poses (``first`` holds
    the R joint, ``second`` the far ball), on branches ``sigma`` (K,); the discriminant
    (ρ² − S²)/L⁴ (K,). The body turns by φ about (c, u) relative to p1 whichever way the
    joint is declared (the joint variable's sign follows from the poses)."""
    from screwkit.kinematics.graph.dyads import rotation_about

    jr, jc, jb = (mech.joints[k] for k in joints)
    R1, p1 = first
    B_world = second[0] @ jb.at + second[1]
    B = np.einsum("kji,kj->ki", R1, B_world - p1)  # in p1's frame
    P, Q, S = leg_terms(mech, joints, B)
    disc = P ** 2 + Q ** 2 - S ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        phi = np.arctan2(Q, P) + sigma * np.arccos(np.clip(S / np.hypot(P, Q), -1.0, 1.0))
    phi = np.where(disc >= 0.0, phi, np.nan)
    M = rotation_about(jr.axis, phi)
    Rb = R1 @ M
    pb = np.einsum("kij,kj->ki", R1, jr.at - M @ jr.at) + p1
    C = Rb @ jc.at + pb
    rod = _least_rotation(jc.at - jb.at, C - B_world)
    return (Rb, pb), (rod, B_world - rod @ jb.at), disc / mech.length_scale ** 4


def _least_rotation(a0: Array, a: Array) -> Array:
    """The rotation (K, 3, 3) of least angle taking the direction a0 (3,) to a (K, 3):
    I + [w]× + [w]×²/(1 + c), w = â0 × â, c = â0·â (NaN where they are opposite)."""
    e0 = a0 / np.linalg.norm(a0)
    e = a / np.linalg.norm(a, axis=1)[:, None]
    w = np.cross(e0, e)
    c = e @ e0
    K = np.zeros((a.shape[0], 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.eye(3) + K + (K @ K) / (1.0 + c)[:, None, None])
