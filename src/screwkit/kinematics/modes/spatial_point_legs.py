"""Legs of the spatial point formulation (modes/spatial_points.py) written as equations on
their end joints' centres instead of bodies of points: telescopic S–P–S legs, pivoted R–P–S
legs (below), U–P–U legs with square axes (:class:`GimbalLeg`) and U–P–S legs
(:class:`UniversalLeg`). Their two bodies carry no points and are read off the solved centres.

A telescopic leg (model/spin_groups.py: two bodies slid by one P joint, each holding one of
the leg's two balls) keeps its balls' centres a and b at the distance its slide s sets: at s
the second body's ball is the first body's drawn vector d0 = b0 − a0 slid by s along the P
joint's axis e, so ‖b − a‖² = ‖d0 + s e‖², a parameter that follows the input (no equation
when the slide is passive: a strut of free length). Its bodies are read off the balls: the
least rotation of d0 + s e onto b − a (the spin about the leg's line left at zero), each body
placed by its ball; a passive slide from the root of ‖d0 + s e‖ = ‖b − a‖ that is 0 at the
drawn distance.

A leg of two bodies, an arm turning on an R joint about an axis of a placed body (the ground,
or a body the inputs place) and a slider on it along a driven P joint, ending in a ball (S)
joint on another body, and nothing else on the arm or the slider (the legs of a 3-RPS parallel
robot): at a given slide s the ball's centre Q is a point of the arm, Q0 + σ s u (drawn, u the
slide's direction, σ its sense), turning about the axis (point A, unit a). So Q is on the
circle

    (Q − A)·a = h(s),   ‖Q − A‖² = r²(s),   h = (Q0 + σ s u − A)·a,   r² = ‖Q0 + σ s u − A‖²,

two quadrics in Q with the placed axis points A, A + a as parameters and h, r² parameters that
follow the input. The arm and slider carry no points and are not unknowns (the leg's 21 point
coordinates become none: a 3-RPS has 9 unknowns, not 63). Their poses are read off Q: the
arm's turn θ about the axis carries the drawn (Q0 + σ s u − A)'s part square to the axis onto
the solved one's, the slider is the arm slid by σ s u. A passive slide square to the axis
(a 3-RPS driven at its platform) leaves the ball its plane alone, (Q − A)·a = h, one
equation; σ s is read off the ball's distance from A (:func:`free_slide`, the root that is 0
at the drawn distance).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.modes.rod_loops import least_rotation

if TYPE_CHECKING:
    from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
Pose = tuple[Array, Array]
#: a leg whose slide or ball is this close (relative) to being along its axis is not taken
#: (the circle degenerates: the arm's turn does not move the ball)
ALONG = 1e-6


@dataclass(frozen=True)
class TelescopicLeg:
    """A telescopic leg (module docstring): its P joint, its balls' centres' points on the P
    joint's first and second body and those balls' joints (indices into the formulation's
    points and ``mech.joints``), and the slide's input column (None: passive)."""

    joint: int
    balls: tuple[int, int]
    ball_joints: tuple[int, int]
    column: int | None


def leg_vectors(mech: Mechanism, leg: TelescopicLeg, s: Array) -> Array:
    """The ball-to-ball vectors d0 + s e (N, 3, unscaled) at the slides s (N,)."""
    a, b = (np.asarray(mech.joints[k].at, float) for k in leg.ball_joints)
    return (b - a) + np.multiply.outer(s, mech.joints[leg.joint].axis)


def free_slide(d0: Array, e: Array, distance: Array) -> Array:
    """A passive slide's travels t (N,) at the distances (N,): the root of
    ‖d0 + t e‖ = distance (e a unit vector) that is 0 at the drawn distance ‖d0‖ (NaN where
    none is real)."""
    along = float(d0 @ e)
    with np.errstate(invalid="ignore"):
        root = np.sqrt(along**2 - d0 @ d0 + distance**2)
    return np.asarray(-along + (1.0 if along >= 0.0 else -1.0) * root)


