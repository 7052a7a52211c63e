"""The order in which a mechanism's bodies become placed from the ground and the inputs, by
sub-chains that have closed forms (Assur-group decomposition; Mruthyunjaya 2003, Mechanism and
Machine Theory 38(9), for the planar groups).

Two kinds of step place bodies:

- a **driven** body: joined to a placed body by a joint whose every freedom is an input (an R or
  P joint): its pose is the placed body's times the joint motion;
- a **planar dyad**: two unplaced bodies b1 and b2 joined to each other by joint J3 and each to a
  placed body (b1 to p1 by J1, b2 to p2 by J2), with nothing else joining them to a placed body.
  J1, J3 and J2 are R or P joints, none driven, forming RRR, RRP (or PRR), RPR or PRP; "planar"
  means every R axis parallel to one normal n and every P direction perpendicular to it (within
  :data:`ANGLE_TOL`, radians: a tilt ε moves points by ε·L on a mechanism of size L), and both
  placed bodies moving in planes normal to n (the ground, or bodies placed by planar steps with
  the same n). A spatial mechanism drawn planar is planar.

- a **spatial RSS leg**: a body joined to a placed body by one R joint only and, by a ball, to
  a rod whose other ball is on a placed body (the rod held by those two balls alone): the body's
  angle from the rod's length, two branches (graph/legs.py); a PSS leg the same on a P joint;
  the "rod" may be a body with a third
  ball on an S–S rod anchored on a placed body (a suspension upright and its tie rod): an "SS"
  step then turns it about its first two balls until the tie rod fits, two branches.

- a **family loop**: when nothing above applies, a loop of four joints through a driven R joint
  (its body already placed by a driven step on a placed body p) and two unplaced bodies back to
  p, whose drawing graph/loop_subchain.py reads as a family with a closed form that fixes
  every loop body (RSRC, RCCC, planar 4R; p standing for the ground): the family's closed form
  gives every loop mode relative to p, and the steps above then place what hangs on its bodies
  (graph/loop_stage.py). An RSSR or slider-crank is an RSS/PSS leg above where its rod is a
  bare S–S rod; where its rod carries more, the rod's spin (idle in the loop alone) is fixed
  by what hangs on it, jointly, so it is no sub-chain: that stays with the tracker. A planar
  4R is two steps above (a crank, an RRR dyad) unless the body it hangs on moves out of its
  plane.

What is left (a Stephenson III triad, a platform, a spatial loop) is reported as needing the
homotopy; the continuation on the stacked closure (graph/follow.py) keeps handling those. The closed forms of the steps
are in graph/dyads.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.loop_subchain import LoopChain
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

#: axes closer than this to parallel (or P directions to perpendicular), in radians, count as
#: parallel: relative to the length scale, a tilt this small moves points by 1e-9 of it
ANGLE_TOL = 1e-9
#: a dyad link shorter than this fraction of the length scale has no direction to solve for
SHORT_LINK = 1e-9

#: planar dyad kinds after orienting so that a single P sits at J2 (RRP) or J3 (RPR); "RSS"
#: is the spatial leg (graph/legs.py), held in the same record
DYAD_KINDS = ("RRR", "RRP", "RPR", "PRP")


@dataclass(frozen=True)
class Driven:
    """A body placed by a driven joint from an already placed body."""

    joint: int
    parent: str
    body: str

    def describe(self, mech: Mechanism) -> str:
        return f"{self.body!r} driven by {mech.joints[self.joint].name}"


@dataclass(frozen=True)
class Dyad:
    """Two bodies placed together: ``bodies = (b1, b2)``, ``joints = (J1, J3, J2)`` (J1 joins
    p1–b1, J3 b1–b2, J2 b2–p2), ``placed = (p1, p2)``, the kind read along J1 J3 J2, and the
    plane normal ``normal``. ``drawn_branch`` is the branch sign of the drawing (+1 or −1; +1
    for a PRP, which has one solution)."""

    kind: str
    bodies: tuple[str, str]
    joints: tuple[int, int, int]
    placed: tuple[str, str]
    normal: Array
    drawn_branch: int

    @property
    def branches(self) -> int:
        return 1 if self.kind == "PRP" else 2

    @property
    def word(self) -> str:
        return {"RSS": "leg", "PSS": "leg", "SS": "rod"}.get(self.kind, "dyad")

    def describe(self, mech: Mechanism) -> str:
        names = "–".join(mech.joints[k].name for k in self.joints)
        return (f"{self.kind} {self.word} {names} placing {self.bodies[0]!r} and "
                f"{self.bodies[1]!r}")


@dataclass(frozen=True, eq=False)
class LoopStage:
    """The bodies of a family loop (module docstring) placed together: ``joints`` the loop's
    joints in loop order from ``parent`` through the driven joint ``joints[0]`` (whose body
    a driven step placed), ``bodies`` the two bodies it places, ``chain`` the loop read as a
    family on ``sub``, the loop alone with ``parent`` as its ground (graph/loop_subchain.py)."""

    kind: str
    joints: tuple[int, ...]
    bodies: tuple[str, ...]
    parent: str
    chain: LoopChain
    sub: Mechanism

    @property
    def branches(self) -> int:
        """The family's largest count of assembly modes at one input (the RSRC's: the roots of
        a quartic, Bagci 1969 eq. 3.63), from the family registry (four where it has none)."""
        from screwkit.kinematics.registry import family_of

        return family_of(self.chain.linkage).max_modes or 4

    word = "loop"

    @property
    def loop_bodies(self) -> tuple[str, ...]:
        """The loop's moving bodies in loop order (the chain's links: the driven one first)."""
        return self.chain.bodies[1:-1]

    def describe(self, mech: Mechanism) -> str:
        names = "–".join(mech.joints[k].name for k in self.joints)
        return (f"{self.kind} loop {names} (closed form, every mode) placing "
                + " and ".join(repr(b) for b in self.bodies))


Step = Driven | Dyad | LoopStage


@dataclass(frozen=True)
class Decomposition:
    """The steps in placing order; the bodies and joints no step places or uses."""

    steps: tuple[Step, ...]
    unplaced: tuple[str, ...]
    unused_joints: tuple[int, ...]

    @property
    def complete(self) -> bool:
        """Every body is placed and every joint is used by a step (a joint left over would
        be a further constraint the closed forms do not see)."""
        return not self.unplaced and not self.unused_joints

    @property
    def dyads(self) -> tuple[Dyad, ...]:
        return tuple(s for s in self.steps if isinstance(s, Dyad))

    @property
    def loops(self) -> tuple[LoopStage, ...]:
        return tuple(s for s in self.steps if isinstance(s, LoopStage))

    @property
    def stages(self) -> tuple[Dyad | LoopStage, ...]:
        """The steps with branches (dyads, legs, loops), in placing order."""
        return tuple(s for s in self.steps if not isinstance(s, Driven))

    @property
    def mode_count(self) -> int:
        """Branch combinations: 2 per two-branch dyad, times each loop's largest mode count."""
        return int(np.prod([s.branches for s in self.stages], dtype=float))

    def describe(self, mech: Mechanism) -> list[str]:
        lines = [s.describe(mech) for s in self.steps]
        if self.unplaced:
            lines.append("needs the homotopy (no closed-form sub-chain places them): bodies "
                         + ", ".join(repr(b) for b in self.unplaced))
        elif self.unused_joints:
            lines.append("needs the homotopy: joints "
                         + ", ".join(mech.joints[k].name for k in self.unused_joints)
                         + " constrain bodies the closed forms already placed")
        return lines


