"""Any spatial graph of R, P, C, S and U joints as a polynomial system in its joints' points.

The spatial counterpart of the planar formulation (modes/planar.py), after the "natural
coordinates" of García de Jalón & Bayo (*Kinematic and Dynamic Simulation of Multibody
Systems*, 1994, ch. 2): every body is carried by points, and every constraint is quadratic.

- An S joint is one point, its centre, in both bodies.
- An R joint is two points on its axis (its point and one length unit along the axis), in both
  bodies: the bodies may turn about the line through them and nothing else. Driven between two
  moving bodies, its second body also carries a point one unit across the axis, which the
  first body's base carries with coefficients that follow the input angle.
- A U joint is its centre in both bodies, a point one unit along its first axis in its first
  body and one along its second axis in its second body, and one equation: the two arms keep
  their drawn angle, (A − C)·(B − C) = g.
- A P joint is three points in each body (its point, one unit along the axis, one unit across
  it) and a C joint the first two; the second body's are the first body's slid along the axis,
  b_i = a_i + s (a_1 − a_0), with the slide s an unknown, or a parameter when it is an input.
- A P or R input that joins a body to the ground, or to a body so placed, places it.

At given input values the ground and every body driven from it through input joints are
placed; the points they carry are parameters. Every other point (x, y, z) is an unknown, and
each remaining body with points P_1, …, P_k (its base b1, b2, b3 taken among them, the points
the inputs place first) gives

    ‖b2 − b1‖² = d12,  ‖b3 − b1‖² = d13,  ‖b3 − b2‖² = d23     (its base triangle)
    P_m = b1 + a_m u + b_m v + c_m (u × v),  u = b2 − b1, v = b3 − b1   (every other point)

(a triangle fixed by its three sides is the same up to a rotation, so no mirror image is
admitted; the cross product keeps every other point on its own side). A body whose points lie
on one line (an S–S rod, an R axis with a ball on it) has one distance and P_m = b1 + a_m u:
its spin about that line is idle and is not an unknown. Equations among points whose distances
hold already are left out: among placed points, among the points a slide carries over, among
points a body shares with one written before it (an R joint's axis), and among a driven R
joint's axis and turned point; the base is taken in the largest such group. The system is square exactly when the mechanism has no
freedom left at fixed inputs but its rods' spins (otherwise, or with more than
:data:`MAX_UNKNOWNS` unknowns, the formulation refuses it by name); every equation is of degree
two, so the total degree is 2^n.

Coordinates are taken from the centroid of the drawn joints in units of the mechanism's length
scale. Every parameter (the placed points, the squared distances, the carried points'
coefficients, the U joints' angles) is free, so a real mechanism is a member of the generic
family whose start solutions are found once: by the total-degree homotopy when it has at most
:data:`TOTAL_DEGREE_LIMIT` paths, then looped round monodromy loops from those solutions (a
system of natural coordinates has solution sets at infinity, and the total-degree homotopy
loses paths there: 23 of the double wishbone's 64), else by monodromy from a random complex
instance; monodromy stops when :data:`STALE_LOOPS` loops in a row find nothing new, so its
count is a lower bound on the generic count, and ``how_found`` says so.

The solutions are turned into body poses (the rotation that carries a body's drawn points onto
its solved ones, Kabsch's least-squares fit, exact for a rigid image; the least rotation for a
body on a line) and from them into joint variables (modes/stewart_decode.py ``joint_values``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.algebraic.solve import StartSolutions
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout, joint_motion
from screwkit.kinematics.modes.rod_loops import least_rotation
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.modes.stewart_decode import Pose, joint_values
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import listing
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]
#: start solutions by the total-degree homotopy up to this many paths, else by monodromy
TOTAL_DEGREE_LIMIT = 1024
#: monodromy stops after this many loops in a row find nothing new (the five-link example's
#: 40 need 42 loops from seed 0; at 6 it stopped at 37)
STALE_LOOPS = 24
#: larger point systems are refused (monodromy there is slow and unreliable: module docstring)
MAX_UNKNOWNS = 48
#: a body's points lie on one line when none is farther than this (in length units) from it
COLLINEAR = 1e-9


@dataclass(frozen=True)
class BodyEquations:
    """One unplaced body's equations: its base points (indices into the formulation's points;
    two for a body on a line), the distance pairs kept, the carried points kept, and the
    drawn coefficients of every carried point (a, b, c; a only on a line)."""

    body: str
    points: tuple[int, ...]
    base: tuple[int, ...]
    distances: tuple[tuple[int, int], ...]
    carried: tuple[int, ...]
    coefficients: tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class SlideJoint:
    """A P or C joint that places no body: its points in the first body (``a``: the joint's
    point, one unit along its axis and, for a P joint, one unit across it) and the same
    drawn points in the second (``b``), with b_i = a_i + s (a_1 − a_0); ``column`` the input
    column of its slide when it is an input (then s is a parameter), else None (s an
    unknown)."""

    joint: int
    a: tuple[int, ...]
    b: tuple[int, ...]
    column: int | None


@dataclass(frozen=True)
class TurnJoint:
    """An R joint driven between two moving bodies: the point ``point`` of its second body
    (one unit across the axis) is carried by the first body's base with coefficients that
    follow the input (column ``column``)."""

    joint: int
    frame: str
    point: int
    column: int
    axis: tuple[int, int] = (-1, -1)


@dataclass(frozen=True)
class SpatialPointFormulation:
    """The point system of one mechanism (module docstring) and how to read its solutions.

    ``drawn`` every point's drawn position (P, 3) in scaled coordinates ((x − origin)/scale);
    ``owners`` the bodies carrying each point; ``placed`` the bodies the inputs place (ground
    first, each with the input joint that places it); ``known`` and ``unknown`` the points
    placed and solved; ``bodies`` the unplaced bodies' equations; ``u_joints`` each U joint's
    (centre, first-arm point, second-arm point)."""

    mechanism: Mechanism
    system: PolynomialSystem
    origin: Array
    scale: float
    drawn: Array
    owners: tuple[frozenset[str], ...]
    placed: tuple[tuple[str, int | None], ...]
    known: tuple[int, ...]
    unknown: tuple[int, ...]
    bodies: tuple[BodyEquations, ...]
    u_joints: tuple[tuple[int, int, int], ...]
    source: dict[int, str] = field(default_factory=dict)
    slides: tuple[SlideJoint, ...] = ()
    turns: tuple[TurnJoint, ...] = ()

    def _frame_of(self, body: str) -> BodyEquations:
        return next(be for be in self.bodies if be.body == body)

    def _turn_coefficients(self, t: TurnJoint, X: Array) -> Array:
        """The driven point's coefficients (N, 3) in its first body's base at inputs X."""
        j = self.mechanism.joints[t.joint]
        be = self._frame_of(t.frame)
        d = self.drawn
        c = (j.at - self.origin) / self.scale
        th = X[:, t.column]
        q0 = d[t.point] - c
        u = j.axis
        turned = (c + np.multiply.outer(np.cos(th), q0)
                  + np.multiply.outer(np.sin(th), np.cross(u, q0))
                  + np.multiply.outer(1.0 - np.cos(th), (u @ q0) * u))
        b1, b2, b3 = be.base
        e1, e2 = d[b2] - d[b1], d[b3] - d[b1]
        M = np.stack([e1, e2, np.cross(e1, e2)], 1)
        return np.asarray(np.linalg.solve(M, (turned - d[b1]).T).T)

    # ----------------------------------------------------------------- parameters
    def parameters(self, input_values: ArrayLike) -> Array:
        """Parameters at input values (N, n_inputs) or (n_inputs,): the placed points'
        scaled (x, y, z), then per body its squared distances and carried coefficients, then
        each U joint's g, then the driven slides (scaled) and the driven turns' coefficients."""
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        poses = self.placed_poses(X)
        cols = [self._placed_point(k, poses) for k in self.known]
        known = np.stack(cols, 1).reshape(X.shape[0], -1) if cols else np.zeros((X.shape[0], 0))
        const = self._constants(self.drawn)
        driven = [X[:, sl.column:sl.column + 1] / self.scale for sl in self.slides
                  if sl.column is not None]
        driven += [self._turn_coefficients(t, X) for t in self.turns]
        return np.hstack([known, np.broadcast_to(const, (X.shape[0], const.size)), *driven])

    def _constants(self, pts: ArrayLike) -> NDArray[np.complex128] | Array:
        """The distance, coefficient and U parameters of the points ``pts`` (P, 3)."""
        pts = np.asarray(pts)
        out: list[complex] = []
        for be in self.bodies:
            out += [complex((pts[j] - pts[i]) @ (pts[j] - pts[i])) for i, j in be.distances]
            out += [c for m in be.carried for c in be.coefficients[be.points.index(m)]]
        out += [complex((pts[a] - pts[c]) @ (pts[b] - pts[c])) for c, a, b in self.u_joints]
        arr = np.array(out, dtype=complex)
        return arr.real if np.isrealobj(pts) else arr

    def placed_poses(self, X: Array) -> dict[str, Pose]:
        """World poses (R (N, 3, 3), p (N, 3)) of the placed bodies at the input rows X."""
        mech = self.mechanism
        lay = graph_layout(mech)
        N = X.shape[0]
        conf = Configuration(np.zeros((N, lay.n_scalar)),
                             np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy())
        for c, f in enumerate(lay.inputs):
            conf.scalars[:, lay.scalar_col[f]] = X[:, c]
        poses: dict[str, Pose] = {GROUND: (np.broadcast_to(np.eye(3), (N, 3, 3)),
                                           np.zeros((N, 3)))}
        for body, k in self.placed[1:]:
            assert k is not None
            j = mech.joints[k]
            Mr, Mp = joint_motion(mech, lay, conf, k)
            parent = j.bodies[0] if j.bodies[1] == body else j.bodies[1]
            if j.bodies[0] != parent:  # placed against the joint's direction: M⁻¹
                Mr = np.swapaxes(Mr, -1, -2)
                Mp = -np.einsum("nij,nj->ni", Mr, Mp)
            Ra, pa = poses[parent]
            poses[body] = (Ra @ Mr, np.einsum("nij,nj->ni", Ra, Mp) + pa)
        return poses

    def _placed_point(self, k: int, poses: dict[str, Pose]) -> Array:
        """Point k (placed) in scaled coordinates at each row (N, 3)."""
        R, p = poses[self.source[k]]
        world = np.einsum("nij,j->ni", R, self.origin + self.scale * self.drawn[k]) + p
        return (world - self.origin) / self.scale

    # ------------------------------------------------------------ start solutions
    def random_instance(self, rng: np.random.Generator) -> tuple[Complex, Complex]:
        """A random complex instance with a known solution (p (1, k), x (1, n)): random
        points (a body on a line keeps its carried points on the line), the parameters
        computed from them."""
        P = len(self.drawn)
        pts = rng.standard_normal((P, 3)) + 1j * rng.standard_normal((P, 3))
        slide = {}
        for sl in self.slides:  # b_i = a_i + s (a_1 − a_0)
            slide[sl.joint] = rng.standard_normal() + 1j * rng.standard_normal()
            for ia, ib in zip(sl.a, sl.b, strict=True):
                pts[ib] = pts[ia] + slide[sl.joint] * (pts[sl.a[1]] - pts[sl.a[0]])
        coef = {}
        for be in self.bodies:
            b1, b2 = be.base[0], be.base[1]
            u = pts[b2] - pts[b1]
            for m in be.points:
                if m in be.base:
                    continue
                if len(be.base) == 2:  # on a line: P_m = b1 + a u
                    along = rng.standard_normal() + 1j * rng.standard_normal()
                    if m not in self.known or m in be.carried:
                        pts[m] = pts[b1] + along * u
                    coef[(be.body, m)] = (along,)
                else:
                    v = pts[be.base[2]] - pts[b1]
                    abc = np.linalg.solve(np.stack([u, v, np.cross(u, v)], 1), pts[m] - pts[b1])
                    coef[(be.body, m)] = tuple(abc)
        out: list[complex] = [c for k in self.known for c in pts[k]]
        for be in self.bodies:
            out += [complex((pts[j] - pts[i]) @ (pts[j] - pts[i])) for i, j in be.distances]
            out += [c for m in be.carried for c in coef[(be.body, m)]]
        out += [complex((pts[a1] - pts[c]) @ (pts[a2] - pts[c])) for c, a1, a2 in self.u_joints]
        out += [slide[sl.joint] for sl in self.slides if sl.column is not None]
        for t in self.turns:
            b1, b2, b3 = self._frame_of(t.frame).base
            u, v = pts[b2] - pts[b1], pts[b3] - pts[b1]
            out += list(np.linalg.solve(np.stack([u, v, np.cross(u, v)], 1),
                                        pts[t.point] - pts[b1]))
        x = np.concatenate([pts[list(self.unknown)].reshape(-1),
                            [slide[sl.joint] for sl in self.slides if sl.column is None]])
        return np.array(out, dtype=complex)[None, :], x[None, :]

    def start(self) -> StartSolutions:
        """The topology's start solutions (module docstring): total degree up to
        :data:`TOTAL_DEGREE_LIMIT` paths, else monodromy."""
        return start_solutions(self.system, self.random_instance,
                               total_degree_paths=TOTAL_DEGREE_LIMIT, then_monodromy=True,
                               stale_loops=STALE_LOOPS)

    # ------------------------------------------------------------- configurations
    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """Graph-tracker configurations (N) of real solutions (N, 3u) at the input values."""
        sol = np.real(np.asarray(solutions))
        N = sol.shape[0]
        mech = self.mechanism
        X = np.broadcast_to(np.atleast_2d(np.asarray(input_values, dtype=float)),
                            (N, len(mech.inputs)))
        poses = self.placed_poses(np.ascontiguousarray(X))
        world = np.empty((N, len(self.drawn), 3))
        for k in self.known:
            world[:, k] = self._placed_point(k, poses)
        world[:, list(self.unknown)] = sol[:, :3 * len(self.unknown)].reshape(
            N, len(self.unknown), 3)
        world = self.origin + self.scale * world
        drawn = self.origin + self.scale * self.drawn
        for be in self.bodies:
            poses[be.body] = _fit_pose(drawn[list(be.points)], world[:, list(be.points)],
                                       len(be.base) == 2)
        lay = graph_layout(mech)
        return joint_values(mech, lay, poses), lay


def _fit_pose(drawn: Array, solved: Array, on_a_line: bool) -> Pose:
    """The pose (R (N, 3, 3), p (N, 3)) carrying a body's drawn points (k, 3) onto its solved
    ones (N, k, 3): Kabsch's rotation (exact for a rigid image), or the least rotation of the
    first two points' direction for a body on a line."""
    if on_a_line:
        R = least_rotation(drawn[1] - drawn[0], solved[:, 1] - solved[:, 0])
        return R, solved[:, 0] - np.einsum("nij,j->ni", R, drawn[0])
    dc = drawn.mean(0)
    sc = solved.mean(1)
    H = np.einsum("ki,nkj->nij", drawn - dc, solved - sc[:, None])
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.swapaxes(Vt, -1, -2) @ np.swapaxes(U, -1, -2)))
    D = np.broadcast_to(np.eye(3), H.shape).copy()
    D[:, 2, 2] = d
    R = np.swapaxes(Vt, -1, -2) @ D @ np.swapaxes(U, -1, -2)
    return R, sc - np.einsum("nij,j->ni", R, dc)


