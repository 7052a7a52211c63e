"""Any mechanism as an immutable graph: bodies, joints between any two bodies, driven freedoms.

A :class:`Mechanism` is described the way a drawing is dimensioned: every joint is placed in one
assembled, *drawn* configuration by its point and axis in world coordinates. Every body's frame
coincides with the world frame in the drawing, so a joint's screw in either body's frame is its
drawn world screw, and the relative motion of the joint's second body with respect to its first
is the product of exponentials of those screws (Brockett's form; Murray, Li & Sastry 1994 §3.2):

    T_second = T_first · M_j(q_j),   M_j(0) = I

with, for the joint's point c and unit axis u (docs/mechanisms.md):

====  ======================================  ====================================
kind  freedoms                                M_j(q)
====  ======================================  ====================================
R     theta                                   rotation θ about the line (c, u)
P     s                                       translation s along u
C     theta, s                                rotation θ about and slide s along (c, u)
H     theta                                   rotation θ about (c, u), slide pitch·θ along u
U     theta1, theta2                          rotation θ1 about (c, u) · rotation θ2 about (c, u2)
S     wx, wy, wz (body increments)            any rotation about c
====  ======================================  ====================================

Input values are measured from the drawing (every freedom is 0 there). A single loop is the case
with one independent loop (:func:`screwkit.kinematics.graph.from_loop.mechanism_from_loop`
redraws a solved loop as a graph).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError, UnknownNameError
from screwkit.messages import given, listing
from screwkit.model.joints import JOINT_DESCRIPTIONS, JOINT_FREEDOMS
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism_drives import DRIVE_FREEDOMS, BodyDrive
from screwkit.model.mechanism_outputs import BodyAngle, Output, PointTravel

Array = NDArray[np.float64]

GROUND = "ground"
#: the largest mechanism accepted (bodies, joints): the stacked closure is dense, so its cost
#: grows with the cube of the joint count; past this the work is not bounded sensibly
MAX_BODIES = 200
MAX_JOINTS = 400
#: names a spreadsheet would evaluate as a formula when they reach a CSV header
_FORMULA_STARTS = ("=", "+", "-", "@")


class MechanismError(InputError):
    """A mechanism description that cannot be right (names, bodies, joints, inputs)."""


@dataclass(frozen=True)
class Body:
    """A moving body. ``mass`` is in the body frame, which is the world frame of the drawing
    (CAD's world-axes mass properties go in unchanged); ``None`` when no loads are asked for."""

    name: str
    mass: MassProperties | None = None


@dataclass(frozen=True, eq=False)
class MechanismJoint:
    """A joint between ``bodies[0]`` and ``bodies[1]``, placed in the drawn configuration.

    ``at`` is its point (a U or S joint's centre), ``axis`` its unit axis (a P joint's slide
    direction; a U joint's first axis, fixed in ``bodies[0]``), ``axis2`` a U joint's second
    axis (fixed in ``bodies[1]``), ``pitch`` an H joint's lead per radian (m/rad).

    ``seat_offset`` (default none) models a part made off its drawing: the joint's point is
    ``at`` in ``bodies[0]`` but ``at − seat_offset`` in ``bodies[1]``, so T_second =
    T_first · M_j(q) · Trans(seat_offset) and the drawing no longer closes; the mechanism is
    then re-assembled near it by Newton's method (kinematics/graph/motion.py, docs/sweeps.md
    "Tolerances on a graph")."""

    name: str
    kind: str
    bodies: tuple[str, str]
    at: Array
    axis: Array
    axis2: Array | None = None
    pitch: float = 0.0
    seat_offset: Array | None = None

    def __post_init__(self) -> None:
        where = f"joint {self.name!r}"
        if self.seat_offset is not None:
            object.__setattr__(self, "seat_offset",
                               point3(self.seat_offset, f"{where}: 'seat_offset'"))
        object.__setattr__(self, "at", point3(self.at, f"{where}: 'at'"))
        object.__setattr__(self, "axis", unit_vector(self.axis, f"{where}: 'axis'"))
        if self.axis2 is not None:
            object.__setattr__(self, "axis2", unit_vector(self.axis2, f"{where}: 'axis2'"))
        if not np.isfinite(self.pitch):
            raise MechanismError(f"{where}: the pitch must be a finite number")

    @property
    def freedoms(self) -> tuple[str, ...]:
        return JOINT_FREEDOMS[self.kind]

    def freedom_names(self) -> list[str]:
        return [f"{self.name}.{f}" for f in self.freedoms]


@dataclass(frozen=True)
class BodyPoint:
    """A point carried by a body, given where it is in the drawn configuration (world)."""

    name: str
    body: str
    at: Array

    def __post_init__(self) -> None:
        object.__setattr__(self, "at", point3(self.at, f"point {self.name!r}: 'at'"))


@dataclass(frozen=True)
class Topology:
    """The body–joint graph: a spanning tree from the ground and the independent loops.

    ``tree`` lists (joint index, parent body, child body) in an order where every parent is
    placed before its child; ``chords`` are the joints that close a loop; ``loops[k]`` is loop
    k as (joint index, sign) pairs, the sign +1 where the loop runs from the joint's first body
    to its second (the closure is Σ sign·S q̇ = 0 round the loop)."""

    tree: tuple[tuple[int, str, str], ...]
    chords: tuple[int, ...]
    loops: tuple[tuple[tuple[int, int], ...], ...]
    depth: dict[str, int]


def _name_ok(kind: str, name: object) -> str:
    if not isinstance(name, str) or not name.strip():
        raise MechanismError(f"{kind} name {name!r} must be a non-empty string")
    if "." in name:
        raise MechanismError(f"{kind} name {name!r} must contain no '.' (it labels variables "
                             "as '<joint>.<freedom>')")
    if name.startswith(_FORMULA_STARTS):
        raise MechanismError(f"{kind} name {name!r} must not start with '=', '+', '-' or '@' "
                             "(a spreadsheet would run it as a formula from a CSV header)")
    return name


def unit_vector(value: ArrayLike, what: str) -> Array:
    """A 3-vector scaled to unit length; a clear error for a wrong shape or zero length."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise MechanismError(f"{what} must be three numbers; got {given(value)}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise MechanismError(f"{what} must be three finite numbers; got {given(value)}")
    v = v / max(float(np.max(np.abs(v))), 1e-300)  # scaled first: no overflow in the norm
    n = float(np.linalg.norm(v))
    if n == 0.0:
        raise MechanismError(f"{what} has zero length; give a direction such as [0, 0, 1]")
    return v / n


def point3(value: ArrayLike, what: str) -> Array:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise MechanismError(f"{what} must be three numbers [x, y, z]; got {given(value)}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise MechanismError(f"{what} must be three finite numbers [x, y, z]; got {given(value)}")
    return v


@dataclass(frozen=True, eq=False)
class Mechanism:
    """Any mechanism: moving ``bodies`` (the ground is implicit, named ``"ground"``), ``joints``
    between any two bodies, the driven freedoms ``inputs`` (``"<joint>.<freedom>"``) and
    ``points`` carried by bodies. Never modified: solvers return new result objects."""

    name: str
    bodies: tuple[Body, ...]
    joints: tuple[MechanismJoint, ...]
    inputs: tuple[str, ...]
    points: tuple[BodyPoint, ...] = ()
    #: a characteristic length (m): the spread of the joint points, for scale-aware checks
    length_scale: float = field(default=0.0)
    #: named outputs (body angles, point travels), reported beside the joint variables
    outputs: tuple[Output, ...] = ()
    #: driven body freedoms (model/mechanism_drives.py), after the joint inputs
    drives: tuple[BodyDrive, ...] = ()
    #: the freedoms whose efforts hold a body-driven mechanism (one per drive), for loads
    actuated: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if len(self.bodies) > MAX_BODIES or len(self.joints) > MAX_JOINTS:
            raise MechanismError(
                f"mechanism {self.name!r}: {len(self.bodies)} bodies and {len(self.joints)} "
                f"joints; at most {MAX_BODIES} bodies and {MAX_JOINTS} joints are accepted")
        names = [_name_ok("body", b.name) for b in self.bodies]
        _unique("body", [GROUND, *names], self.name)
        _unique("joint", [_name_ok("joint", j.name) for j in self.joints], self.name)
        _unique("point", [_name_ok("point", p.name) for p in self.points], self.name)
        known = {GROUND, *names}
        for j in self.joints:
            self._check_joint(j, known)
        for p in self.points:
            if p.body not in known:
                raise UnknownNameError(f"point {p.name!r}: body {p.body!r} is not a body of "
                                       f"{self.name!r}; the bodies are {listing(sorted(known))}")
        self._check_inputs()
        self._check_outputs(known)
        self._check_drives(known)
        if not self.length_scale:
            pts = np.array([j.at for j in self.joints])
            spread = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
            object.__setattr__(self, "length_scale", max(spread, 1e-9))
        self._check_rods()
        _ = self.topology  # bodies attached to nothing are refused here

    def _check_joint(self, j: MechanismJoint, known: set[str]) -> None:
        if j.kind not in JOINT_FREEDOMS:
            raise MechanismError(
                f"joint {j.name!r}: unknown kind {j.kind!r}; use one of "
                + ", ".join(f"{k} ({v})" for k, v in JOINT_DESCRIPTIONS.items()))
        a, b = j.bodies
        for body in (a, b):
            if body not in known:
                raise UnknownNameError(f"joint {j.name!r}: body {body!r} is not a body of "
                                       f"{self.name!r}; the bodies are {listing(sorted(known))}")
        if a == b:
            raise MechanismError(f"joint {j.name!r} joins body {a!r} to itself; "
                                 "give two different bodies in 'between'")
        if j.kind == "H" and j.pitch == 0.0:
            raise MechanismError(f"joint {j.name!r}: a helical (H) joint needs a non-zero pitch")
        if j.kind == "U":
            if j.axis2 is None:
                raise MechanismError(f"joint {j.name!r}: a U joint needs 'axis2', its second axis")
            if float(np.linalg.norm(np.cross(j.axis, j.axis2))) < 1e-6:
                raise MechanismError(f"joint {j.name!r}: a U joint's two axes must not be "
                                     "parallel")

    def _check_rods(self) -> None:
        """A rod (a body held by exactly two ball joints, or a telescopic leg of bodies slid
        along the line through them: model/spin_groups.py) spins idly about that line: a
        point off the line, or an angle of one of its bodies, has no defined motion."""
        from screwkit.model.spin_groups import spin_groups

        for g in spin_groups(self):
            j0, j1 = (self.joints[k] for k in g.balls)
            a, c = j0.at, j1.at
            u = (c - a) / max(float(np.linalg.norm(c - a)), 1e-300)
            what = (f"a rod between two balls ({j0.name!r} and {j1.name!r})" if len(g.bodies) == 1
                    else f"in the leg {g.label} between the balls {j0.name!r} and {j1.name!r} "
                         "(slid by a P joint)")
            for p in self.points:
                off = p.at - a - ((p.at - a) @ u) * u
                if p.body in g.bodies and float(np.linalg.norm(off)) > 1e-9 * self.length_scale:
                    raise MechanismError(
                        f"point {p.name!r} is on {p.body!r}, {what}, off their line: the "
                        "rod's spin about that line is idle, so the point has no defined path; "
                        "put it on the line, or join the rod by a U joint at one end")
            for d in self.drives:
                off = d.at - a - ((d.at - a) @ u) * u
                if d.body in g.bodies and (not d.is_translation
                                           or float(np.linalg.norm(off)) > 1e-9 * self.length_scale):
                    raise MechanismError(
                        f"drive {d.name!r}: {d.body!r} is {what}, whose spin is idle; drive a "
                        "body the joints hold fully (or the travel of a point on the rod's "
                        "line)")
            for o in self.outputs:
                if isinstance(o, BodyAngle) and o.body in g.bodies:
                    raise MechanismError(
                        f"output {o.name!r}: {o.body!r} is {what}, whose spin is idle; measure "
                        "the angle on a body the joints hold fully")

    def _check_outputs(self, known: set[str]) -> None:
        _unique("output", [_name_ok("output", o.name) for o in self.outputs], self.name)
        unit: list[Output] = []  # directions as unit vectors (a clear error for a bad one)
        for o in self.outputs:
            if isinstance(o, BodyAngle):
                unit.append(replace(o, vector=unit_vector(o.vector, f"output {o.name!r}: vector"),
                                    about=unit_vector(o.about, f"output {o.name!r}: about")))
            else:
                unit.append(replace(o, along=unit_vector(o.along, f"output {o.name!r}: along")))
        object.__setattr__(self, "outputs", tuple(unit))
        points = {p.name for p in self.points}
        taken = set(self.freedom_names) | points
        for o in self.outputs:
            if o.name in taken:
                raise MechanismError(f"output {o.name!r}: the name is taken by a freedom or a "
                                     "point; give the output its own name")
            if isinstance(o, BodyAngle) and o.body not in known:
                raise UnknownNameError(f"output {o.name!r}: body {o.body!r} is not a body of "
                                       f"{self.name!r}; the bodies are {listing(sorted(known))}")
            if isinstance(o, BodyAngle) and np.linalg.norm(np.cross(o.vector, o.about)) < 1e-9:
                raise MechanismError(f"output {o.name!r}: 'vector' lies along 'about', so it "
                                     "turns through no angle about it; choose another vector")
            if isinstance(o, PointTravel) and o.point not in points:
                raise UnknownNameError(f"output {o.name!r}: point {o.point!r} is not a point of "
                                       f"{self.name!r}; points are {listing(sorted(points))}")

    def _check_inputs(self) -> None:
        freedoms = self.freedom_names
        if len(set(self.inputs)) != len(self.inputs):
            raise MechanismError(f"mechanism {self.name!r}: an input is named twice: "
                                 f"{listing(self.inputs)}")
        balls = {j.name for j in self.joints if j.kind == "S"}
        for inp in self.inputs:
            if inp.split(".")[0] in balls:
                raise MechanismError(f"input {inp!r}: a spherical joint's freedoms cannot be "
                                     "driven; drive an R, P, C, H or U joint")
            if inp not in freedoms:
                joint = inp.split(".")[0]
                own = [f for f in freedoms if f.split(".")[0] == joint]
                hint = (f"joint {joint!r} has {listing(own)}" if own else
                        f"there is no joint {joint!r}")
                raise MechanismError(f"input {inp!r} is not a freedom of {self.name!r} ({hint})")

    def _check_drives(self, known: set[str]) -> None:
        taken = set(self.freedom_names) | {p.name for p in self.points} | {
            o.name for o in self.outputs}
        points: dict[str, Array] = {}
        object.__setattr__(self, "drives", tuple(
            replace(d, at=point3(d.at, f"drive {d.name!r}: 'at'")) for d in self.drives))
        for d in self.drives:
            where = f"drive {d.name!r}"
            if d.freedom not in DRIVE_FREEDOMS:
                raise MechanismError(f"{where}: unknown freedom {d.freedom!r}; a body's driven "
                                     f"freedom is one of {', '.join(DRIVE_FREEDOMS)}")
            if d.body == GROUND or d.body not in known:
                raise UnknownNameError(f"{where}: {d.body!r} is not a moving body of "
                                       f"{self.name!r}; the bodies are {listing(self.body_names)}")
            if d.name in taken:
                raise MechanismError(f"{where}: the body's {d.freedom} is driven twice, or the "
                                     "name is taken by a freedom, point or output")
            taken.add(d.name)
            if d.is_translation:
                if d.body in points and np.any(points[d.body] != d.at):
                    raise MechanismError(f"{where}: the travels of one body are measured at "
                                         "one point; give every x, y, z drive of "
                                         f"{d.body!r} the same point")
                points[d.body] = d.at
        if len(set(self.actuated)) != len(self.actuated):
            raise MechanismError(f"mechanism {self.name!r}: a freedom is actuated twice: "
                                 f"{listing(self.actuated)}")
        freedoms = self.freedom_names
        balls = {j.name for j in self.joints if j.kind == "S"}
        for a in self.actuated:
            joint = a.split(".")[0]
            if joint in balls or a not in freedoms:
                own = [f for f in freedoms if f.split(".")[0] == joint]
                hint = (f"joint {joint!r} has {listing(own)}" if own else f"there is no joint {joint!r}")
                if joint in balls:
                    hint = "a ball joint has no freedom a motor can drive"
                raise MechanismError(f"actuated freedom {a!r} is not a motorised freedom of "
                                     f"{self.name!r} ({hint})")
            if a in self.inputs:
                raise MechanismError(f"actuated freedom {a!r} is also an input: an input is "
                                     "actuated already; remove one of the two")
        if self.actuated and len(self.actuated) != len(self.drives):
            raise MechanismError(
                f"mechanism {self.name!r}: {len(self.actuated)} actuated freedom(s) "
                f"({', '.join(self.actuated)}) for {len(self.drives)} driven body freedom(s); "
                f"the loads need one actuated joint freedom per driven body freedom")

    # --- derived data ----------------------------------------------------------------------
    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bodies)

    @property
    def freedom_names(self) -> list[str]:
        return [f for j in self.joints for f in j.freedom_names()]

    @property
    def driven_names(self) -> tuple[str, ...]:
        """The joint inputs, then the driven body freedoms: the columns of the input rows."""
        return (*self.inputs, *(d.name for d in self.drives))

    def driven_is_translation(self) -> list[bool]:
        """Per driven name: whether it is a length (a slide, a body's travel)."""
        slides = {j.name for j in self.joints if j.kind == "P"}
        out = [x.endswith(".s") or x.split(".")[0] in slides for x in self.inputs]
        return out + [d.is_translation for d in self.drives]

    @property
    def passive_names(self) -> list[str]:
        return [f for f in self.freedom_names if f not in self.inputs]

    def joint(self, name: str) -> MechanismJoint:
        for j in self.joints:
            if j.name == name:
                return j
        raise UnknownNameError(f"{self.name!r} has no joint {name!r}; joints are "
                               f"{[j.name for j in self.joints]}")

    def body_index(self, name: str) -> int:
        """Index of a body in :attr:`bodies` (the ground is −1)."""
        if name == GROUND:
            return -1
        names = self.body_names
        if name not in names:
            raise UnknownNameError(f"{self.name!r} has no body {name!r}; bodies are "
                                   f"{[GROUND, *names]}")
        return names.index(name)

    @cached_property
    def topology(self) -> Topology:
        """Spanning tree by breadth-first search from the ground; each chord closes one loop
        (a fundamental cycle basis of the body–joint graph)."""
        adjacent: dict[str, list[int]] = {GROUND: [], **{b: [] for b in self.body_names}}
        for k, j in enumerate(self.joints):
            adjacent[j.bodies[0]].append(k)
            adjacent[j.bodies[1]].append(k)
        parent_joint: dict[str, int] = {}
        depth = {GROUND: 0}
        order: list[tuple[int, str, str]] = []
        queue = [GROUND]
        used: set[int] = set()
        while queue:
            body = queue.pop(0)
            for k in adjacent[body]:
                if k in used:
                    continue
                a, b = self.joints[k].bodies
                other = b if a == body else a
                if other in depth:
                    continue
                used.add(k)
                depth[other] = depth[body] + 1
                parent_joint[other] = k
                order.append((k, body, other))
                queue.append(other)
        loose = [b for b in self.body_names if b not in depth]
        if loose:
            raise MechanismError(
                f"mechanism {self.name!r}: {'body' if len(loose) == 1 else 'bodies'} "
                f"{listing(loose)} {'is' if len(loose) == 1 else 'are'} attached to nothing that "
                "leads to the ground; join each to the mechanism with a joint")
        chords = tuple(k for k in range(len(self.joints)) if k not in used)
        loops = tuple(self._loop_of(c, parent_joint, depth) for c in chords)
        return Topology(tuple(order), chords, loops, depth)

    def _loop_of(self, chord: int, parent_joint: dict[str, int], depth: dict[str, int]
                 ) -> tuple[tuple[int, int], ...]:
        """The fundamental loop of a chord from body a to body b: a's tree path from the
        common ancestor down (+), the chord (+), b's path back up (−), each signed by the
        joint's own direction."""
        a, b = self.joints[chord].bodies

        def up(body: str) -> list[tuple[int, int]]:  # joints from body up to the ground
            out = []
            while body != GROUND:
                k = parent_joint[body]
                first, second = self.joints[k].bodies
                out.append((k, 1 if second == body else -1))  # +1: parent→child is first→second
                body = first if second == body else second
            return out

        pa, pb = up(a), up(b)
        common = {k for k, _ in pa} & {k for k, _ in pb}
        down_a = [(k, s) for k, s in reversed(pa) if k not in common]
        up_b = [(k, -s) for k, s in pb if k not in common]
        return (*down_a, (chord, 1), *up_b)

    def loop_joint_names(self) -> list[list[str]]:
        return [[self.joints[k].name for k, _ in loop] for loop in self.topology.loops]

    def with_bodies(self, bodies: Sequence[Body]) -> Mechanism:
        """A copy with other body data (e.g. mass properties)."""
        return Mechanism(self.name, tuple(bodies), self.joints, self.inputs, self.points,
                         self.length_scale, self.outputs, self.drives, self.actuated)

    def with_inputs(self, inputs: Sequence[str], drives: Sequence[BodyDrive] = (),
                    actuated: Sequence[str] = ()) -> Mechanism:
        """A copy driven by other joint freedoms and body freedoms (the same drawing)."""
        return Mechanism(self.name, self.bodies, self.joints, tuple(inputs), self.points,
                         self.length_scale, self.outputs, tuple(drives), tuple(actuated))


def _unique(kind: str, names: list[str], mechanism: str) -> None:
    seen: set[str] = set()
    for n in names:
        if n in seen:
            extra = " ('ground' exists already)" if n == GROUND else ""
            raise MechanismError(f"mechanism {mechanism!r}: {kind} name {n!r} is used twice"
                                 f"{extra}; give each {kind} its own name")
        seen.add(n)
