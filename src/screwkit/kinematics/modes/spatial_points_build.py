"""Building the point system of a spatial R/P/C/S/U graph (modes/spatial_points.py): its
points, the bodies' equations with the rigid groups left out, the slides and driven knees turned
so that their carried points are in the body written later, the count and generic-rank checks,
and the compiled system.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.errors import CapabilityError
from screwkit.kinematics.modes.planar import placed_by_inputs
from screwkit.kinematics.modes.spatial_point_drives import (
    PointDrive,
    check_turns,
    real_mechanism,
)
from screwkit.kinematics.modes.spatial_point_legs import (
    GimbalLeg,
    PivotLeg,
    TelescopicLeg,
    UniversalLeg,
    gimbal_legs,
    pivot_legs,
    universal_legs,
)
from screwkit.kinematics.modes.spatial_points import (
    COLLINEAR,
    MAX_UNKNOWNS,
    Array,
    BodyEquations,
    SlideJoint,
    SpatialPointFormulation,
    TurnJoint,
)
from screwkit.messages import listing
from screwkit.model.mechanism import Mechanism
from screwkit.model.spin_groups import SpinGroup, spin_groups


def _refuse(mech: Mechanism, why: str) -> CapabilityError:
    return CapabilityError(f"{mech.name}: the spatial point formulation does not take this "
                           f"mechanism: {why}")


def _placed_bodies(mech: Mechanism) -> list[tuple[str, int | None]]:
    """The ground and every body reached from it through input joints, with the joint; R
    and P inputs only."""
    placed = placed_by_inputs(mech)
    driven = {x.split(".")[0] for x in mech.inputs}
    for j in mech.joints:
        if j.name in driven and j.kind not in ("R", "P"):
            raise _refuse(mech, f"input joint {j.name!r} is a {j.kind} joint; it takes R and P "
                          "joints as inputs")
    return placed


def _across(u: Array) -> Array:
    """A unit vector square to the unit vector u."""
    n = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
    return np.asarray(n / np.linalg.norm(n))


@dataclass
class _Points:
    drawn: list[Array]
    owners: list[frozenset[str]]
    u_joints: list[tuple[int, int, int]]
    slides: list[SlideJoint]
    turns: list[TurnJoint]
    #: each S joint's centre point, each R joint's two axis points (not the inputs that place)
    centres: dict[int, int]
    axes: dict[int, tuple[int, int]]
    #: each body driven at a translation: its drive point
    drive_points: dict[str, int]


def _points(mech: Mechanism, origin: Array, scale: float, placing: set[int],
            legs: set[int], drives: tuple[PointDrive, ...] = (),
            leg_u: dict[int, str | None] | None = None) -> _Points:
    """Every joint's points (scaled drawn positions, owning bodies), the U joints' (centre,
    first arm, second arm), the P and C joints that place no body and the R inputs between
    moving bodies (module docstring); the P joints of telescopic legs (``legs``) have none; a
    body driven at a translation carries its drive point (modes/spatial_point_drives.py)."""
    drawn: list[Array] = []
    owners: list[frozenset[str]] = []
    u_joints = []
    slides: list[SlideJoint] = []
    turns: list[TurnJoint] = []
    centres: dict[int, int] = {}
    axes: dict[int, tuple[int, int]] = {}
    columns = {x.split(".")[0]: c for c, x in enumerate(mech.inputs)}

    def add(at: Array, bodies: tuple[str, ...]) -> int:
        drawn.append((at - origin) / scale)
        owners.append(frozenset(bodies))
        return len(drawn) - 1

    for k, j in enumerate(mech.joints):
        if k in legs:
            continue
        if k in placing:
            if j.kind == "R":  # its axis, in both placed bodies
                add(j.at, j.bodies)
                add(j.at + scale * j.axis, j.bodies)
            continue
        if j.kind == "S":
            centres[k] = add(j.at, j.bodies)
        elif j.kind == "R":
            ends = axes[k] = (add(j.at, j.bodies), add(j.at + scale * j.axis, j.bodies))
            if j.name in columns:  # driven between two moving bodies
                q = add(j.at + scale * _across(j.axis), (j.bodies[1],))
                turns.append(TurnJoint(k, j.bodies[0], q, columns[j.name], ends))
        elif j.kind in ("P", "C"):
            line = [j.at, j.at + scale * j.axis]
            if j.kind == "P":
                line.append(j.at + scale * _across(j.axis))
            first = tuple(add(e, (j.bodies[0],)) for e in line)
            second = tuple(add(e, (j.bodies[1],)) for e in line)
            slides.append(SlideJoint(k, first, second, columns.get(j.name)))
        elif j.kind == "U" and leg_u and k in leg_u and leg_u[k] is None:  # a U–P–S leg's
            centres[k] = add(j.at, j.bodies)
        elif j.kind == "U" and leg_u and k in leg_u:  # a gimballed leg's (modes/spatial_point_legs.py)
            assert j.axis2 is not None
            centres[k] = add(j.at, j.bodies)
            off = 1 if j.bodies[0] == leg_u[k] else 0  # the body off the leg, its axis
            arm = j.axis2 if off == 1 else j.axis
            axes[k] = (centres[k], add(j.at + scale * arm, (j.bodies[off],)))
        elif j.kind == "U":
            assert j.axis2 is not None
            c = add(j.at, j.bodies)
            a = add(j.at + scale * j.axis, (j.bodies[0],))
            b = add(j.at + scale * j.axis2, (j.bodies[1],))
            u_joints.append((c, a, b))
    drive_points = {d.body: add(d.at, (d.body,)) for d in drives if not d.is_turn}
    return _Points(drawn, owners, u_joints, slides, turns, centres, axes, drive_points)


def _third(pts: Array, b1: int, b2: int, candidates: list[int]) -> int | None:
    """The candidate farthest from the line b1 b2, or None when all are on it."""
    u = (pts[b2] - pts[b1]) / np.linalg.norm(pts[b2] - pts[b1])

    def off(m: int) -> float:
        w = pts[m] - pts[b1]
        return float(np.linalg.norm(w - (w @ u) * u))

    rest = [m for m in candidates if m not in (b1, b2)]
    if not rest:
        return None
    b3 = max(rest, key=off)
    return b3 if off(b3) > COLLINEAR else None


def _base(pts: Array, placed: list[int], order: list[int]) -> tuple[int, ...]:
    """A well-shaped base among a body's points ``order`` (placed first): the first, the
    farthest from it, the farthest from their line (two when all lie on a line). With two or
    more placed points the base is made of placed points as far as they span, so that the
    equations among placed points only are exactly the ones left out."""
    pool = placed if len(placed) >= 2 else order
    b1 = pool[0]
    b2 = max(pool[1:], key=lambda m: float(np.linalg.norm(pts[m] - pts[b1])))
    b3 = _third(pts, b1, b2, placed) if len(placed) >= 3 else None
    if b3 is None:
        b3 = _third(pts, b1, b2, order)
    return (b1, b2) if b3 is None else (b1, b2, b3)


def _body_equations(mech: Mechanism, body: str, pts: Array, members: list[int],
                    known: set[int], source: dict[int, str],
                    slid: tuple[int, ...] | list[int] = ()) -> BodyEquations:
    """The equations of one unplaced body (module docstring), leaving out those among
    points already rigid with each other: the placed points, or ``slid``, points whose
    distances other equations keep (those a slide carries over from the joint's first body,
    b_i = a_i + s (a_1 − a_0), or those the body shares with a body before it, e.g. an R
    joint's axis), whichever group is larger (the base is taken in it; the other group's
    points are carried by it)."""
    placed_here = [m for m in members if m in known]
    sources = sorted({source[m] for m in placed_here})
    if len(sources) > 1:
        raise _refuse(mech, f"body {body!r} is joined to {listing(sources)}, which the inputs "
                      "place each on its own, so at fixed inputs it cannot move and the "
                      "mechanism is locked (or it has more inputs than freedoms)")
    if slid and len(slid) >= len(placed_here):  # the larger rigid group makes the base
        placed_here = list(slid)
    known = set(placed_here)
    order = placed_here + [m for m in members if m not in known]
    if len(order) < 2 or np.linalg.norm(pts[order] - pts[order[0]], axis=1).max() <= COLLINEAR:
        raise _refuse(mech, f"body {body!r} hangs from a single point (one S joint), so it "
                      "turns freely about it; join it to another body or remove it")
    base = _base(pts, placed_here, order)
    b1, b2 = base[0], base[1]
    u = pts[b2] - pts[b1]
    pairs = [(b1, b2)] if len(base) == 2 else [(b1, b2), (b1, base[2]), (b2, base[2])]
    distances = tuple((i, j) for i, j in pairs if not (i in known and j in known))
    carried: list[int] = []
    coefficients: list[tuple[float, ...]] = []
    for m in members:
        if m in base:
            coefficients.append(())
            continue
        w = pts[m] - pts[b1]
        if len(base) == 2:
            abc: tuple[float, ...] = (float(w @ u / (u @ u)),)
            involved = {m, b1, b2}
        else:
            v = pts[base[2]] - pts[b1]
            abc = tuple(float(c) for c in np.linalg.solve(np.stack([u, v, np.cross(u, v)], 1), w))
            involved = {m, b1, b2} | ({base[2]} if max(abs(abc[1]), abs(abc[2])) > 1e-12
                                      else set())
        coefficients.append(abc)
        if not involved <= known:
            carried.append(m)
    return BodyEquations(body, tuple(members), tuple(base), distances, tuple(carried),
                         tuple(coefficients))


def spatial_point_formulation(mech: Mechanism) -> SpatialPointFormulation:
    """The point system of ``mech`` (module docstring), or a CapabilityError that says why it
    does not take the mechanism (a joint other than R, S, U or an input P; an input between
    moving bodies; a body that turns freely or is locked; freedoms left at fixed inputs)."""
    other = sorted({j.kind for j in mech.joints} - {"R", "S", "U", "P", "C"})
    if other:
        raise _refuse(mech, f"it has {listing(other)} joints; it takes R, P, C, S and U joints")
    if mech.drives:
        raise _refuse(mech, "it is driven at a body's freedom, not at joints (its augmented "
                      "mechanism, kinematics/graph/drives.py, is taken)")
    whole = mech
    mech, drives = real_mechanism(whole)  # an augmented mechanism's real one and its drives
    placed = _placed_bodies(mech)
    placing = {k for _, k in placed[1:] if k is not None}
    have = {b for b, _ in placed}
    locked = [j.name for k, j in enumerate(mech.joints)
              if k not in placing and set(j.bodies) <= have]
    if locked:
        raise _refuse(mech, f"joint(s) {listing(locked)} join two bodies the inputs place, so "
                      "the mechanism is locked at fixed inputs (or has more inputs than "
                      "freedoms)")
    origin = np.array([j.at for j in mech.joints]).mean(0)
    scale = float(mech.length_scale)
    # legs written on their balls: not where a body of theirs is driven (its drive point needs
    # the body's points), and a telescopic one only where each slid body holds one ball
    driven = {d.body for d in drives}
    telescopic = [g for g in spin_groups(mech) if _telescopic(mech, g) and not driven & set(g.bodies)]
    pivoted = [k for k in pivot_legs(mech, have) if not driven & set(k[3:5])]
    gimballed = [k for k in gimbal_legs(mech, have) if not driven & set(k[3:5])]
    swung = [k for k in universal_legs(mech, have) if not driven & set(k[3:5])]
    leg_slides = ({g.slides[0] for g in telescopic} | {k[1] for k in pivoted}
                  | {k[1] for k in gimballed} | {k[1] for k in swung})
    leg_bodies = ({b for g in telescopic for b in g.bodies} | {b for k in pivoted for b in k[3:5]}
                  | {b for k in gimballed for b in k[3:5]} | {b for k in swung for b in k[3:5]})
    # a gimballed leg's U joints: their centres and their arms on the bodies off the leg only
    leg_u: dict[int, str | None] = {}
    for ku, _, kt, cylinder, piston in gimballed:
        leg_u[ku], leg_u[kt] = cylinder, piston
    for ku, *_ in swung:  # a U–P–S leg's U: its centre only
        leg_u[ku] = None
    pts = _points(mech, origin, scale, placing, leg_slides, drives, leg_u)
    legs = [_leg(mech, g, pts, scale) for g in telescopic]
    pivots = [_pivot(mech, k, pts) for k in pivoted]
    gimbals = [_gimbal(mech, k, pts, have) for k in gimballed]
    universals = [_universal(mech, k, pts, have) for k in swung]
    drawn = np.array(pts.drawn)
    known, source = [], {}
    for k, own in enumerate(pts.owners):
        mine = [b for b, _ in placed if b in own]
        if mine:
            known.append(k)
            source[k] = mine[0]
    unknown = [k for k in range(len(drawn)) if k not in source]
    # the count depends on which rigid group each body's base is taken in, and so on the
    # order the bodies are written: nearest the inputs first, ties in the spec's order, then
    # in reverse (RSCR with an S–S dyad is square in one of the two)
    tried = []
    for ties_reversed in (False, True):
        pts = _points(mech, origin, scale, placing, leg_slides, drives, leg_u)
        order = [b for b in _body_order(mech, have, ties_reversed) if b not in leg_bodies]
        bodies = _write_bodies(mech, pts, order, have, drawn, known, source)
        passive = [sl for sl in pts.slides if sl.column is None]
        n = 3 * len(unknown) + len(passive)
        n_eq = _equation_count(bodies, pts, legs + pivots + gimbals + universals, drives)
        tried.append(n_eq)
        if n_eq == n:
            break
    if n_eq != n:
        n_eq = tried[0]
        more = n - n_eq
        why = (f"{more} freedom(s) are left at fixed inputs beyond the spins of rods about their "
               "own lines: give it as many inputs as freedoms" if more > 0 else
               f"{-more} constraint(s) more than unknowns: it is over-constrained in space "
               "(e.g. a planar or spherical loop drawn with R joints, a Bennett loop), or a "
               "body holds two groups of points already rigid (a slide and an R axis), which "
               "this formulation writes once too often; the graph tracker follows it")
        raise _refuse(mech, f"at fixed inputs its point closure has {n_eq} equations in {n} "
                      f"unknowns; {why}")
    if n == 0:
        raise _refuse(mech, "its inputs place every body (but struts of free length, which "
                      "follow their balls), so it has one mode at each input, the one the graph "
                      "tracker follows; there is nothing for the homotopy to solve")
    if n > MAX_UNKNOWNS:
        raise _refuse(mech, f"its point closure has {n} unknowns, more than {MAX_UNKNOWNS}: "
                      "the monodromy that would find its start solutions is not practical at "
                      "that size (a 3-UPU whose U axes are not square, 90 unknowns, reached one solution in 36 s); follow the drawn "
                      "mode with the graph tracker (--modes drawn)")
    check_turns(mech, drives, {be.body for be in bodies if len(be.base) == 3})
    system = _compile(unknown, known, bodies, pts, legs, pivots, drives, gimbals, universals)
    form = SpatialPointFormulation(mech, system, origin, scale, drawn, tuple(pts.owners),
                                   tuple(placed), tuple(known), tuple(unknown), tuple(bodies),
                                   tuple(pts.u_joints), source, tuple(pts.slides),
                                   tuple(pts.turns), tuple(legs), tuple(pivots), drives,
                                   tuple(pts.drive_points.get(d.body, -1) for d in drives),
                                   whole if drives else None, tuple(gimbals), tuple(universals))
    _check_rank(form)
    return form


def _equation_count(bodies: list[BodyEquations], pts: _Points,
                    legs: list[TelescopicLeg | PivotLeg | GimbalLeg | UniversalLeg],
                    drives: tuple[PointDrive, ...]) -> int:
    """The number of equations :func:`_compile` writes (a leg's: its kind's count when its
    slide is driven, one fewer when passive)."""
    driven = {TelescopicLeg: 1, PivotLeg: 2, GimbalLeg: 2, UniversalLeg: 1}
    return (sum(len(be.distances) + 3 * len(be.carried) for be in bodies)
            + len(pts.u_joints) + sum(3 * len(sl.a) for sl in pts.slides)
            + 3 * len(pts.turns) + len(drives)
            + sum(driven[type(leg)] - (leg.column is None) for leg in legs))


def _check_rank(form: SpatialPointFormulation) -> None:
    """Refuse a square system whose Jacobian is singular at a generic instance: it has
    redundant equations and leaves freedoms at fixed inputs (its solutions would be curves,
    found as none)."""
    p, x = form.random_instance(np.random.default_rng(0))
    J = form.system.evaluate(x, p[0], want_jp=False)[1][0]
    sv = np.linalg.svd(J, compute_uv=False)
    short = int(np.count_nonzero(sv <= 1e-8 * sv[0]))
    if short:
        raise _refuse(form.mechanism, f"its point closure is square but {short} of its "
                      "equations repeat others, so the mechanism keeps "
                      f"{short} freedom(s) at fixed inputs beyond the spins of rods about "
                      "their own lines (or the formulation wrote a rigid group twice): give it "
                      "as many inputs as freedoms, or follow it with the graph tracker")


def _write_bodies(mech: Mechanism, pts: _Points, order: list[str], have: set[str],
                  drawn: Array, known: list[int], source: dict[int, str]
                  ) -> list[BodyEquations]:
    """Every unplaced body's equations, written in ``order`` (slides and knees turned to it
    first), each leaving out its largest group of points already rigid."""
    rank = {b: -1 for b in have} | {b: i for i, b in enumerate(order)}
    _orient(mech, pts, rank)
    bodies: list[BodyEquations] = []
    for b in order:
        members = [k for k, own in enumerate(pts.owners) if b in own]
        joints = [j for j in mech.joints if b in j.bodies]
        if len(joints) < 2:
            raise _refuse(mech, f"body {b!r} has a single joint, so it turns freely about it; "
                          "join it to another body or remove it")
        # points other equations keep rigid: a slide's carried-over points, a driven R joint's
        # axis and turned point (its frame body is written first), points shared with a body
        # written before
        groups = [list(sl.b) for sl in pts.slides if b in pts.owners[sl.b[0]]]
        groups += [[*t.axis, t.point] for t in pts.turns if b in pts.owners[t.point]]
        groups += [[m for m in members if m in be.points and m not in source] for be in bodies]
        slid = max(groups, key=len, default=[])
        bodies.append(_body_equations(mech, b, drawn, members, set(known), source,
                                      slid if len(slid) >= 2 else ()))
    for t in pts.turns:
        frame = next(be for be in bodies if be.body == t.frame)
        if len(frame.base) != 3:
            raise _refuse(mech, f"input joint {mech.joints[t.joint].name!r} turns "
                          f"{mech.joints[t.joint].bodies[1]!r} against {t.frame!r}, whose "
                          "joints lie on one line, so the angle has no frame to be measured in")
    return bodies


def _body_order(mech: Mechanism, placed: set[str], ties_reversed: bool = False) -> list[str]:
    """The unplaced bodies, nearest the placed ones first (breadth first through the joints;
    ties in the spec's order, or its reverse), so that a body shares points mostly with bodies
    written before it."""
    depth = {b: 0 for b in placed}
    frontier = set(placed)
    while frontier:
        nxt = set()
        for j in mech.joints:
            a, b = j.bodies
            for x, y in ((a, b), (b, a)):
                if x in frontier and y not in depth:
                    depth[y] = depth[x] + 1
                    nxt.add(y)
        frontier = nxt
    rest = [b for b in mech.body_names if b not in placed]
    sign = -1 if ties_reversed else 1
    return sorted(rest, key=lambda b: (depth.get(b, 10**6), sign * rest.index(b)))


def _orient(mech: Mechanism, pts: _Points, rank: dict[str, int]) -> None:
    """Turn every slide and driven R joint so that its carried points (a slide's ``b``, a
    knee's turned point) are in the body written later: b_i = a_i − s (a_1 − a_0) and a turn
    by −θ when the joint is drawn the other way."""
    for i, sl in enumerate(pts.slides):
        first, second = mech.joints[sl.joint].bodies
        if rank[first] > rank[second]:
            pts.slides[i] = SlideJoint(sl.joint, sl.b, sl.a, sl.column, -sl.sign)
    for i, t in enumerate(pts.turns):
        first, second = mech.joints[t.joint].bodies
        if rank[first] > rank[second]:
            pts.owners[t.point] = frozenset((first,))
            pts.turns[i] = TurnJoint(t.joint, second, t.point, t.column, t.axis, -t.sign)


def _telescopic(mech: Mechanism, g: SpinGroup) -> bool:
    """Whether the spin group ``g`` is a telescopic leg the formulation writes as one distance:
    two bodies, one P joint, each body holding one of the two balls."""
    if len(g.bodies) != 2 or len(g.slides) != 1:
        return False
    holders = [set(mech.joints[k].bodies) & set(g.bodies) for k in g.balls]
    return holders[0] != holders[1]


def _leg(mech: Mechanism, g: SpinGroup, pts: _Points, scale: float) -> TelescopicLeg:
    """The telescopic leg of the spin group ``g`` (:func:`_telescopic`): its balls' points
    and joints on the P joint's first and second body, and its slide's input column."""
    k = g.slides[0]
    j = mech.joints[k]
    ball = {b: next(m for m in g.balls if b in mech.joints[m].bodies) for b in j.bodies}
    joints = (ball[j.bodies[0]], ball[j.bodies[1]])
    columns = {x.split(".")[0]: c for c, x in enumerate(mech.inputs)}
    return TelescopicLeg(k, (pts.centres[joints[0]], pts.centres[joints[1]]), joints,
                         columns.get(j.name))


def _pivot(mech: Mechanism, found: tuple[int, int, int, str, str, str], pts: _Points
           ) -> PivotLeg:
    """The pivoted leg (modes/spatial_point_legs.py) of the joints and bodies ``found``."""
    kr, kp, ks, arm, slider, base = found
    _, column, sign = _leg_ends(mech, kr, kp, slider, {base})
    return PivotLeg((kr, kp, ks), arm, slider, base, pts.axes[kr], pts.centres[ks], column,
                    sign)


def _leg_ends(mech: Mechanism, kb: int, kp: int, second: str, placed: set[str]
              ) -> tuple[str, int | None, float]:
    """A leg's placed base body (across its base joint ``kb``), its slide's input column (None:
    passive) and the slide's sense (+1: ``second`` is the P joint ``kp``'s second body)."""
    b = mech.joints[kb]
    columns = {x.split(".")[0]: c for c, x in enumerate(mech.inputs)}
    return (b.bodies[0] if b.bodies[0] in placed else b.bodies[1],
            columns.get(mech.joints[kp].name),
            1.0 if mech.joints[kp].bodies[1] == second else -1.0)


def _gimbal(mech: Mechanism, found: tuple[int, int, int, str, str], pts: _Points,
            placed: set[str]) -> GimbalLeg:
    """The gimballed leg (modes/spatial_point_legs.py) of the joints and bodies ``found``."""
    ku, kp, kt, cyl, piston = found
    base, column, sign = _leg_ends(mech, ku, kp, piston, placed)
    (c, e), (q, a) = pts.axes[ku], pts.axes[kt]
    return GimbalLeg((ku, kp, kt), cyl, piston, base, c, e, q, a, column, sign)


def _universal(mech: Mechanism, found: tuple[int, int, int, str, str], pts: _Points,
               placed: set[str]) -> UniversalLeg:
    """The U–P–S leg (modes/spatial_point_legs.py) of the joints and bodies ``found``."""
    ku, kp, ks, cyl, piston = found
    base, column, sign = _leg_ends(mech, ku, kp, piston, placed)
    return UniversalLeg((ku, kp, ks), cyl, piston, base, pts.centres[ku], pts.centres[ks],
                        column, sign)


def _sub(a: list[Poly], b: list[Poly]) -> list[Poly]:
    return [x - y for x, y in zip(a, b, strict=True)]


def _dot(a: list[Poly], b: list[Poly]) -> Poly:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(u: list[Poly], v: list[Poly]) -> list[Poly]:
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def _base_sides(point: dict[int, list[Poly]], be: BodyEquations
          ) -> tuple[list[Poly], list[Poly], list[Poly], list[Poly]]:
    """A body's base point b1 and sides u = b2 − b1, v = b3 − b1 and u × v (v and u × v
    empty for a body on a line)."""
    b1 = point[be.base[0]]
    u = _sub(point[be.base[1]], b1)
    if len(be.base) == 2:
        return b1, u, [], []
    v = _sub(point[be.base[2]], b1)
    return b1, u, v, _cross(u, v)


def _compile(unknown: list[int], known: list[int], bodies: list[BodyEquations],
             pts: _Points, legs: list[TelescopicLeg], pivots: list[PivotLeg],
             drives: tuple[PointDrive, ...], gimbals: list[GimbalLeg],
             universals: list[UniversalLeg]) -> PolynomialSystem:
    """The system of the module docstring: unknowns the solved points' (x, y, z); parameters
    the placed points', then per body its d's and coefficients, then the U joints' g, the
    driven slides, the driven turns' coefficients and the driven legs' squared lengths."""
    counter = iter(range(10**9))
    point: dict[int, list[Poly]] = {}
    for k in unknown:
        point[k] = [Poly.variable(next(counter)) for _ in range(3)]
    names = [f"{c}{k}" for k in unknown for c in "xyz"]
    slide: dict[int, Poly] = {}
    for sl in pts.slides:
        if sl.column is None:
            slide[sl.joint] = Poly.variable(next(counter))
            names.append(f"s{sl.joint}")
    for k in known:
        point[k] = [Poly.variable(next(counter)) for _ in range(3)]

    sub, dot = _sub, _dot
    eqs: list[Poly] = []
    params = [f"{c}{k}" for k in known for c in "xyz"]
    for be in bodies:
        for i, j in be.distances:
            d = sub(point[j], point[i])
            eqs.append(dot(d, d) - Poly.variable(next(counter)))
            params.append(f"d{i}_{j}")
        b1, u, v, w = _base_sides(point, be)
        for m in be.carried:
            if len(be.base) == 2:
                a = Poly.variable(next(counter))
                params.append(f"a{m}_{be.body}")
                eqs += [point[m][c] - b1[c] - a * u[c] for c in range(3)]
            else:
                a, b, c_ = (Poly.variable(next(counter)) for _ in range(3))
                params += [f"{x}{m}_{be.body}" for x in "abc"]
                eqs += [point[m][c] - b1[c] - a * u[c] - b * v[c] - c_ * w[c] for c in range(3)]
    for centre, arm1, arm2 in pts.u_joints:
        eqs.append(dot(sub(point[arm1], point[centre]), sub(point[arm2], point[centre]))
                   - Poly.variable(next(counter)))
        params.append(f"g{centre}")
    for sl in pts.slides:
        if sl.column is not None:
            slide[sl.joint] = Poly.variable(next(counter))
            params.append(f"s{sl.joint}")
    for sl in pts.slides:  # b_i = a_i + s (a_1 − a_0)
        axis = sub(point[sl.a[1]], point[sl.a[0]])
        for ia, ib in zip(sl.a, sl.b, strict=True):
            eqs += [point[ib][c] - point[ia][c] - sl.sign * slide[sl.joint] * axis[c]
                    for c in range(3)]
    for t in pts.turns:
        b1, u, v, w = _base_sides(point, next(be for be in bodies if be.body == t.frame))
        ta, tb, tc = (Poly.variable(next(counter)) for _ in range(3))
        params += [f"{x}{t.point}_turn" for x in "abc"]
        eqs += [point[t.point][c] - b1[c] - ta * u[c] - tb * v[c] - tc * w[c] for c in range(3)]
    for leg in legs:  # ‖b − a‖² = ℓ² (a passive slide: no equation, a strut of free length)
        if leg.column is not None:
            d = sub(point[leg.balls[1]], point[leg.balls[0]])
            eqs.append(dot(d, d) - Poly.variable(next(counter)))
            params.append(f"l{leg.joint}")
    for pv in pivots:  # the ball on its circle: (Q − A)·(A1 − A) = h, ‖Q − A‖² = r²
        w = sub(point[pv.ball], point[pv.axis[0]])
        eqs.append(dot(w, sub(point[pv.axis[1]], point[pv.axis[0]])) - Poly.variable(next(counter)))
        params.append(f"h{pv.joints[0]}")
        if pv.column is not None:  # (a passive slide: its plane alone)
            eqs.append(dot(w, w) - Poly.variable(next(counter)))
            params.append(f"r{pv.joints[0]}")
    for drive in drives:  # e · P_a = e · a + v; a turn Σ W_ik U_ik = h
        if drive.is_turn:  # (a body with a base triangle: check_turns)
            be = next(be for be in bodies if be.body == drive.body)
            _, u, v, w = _base_sides(point, be)
            W = [Poly.variable(next(counter)) for _ in range(9)]
            eqs.append(sum((W[3 * i + k] * col[i] for k, col in enumerate((u, v, w))
                            for i in range(3)), start=Poly.constant(0.0))
                       - Poly.variable(next(counter)))
            params += [f"W{i}{k}{drive.body}_{drive.freedom}" for i in range(3) for k in range(3)]
            params.append(f"h{drive.body}_{drive.freedom}")
            continue
        q = point[pts.drive_points[drive.body]]
        eqs.append(q["xyz".index(drive.freedom)] - Poly.variable(next(counter)))
        params.append(f"v{drive.body}_{drive.freedom}")
    for gl in gimbals:  # ‖Q − C‖² = ‖w(s)‖², ((E − C) × (Q − C))·(A − Q) = g
        pc, pe, pq, pa = (point[k] for k in (gl.centre, gl.arm, gl.ball, gl.top_arm))
        d = sub(pq, pc)
        n = _cross(sub(pe, pc), d)
        if gl.column is not None:  # (a passive slide: the second alone)
            eqs.append(dot(d, d) - Poly.variable(next(counter)))
            params.append(f"w{gl.joints[1]}")
        eqs.append(dot(n, sub(pa, pq)) - Poly.variable(next(counter)))
        params.append(f"g{gl.joints[1]}")
    for ul in universals:  # ‖Q − C‖² = ‖w(s)‖² (a passive slide: none)
        if ul.column is None:
            continue
        d = sub(point[ul.ball], point[ul.centre])
        eqs.append(dot(d, d) - Poly.variable(next(counter)))
        params.append(f"w{ul.joints[1]}")
    return compile_system(eqs, names, params)