def _parallel(u: Array, v: Array) -> bool:
    return float(np.linalg.norm(np.cross(u, v))) <= ANGLE_TOL


def _perpendicular(u: Array, v: Array) -> bool:
    return abs(float(u @ v)) <= ANGLE_TOL


def _normals(mech: Mechanism) -> list[Array]:
    """Candidate plane normals: the distinct R axis directions (up to sign)."""
    out: list[Array] = []
    for j in mech.joints:
        if j.kind == "R" and not any(_parallel(j.axis, n) for n in out):
            out.append(j.axis)
    return out


def _planar_in(mech: Mechanism, k: int, normals: list[Array]) -> set[int]:
    """Indices of the normals joint ``k`` keeps motion planar about (R ∥ n, P ⊥ n)."""
    j = mech.joints[k]
    if j.kind == "R":
        return {i for i, n in enumerate(normals) if _parallel(j.axis, n)}
    if j.kind == "P":
        return {i for i, n in enumerate(normals) if _perpendicular(j.axis, n)}
    return set()


def decompose(mech: Mechanism) -> Decomposition:
    """Place bodies from the ground by driven joints, planar dyads and spatial legs until
    none applies (module docstring)."""
    normals = _normals(mech)
    planes: dict[str, set[int]] = {GROUND: set(range(len(normals)))}  # placed body -> normals
    used: set[int] = set()
    steps: list[Step] = []
    inputs = {f.split(".")[0] for f in mech.inputs}
    driven = {k for k, j in enumerate(mech.joints) if j.kind in "RP" and j.name in inputs}
    joints_of: dict[str, list[int]] = {GROUND: [], **{b: [] for b in mech.body_names}}
    for k, j in enumerate(mech.joints):
        joints_of[j.bodies[0]].append(k)
        joints_of[j.bodies[1]].append(k)
    progress = True
    while progress:
        progress = False
        for k, j in enumerate(mech.joints):
            a, b = j.bodies
            if k in driven and k not in used and (a in planes) != (b in planes):
                parent, body = (a, b) if a in planes else (b, a)
                steps.append(Driven(k, parent, body))
                planes[body] = planes[parent] & _planar_in(mech, k, normals)
                used.add(k)
                progress = True
        dyad = _find_dyad(mech, planes, used, driven, normals, joints_of)
        found = (dyad,) if dyad is not None else _find_legs(mech, planes, used, driven,
                                                            joints_of)
        for step in found:
            steps.append(step)
            used.update(step.joints)
            planar = {i for i, n in enumerate(normals) if _parallel(n, step.normal)}
            for body in step.bodies:
                planes[body] = planar if step.kind in DYAD_KINDS else set()
            progress = True
        if not progress:
            loop = _find_loop(mech, planes, used, driven, steps, joints_of, normals)
            if loop is not None:
                steps.append(loop)
                used.update(loop.joints)
                planes.update({b: set() for b in loop.bodies})
                progress = True
    unplaced = tuple(b for b in mech.body_names if b not in planes)
    unused = tuple(k for k in range(len(mech.joints)) if k not in used)
    return Decomposition(tuple(steps), unplaced, unused)