def leg_slides(mech: Mechanism, leg: TelescopicLeg, distance: Array) -> Array:
    """A passive leg's slides (N,) at the ball distances (N,) (:func:`free_slide`)."""
    a, b = (np.asarray(mech.joints[k].at, float) for k in leg.ball_joints)
    return free_slide(b - a, np.asarray(mech.joints[leg.joint].axis, float), distance)


def telescopic_poses(mech: Mechanism, leg: TelescopicLeg, balls: tuple[Array, Array],
                     X: Array) -> dict[str, Pose]:
    """The leg's two bodies' poses with its balls' centres at ``balls`` ((N, 3) each, world):
    the least rotation of d0 + s e onto b − a, each body placed by its ball."""
    a, b = balls
    w = b - a
    s = (X[:, leg.column] if leg.column is not None
         else leg_slides(mech, leg, np.linalg.norm(w, axis=1)))
    R = least_rotation(leg_vectors(mech, leg, s), w)
    first, second = mech.joints[leg.joint].bodies
    a0, b0 = (np.asarray(mech.joints[k].at, float) for k in leg.ball_joints)
    return {first: (R, a - np.einsum("nij,j->ni", R, a0)),
            second: (R, b - np.einsum("nij,j->ni", R, b0))}


@dataclass(frozen=True)
class PivotLeg:
    """An R–P–S leg (module docstring): its joints (R, P, S), its arm and slider, the placed
    body the R joint turns on, the R joint's two axis points and the ball's point (indices
    into the formulation's points), the slide's input column and its sense σ (+1: the slider
    is the P joint's second body)."""

    joints: tuple[int, int, int]
    arm: str
    slider: str
    base: str
    axis: tuple[int, int]
    ball: int
    column: int | None
    sign: float


def leg_chains(mech: Mechanism, placed: set[str], kind: str, end: str, passive: bool = False
               ) -> list[tuple[int, int, int, str, str, str]]:
    """(base joint, P, end joint indices, first body, second body, base body) of every
    two-body leg: a ``kind`` joint (not an input) from a placed body to a first body that
    holds only it and a P joint (driven, or also passive with ``passive``), the P joint's
    second body holding only it and an ``end`` joint to a third body."""
    driven = {x.split(".")[0] for x in mech.inputs}
    held = {b: [k for k, j in enumerate(mech.joints) if b in j.bodies] for b in mech.body_names}
    out = []
    for kb, j in enumerate(mech.joints):
        if j.kind != kind or j.name in driven:
            continue
        for base, first in (j.bodies, j.bodies[::-1]):
            if base not in placed or first in placed or len(held.get(first, ())) != 2:
                continue
            kp = next(k for k in held[first] if k != kb)
            p = mech.joints[kp]
            second = p.bodies[1] if p.bodies[0] == first else p.bodies[0]
            if (p.kind != "P" or (p.name not in driven and not passive) or second in placed
                    or len(held.get(second, ())) != 2):
                continue
            ke = next(k for k in held[second] if k != kp)
            if mech.joints[ke].kind == end and first not in mech.joints[ke].bodies:
                out.append((kb, kp, ke, first, second, base))
    return out


def pivot_legs(mech: Mechanism, placed: set[str]) -> list[tuple[int, int, int, str, str, str]]:
    """(R, P, S joint indices, arm, slider, base) of every R–P–S leg (module docstring)
    whose R joint turns on a placed body and whose P joint is an input, or is passive and
    square to the R axis."""
    driven = {x.split(".")[0] for x in mech.inputs}
    out = []
    for kr, kp, ks, arm, slider, base in leg_chains(mech, placed, "R", "S", passive=True):
        r, p, s = (mech.joints[k] for k in (kr, kp, ks))
        if p.name not in driven and abs(float(p.axis @ r.axis)) > ALONG:
            continue
        if (np.linalg.norm(np.cross(p.axis, r.axis)) > ALONG
                and np.linalg.norm(np.cross(s.at - r.at, r.axis)) > ALONG * mech.length_scale):
            out.append((kr, kp, ks, arm, slider, base))
    return out


