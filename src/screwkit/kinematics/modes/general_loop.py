"""A single loop of R, P, C and U joints with six free freedoms (a U joint as two R joints on
intersecting lines) as the system of
:mod:`.general_loop_system`: the loop's geometry at the inputs as the system's parameters, and
the way back from solutions to the graph tracker's :class:`Configuration` (issue 27).

The loop is walked from the ground, each joint's axis oriented along the walk (so that its
values move the next body positively either way, as modes/r_loop.py does). Driven freedoms
are fixed motions folded into the links; each free joint j gets a frame F_j on its line (z
along the oriented axis), and the link between free joints j and j+1 is
L_j = F_j⁻¹ G_j F_{j+1} (G_j the driven motions between them), split as
Rz(φ) Tz(b) Tx(a) Rx(α) Rz(ψ) Tz(e) (:func:`~.general_loop_system.split_link`). The ψ and e of
link j−1 and the φ and b of link j are screws about joint j's line: they are the system's
parameters where the joint does not turn or slide, otherwise offsets of the joint's own
variable, kept here so that a solution reads as joint values from the drawing.

Not solved itself: :mod:`.rpc_loop` reads the loop through it (its DH values, the way back to
joint values) and solves the quadrics of :mod:`.rpc_quadrics`; this system (cubic, up to
20,687 terms, on which monodromy was slow and lost paths) is the independent check of whole-
loop closure (docs/kinematics.md "Closures as polynomials").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.modes.general_loop_system import (
    general_loop_system,
    loop_layout,
    split_link,
)
from screwkit.kinematics.modes.r_loop import loop_walk
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.messages import listing
from screwkit.model.mechanism import Mechanism, MechanismJoint

Array = NDArray[np.float64]
#: below this sin α two consecutive free axes are taken as parallel (the normal is then chosen)
PARALLEL = 1e-9


def _screw(c: Array, w: Array, theta: float, slide: float) -> Array:
    """The 4×4 motion: turn θ about the line (c, w) and slide along w."""
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    R = np.eye(3) + np.sin(theta) * K + (1.0 - np.cos(theta)) * (K @ K)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, c - R @ c + slide * w
    return T


def _frame(c: Array, w: Array) -> Array:
    """A frame on the line (c, w): z along w, x along the cross product with the coordinate
    axis least aligned with w."""
    x = np.cross(w, np.eye(3)[int(np.argmin(np.abs(w)))])
    x /= np.linalg.norm(x)
    F = np.eye(4)
    F[:3, :3], F[:3, 3] = np.stack([x, np.cross(w, x), w], axis=1), c
    return F


def _split_real(L: Array) -> tuple[float, float, float, float, float, float]:
    """(φ, b, a, α, ψ, e) of a real link (split_link, or the parallel case: the normal along
    the offset between the lines, or any when they coincide)."""
    R, t = L[:3, :3], L[:3, 3]
    if np.hypot(R[0, 2], R[1, 2]) > PARALLEL:
        (cp, sp), b, a, (ca, sa), (cs, ss), e = split_link(L.astype(complex))
        return (float(np.arctan2(sp.real, cp.real)), b.real, a.real,
                float(np.arctan2(sa.real, ca.real)), float(np.arctan2(ss.real, cs.real)), e.real)
    phi = float(np.arctan2(t[1], t[0])) if np.hypot(t[0], t[1]) > PARALLEL else 0.0
    a = float(np.hypot(t[0], t[1]))
    alpha = 0.0 if R[2, 2] > 0 else np.pi
    M = _screw(np.zeros(3), np.array([1.0, 0, 0]), alpha, 0.0)[:3, :3].T @ \
        _screw(np.zeros(3), np.array([0, 0, 1.0]), phi, 0.0)[:3, :3].T @ R
    return phi, float(t[2]), a, alpha, float(np.arctan2(M[1, 0], M[0, 0])), 0.0


@dataclass(frozen=True)
class _Walk:
    """The loop from the ground as steps, each a line with a turn and/or a slide: the joint
    index, oriented point and axis, the names of the step's turn and slide freedoms ("" where
    it has none), their indices among the joint's freedoms (−1 where none) and whether each is
    free. A U joint is two steps, two R joints on intersecting lines (its first axis, then its
    second, as T = M_axis(θ1) M_axis2(θ2); the other way round when walked backwards)."""

    order: tuple[int, ...]
    points: tuple[Array, ...]
    axes: tuple[Array, ...]
    turn_name: tuple[str, ...]
    slide_name: tuple[str, ...]
    turn_index: tuple[int, ...]
    slide_index: tuple[int, ...]
    turn_free: tuple[bool, ...]
    slide_free: tuple[bool, ...]


def _steps(joint: MechanismJoint, forward: bool) -> list[tuple[Array, str, str]]:
    """A joint's steps along the walk: (oriented axis, turn freedom, slide freedom)."""
    sign = 1.0 if forward else -1.0
    if joint.kind == "U":
        assert joint.axis2 is not None
        both = [(sign * joint.axis, "theta1", ""), (sign * joint.axis2, "theta2", "")]
        return both if forward else both[::-1]
    return [(sign * joint.axis, "theta" if joint.kind in "RC" else "",
             "s" if joint.kind in "PC" else "")]