def _find_dyad(mech: Mechanism, planes: dict[str, set[int]], used: set[int], driven: set[int],
               normals: list[Array], joints_of: dict[str, list[int]]) -> Dyad | None:
    """The first planar dyad on the placed bodies, or None."""
    for k3, j3 in enumerate(mech.joints):
        b1, b2 = j3.bodies
        if k3 in used or k3 in driven or b1 in planes or b2 in planes or j3.kind not in "RP":
            continue
        first = _attachments(mech, b1, planes, used, joints_of)
        second = _attachments(mech, b2, planes, used, joints_of)
        if len(first) != 1 or len(second) != 1:
            continue
        k1, k2 = first[0], second[0]
        if k1 in driven or k2 in driven:
            continue
        kinds = "".join(mech.joints[k].kind for k in (k1, k3, k2))
        if kinds == "PRR":  # orient so the P is J2
            b1, b2, k1, k2 = b2, b1, k2, k1
            kinds = "RRP"
        if kinds not in DYAD_KINDS:
            continue
        p1 = _other(mech, k1, b1)
        p2 = _other(mech, k2, b2)
        common = planes[p1] & planes[p2]
        for k in (k1, k3, k2):
            common &= _planar_in(mech, k, normals)
        if not common:
            continue
        n = normals[min(common)]
        branch = drawn_branch(mech, kinds, (k1, k3, k2), n)
        if branch is None:
            continue
        return Dyad(kinds, (b1, b2), (k1, k3, k2), (p1, p2), n, branch)
    return None