def arm_point(mech: Mechanism, leg: PivotLeg, X: Array) -> tuple[Array, Array, Array]:
    """The ball's drawn centre slid as at the input rows X, Q0 + σ s u (N, 3, unscaled world
    coordinates of the drawing), the R joint's drawn point A and unit axis a."""
    r, p, s = (mech.joints[k] for k in leg.joints)
    t = leg.sign * X[:, leg.column] if leg.column is not None else np.zeros(len(X))
    q = s.at + np.multiply.outer(t, p.axis)
    return q, np.asarray(r.at, float), np.asarray(r.axis, float)


def circle_parameters(mech: Mechanism, leg: PivotLeg, X: Array, scale: float) -> Array:
    """The circle's h and r² (N, 2) at the input rows X, in the formulation's scaled
    coordinates; a passive slide's plane's h alone (N, 1)."""
    q, A, a = arm_point(mech, leg, X)
    w = (q - A) / scale
    if leg.column is None:
        return (w @ a)[:, None]
    return np.stack([w @ a, np.einsum("ni,ni->n", w, w)], axis=1)


def leg_poses(mech: Mechanism, leg: PivotLeg, base: Pose, ball: Array, X: Array
              ) -> dict[str, Pose]:
    """The arm's and slider's poses (R (N, 3, 3), p (N, 3)) with the ball's centre at
    ``ball`` (N, 3, world), the base body at ``base`` (module docstring)."""
    Rb, pb = base
    q0, A, a = arm_point(mech, leg, X)
    local = np.einsum("nji,nj->ni", Rb, ball - pb) - A  # in the base's drawn frame
    u = np.asarray(mech.joints[leg.joints[1]].axis, float)
    if leg.column is None:  # a passive slide square to the axis: from the ball's distance
        t = free_slide(mech.joints[leg.joints[2]].at - A, u, np.linalg.norm(local, axis=1))
        q0 = q0 + np.multiply.outer(t, u)
    else:
        t = leg.sign * X[:, leg.column]
    w0 = q0 - A
    w0 = w0 - np.multiply.outer(w0 @ a, a)
    w1 = local - np.multiply.outer(local @ a, a)
    theta = np.arctan2(np.cross(w0, w1) @ a, np.einsum("ni,ni->n", w0, w1))
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    turn = (np.eye(3) + np.sin(theta)[:, None, None] * K
            + (1.0 - np.cos(theta))[:, None, None] * (K @ K))
    R = Rb @ turn
    p = np.einsum("nij,nj->ni", Rb, A - np.einsum("nij,j->ni", turn, A)) + pb
    slid = p + np.einsum("nij,j->ni", R, u) * t[:, None]
    return {leg.arm: (R, p), leg.slider: (R, slid)}


@dataclass(frozen=True)
class GimbalLeg:
    """A U–P–U leg with square axes (the legs of a translational 3-UPU; module text below):
    its joints (base U, P, top U), its cylinder and piston, the placed body its base U is on,
    the base U's centre C and its arm point E on that body, the top U's centre Q and its arm
    point A on the top body (indices into the formulation's points), the slide's input column
    and its sense (+1: the piston is the P joint's second body).

    The base U turns the cylinder about e1 = E − C (fixed in the base) and then about e2 (fixed
    in the cylinder, square to e1); the leg's vector w(s) = Q0 − C0 + σ s u and its slide u are
    square to e2, and the top U's piston axis is e2 again, its top axis square to it. Then e2 is
    along e1 × (Q − C), and the leg is two equations on Q and A:

        ‖Q − C‖² = ‖w(s)‖²,   ((E − C) × (Q − C)) · (A − Q) = g   (g = 0 drawn)

    (g a free parameter, so the topology's family is generic); a passive slide (a platform
    driven at its translation) gives the second alone, and s is read off ‖Q − C‖
    (:func:`free_slide`). Its bodies are read off Q: e2
    the sign of e1 × (Q − C) nearer its drawn direction (the U joint's root nearer the
    drawing, as the Stewart route decodes a U–P–S leg), the cylinder the rotation carrying
    the drawn frame (e2, w, e2 × w) onto the solved one, the piston slid along it."""

    joints: tuple[int, int, int]
    cylinder: str
    piston: str
    base: str
    centre: int
    arm: int
    ball: int
    top_arm: int
    column: int | None
    sign: float


