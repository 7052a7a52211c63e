"""A mechanism that is one loop, solved by the loop engine as a sub-chain of the graph (issue 26:
one solving path for loops and graphs).

:func:`loop_chain` recognises a mechanism that is a single loop — one independent cycle through
every joint and moving body, no driven body freedoms, no part made off its drawing, joints
R/P/C/H/U/S (a U joint's axes perpendicular, as the loop's U joint has them) — and builds the
equivalent :class:`~screwkit.model.linkage.Linkage` from the drawing: the inverse of
graph/from_loop.py. The loop runs from the ground through the input joint (when the input is on
the ground) round to the ground. Two forms:

* a loop driven at a ground R joint whose drawing is a family with a closed form: a planar
  four-bar (four parallel R axes) the 4R (:func:`screwkit.model.families.fourbar`, Bagci's frame
  a, crank d1, coupler d2, rocker d3 measured off the drawing), an R–S–R–C loop Bagci's RSRC
  (:func:`_rsrc`), an R–S–S–R loop the RSSR (:func:`_rssr`), an R–C–C–C loop the RCCC
  (:func:`_rccc`), an R–S–S–P loop Rahman's slider-crank CSSP (:func:`_cssp`; its quadratic in
  s4, Rahman 1996 §1.2), each placed in the world by the linkage ``base`` and kept only if its closed
  form draws the drawing's joint lines, so that ``solve_motion`` uses the family's closed form
  (Bagci 1969 eqs. 3.59–3.82, the 4R its δ0 = λ0 = b = e = 0 case; the RSSR's and the RCCC's
  A cos φ + B sin φ = C) and gives every mode;
* any loop as a joint list (``generic=True``) whose joint i has the frame F_i (origin the
  joint's drawn point, z its axis, signed so the loop runs from the joint's first body to its
  second; a U joint's y axis its second axis) and the link transforms L_i = F_i⁻¹ F_{i+1}
  (Rahman eq. 2.2 with a general screw matrix in place of X(α + εa)), base F_1. Then every
  joint variable is 0 at the drawing and equals the graph's: the graph's M_j(q)
  (model/mechanism.py) is F_i J_i(q) F_i⁻¹, or its inverse with the axis reversed (R, P, C, H:
  the same variable; a U joint's two angles swap). This is the joint list the generic loop
  solver takes.

Which single loops take which path (docs/mechanisms.md, "How a single loop drawn as a graph is
solved"): those with a closed form the family's, every mode; any other single loop the frame
form, its drawn mode followed by the loop engine's continuation (the generic loop solver's
tracker, seeded at the drawing: graph/loop_track.py), and every mode, where asked for, by the
every-mode homotopy (modes/). Measured in benchmarks/bench_graph.py, the loop engine follows
a drawn loop in the stacked closure's time or less (its RSSR rod pose, held at zero spin, costs
more); the same engine on the stacked closure (graph/follow.py) takes mechanisms of several loops.

The motion itself is graph/loop_motion.py's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.dual import ScrewMatrix
from screwkit.model.joints import Joint
from screwkit.model.linkage import Link, Linkage
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

#: drawn lines and loop joint lines agree within this fraction of the length scale (and the
#: axes within this angle, rad): the test that picks the drawn mode and checks the 4R's reading
LINE_TOL = 1e-7
#: the largest input step (rad, or this fraction of the length scale for a slide) on the
#: straight approach from the drawing to the first input row (as graph/closed_modes.py)
APPROACH_STEP = 0.05
#: axes closer to parallel than this (|u × v|) are parallel for the 4R reading
PARALLEL_TOL = 1e-12


@dataclass(frozen=True)
class LoopChain:
    """A single-loop mechanism as a loop: loop joint i is graph joint ``joints[i]``, traversed
    from graph body ``bodies[i]`` to ``bodies[i + 1]`` (``bodies[0]`` and ``bodies[-1]`` the
    ground); loop link k is graph body ``bodies[k + 1]``. Loop input k = ``offset[k]`` +
    ``sign[k]`` · graph input ``order[k]``."""

    linkage: Linkage
    joints: tuple[int, ...]
    bodies: tuple[str, ...]
    order: tuple[int, ...]
    sign: Array
    offset: Array

    def loop_inputs(self, X: Array) -> Array:
        """Graph input rows (N, n_in) as the loop's input rows."""
        return self.offset + self.sign * X[:, list(self.order)]


