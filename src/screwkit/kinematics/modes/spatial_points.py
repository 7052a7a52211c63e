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
- A telescopic leg (two bodies slid by one P joint between two balls: model/spin_groups.py)
  is one distance between its balls' centres, ‖b − a‖² = ‖d0 + s e‖²; a pivoted R–P–S leg two
  equations on its ball's centre (one, its plane, when the slide is passive and square to the
  axis), a U–P–U leg with square axes two equations on its top U's centre and platform arm, a
  U–P–S leg one sphere (none when passive) (all modes/spatial_point_legs.py). Their bodies
  carry no other points. A driven body translation is one linear equation on the body's drive
  point, a driven body turn one quadric in its base points (modes/spatial_point_drives.py).

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
count is a lower bound on the generic count, and ``how_found`` says so, until the count check
(modes/starts.py ``count_check``: the trace test) shows it complete.

The solutions are turned into body poses (the rotation that carries a body's drawn points onto
its solved ones, Kabsch's least-squares fit, exact for a rigid image; the least rotation for a
body on a line) and from them into joint variables (modes/stewart_decode.py ``joint_values``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.monodromy import MonodromyOptions
from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import StartSolutions
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout, joint_motion
from screwkit.kinematics.modes.rod_loops import least_rotation
from screwkit.kinematics.modes.spatial_point_drives import (
    PointDrive,
    chain_poses,
    turn_parameters,
)
from screwkit.kinematics.modes.spatial_point_legs import (
    GimbalLeg,
    PivotLeg,
    TelescopicLeg,
    UniversalLeg,
    circle_parameters,
    gimbal_parameters,
    gimbal_poses,
    leg_poses,
    leg_vectors,
    telescopic_poses,
    universal_parameters,
    universal_poses,
)
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.modes.stewart_decode import Pose, joint_values
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]
#: start solutions by the total-degree homotopy up to this many paths, else by monodromy
TOTAL_DEGREE_LIMIT = 1024
#: monodromy stops after this many loops in a row find nothing new (the five-link example's
#: 40 need 42 loops from seed 0; at 6 it stopped at 37)
STALE_LOOPS = 24
#: a random instance is the drawing moved by this much (complex, in length units)
RANDOM_SPREAD = 0.5
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
    #: +1: ``b`` in the joint's second body; −1: the roles swapped (``b`` in its first body,
    #: b_i = a_i − s (a_1 − a_0)), so that ``b`` is in the body written later
    sign: float = 1.0


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
    #: +1: ``frame`` is the joint's first body; −1: its second (the point turns by −θ)
    sign: float = 1.0


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
    legs: tuple[TelescopicLeg, ...] = ()
    pivots: tuple[PivotLeg, ...] = ()
    #: driven translations of body points (modes/spatial_point_drives.py), each one's point,
    #: and the augmented mechanism (with its virtual chains) whose inputs and joints the
    #: parameters and configurations follow, when the mechanism is driven at body freedoms
    drives: tuple[PointDrive, ...] = ()
    drive_points: tuple[int, ...] = ()  # −1 for a turn
    augmented: Mechanism | None = None
    gimbals: tuple[GimbalLeg, ...] = ()
    universals: tuple[UniversalLeg, ...] = ()

    def _frame_of(self, body: str) -> BodyEquations:
        return next(be for be in self.bodies if be.body == body)

    def _base_frame(self, body: str, pts: Array) -> Array:
        """``body``'s base frame U = [u, v, u × v] (3, 3) on the points ``pts``."""
        b1, b2, b3 = self._frame_of(body).base
        u, v = pts[b2] - pts[b1], pts[b3] - pts[b1]
        return np.stack([u, v, np.cross(u, v)], 1)

    def _turn_coefficients(self, t: TurnJoint, X: Array) -> Array:
        """The driven point's coefficients (N, 3) in its first body's base at inputs X."""
        j = self.mechanism.joints[t.joint]
        be = self._frame_of(t.frame)
        d = self.drawn
        c = (j.at - self.origin) / self.scale
        th = t.sign * X[:, t.column]
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
        each U joint's g, then the driven slides (scaled), the driven turns' coefficients, the
        driven telescopic legs' squared lengths, the pivoted legs' circles (h, r²) and the
        driven body translations' e·a + v (an augmented mechanism's X: its joint inputs,
        then its drives)."""
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        poses = self.placed_poses(X)
        cols = [self._placed_point(k, poses) for k in self.known]
        known = (np.stack(cols, 1).reshape(X.shape[0], 3 * len(cols)) if cols
                 else np.zeros((X.shape[0], 0)))
        const = self._constants(self.drawn)
        driven = [X[:, sl.column:sl.column + 1] / self.scale for sl in self.slides
                  if sl.column is not None]
        driven += [self._turn_coefficients(t, X) for t in self.turns]
        driven += [np.sum(leg_vectors(self.mechanism, leg, X[:, leg.column]) ** 2, axis=1,
                          keepdims=True) / self.scale**2
                   for leg in self.legs if leg.column is not None]
        driven += [circle_parameters(self.mechanism, leg, X, self.scale) for leg in self.pivots]
        driven += [turn_parameters(d, X[:, d.column], self._base_frame(d.body, self.drawn))
                   if d.is_turn else
                   (d.axis @ (d.at - self.origin) / self.scale + X[:, d.column] / self.scale
                    )[:, None] for d in self.drives]
        driven += [gimbal_parameters(self.mechanism, gl, X, self.scale) for gl in self.gimbals]
        driven += [universal_parameters(self.mechanism, ul, X, self.scale)
                   for ul in self.universals if ul.column is not None]
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
        points, a body on a line's points put on its line, a slide's points slid over, and the
        parameters computed from them; a CapabilityError where these do not agree (a point on
        a line that a slide also carries)."""
        P = len(self.drawn)
        # the drawing moved by a complex random half unit: generic, but with the drawing's
        # shapes (a skinny random triangle makes huge coefficients, and monodromy loops that
        # start there lose every path)
        pts = np.asarray(self.drawn + RANDOM_SPREAD * (rng.standard_normal((P, 3))
                                                       + 1j * rng.standard_normal((P, 3))),
                         dtype=complex)
        self._onto_lines(pts, rng, frozenset())
        slide = {}
        for sl in self.slides:  # b_i = a_i ± s (a_1 − a_0)
            slide[sl.joint] = rng.standard_normal() + 1j * rng.standard_normal()
            for ia, ib in zip(sl.a, sl.b, strict=True):
                pts[ib] = pts[ia] + sl.sign * slide[sl.joint] * (pts[sl.a[1]] - pts[sl.a[0]])
        # a line whose base a slide has just moved: its other points onto it again
        self._onto_lines(pts, rng, frozenset(m for sl in self.slides for m in sl.a + sl.b))
        coef = {}
        for be in self.bodies:
            b1, b2 = be.base[0], be.base[1]
            u = pts[b2] - pts[b1]
            for m in be.carried:
                if len(be.base) == 2:
                    coef[(be.body, m)] = (complex(np.sum((pts[m] - pts[b1]) * u)
                                                  / np.sum(u * u)),)
                else:
                    v = pts[be.base[2]] - pts[b1]
                    coef[(be.body, m)] = tuple(np.linalg.solve(
                        np.stack([u, v, np.cross(u, v)], 1), pts[m] - pts[b1]))
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
        for leg in self.legs:
            if leg.column is not None:
                d = pts[leg.balls[1]] - pts[leg.balls[0]]
                out.append(complex(d @ d))
        for pv in self.pivots:  # the ball's circle: (Q − A)·(A1 − A) = h, ‖Q − A‖² = r²
            w = pts[pv.ball] - pts[pv.axis[0]]
            out += [complex(w @ (pts[pv.axis[1]] - pts[pv.axis[0]]))]
            out += [complex(w @ w)] if pv.column is not None else []
        for d, k in zip(self.drives, self.drive_points, strict=True):
            if d.is_turn:  # Σ W_ik U_ik = h, W random
                W = rng.standard_normal(9) + 1j * rng.standard_normal(9)
                out += [*W, complex(np.sum(W * self._base_frame(d.body, pts).reshape(-1)))]
            else:
                out.append(complex(d.axis @ pts[k]))
        for gl in self.gimbals:  # ‖Q − C‖², ((E − C) × (Q − C))·(A − Q)
            d = pts[gl.ball] - pts[gl.centre]
            n = np.cross(pts[gl.arm] - pts[gl.centre], d)
            out += [complex(d @ d)] if gl.column is not None else []
            out.append(complex(n @ (pts[gl.top_arm] - pts[gl.ball])))
        for ul in self.universals:  # ‖Q − C‖² (a passive slide: none)
            if ul.column is None:
                continue
            d = pts[ul.ball] - pts[ul.centre]
            out.append(complex(d @ d))
        x = np.concatenate([pts[list(self.unknown)].reshape(-1),
                            [slide[sl.joint] for sl in self.slides if sl.column is None]])
        p = np.array(out, dtype=complex)
        F = self.system.evaluate(x[None, :], p, want_jp=False)[0]
        if np.abs(F).max(initial=0.0) > 1e-9 * (1.0 + np.abs(x).max()) ** 2:
            raise CapabilityError(
                f"{self.mechanism.name}: the spatial point formulation cannot draw a generic "
                "instance of this topology (a point that a body on a line and a slide both "
                "carry); follow the drawn mode with the graph tracker (--modes drawn)")
        return p[None, :], x[None, :]

    def _onto_lines(self, pts: Complex, rng: np.random.Generator, keep: frozenset[int]
                    ) -> None:
        """Put every body on a line's carried points (not in ``keep``) on its line, at
        random places."""
        for be in self.bodies:
            if len(be.base) == 2:
                b1, b2 = be.base
                for m in be.points:
                    if m not in be.base and m not in keep and (m not in self.known
                                                               or m in be.carried):
                        along = rng.standard_normal() + 1j * rng.standard_normal()
                        pts[m] = pts[b1] + along * (pts[b2] - pts[b1])

    def start(self) -> StartSolutions:
        """The topology's start solutions (module docstring): total degree up to
        :data:`TOTAL_DEGREE_LIMIT` paths, else monodromy."""
        return start_solutions(self.system, self.random_instance,
                               total_degree_paths=TOTAL_DEGREE_LIMIT, then_monodromy=True,
                               monodromy=MonodromyOptions(stale_loops=STALE_LOOPS,
                                                          each_own_size=True))

    # ------------------------------------------------------------- configurations
    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """Graph-tracker configurations (N) of real solutions (N, 3u) at the input values."""
        sol = np.real(np.asarray(solutions))
        N = sol.shape[0]
        mech = self.mechanism
        whole = mech if self.augmented is None else self.augmented
        X = np.broadcast_to(np.atleast_2d(np.asarray(input_values, dtype=float)),
                            (N, len(whole.inputs)))
        poses = self.placed_poses(np.ascontiguousarray(X))
        world = np.empty((N, len(self.drawn), 3))
        for k in self.known:
            world[:, k] = self._placed_point(k, poses)
        world[:, list(self.unknown)] = sol[:, :3 * len(self.unknown)].reshape(
            N, len(self.unknown), 3)
        world = self.origin + self.scale * world
        drawn = self.origin + self.scale * self.drawn
        for be in self.bodies:
            pick = list(be.base) + [m for m in be.points if m not in be.base]
            poses[be.body] = _fit_pose(drawn[pick], world[:, pick], len(be.base) == 2)
        for leg in self.legs:
            poses.update(telescopic_poses(mech, leg, (world[:, leg.balls[0]],
                                                      world[:, leg.balls[1]]), X))
        for pv in self.pivots:
            poses.update(leg_poses(mech, pv, poses[pv.base], world[:, pv.ball], X))
        for gl in self.gimbals:
            poses.update(gimbal_poses(mech, gl, world, X))
        for ul in self.universals:
            poses.update(universal_poses(mech, ul, poses[ul.base], world, X))
        if self.augmented is not None:  # the virtual chains read off their bodies' poses
            poses.update(chain_poses(self.augmented, poses, X))
        lay = graph_layout(whole)
        return joint_values(whole, lay, poses), lay


def _fit_pose(drawn: Array, solved: Array, on_a_line: bool) -> Pose:
    """The pose (R (N, 3, 3), p (N, 3)) carrying a body's drawn points (k, 3) onto its solved
    ones (N, k, 3): Kabsch's rotation (exact for a rigid image), or the least rotation of the
    first two points' direction (the body's base) for a body on a line."""
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