def _walk(mech: Mechanism) -> _Walk:
    if len(mech.topology.loops) != 1 or len(mech.topology.tree) + 1 != len(mech.joints):
        raise CapabilityError(f"{mech.name}: the general loop formulation takes a single loop "
                              f"and nothing else; this mechanism has "
                              f"{len(mech.topology.loops)} loops")
    bad = [j.name for j in mech.joints if j.kind not in "RPCU"]
    if bad:
        raise CapabilityError(f"{mech.name}: joints {listing(bad)} are not R, P, C or U "
                              "joints; the general loop formulation takes those only")
    driven = set(mech.inputs)
    rows: list[tuple[int, Array, Array, str, str, int, int]] = []
    for k, forward in loop_walk(mech):
        j = mech.joints[k]
        for axis, turn, slide in _steps(j, forward):
            rows.append((k, j.at, axis, f"{j.name}.{turn}" if turn else "",
                         f"{j.name}.{slide}" if slide else "",
                         j.freedoms.index(turn) if turn else -1,
                         j.freedoms.index(slide) if slide else -1))
    return _Walk(tuple(r[0] for r in rows), tuple(r[1] for r in rows),
                 tuple(r[2] for r in rows), tuple(r[3] for r in rows),
                 tuple(r[4] for r in rows), tuple(r[5] for r in rows),
                 tuple(r[6] for r in rows),
                 tuple(bool(r[3]) and r[3] not in driven for r in rows),
                 tuple(bool(r[4]) and r[4] not in driven for r in rows))


def loop_kinds(mech: Mechanism) -> str:
    """The free joints' kinds round the loop from the first free joint after the ground
    (R: turns only, P: slides only, C: both), e.g. "RPRRRR"."""
    w = _walk(mech)
    return "".join("C" if t and s else "R" if t else "P"
                   for t, s in zip(w.turn_free, w.slide_free, strict=True) if t or s)