def loop_chain(mech: Mechanism, *, generic: bool = False) -> LoopChain | None:
    """The loop of ``mech`` as a family with a closed form (4R, RSRC, RSSR, RCCC, CSSP), when it is a
    single loop the drawing shows to be one (module docstring); else None, or with
    ``generic`` the joint list in frame form that the generic loop solver takes."""
    if mech.drives or any(j.seat_offset is not None for j in mech.joints):
        return None
    top = mech.topology
    if len(top.loops) != 1 or len(top.loops[0]) != len(mech.joints) or len(mech.joints) < 2:
        return None
    for j in mech.joints:
        if j.kind == "U" and abs(float(j.axis @ j.axis2)) > 1e-12:  # type: ignore[operator]
            return None
    order = _loop_order(mech)
    if order is None:
        return None
    joints, bodies = order
    if generic:
        return _joint_list(mech, joints, bodies)
    for family in (_fourbar, _rsrc, _rssr, _rccc, _cssp):
        found = family(mech, joints, bodies)
        if found is not None:
            return found
    return None


def _loop_order(mech: Mechanism) -> tuple[tuple[int, ...], tuple[str, ...]] | None:
    """The joints in loop order from the ground (through a ground input joint first, when
    there is one) and the bodies between them."""
    on_ground = [k for k, j in enumerate(mech.joints) if GROUND in j.bodies]
    if len(on_ground) != 2:
        return None
    driven = {x.split(".")[0] for x in mech.inputs}
    first = next((k for k in on_ground if mech.joints[k].name in driven), on_ground[0])
    joints, bodies = [first], [GROUND]
    body = _other(mech, first, GROUND)
    while body != GROUND:
        bodies.append(body)
        nxt = [k for k, j in enumerate(mech.joints) if body in j.bodies and k != joints[-1]]
        if len(nxt) != 1:
            return None
        joints.append(nxt[0])
        body = _other(mech, nxt[0], body)
    bodies.append(GROUND)
    if len(joints) != len(mech.joints):
        return None
    return tuple(joints), tuple(bodies)


def _other(mech: Mechanism, k: int, body: str) -> str:
    a, b = mech.joints[k].bodies
    return b if a == body else a


def _frame(z: Array, y_hint: Array | None, origin: Array) -> Array:
    """A 4×4 frame with z axis ``z`` (and y axis ``y_hint`` when given, perpendicular to z)."""
    if y_hint is None:
        helper = np.eye(3)[int(np.argmin(np.abs(z)))]
        x = np.cross(helper, z)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
    else:
        y = y_hint
        x = np.cross(y, z)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, y, z])
    T[:3, 3] = origin
    return T


def _screw(T: Array) -> ScrewMatrix:
    return ScrewMatrix.from_rotation_translation(T[:3, :3], T[:3, 3])


def _joint_list(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]) -> LoopChain:
    """The frame form (module docstring)."""
    frames, loop_joints, rename = [], [], {}
    for i, k in enumerate(joints):
        j = mech.joints[k]
        forward = j.bodies == (bodies[i], bodies[i + 1])
        s = 1.0 if forward else -1.0
        if j.kind == "S":
            frames.append(_frame(np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]), j.at))
        elif j.kind == "U":
            assert j.axis2 is not None
            z, y = (j.axis, j.axis2) if forward else (-j.axis2, -j.axis)
            frames.append(_frame(z, y, j.at))
            if not forward:
                rename[f"{j.name}.theta1"] = f"{j.name}.theta2"
                rename[f"{j.name}.theta2"] = f"{j.name}.theta1"
        else:
            frames.append(_frame(s * j.axis, None, j.at))
        loop_joints.append(Joint(j.name, j.kind, 0.0, j.pitch))
    n = len(joints)
    transforms = tuple(_screw(np.linalg.inv(frames[i]) @ frames[(i + 1) % n]) for i in range(n))
    graph_inputs = list(mech.inputs)
    loop_inputs = tuple(rename.get(x, x) for x in graph_inputs)
    lk = Linkage(mech.name, tuple(loop_joints), transforms,
                 tuple(Link(b) for b in bodies[1:-1]), loop_inputs, base=_screw(frames[0]))
    order = tuple(graph_inputs.index(rename.get(x, x)) for x in loop_inputs)
    n_in = len(loop_inputs)
    return LoopChain(lk, joints, bodies, order, np.ones(n_in), np.zeros(n_in))