def _find_legs(mech: Mechanism, planes: dict[str, set[int]], used: set[int],
               driven: set[int], joints_of: dict[str, list[int]]) -> tuple[Dyad, ...]:
    """The first RSS (or PSS) leg on the placed bodies (graph/legs.py), or (): a body b joined
    to a placed body by one passive R (or P) joint only and by a ball to a rod, the rod held by that ball
    and one ball on a placed body, and by nothing else. The rod may instead be a body held by
    a third ball to an S–S rod whose other ball is on a placed body (a suspension's upright
    with its tie rod): then a second step fixes its spin about its first two balls."""
    from screwkit.kinematics.graph.legs import drawn_leg_branch, drawn_slide_branch

    for rod in mech.body_names:
        own = joints_of[rod]
        if rod in planes or len(own) not in (2, 3) or any(mech.joints[k].kind != "S"
                                                          for k in own):
            continue
        for kc in own:
            body = _other(mech, kc, rod)
            rest = [k for k in own if k != kc]
            anchored = [k for k in rest if _other(mech, k, rod) in planes]
            if body in planes or len(anchored) != 1:
                continue
            kb = anchored[0]
            tie = [k for k in rest if k != kb]
            axis = mech.joints[kc].at - mech.joints[kb].at
            axis = axis / max(float(np.linalg.norm(axis)), 1e-300)
            spin = _spin_step(mech, planes, joints_of, rod, kb, tie[0], axis) if tie else None
            if tie and spin is None:
                continue
            hold = _attachments(mech, body, planes, used, joints_of)
            if len(hold) != 1 or mech.joints[hold[0]].kind not in "RP" or hold[0] in driven:
                continue
            joints = (hold[0], kc, kb)
            kind = mech.joints[hold[0]].kind + "SS"
            branch = (drawn_leg_branch if kind == "RSS" else drawn_slide_branch)(mech, joints)
            if branch is None:
                continue
            leg = Dyad(kind, (body, rod), joints,
                       (_other(mech, hold[0], body), _other(mech, kb, rod)),
                       mech.joints[hold[0]].axis, branch)
            return (leg,) if spin is None else (leg, spin)
    return ()


#: the joint kinds, read from the driven joint, of loops whose family fixes every loop body
#: (the planar 4R, the RSRC, the RCCC; loop_subchain.py reads the family). Not the RSSR nor the
#: CSSP: their coupler is a rod between two balls whose spin the loop leaves idle, so a loop
#: body whose pose the loop alone does not fix; with nothing more on the rod they are RSS and
#: PSS legs, and with more on it the rod's spin is fixed by what hangs on it, jointly
LOOP_KINDS = ("RRRR", "RSRC", "RCCC")


def _find_loop(mech: Mechanism, planes: dict[str, set[int]], used: set[int], driven: set[int],
               steps: list[Step], joints_of: dict[str, list[int]], normals: list[Array]
               ) -> LoopStage | None:
    """The first family loop (module docstring) through a body a driven R joint placed, or
    None: the loop P –k– c –j2– b2 –j3– b3 –j4– P with b2, b3 unplaced and j2, j3, j4 unused
    and not driven, read by graph/loop_subchain.py's ``loop_chain`` on the loop alone. A planar
    4R only where P moves out of its plane (else it is a crank and an RRR dyad, or a dyad
    refused for a reason that holds for the loop too, such as a drawing on its fold)."""
    from screwkit.kinematics.graph.loop_subchain import loop_chain
    from screwkit.kinematics.registry import family_of

    for step in steps:
        if not isinstance(step, Driven) or mech.joints[step.joint].kind != "R":
            continue
        k, P, c = step.joint, step.parent, step.body
        free = [j for j in joints_of[c] if j not in used and j not in driven]
        for j2 in free:
            b2 = _other(mech, j2, c)
            if b2 in planes:
                continue
            for j3 in joints_of[b2]:
                b3 = _other(mech, j3, b2)
                if j3 == j2 or j3 in used or j3 in driven or b3 in planes or b3 == c:
                    continue
                for j4 in joints_of[b3]:
                    if j4 in (j3, j2) or j4 in used or j4 in driven \
                            or _other(mech, j4, b3) != P:
                        continue
                    loop = (k, j2, j3, j4)
                    kinds = "".join(mech.joints[i].kind for i in loop)
                    if kinds not in LOOP_KINDS or (kinds == "RRRR" and any(
                            _parallel(mech.joints[k].axis, normals[n]) for n in planes[P])):
                        continue
                    sub = _loop_alone(mech, loop, (c, b2, b3), P)
                    chain = loop_chain(sub)
                    if chain is not None:
                        return LoopStage(family_of(chain.linkage).name, loop, (b2, b3), P,
                                         chain, sub)
    return None