def gimbal_legs(mech: Mechanism, placed: set[str]) -> list[tuple[int, int, int, str, str]]:
    """(base U, P, top U joint indices, cylinder, piston) of every U–P–U leg with square axes
    (:class:`GimbalLeg`) whose base U is on a placed body, its P joint an input or passive."""
    tol = 1e-9
    out = []
    for ku, kp, kt, cyl, piston, base in leg_chains(mech, placed, "U", "U", passive=True):
        u, p, t = (mech.joints[k] for k in (ku, kp, kt))
        assert u.axis2 is not None and t.axis2 is not None
        e1, e2 = (u.axis, u.axis2) if u.bodies[0] == base else (u.axis2, u.axis)
        e3, e4 = (t.axis, t.axis2) if t.bodies[0] == piston else (t.axis2, t.axis)
        w = (t.at - u.at) / mech.length_scale
        if (abs(e1 @ e2) <= tol and abs(e2 @ w) <= tol and abs(e2 @ p.axis) <= tol
                and np.linalg.norm(np.cross(e2, e3)) <= tol and abs(e3 @ e4) <= tol):
            out.append((ku, kp, kt, cyl, piston))
    return out


def gimbal_parameters(mech: Mechanism, leg: GimbalLeg, X: Array, scale: float) -> Array:
    """The leg's squared length ‖w(s)‖² and g = 0 (N, 2) at the input rows X (scaled); g
    alone (N, 1) for a passive slide."""
    if leg.column is None:
        return np.zeros((len(X), 1))
    u, p, t = (mech.joints[k] for k in leg.joints)
    w = (t.at - u.at) + np.multiply.outer(leg.sign * X[:, leg.column], p.axis)
    return np.stack([np.einsum("ni,ni->n", w, w) / scale**2, np.zeros(len(X))], axis=1)


def gimbal_poses(mech: Mechanism, leg: GimbalLeg, world: Array, X: Array) -> dict[str, Pose]:
    """The cylinder's and piston's poses from the solved points ``world`` (N, P, 3)
    (:class:`GimbalLeg`)."""
    u, p, t = (mech.joints[k] for k in leg.joints)
    e2_0 = u.axis2 if u.bodies[0] == leg.base else u.axis
    C, E, Q = world[:, leg.centre], world[:, leg.arm], world[:, leg.ball]
    s = (leg.sign * X[:, leg.column] if leg.column is not None else
         free_slide(t.at - u.at, np.asarray(p.axis, float), np.linalg.norm(Q - C, axis=1)))
    w0 = (t.at - u.at) + np.multiply.outer(s, p.axis)
    d = Q - C
    e2 = np.cross(E - C, d)
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    # the root nearer the drawing: e2 turned least from its drawn direction (about e1)
    drawn_e2 = np.asarray(e2_0, float)
    e2 *= np.where(e2 @ drawn_e2 >= 0.0, 1.0, -1.0)[:, None]
    F0 = _frame(np.broadcast_to(drawn_e2, w0.shape), w0)
    F = _frame(e2, d)
    R = F @ np.swapaxes(F0, 1, 2)
    pc = C - np.einsum("nij,j->ni", R, u.at)
    return {leg.cylinder: (R, pc),
            leg.piston: (R, pc + np.einsum("nij,j->ni", R, p.axis) * s[:, None])}