def _fourbar(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]
             ) -> LoopChain | None:
    """A planar four-bar with its input on the ground as the 4R family (module docstring)."""
    from screwkit.model.families import fourbar

    J = [mech.joints[k] for k in joints]
    if len(J) != 4 or any(j.kind != "R" for j in J) or len(mech.inputs) != 1 \
            or mech.inputs[0] != f"{J[0].name}.theta":
        return None
    z = J[0].axis if J[0].bodies == (GROUND, bodies[1]) else -J[0].axis
    if any(float(np.linalg.norm(np.cross(z, j.axis))) > PARALLEL_TOL for j in J):
        return None
    o = J[0].at
    pts = [j.at - ((j.at - o) @ z) * z for j in J]  # every pivot in the input's plane
    d = [float(np.linalg.norm(pts[(i + 1) % 4] - pts[i])) for i in range(4)]
    if min(d) <= 1e-9 * mech.length_scale:
        return None
    x = (pts[3] - o) / d[3]
    crank = (pts[1] - o) / d[0]
    theta0 = float(np.arctan2(np.cross(x, crank) @ z, x @ crank))
    lk = fourbar(a=d[3], d1=d[0], d2=d[1], d3=d[2])
    base = _frame(z, np.cross(z, x), o)
    lk = replace(lk, name=mech.name, links=tuple(Link(b) for b in bodies[1:-1]),
                 base=_screw(base) @ lk.base)
    return LoopChain(lk, joints, bodies, (0,), np.ones(1), np.array([theta0]))


def _line_foot(c: Array, u: Array, point: Array) -> Array:
    return c + ((point - c) @ u) * u


def _common_normal(c1: Array, u1: Array, c2: Array, u2: Array) -> tuple[Array, Array] | None:
    """The feet on lines (c1, u1) and (c2, u2) of their common normal (None: parallel)."""
    n = np.cross(u1, u2)
    if float(np.linalg.norm(n)) < 1e-9:
        return None
    d = c2 - c1
    b = float(u1 @ u2)
    t1 = (d @ u1 - b * (d @ u2)) / (1.0 - b * b)
    t2 = (b * (d @ u1) - d @ u2) / (1.0 - b * b)
    return c1 + t1 * u1, c2 + t2 * u2


@dataclass(frozen=True)
class _BagciFrame:
    """The RSRC's and RSSR's frame read off a drawing: the world frame W (X the input axis, Y
    the common normal to the output axis, origin O the foot of the first ball centre on the input
    axis), d1, a, b, the foot f3 on the output axis and θ0 of the drawing."""

    W: Array
    d1: float
    a: float
    b: float
    f3: Array
    theta0: float

    def lam(self, u3: Array) -> float:
        """λ0 of the output axis direction u3 = (cos λ0, 0, −sin λ0) in W."""
        return float(np.arctan2(-(u3 @ self.W[:3, 2]), u3 @ self.W[:3, 0]))


def _bagci_frames(mech: Mechanism, J: list, bodies: tuple[str, ...]) -> list[_BagciFrame]:
    """The frame of the RSRC's and RSSR's dimensions (Bagci 1969 Fig. 5; families.py sketches)
    read off the input joint J[0], the first ball J[1] and the output joint J[3]: with Y along
    the common normal towards the output axis (a ≥ 0) first, then turned by π about X."""
    fr = _bagci_frame(mech, J, bodies)
    if fr is None:
        return []
    W = fr.W.copy()
    W[:3, 1:3] *= -1.0
    return [fr, _BagciFrame(W, fr.d1, -fr.a, fr.b, fr.f3, float(np.angle(-np.exp(1j * fr.theta0))))]


