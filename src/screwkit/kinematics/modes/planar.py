"""A planar mechanism of R joints as a polynomial system in its joints' plane coordinates.

At given input values the ground and every body driven from it through input joints are placed;
the joints they carry are parameters. Every other joint's position (x, y) in the plane is an
unknown, and each remaining body with joints P_1, P_2, …, P_k gives

    ‖P_2 − P_1‖² = L²                          (its first two joints keep their distance)
    P_m − P_1 = M_m (P_2 − P_1),  m = 3..k      (the others are carried rigidly; M_m the
                                                  rotation-and-scale of the drawing, a complex
                                                  number acting on (x, y))

(a body's rigidity as a complex rotation-and-scale, the complex-plane view of Wampler 2001,
"Solving the kinematics of planar mechanisms by Dixon determinant and a complex-plane
formulation", written here in Cartesian coordinates). The system is square
exactly when the mechanism has no freedom left at fixed inputs. The linear rigid-body equations
keep a ternary body from being mirrored, so every solution is an assembly: a 4R gives 2, a
Stephenson III six-bar driven at its crank 6 (a triad; checked by the total-degree
homotopy, tests/kinematics/test_modes_counts.py). Every parameter (the placed joints,
the squared distances and the complex ratios M) is free, so the real instances are generic
members of the family.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from screwkit.kinematics.modes.planar_folds import InputFolds

from screwkit.algebraic.multi_homogeneous import Grouping
from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import listing
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]


@dataclass(frozen=True)
class PlanarFormulation:
    """The planar system of one mechanism (its topology and drawn geometry) and how to read it.

    ``plane`` is (origin, e1, e2, normal); ``placed`` the bodies placed by the inputs (ground
    and cranks, in placement order with the input joint that places each); ``unknown_joints``
    the joints whose positions are the unknowns (x, y each, in order); ``rigid`` the remaining
    bodies with their joints' indices, the first two being the distance pair."""

    mechanism: Mechanism
    system: PolynomialSystem
    plane: tuple[Array, Array, Array, Array]
    placed: tuple[tuple[str, int | None], ...]
    known_joints: tuple[int, ...]
    unknown_joints: tuple[int, ...]
    rigid: tuple[tuple[str, tuple[int, ...]], ...]

    def drawn_points(self) -> Complex:
        """Every joint's drawn position as a complex number x + iy in the plane (J,)."""
        o, e1, e2, _ = self.plane
        pts = np.array([j.at for j in self.mechanism.joints]) - o
        return (pts @ e1) + 1j * (pts @ e2)

    def parameters(self, input_values: ArrayLike) -> Array:
        """Parameters at input values (N, n_inputs) or (n_inputs,): the placed joints' (x, y),
        then each rigid body's L² and its (Re M, Im M) per further joint."""
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        angle = self._body_angles(X)
        drawn = self.drawn_points()
        cols = []
        for k in self.known_joints:
            body = self._placed_body_of(k)
            z = self._place(body, drawn[k], angle, drawn)
            cols += [z.real, z.imag]
        for _, joints in self.rigid:
            d = drawn[joints[1]] - drawn[joints[0]]
            cols.append(np.full(X.shape[0], abs(d) ** 2))
            for m in joints[2:]:
                M = (drawn[m] - drawn[joints[0]]) / d
                cols += [np.full(X.shape[0], M.real), np.full(X.shape[0], M.imag)]
        return np.stack(cols, -1)

    @property
    def grouping(self) -> Grouping:
        """The isotropic coordinates z = x + iy, z̄ = x − iy of the unknown joints, in two
        groups (every z, every z̄), with each rigid body's pair of carried-joint equations
        mixed into (x-eq + i·y-eq, x-eq − i·y-eq): a distance equation is then bilinear
        (z2 − z1)(z̄2 − z̄1) = L² and a carried joint's equations linear in one group each
        (Wampler 2001), so the multi-homogeneous start system
        (:mod:`screwkit.algebraic.multi_homogeneous`) tracks C(d, d/2)-like counts (6 for a
        Stephenson III six-bar) instead of the total degree (16)."""
        n = self.system.n
        basis = np.zeros((n, n), dtype=complex)
        for j in range(n // 2):  # x = (z + z̄)/2, y = (z − z̄)/(2i); u = (z_j, z̄_j) per joint
            basis[2 * j, 2 * j], basis[2 * j, 2 * j + 1] = 0.5, 0.5
            basis[2 * j + 1, 2 * j], basis[2 * j + 1, 2 * j + 1] = -0.5j, 0.5j
        mix = np.zeros((n, n), dtype=complex)
        row = 0
        for _, js in self.rigid:
            mix[row, row] = 1.0
            row += 1
            for _ in js[2:]:
                mix[row, row], mix[row, row + 1] = 1.0, 1.0j
                mix[row + 1, row], mix[row + 1, row + 1] = 1.0, -1.0j
                row += 2
        return Grouping((tuple(range(0, n, 2)), tuple(range(1, n, 2))), basis, mix)

    def fold_system(self, which: int = 0) -> PolynomialSystem:
        """The kernel system whose real solutions are the folds of input ``which``
        (modes/planar_folds.py)."""
        from screwkit.kinematics.modes.planar_folds import fold_system, placed_circles

        drawn = np.zeros(len(self.mechanism.inputs))
        return fold_system(self, placed_circles(self, drawn, which).moving)

    def input_folds(self, reference: ArrayLike, which: int = 0) -> InputFolds:
        """Every fold of input ``which``, the other inputs at the row ``reference``
        (modes/planar_folds.py)."""
        from screwkit.kinematics.modes.planar_folds import input_folds

        return input_folds(self, reference, which)

    def _placed_body_of(self, joint: int) -> str:
        names = [b for b, _ in self.placed]
        return next(b for b in self.mechanism.joints[joint].bodies if b in names)

    def _body_angles(self, X: Array) -> dict[str, Array]:
        """Angles of the placed bodies (about the plane normal) at inputs X (N, n_in)."""
        angle = {GROUND: np.zeros(X.shape[0])}
        for body, k in self.placed[1:]:
            assert k is not None
            j = self.mechanism.joints[k]
            q = X[:, self.mechanism.inputs.index(f"{j.name}.theta")] * self._axis_sign(k)
            other = j.bodies[0] if j.bodies[1] == body else j.bodies[1]
            angle[body] = angle[other] + (q if j.bodies[1] == body else -q)
        return angle

    def _place(self, body: str, point: complex, angle: dict[str, Array], drawn: Complex
               ) -> Complex:
        """Where a placed body carries its drawn point: turned about each input pivot on the
        way from the ground."""
        chain = []
        while body != GROUND:
            k = dict(self.placed)[body]
            assert k is not None
            j = self.mechanism.joints[k]
            other = j.bodies[0] if j.bodies[1] == body else j.bodies[1]
            chain.append((k, body, other))
            body = other
        z = np.full(next(iter(angle.values())).shape, point, dtype=complex)
        for k, b, other in chain:  # innermost body first
            z = drawn[k] + np.exp(1j * (angle[b] - angle[other])) * (z - drawn[k])
        return z

    def _axis_sign(self, k: int) -> float:
        return 1.0 if self.mechanism.joints[k].axis @ self.plane[3] > 0 else -1.0

    def solution_from_points(self, points: ArrayLike) -> Complex:
        """The unknowns (N, 2u) from every joint's plane position (N, J) (complex x + iy)."""
        z = np.asarray(points)[:, list(self.unknown_joints)]
        return np.stack([z.real, z.imag], -1).reshape(z.shape[0], -1).astype(complex)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """Graph-tracker configurations (N) of real solutions (N, 2u) at the input values."""
        sol = np.real(np.asarray(solutions))
        N = sol.shape[0]
        X = np.broadcast_to(np.atleast_2d(np.asarray(input_values, dtype=float)),
                            (N, len(self.mechanism.inputs)))
        angle = self._body_angles(X)
        pos = dict(zip(self.unknown_joints, (sol[:, 0::2] + 1j * sol[:, 1::2]).T, strict=True))
        drawn = self.drawn_points()
        for k in self.known_joints:
            pos[k] = self._place(self._placed_body_of(k), drawn[k], angle, drawn)
        for body, joints in self.rigid:
            ratio = (pos[joints[1]] - pos[joints[0]]) / (drawn[joints[1]] - drawn[joints[0]])
            angle[body] = np.angle(ratio)
        lay = graph_layout(self.mechanism)
        scalars = np.zeros((N, lay.n_scalar))
        for k, j in enumerate(self.mechanism.joints):
            q = (angle[j.bodies[1]] - angle[j.bodies[0]]) * self._axis_sign(k)
            scalars[:, lay.scalar_col[lay.first_freedom[k]]] = np.mod(q + np.pi, 2 * np.pi) - np.pi
        return Configuration(scalars, np.zeros((N, 0, 3, 3))), lay


def _plane(mech: Mechanism) -> tuple[Array, Array, Array, Array]:
    bad = [j.name for j in mech.joints if j.kind != "R"]
    if bad:
        raise CapabilityError(f"{mech.name}: joints {listing(bad)} are not R joints; the planar "
                              "formulation takes R joints only")
    n = mech.joints[0].axis
    if any(np.linalg.norm(np.cross(j.axis, n)) > 1e-9 for j in mech.joints):
        raise CapabilityError(f"{mech.name}: the R joints' axes are not all parallel, so the "
                              "mechanism is not planar; use the 6R or the general formulation")
    e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return mech.joints[0].at, e1, np.cross(n, e1), n


def placed_by_inputs(mech: Mechanism) -> list[tuple[str, int | None]]:
    """The ground and every body reached from it through input joints, each with the index
    of the joint that places it (None for the ground), in placement order."""
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
    return placed


def planar_formulation(mech: Mechanism) -> PlanarFormulation:
    """The planar system of ``mech`` (module docstring). Raises a CapabilityError for a
    mechanism that is not planar or has joints other than R, and an InputError when the
    mechanism keeps a freedom (or is overconstrained) at fixed inputs."""
    plane = _plane(mech)
    placed = placed_by_inputs(mech)
    have = {b for b, _ in placed}
    known = tuple(k for k, j in enumerate(mech.joints) if set(j.bodies) & have)
    unknown = tuple(k for k in range(len(mech.joints)) if k not in known)
    rigid = []
    for b in mech.body_names:
        if b in have:
            continue
        js = tuple(k for k, j in enumerate(mech.joints) if b in j.bodies)
        if len(js) < 2:
            raise CapabilityError(f"{mech.name}: body {b!r} has a single joint; it turns "
                                  "freely about it, so its position is not determined")
        rigid.append((b, js))
    n_eq = sum(2 * len(js) - 3 for _, js in rigid)
    if n_eq != 2 * len(unknown):
        raise InputError(f"{mech.name}: at fixed inputs the planar closure has {n_eq} "
                         f"equations in {2 * len(unknown)} unknowns; it is square only for a "
                         "mechanism with as many inputs as freedoms")
    system = _compile(known, unknown, rigid)
    return PlanarFormulation(mech, system, plane, tuple(placed), known, unknown, tuple(rigid))


def _compile(known: tuple[int, ...], unknown: tuple[int, ...],
             rigid: list[tuple[str, tuple[int, ...]]]) -> PolynomialSystem:
    n = 2 * len(unknown)
    sym = [Poly.variable(i) for i in range(n + 2 * len(known) + sum(
        2 * len(js) - 3 for _, js in rigid))]
    point = {k: (sym[2 * i], sym[2 * i + 1]) for i, k in enumerate(unknown)}
    point |= {k: (sym[n + 2 * i], sym[n + 2 * i + 1]) for i, k in enumerate(known)}
    eqs = closure_equations(point, rigid, sym[n + 2 * len(known):])
    names = [f"{c}{k}" for k in unknown for c in "xy"]
    params = [f"{c}{k}" for k in known for c in "xy"]
    params += [f"{w}{b}" for b, js in rigid for w in (["L2_"] + [f"M{m}{c}_" for m in js[2:]
                                                                  for c in "ri"])]
    return compile_system(eqs, names, params)


def closure_equations(point: dict[int, tuple[Poly, Poly]],
                      rigid: Sequence[tuple[str, tuple[int, ...]]],
                      body_symbols: Sequence[Poly]) -> list[Poly]:
    """The rigid bodies' equations (module docstring) with every joint's (x, y) given by
    ``point`` and each body's L², (Re M, Im M) … taken in order from ``body_symbols``."""
    eqs = []
    nxt = 0
    for _, js in rigid:
        (x1, y1), (x2, y2) = point[js[0]], point[js[1]]
        dx, dy = x2 - x1, y2 - y1
        eqs.append(dx * dx + dy * dy - body_symbols[nxt])
        nxt += 1
        for m in js[2:]:
            mc, ms = body_symbols[nxt], body_symbols[nxt + 1]
            nxt += 2
            xm, ym = point[m]
            eqs.append(xm - x1 - (mc * dx - ms * dy))
            eqs.append(ym - y1 - (ms * dx + mc * dy))
    return eqs