def _loop_alone(mech: Mechanism, loop: tuple[int, ...], bodies: tuple[str, ...], parent: str
                ) -> Mechanism:
    """The loop's joints and bodies as a mechanism of their own, ``parent`` as its ground,
    driven by ``loop[0]``'s angle, at the whole mechanism's length scale."""
    from dataclasses import replace

    from screwkit.model.mechanism import Body

    rename = {parent: GROUND, GROUND: parent}  # the parent may itself be the ground
    joints = tuple(replace(j, bodies=(rename.get(j.bodies[0], j.bodies[0]),
                                      rename.get(j.bodies[1], j.bodies[1])))
                   for j in (mech.joints[k] for k in loop))
    return Mechanism(f"{mech.name}: loop", tuple(Body(b) for b in bodies), joints,
                     (f"{mech.joints[loop[0]].name}.theta",), length_scale=mech.length_scale)


def _spin_step(mech: Mechanism, planes: dict[str, set[int]], joints_of: dict[str, list[int]],
               body: str, kb: int, kt: int, axis: Array) -> Dyad | None:
    """The step fixing ``body``'s spin about the line through its ball ``kb`` along ``axis``
    (drawn; towards its other ball) by the S–S rod on its ball ``kt`` (graph/legs.py), or
    None where that is not the shape (or it is drawn on its fold)."""
    from screwkit.kinematics.graph.legs import drawn_spin_branch

    tie = _other(mech, kt, body)
    own = joints_of[tie]
    if tie in planes or len(own) != 2 or any(mech.joints[k].kind != "S" for k in own):
        return None
    kti = own[0] if own[1] == kt else own[1]
    anchor = _other(mech, kti, tie)
    if anchor not in planes:
        return None
    branch = drawn_spin_branch(mech, (kb, kt, kti), axis)
    if branch is None:
        return None
    return Dyad("SS", (body, tie), (kb, kt, kti), (body, anchor), axis, branch)


def _attachments(mech: Mechanism, body: str, planes: dict[str, set[int]], used: set[int],
                 joints_of: dict[str, list[int]]) -> list[int]:
    """Unused joints from ``body`` to an already placed body."""
    return [k for k in joints_of[body] if k not in used and _other(mech, k, body) in planes]


def _other(mech: Mechanism, k: int, body: str) -> str:
    a, b = mech.joints[k].bodies
    return b if a == body else a


def _in_plane(v: Array, n: Array) -> Array:
    return v - (v @ n) * n


def drawn_branch(mech: Mechanism, kind: str, joints: tuple[int, int, int], n: Array
                 ) -> int | None:
    """The branch sign of the drawing (graph/dyads.py's conventions), or None where the
    dyad is degenerate in the drawing (a link of no length, parallel slides) or drawn on a
    fold (its links in line: the two branches meet there)."""
    L = mech.length_scale
    j1, j3, j2 = (mech.joints[k] for k in joints)
    if kind == "RRR":
        w0 = _in_plane(j2.at - j1.at, n)
        r1 = _in_plane(j3.at - j1.at, n)
        r2 = _in_plane(j3.at - j2.at, n)
        if min(np.linalg.norm(w0), np.linalg.norm(r1), np.linalg.norm(r2)) <= SHORT_LINK * L:
            return None
        side = float(n @ np.cross(w0, r1)) / float(np.linalg.norm(w0))  # B's height over A–C
    elif kind == "RRP":
        r1 = _in_plane(j3.at - j1.at, n)
        if np.linalg.norm(r1) <= SHORT_LINK * L:
            return None
        side = float(r1 @ j2.axis)
    elif kind == "RPR":
        side = float(_in_plane(j2.at - j1.at, n) @ j3.axis)
    else:  # PRP: one solution where the two slides cross
        return None if abs(float(n @ np.cross(j1.axis, j2.axis))) <= ANGLE_TOL else 1
    # a drawing on a fold (the dyad's links in line) belongs to neither branch: the tracker
    # decides there
    if abs(side) <= SHORT_LINK * L:
        return None
    return 1 if side > 0.0 else -1