def _bagci_frame(mech: Mechanism, J: list, bodies: tuple[str, ...]) -> _BagciFrame | None:
    """:func:`_bagci_frames`' first frame."""
    X = J[0].axis if J[0].bodies == (GROUND, bodies[1]) else -J[0].axis
    ball = J[1].at
    O = _line_foot(J[0].at, X, ball)
    d1 = float(np.linalg.norm(ball - O))
    c3 = J[3].at
    n = np.cross(X, J[3].axis)
    if float(np.linalg.norm(n)) < 1e-9:  # parallel axes: the normal from the input axis
        n = (c3 - O) - ((c3 - O) @ X) * X
    if d1 <= 1e-9 * mech.length_scale or float(np.linalg.norm(n)) <= 1e-9 * mech.length_scale:
        return None
    feet = _common_normal(O, X, c3, J[3].axis)
    f3 = feet[1] if feet is not None else c3 - ((c3 - O) @ X) * X
    Y = n / np.linalg.norm(n)
    if float((f3 - O) @ Y) < 0.0:
        Y = -Y
    Z = np.cross(X, Y)
    W = np.eye(4)
    W[:3, :3] = np.column_stack([X, Y, Z])
    W[:3, 3] = O
    return _BagciFrame(W, d1, float((f3 - O) @ Y), float((f3 - O) @ X), f3,
                       float(np.arctan2((ball - O) @ Z, (ball - O) @ Y)))


def _placed(mech: Mechanism, lk: Linkage, W: Array, joints: tuple[int, ...],
            bodies: tuple[str, ...], theta0: float) -> LoopChain | None:
    """A family's loop placed in the world by W, kept if its closed form draws the drawing."""
    lk = replace(lk, name=mech.name, links=tuple(Link(x) for x in bodies[1:-1]),
                 base=_screw(W) @ lk.base)
    chain = LoopChain(lk, joints, bodies, (0,), np.ones(1), np.array([theta0]))
    return chain if _draws(mech, chain) else None


def _driven_at_ground(mech: Mechanism, J: list, kinds: str) -> bool:
    return "".join(j.kind for j in J) == kinds and len(mech.inputs) == 1 \
        and mech.inputs[0] == f"{J[0].name}.theta"


def _rsrc(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]
          ) -> LoopChain | None:
    """An R–S–R–C loop driven at its ground R joint as Bagci's RSRC
    (:func:`screwkit.model.families.rsrc`): the input axis is its X axis, through the foot O of
    the ball centre (the crank d1 in the plane X = 0, θ0 from +Y about +X); Y is the common
    normal to the output axis u3 = (cos λ0, 0, −sin λ0), which passes through (b, a, 0); d2 is the
    ball centre's distance from the coupler R axis, d3 and δ0 that axis's common normal and
    angle to the output axis, e the offset along it between the two feet. The signs of u3, e and
    δ0 the drawing does not fix are those whose loop draws the drawing's joint lines."""
    from screwkit.model.families import rsrc

    J = [mech.joints[k] for k in joints]
    if not _driven_at_ground(mech, J, "RSRC"):
        return None
    ball = J[1].at
    c2, u2 = J[2].at, J[2].axis
    d2 = float(np.linalg.norm(ball - _line_foot(c2, u2, ball)))
    normal = _common_normal(c2, u2, J[3].at, J[3].axis)
    if normal is None or d2 <= 1e-9 * mech.length_scale:
        return None
    d3 = float(np.linalg.norm(normal[1] - normal[0]))
    e = float(np.linalg.norm(normal[0] - _line_foot(c2, u2, ball)))
    delta = float(np.arccos(np.clip(abs(float(u2 @ J[3].axis)), 0.0, 1.0)))
    for fr in _bagci_frames(mech, J, bodies):
        for s3 in (1.0, -1.0):
            lam = fr.lam(s3 * J[3].axis)
            for ee in (e, -e):
                for dd in (delta, -delta, np.pi - delta, delta - np.pi):
                    chain = _placed(mech, rsrc(fr.d1, d2, d3, fr.a, fr.b, ee, dd, lam), fr.W,
                                    joints, bodies, fr.theta0)
                    if chain is not None:
                        return chain
    return None