def _frame(a: Array, b: Array) -> Array:
    """Orthonormal frames (N, 3, 3), columns a/|a|, b/|b| (b square to a) and their cross."""
    x = a / np.linalg.norm(a, axis=1)[:, None]
    y = b / np.linalg.norm(b, axis=1)[:, None]
    return np.stack([x, y, np.cross(x, y)], axis=2)


@dataclass(frozen=True)
class UniversalLeg:
    """A U–P–S leg (a Stewart–Gough platform's, outside the Stewart route): its base U on a
    placed body, its P joint driven, its ball on another body. At slide s the ball's centre Q
    is the cylinder's drawn w(s) = Q0 − C0 + σ s u from the U's centre C, turned by the U: Q
    is on the sphere ‖Q − C‖² = ‖w(s)‖², one equation; a passive slide (a platform driven at
    its pose) gives none, a strut of free length, and s is read off ‖Q − C‖
    (:func:`free_slide`, the root that is 0 at the drawn length). Its bodies are read off Q,
    the U on its root nearer the drawing (the Stewart route's rule, modes/stewart_decode.py
    ``u_rotation``; a Q out of the U's reach gives a pose that does not close, which the
    closure check drops). ``joints`` (U, P, S), the cylinder and piston, the placed base, the
    U's and the ball's centre points, the slide's input column (None: passive) and sense."""

    joints: tuple[int, int, int]
    cylinder: str
    piston: str
    base: str
    centre: int
    ball: int
    column: int | None
    sign: float


def universal_legs(mech: Mechanism, placed: set[str]) -> list[tuple[int, int, int, str, str]]:
    """(U, P, S joint indices, cylinder, piston) of every U–P–S leg (:class:`UniversalLeg`)
    whose U is on a placed body, its P joint an input or passive."""
    return [k[:5] for k in leg_chains(mech, placed, "U", "S", passive=True)]


def universal_parameters(mech: Mechanism, leg: UniversalLeg, X: Array, scale: float) -> Array:
    """The leg's squared length ‖w(s)‖² (N, 1) at the input rows X (scaled)."""
    u, p, s = (mech.joints[k] for k in leg.joints)
    w = (s.at - u.at) + np.multiply.outer(leg.sign * X[:, leg.column], p.axis)
    return (np.einsum("ni,ni->n", w, w) / scale**2)[:, None]


def universal_poses(mech: Mechanism, leg: UniversalLeg, base: Pose, world: Array, X: Array
                    ) -> dict[str, Pose]:
    """The cylinder's and piston's poses from the solved points ``world`` (N, P, 3), the base
    body at ``base`` (:class:`UniversalLeg`)."""
    from screwkit.kinematics.modes.stewart_decode import u_rotation

    u, p, b = (mech.joints[k] for k in leg.joints)
    assert u.axis2 is not None
    e1, e2 = (u.axis, u.axis2) if u.bodies[0] == leg.base else (u.axis2, u.axis)
    Rb, pb = base
    C = world[:, leg.centre]
    if leg.column is None:  # a strut of free length: the slide from the ball's distance
        s = free_slide(b.at - u.at, np.asarray(p.axis, float),
                       np.linalg.norm(world[:, leg.ball] - C, axis=1))
    else:
        s = leg.sign * X[:, leg.column]
    w = (b.at - u.at) + np.multiply.outer(s, p.axis)
    d = np.einsum("nji,nj->ni", Rb, world[:, leg.ball] - C)  # in the base's drawn frame
    R = Rb @ u_rotation(np.asarray(e1, float), np.asarray(e2, float), w, d)
    pc = C - np.einsum("nij,j->ni", R, u.at)
    return {leg.cylinder: (R, pc),
            leg.piston: (R, pc + np.einsum("nij,j->ni", R, p.axis) * s[:, None])}