# --------------------------------------------------------------------------- building
def _refuse(mech: Mechanism, why: str) -> CapabilityError:
    return CapabilityError(f"{mech.name}: the spatial point formulation does not take this "
                           f"mechanism: {why}")


def _placed_bodies(mech: Mechanism) -> list[tuple[str, int | None]]:
    """The ground and every body reached from it through input joints, with the joint."""
    driven = {x.split(".")[0] for x in mech.inputs}
    placed: list[tuple[str, int | None]] = [(GROUND, None)]
    grew = True
    while grew:
        grew = False
        have = {b for b, _ in placed}
        for k, j in enumerate(mech.joints):
            if j.name in driven and (j.bodies[0] in have) != (j.bodies[1] in have):
                placed.append((j.bodies[1] if j.bodies[0] in have else j.bodies[0], k))
                grew = True
                break
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


def _points(mech: Mechanism, origin: Array, scale: float, placing: set[int]) -> _Points:
    """Every joint's points (scaled drawn positions, owning bodies), the U joints' (centre,
    first arm, second arm), the P and C joints that place no body and the R inputs between
    moving bodies (module docstring)."""
    drawn: list[Array] = []
    owners: list[frozenset[str]] = []
    u_joints = []
    slides: list[SlideJoint] = []
    turns: list[TurnJoint] = []
    columns = {x.split(".")[0]: c for c, x in enumerate(mech.inputs)}

    def add(at: Array, bodies: tuple[str, ...]) -> int:
        drawn.append((at - origin) / scale)
        owners.append(frozenset(bodies))
        return len(drawn) - 1

    for k, j in enumerate(mech.joints):
        if k in placing:
            if j.kind == "R":  # its axis, in both placed bodies
                add(j.at, j.bodies)
                add(j.at + scale * j.axis, j.bodies)
            continue
        if j.kind == "S":
            add(j.at, j.bodies)
        elif j.kind == "R":
            ends = (add(j.at, j.bodies), add(j.at + scale * j.axis, j.bodies))
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
        elif j.kind == "U":
            assert j.axis2 is not None
            c = add(j.at, j.bodies)
            a = add(j.at + scale * j.axis, (j.bodies[0],))
            b = add(j.at + scale * j.axis2, (j.bodies[1],))
            u_joints.append((c, a, b))
    return _Points(drawn, owners, u_joints, slides, turns)


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
        raise _refuse(mech, "it is driven at a body's freedom, not at joints")
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
    pts = _points(mech, origin, scale, placing)
    drawn = np.array(pts.drawn)
    known, source = [], {}
    for k, own in enumerate(pts.owners):
        mine = [b for b, _ in placed if b in own]
        if mine:
            known.append(k)
            source[k] = mine[0]
    unknown = [k for k in range(len(drawn)) if k not in source]
    bodies: list[BodyEquations] = []
    for b in mech.body_names:
        if b in have:
            continue
        members = [k for k, own in enumerate(pts.owners) if b in own]
        joints = [j for j in mech.joints if b in j.bodies]
        if len(joints) < 2:
            raise _refuse(mech, f"body {b!r} has a single joint, so it turns freely about it; "
                          "join it to another body or remove it")
        groups = [list(sl.b) for sl in pts.slides if mech.joints[sl.joint].bodies[1] == b]
        # a driven R joint's axis and turned point are all placed by its first body's frame
        groups += [[*t.axis, t.point] for t in pts.turns if mech.joints[t.joint].bodies[1] == b
                   and any(be.body == t.frame for be in bodies)]
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
    passive = [sl for sl in pts.slides if sl.column is None]
    n = 3 * len(unknown) + len(passive)
    n_eq = (sum(len(be.distances) + 3 * len(be.carried) for be in bodies) + len(pts.u_joints)
            + sum(3 * len(sl.a) for sl in pts.slides) + 3 * len(pts.turns))
    if n_eq != n:
        more = n - n_eq
        why = (f"{more} freedom(s) are left at fixed inputs beyond the spins of rods about their "
               "own lines: give it as many inputs as freedoms" if more > 0 else
               f"{-more} constraint(s) more than unknowns: it is over-constrained in space "
               "(e.g. a planar or spherical loop drawn with R joints, a Bennett loop); the "
               "graph tracker follows it")
        raise _refuse(mech, f"at fixed inputs its point closure has {n_eq} equations in {n} "
                      f"unknowns; {why}")
    if n > MAX_UNKNOWNS:
        raise _refuse(mech, f"its point closure has {n} unknowns, more than {MAX_UNKNOWNS}: "
                      "the monodromy that would find its start solutions is not practical at "
                      "that size (the 3-UPU's 90 reached one solution in 36 s); follow the drawn "
                      "mode with the graph tracker (--modes drawn)")
    system = _compile(unknown, known, bodies, pts)
    return SpatialPointFormulation(mech, system, origin, scale, drawn, tuple(pts.owners),
                                   tuple(placed), tuple(known), tuple(unknown), tuple(bodies),
                                   tuple(pts.u_joints), source, tuple(pts.slides),
                                   tuple(pts.turns))