def _rssr(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]
          ) -> LoopChain | None:
    """An R–S–S–R loop driven at its ground R joint as the RSSR family
    (:func:`screwkit.model.families.rssr`): the RSRC's frame (:func:`_rsrc`), d2 the distance
    between the ball centres, d3 the second ball's distance from the output axis and
    ``output_offset`` its offset along u3 from the foot (b, a, 0)."""
    from screwkit.model.families import rssr

    J = [mech.joints[k] for k in joints]
    if not _driven_at_ground(mech, J, "RSSR"):
        return None
    ball2 = J[2].at
    d2 = float(np.linalg.norm(ball2 - J[1].at))
    d3 = float(np.linalg.norm(ball2 - _line_foot(J[3].at, J[3].axis, ball2)))
    if min(d2, d3) <= 1e-9 * mech.length_scale:
        return None
    for fr in _bagci_frames(mech, J, bodies):
        for s3 in (1.0, -1.0):
            u3 = s3 * J[3].axis
            chain = _placed(mech, rssr(fr.d1, d2, d3, fr.a, fr.b, fr.lam(u3),
                                       float((ball2 - fr.f3) @ u3)),
                            fr.W, joints, bodies, fr.theta0)
            if chain is not None:
                return chain
    return None


def _rccc(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]
          ) -> LoopChain | None:
    """An R–C–C–C loop driven at its ground R joint as the RCCC family
    (:func:`screwkit.model.families.rccc`) in Hartenberg–Denavit form: axis i signed so the loop
    runs from the joint's first body to its second, x_i the common normal from axis i to axis
    i+1 (a_i its length, α_i the angle from axis i to axis i+1 about it), the ground frame at the
    foot of the normal from axis 4 on axis 1 (Rahman eq. 2.2); the input's offset s1 is the
    distance along axis 1 between the feet of its two normals, the drawn θ1 the angle between
    them."""
    from screwkit.model.families import rccc

    J = [mech.joints[k] for k in joints]
    if not _driven_at_ground(mech, J, "RCCC"):
        return None
    u = [j.axis if j.bodies == (bodies[i], bodies[i + 1]) else -j.axis
         for i, j in enumerate(J)]
    c = [j.at for j in J]
    xs, out_feet, in_feet = [], [], []  # per normal i → i+1: x, foot on i, foot on i+1
    for i in range(4):
        k = (i + 1) % 4
        feet = _common_normal(c[i], u[i], c[k], u[k])
        if feet is None:  # parallel axes: the normal from axis i's drawn point
            f = c[i]
            g = _line_foot(c[k], u[k], f)
        else:
            f, g = feet
        d = g - f
        if float(np.linalg.norm(d)) > 1e-12 * mech.length_scale:
            x = d / np.linalg.norm(d)
        else:
            x = np.cross(u[i], u[k])
            if float(np.linalg.norm(x)) < 1e-9:
                return None
            x /= np.linalg.norm(x)
        xs.append(x)
        out_feet.append(f)
        in_feet.append(g)
    lengths = [float((in_feet[i] - out_feet[i]) @ xs[i]) for i in range(4)]
    twists = [float(np.arctan2(np.cross(u[i], u[(i + 1) % 4]) @ xs[i], u[i] @ u[(i + 1) % 4]))
              for i in range(4)]
    g1 = in_feet[3]  # the foot of the normal 4 → 1 on axis 1
    s1 = float((out_feet[0] - g1) @ u[0])
    theta1 = float(np.arctan2(np.cross(xs[3], xs[0]) @ u[0], xs[3] @ xs[0]))
    W = np.eye(4)
    W[:3, :3] = np.column_stack([xs[3], np.cross(u[0], xs[3]), u[0]])
    W[:3, 3] = g1
    try:
        lk = rccc(tuple(lengths), tuple(twists), s1)  # type: ignore[arg-type]
    except ValueError:
        return None
    from screwkit.kinematics.registry import family_of

    if family_of(lk).closed_form_for(lk) is None:
        return None
    return _placed(mech, lk, W, joints, bodies, theta1)