@dataclass(frozen=True)
class GeneralLoop:
    """A single loop of R, P and C joints as a formulation over rows of inputs."""

    mechanism: Mechanism
    kinds: str

    @property
    def system(self) -> PolynomialSystem:
        """The compiled system of the loop's free joints (compiled on first use: 0.26 s for
        RPRRRR's 20,687 terms, 0.85 s for PRPRPR's 68,201, which :mod:`.rpc_loop` never
        needs)."""
        return general_loop_system(self.kinds)

    def _instance(self, row: Array) -> tuple[Array, Array, Array]:
        """Parameters (k,), turn offsets Φ (n,) and slide offsets (n,) at one row of inputs."""
        mech, w = self.mechanism, _walk(self.mechanism)
        value = dict(zip(mech.inputs, row, strict=True))
        free = [i for i in range(len(w.order)) if w.turn_free[i] or w.slide_free[i]]
        frames = [_frame(w.points[i], w.axes[i]) for i in free]
        links = []
        for n_j, i in enumerate(free):
            G = np.eye(4)
            nxt = free[(n_j + 1) % len(free)]
            steps = list(range(i, len(w.order))) + list(range(0, nxt)) if nxt <= i else \
                list(range(i, nxt))
            for s in steps:
                th = value.get(w.turn_name[s], 0.0) if not w.turn_free[s] else 0.0
                sl = value.get(w.slide_name[s], 0.0) if not w.slide_free[s] else 0.0
                G = G @ _screw(w.points[s], w.axes[s], th, sl)
            links.append(np.linalg.inv(frames[n_j]) @ G @ frames[(n_j + 1) % len(free)])
        parts = [_split_real(L) for L in links]
        lay, L = loop_layout(self.kinds), max(mech.length_scale, 1e-12)
        p = np.zeros(lay.n_parameters)
        turn_off, slide_off = np.zeros(len(free)), np.zeros(len(free))
        k = lay.n_unknowns
        for j in range(len(free)):
            phi, b, a, alpha, _, _ = parts[j]
            psi, e = parts[j - 1][4], parts[j - 1][5]
            turn_off[j], slide_off[j] = phi + psi, b + e
            if lay.phi[j] >= 0:
                p[lay.phi[j] - k: lay.phi[j] - k + 2] = np.cos(turn_off[j] / 2), np.sin(
                    turn_off[j] / 2)
            if lay.b[j] >= 0:
                p[lay.b[j] - k] = slide_off[j] / L
            p[lay.a[j] - k] = a / L
            p[lay.alpha[j] - k: lay.alpha[j] - k + 2] = np.cos(alpha / 2), np.sin(alpha / 2)
        return p, turn_off, slide_off

    def parameters(self, input_values: ArrayLike) -> Array:
        """The parameters (B, k) at rows of inputs (B, n_inputs) (radians, metres)."""
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        if X.shape[1:] != (len(self.mechanism.inputs),):
            raise InputError(f"{self.mechanism.name}: rows of {len(self.mechanism.inputs)} "
                             f"input values are needed; got shape {X.shape}")
        return np.array([self._instance(row)[0] for row in X])

    def _free(self) -> list[tuple[int, int, int, int]]:
        """(free joint j, its mechanism joint index, the indices of its turn and slide among
        that joint's freedoms) round the loop."""
        w = _walk(self.mechanism)
        return [(j, w.order[i], w.turn_index[i], w.slide_index[i]) for j, i in enumerate(
            i for i in range(len(w.order)) if w.turn_free[i] or w.slide_free[i])]

    def unknowns(self, scalars: ArrayLike, input_values: ArrayLike) -> Array:
        """The system's unknowns (N, n) at the graph tracker's joint values (N, n_scalar) at
        one row of inputs: the way in, independent of :meth:`configuration`."""
        S = np.atleast_2d(np.asarray(scalars, dtype=float))
        row = np.asarray(input_values, dtype=float).reshape(-1)
        _, turn_off, slide_off = self._instance(row)
        lay, glay = loop_layout(self.kinds), graph_layout(self.mechanism)
        x = np.zeros((S.shape[0], lay.n_unknowns))
        for j, k, ti, si in self._free():
            f0 = glay.first_freedom[k]
            if lay.cs[j] >= 0:
                q = S[:, glay.scalar_col[f0 + ti]] + turn_off[j]
                x[:, lay.cs[j]], x[:, lay.cs[j] + 1] = np.cos(q), np.sin(q)
            if lay.d[j] >= 0:
                x[:, lay.d[j]] = (S[:, glay.scalar_col[f0 + si]] + slide_off[j]) / max(
                    self.mechanism.length_scale, 1e-12)
        return x

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, n) at one row."""
        mech = self.mechanism
        row = np.asarray(input_values, dtype=float).reshape(-1)
        if row.shape != (len(mech.inputs),):
            raise InputError(f"{mech.name}: {len(mech.inputs)} input values are needed")
        sol = np.real(np.atleast_2d(np.asarray(solutions)))
        _, turn_off, slide_off = self._instance(row)
        lay, glay = loop_layout(self.kinds), graph_layout(mech)
        scalars = np.zeros((sol.shape[0], glay.n_scalar))
        for name, v in zip(mech.inputs, row, strict=True):
            joint, freedom = name.split(".")
            k = next(i for i, j in enumerate(mech.joints) if j.name == joint)
            f = glay.first_freedom[k] + mech.joints[k].freedoms.index(freedom)
            scalars[:, glay.scalar_col[f]] = v
        for j, k, ti, si in self._free():
            f0 = glay.first_freedom[k]
            if lay.cs[j] >= 0:
                q = np.arctan2(sol[:, lay.cs[j] + 1], sol[:, lay.cs[j]]) - turn_off[j]
                scalars[:, glay.scalar_col[f0 + ti]] = np.mod(q + np.pi, 2 * np.pi) - np.pi
            if lay.d[j] >= 0:
                scalars[:, glay.scalar_col[f0 + si]] = sol[:, lay.d[j]] * max(
                    mech.length_scale, 1e-12) - slide_off[j]
        return Configuration(scalars, np.zeros((sol.shape[0], 0, 3, 3))), glay


def general_loop(mech: Mechanism) -> GeneralLoop:
    """The general loop formulation of ``mech`` (a CapabilityError where it does not fit)."""
    kinds = loop_kinds(mech)
    loop_layout(kinds)  # a CapabilityError without six freedoms of R, P and C
    return GeneralLoop(mech, kinds)