def _compile(unknown: list[int], known: list[int], bodies: list[BodyEquations],
             pts: _Points) -> PolynomialSystem:
    """The system of the module docstring: unknowns the solved points' (x, y, z); parameters
    the placed points', then per body its d's and coefficients, then the U joints' g."""
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

    def sub(a: list[Poly], b: list[Poly]) -> list[Poly]:
        return [x - y for x, y in zip(a, b, strict=True)]

    def dot(a: list[Poly], b: list[Poly]) -> Poly:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    eqs: list[Poly] = []
    params = [f"{c}{k}" for k in known for c in "xyz"]
    for be in bodies:
        for i, j in be.distances:
            d = sub(point[j], point[i])
            eqs.append(dot(d, d) - Poly.variable(next(counter)))
            params.append(f"d{i}_{j}")
        b1 = point[be.base[0]]
        u = sub(point[be.base[1]], b1)
        if len(be.base) == 3:
            v = sub(point[be.base[2]], b1)
            w = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
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
            eqs += [point[ib][c] - point[ia][c] - slide[sl.joint] * axis[c] for c in range(3)]
    for t in pts.turns:
        be = next(be for be in bodies if be.body == t.frame)
        b1 = point[be.base[0]]
        u, v = sub(point[be.base[1]], b1), sub(point[be.base[2]], b1)
        w = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        ta, tb, tc = (Poly.variable(next(counter)) for _ in range(3))
        params += [f"{x}{t.point}_turn" for x in "abc"]
        eqs += [point[t.point][c] - b1[c] - ta * u[c] - tb * v[c] - tc * w[c] for c in range(3)]
    return compile_system(eqs, names, params)