def _cssp(mech: Mechanism, joints: tuple[int, ...], bodies: tuple[str, ...]
          ) -> LoopChain | None:
    """An R–S–S–P loop driven at its ground R joint as Rahman's slider-crank
    (:func:`screwkit.model.families.cssp`, Hartenberg–Denavit form M1 L2 L3 M4 = I): the ground
    frame's z axis is the crank axis, its origin the foot on it of the common normal from the
    slider's line (the second ball's path along the slide direction), its x axis along that
    normal (a4 its length, α4 the slide direction's angle to z about x); a1 and s1 the first
    ball's distance from the crank axis and its foot's height on it, a2 the distance between the
    balls."""
    from screwkit.model.families import cssp

    J = [mech.joints[k] for k in joints]
    if not _driven_at_ground(mech, J, "RSSP"):
        return None
    z = J[0].axis if J[0].bodies == (GROUND, bodies[1]) else -J[0].axis
    pin, ball, uP = J[1].at, J[2].at, J[3].axis
    feet = _common_normal(J[0].at, z, ball, uP)
    if feet is None:  # parallel: the normal through the ball
        f1, fP = _line_foot(J[0].at, z, ball), ball
    else:
        f1, fP = feet
    a4 = float(np.linalg.norm(f1 - fP))
    crank = pin - _line_foot(J[0].at, z, pin)
    a1, a2 = float(np.linalg.norm(crank)), float(np.linalg.norm(ball - pin))
    if min(a1, a2) <= 1e-9 * mech.length_scale:
        return None
    if a4 > 1e-12 * mech.length_scale:
        xs = [(f1 - fP) / a4]
    else:  # the slide line meets the crank axis: either way round the normal
        n = np.cross(uP, z)
        if float(np.linalg.norm(n)) < 1e-9:
            return None
        xs = [n / np.linalg.norm(n), -n / np.linalg.norm(n)]
    s1 = float((_line_foot(J[0].at, z, pin) - f1) @ z)
    for x in xs:
        y = np.cross(z, x)
        theta0 = float(np.arctan2(crank @ y, crank @ x))
        W = np.eye(4)
        W[:3, :3] = np.column_stack([x, y, z])
        W[:3, 3] = f1
        for sign in (1.0, -1.0):
            z4 = sign * uP
            chain = _placed(mech, cssp(a1, a2, a4, float(np.arctan2(z4 @ y, z4 @ z)), s1), W,
                            joints, bodies, theta0)
            if chain is not None:
                return chain
    return None


def _draws(mech: Mechanism, chain: LoopChain) -> bool:
    """Whether some mode of the chain's loop at its drawn input is the drawing (closed form,
    two samples; only the modes' positions where the family offers its branches)."""
    from screwkit.kinematics.registry import family_of

    lk = chain.linkage
    closed = family_of(lk).closed_form_for(lk)
    assert closed is not None
    branches_of = family_of(lk).closed_branches_for(lk)
    X = chain.offset[None, :] + np.array([[0.0], [1e-3]])
    try:
        if branches_of is None:
            motion = closed(lk, X, np.ones_like(X), np.zeros_like(X))
            return any(is_drawing(mech, chain, md) for md in motion.modes)
        # the modes' positions alone (the numbers of the modes' own: mode_poses)
        from screwkit.kinematics.tracker.loop import layout
        from screwkit.kinematics.tracker.mode_frames import mode_poses

        br = branches_of(lk, X, np.ones_like(X), np.zeros_like(X))
        lay = layout(lk)
        return any(ok[0] and is_drawing(mech, chain, mode_poses(
            lk, lay, br.configuration(m, slice(None)), ok, X)) for m, ok in enumerate(br.assembles))
    except ValueError:
        return False


def is_drawing(mech: Mechanism, chain: LoopChain, md: object) -> bool:
    """Whether a loop mode's joint lines at its first sample are the drawing's."""
    ok = md.assembles  # type: ignore[attr-defined]
    if not ok[0]:
        return False
    tol = LINE_TOL * mech.length_scale
    c, u = md.joint_centres[0], md.joint_axes[0]  # type: ignore[attr-defined]
    for i, k in enumerate(chain.joints):
        j = mech.joints[k]
        if j.kind == "S":
            if np.linalg.norm(c[i] - j.at) > tol:
                return False
            continue
        axes = [j.axis] if j.axis2 is None else [j.axis, j.axis2]
        if min(float(np.linalg.norm(np.cross(u[i], v))) for v in axes) > LINE_TOL:
            return False
        if j.kind != "P":
            off = j.at - c[i]
            if np.linalg.norm(off - (off @ u[i]) * u[i]) > tol:
                return False
    return True
