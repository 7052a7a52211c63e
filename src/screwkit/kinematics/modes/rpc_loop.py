"""A single loop of R, P and C joints with six free freedoms from a mechanism, solved in its
joint axes (:mod:`.rpc_quadrics`; issue 27): the formulation that
:func:`~screwkit.kinematics.modes.every_mode.closure_formulation` routes such loops to. A U
joint is two R joints on intersecting lines.

The loop is read as :mod:`.general_loop` reads it (driven freedoms folded into the links, a U
joint as its two turns, the Denavit–Hartenberg values of each free joint from the drawing,
:class:`.GeneralLoop`). The
quadrics want a turning joint last (the ground link between two turning joints) and no parallel
axes where they divide by sin α or need a run's basis (:func:`.parallel_links`), so the free
joints are relabelled cyclically (joint r first: the loop's product ∏ Z_j K_j = I is unchanged
under a cyclic shift) by the first shift r whose related axes are at least
:data:`WELL_APART` from parallel in the drawing (smallest |sin|), else the shift with the
largest such sine (above :data:`.rpc_quadrics.PARALLEL`). Its parameters
are turned into the quadrics' (:func:`.rpc_parameters`), and each solution back into the general
system's unknowns (:func:`.general_unknowns`, shifted back) and from there into the graph
tracker's joint values (:meth:`.GeneralLoop.configuration`).

Start solutions per topology (the relabelled kinds) come from monodromy or a total-degree
homotopy (:mod:`.starts`, kept on disk), stopped at the loop's generic count
(:data:`LOOP_COUNTS`). A loop is refused (CapabilityError; the generic solver then searches it
by random starts) where fewer than three joints turn (such a loop closes only for special
dimensions), where a joint is made off its drawing (a seat offset), and where no shift avoids
parallel axes in the drawing; a row of inputs where a
driven joint folded into a link makes related axes parallel is not solved (its paths count as
failed, and the loop solver searches it by random starts).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import Solutions, StartSolutions, solve_all
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.modes.general_loop import GeneralLoop, general_loop
from screwkit.kinematics.modes.general_loop_system import loop_layout
from screwkit.kinematics.modes.rpc_quadrics import (
    PARALLEL,
    general_unknowns,
    parallel_links,
    quadric_layout,
    random_rpc,
    related_sines,
    rpc_parameters,
    rpc_system,
)
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]
#: the first labelling whose related axes are this far from parallel (smallest |sin|) is taken;
#: where none is, the labelling with the largest: k = a / sin α and the common normals' feet
#: (~1/sin α away) make a nearly parallel pair ill-conditioned (a 7R loop with two axes 1e-5
#: rad apart, labelled as drawn: no real solution found, the tracked mode among none)
WELL_APART = 1e-2
#: the route of a row whose related axes are parallel (not solved)
PARALLEL_ROW = "not solved: two related axes of the loop are parallel at this row"

#: the generic number of assemblies of a loop, by its free joints up to rotation and reversal
#: (:func:`canonical`). Loops of R and P joints: 6R 16 (Lee & Liang 1988; a mechanism's loop
#: whose C and P joints are driven at their slides, so that only R joints are free), 5R1P 16,
#: 4R2P 8, 3R3P 2 (Kohli & Osvatic 1993; Mavroidis & Roth 1994). Loops with C joints:
#: measured (docs/kinematics.md, "A single loop of R, P and C joints ... in its joint axes"):
#: monodromy of these quadrics from two seeds and a total-degree homotopy agree on every one
#: (tools/rpc_loop_counts.py),
#: and on the R and P loops' (CRCR: 4, below the 8 of the 4R2P it specialises).
LOOP_COUNTS = {
    "RRRRRR": 16, "PRRRRR": 16, "PPRRRR": 8, "PRPRRR": 8, "PRRPRR": 8, "PPPRRR": 2, "PPRPRR": 2,
    "PRPRPR": 2, "CCC": 2, "CCRR": 8, "CCPR": 2, "CRCR": 4, "CPCR": 2, "CRRRR": 16,
    "CPRRR": 8, "CRPRR": 8, "CPPRR": 2, "CPRRP": 2, "CPRPR": 2, "CRPPR": 2,
}


def canonical(kinds: str) -> str:
    """``kinds`` up to cyclic rotation and reversal: the smallest of those strings."""
    turns = [kinds[i:] + kinds[:i] for i in range(len(kinds))]
    return min(turns + [t[::-1] for t in turns])


def loop_count(kinds: str) -> int:
    """The generic count of assemblies of a loop of free joints ``kinds`` (:data:`LOOP_COUNTS`);
    a CapabilityError where fewer than three joints turn or the topology has no count."""
    if sum(k in "RC" for k in kinds) < 3:
        raise CapabilityError(f"a loop of free joints {kinds} turns at fewer than three joints; "
                              "it closes only for special dimensions, which the R/P/C axes "
                              "formulation does not take")
    key = canonical(kinds)
    if key not in LOOP_COUNTS:
        raise CapabilityError(f"no generic count is known for a loop of free joints {kinds}")
    return LOOP_COUNTS[key]


def shift_parameters(kinds: str, r: int, p_dh: ArrayLike) -> Array:
    """Rows of :mod:`.general_loop_system` parameters (B, k) of free joints ``kinds`` as those
    of the loop relabelled to start at joint r (kinds[r:] + kinds[:r])."""
    P = np.atleast_2d(np.asarray(p_dh))
    n, old = len(kinds), loop_layout(kinds)
    new = loop_layout(kinds[r:] + kinds[:r])
    out = np.zeros_like(P)
    for jn in range(n):
        j = (jn + r) % n
        for field, width in (("phi", 2), ("b", 1), ("a", 1), ("alpha", 2)):
            i, k = getattr(old, field)[j], getattr(new, field)[jn]
            if i >= 0:
                out[:, k - new.n_unknowns: k - new.n_unknowns + width] = \
                    P[:, i - old.n_unknowns: i - old.n_unknowns + width]
    return out


def unshift_unknowns(kinds: str, r: int, x_dh: ArrayLike) -> NDArray[np.complex128]:
    """General-system unknowns (N, n) of the loop relabelled to start at joint r, back in the
    labelling of ``kinds``."""
    X = np.atleast_2d(np.asarray(x_dh, dtype=complex))
    n, old = len(kinds), loop_layout(kinds)
    new = loop_layout(kinds[r:] + kinds[:r])
    out = np.zeros_like(X)
    for jn in range(n):
        j = (jn + r) % n
        if old.cs[j] >= 0:
            out[:, old.cs[j]: old.cs[j] + 2] = X[:, new.cs[jn]: new.cs[jn] + 2]
        if old.d[j] >= 0:
            out[:, old.d[j]] = X[:, new.d[jn]]
    return out


@dataclass(frozen=True)
class RPCLoop:
    """A single R/P/C loop (:func:`rpc_loop`) as a formulation over rows of inputs: the loop's
    free joints relabelled to start at joint ``shift`` (``kinds`` is the relabelled string)."""

    mechanism: Mechanism
    kinds: str
    shift: int
    system: PolynomialSystem
    general: GeneralLoop
    #: the formulation's name in a Motion's solver text
    kind: str = "R/P/C loop"

    @property
    def generic_count(self) -> int:
        """The loop's generic count of assemblies (:func:`loop_count`)."""
        return loop_count(self.kinds)

    def dh(self, input_values: ArrayLike) -> Array:
        """The relabelled loop's general-system parameters (B, k) at rows of inputs."""
        return shift_parameters(self.general.kinds, self.shift,
                                self.general.parameters(input_values))

    def parameters(self, input_values: ArrayLike) -> Array:
        """The quadrics' parameters (B, k) at rows of inputs (B, n_inputs); NaN at a row where
        two related axes are parallel (a driven joint folded into a link turns it to zero
        twist), which :meth:`solve` does not solve."""
        p_dh = self.dh(input_values)
        with np.errstate(all="ignore"):
            p = np.real(rpc_parameters(self.kinds, p_dh))
        p[parallel_links(self.kinds, p_dh)] = np.nan
        return p

    def solve(self, p: ArrayLike) -> Solutions:
        """Every solution at the parameter rows p (B, k): the parameter homotopy from
        :meth:`start` at the rows with finite parameters; a row of parallel axes (NaN) gets
        none, its paths counted as failed (so that the loop solver searches it by random
        starts)."""
        P = np.atleast_2d(np.asarray(p, dtype=float))
        ok = np.flatnonzero(np.isfinite(P).all(axis=1))
        start = self.start()
        sol = self._rows(P, ok, start)
        if start.generic_count != self.generic_count:  # monodromy stopped short: say so
            sol = replace(sol, generic_count=self.generic_count, how_found=(
                f"{start.how_found}; {len(start.x)} of the generic count {self.generic_count}: "
                "incomplete"))
        return sol

    def _rows(self, P: Array, ok: NDArray[np.intp], start: StartSolutions) -> Solutions:
        """:meth:`solve` at the rows ``ok`` of P, the others (parallel axes) empty."""
        sol = solve_all(self.system, P[ok], start) if ok.size else None
        if sol is not None and ok.size == len(P):
            return sol
        B = len(P)

        def per_row(values: NDArray[np.int64] | None, fill: int) -> NDArray[np.int64]:
            out = np.full(B, fill, dtype=np.int64)
            if values is not None:
                out[ok] = values
            return out

        n = self.system.n
        if sol is None:
            empty = np.zeros(0)
            return Solutions(np.zeros((0, n), dtype=complex), np.zeros(0, dtype=np.intp),
                             np.zeros(0, dtype=np.int8), empty.astype(bool),
                             empty.astype(bool), empty.astype(bool), empty, empty, empty,
                             empty, empty, np.zeros(0, dtype=np.int64), per_row(None, 0),
                             per_row(None, 0), per_row(None, 0), per_row(None, 0),
                             per_row(None, start.generic_count), start.generic_count,
                             start.how_found, (PARALLEL_ROW,) * B)
        route = [PARALLEL_ROW] * B
        for i, b in enumerate(ok):
            route[b] = sol.route[i]
        return replace(sol, instance=ok[sol.instance], found=per_row(sol.found, 0),
                       real_count=per_row(sol.real_count, 0),
                       certified_real_count=per_row(sol.certified_real_count, 0),
                       at_infinity=per_row(sol.at_infinity, 0),
                       failed=per_row(sol.failed, start.generic_count), route=tuple(route))

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, n), at one row of
        inputs (n_inputs,) or one row per solution (N, n_inputs)."""
        X = np.atleast_2d(np.asarray(solutions))
        n_in = len(self.mechanism.inputs)
        rows = np.asarray(input_values, dtype=float)
        rows = rows.reshape(-1, n_in) if n_in else rows.reshape(
            rows.shape[0] if rows.ndim == 2 else 1, 0)
        rows = np.broadcast_to(rows, (len(X), n_in)) if len(rows) == 1 else rows
        x_dh = np.zeros((len(X), loop_layout(self.general.kinds).n_unknowns))
        for row in np.unique(rows, axis=0):
            at = np.flatnonzero((rows == row).all(axis=1))
            p_dh = self.dh(row[None, :])
            x = general_unknowns(self.kinds, X[at], rpc_parameters(self.kinds, p_dh), p_dh)
            x_dh[at] = np.real(unshift_unknowns(self.general.kinds, self.shift, x))
        if len(X) == 0:
            return self.general.configuration(x_dh, np.zeros(n_in))
        scalars, lay = None, None
        for row in np.unique(rows, axis=0):
            at = np.flatnonzero((rows == row).all(axis=1))
            conf, lay = self.general.configuration(x_dh[at], row)
            if scalars is None:
                scalars = np.zeros((len(X), conf.scalars.shape[1]))
            scalars[at] = conf.scalars
        assert scalars is not None and lay is not None
        return Configuration(scalars, np.zeros((len(X), 0, 3, 3))), lay

    def start(self) -> StartSolutions:
        """Every solution of the system at a generic complex point (cached per topology),
        stopped at the loop's generic count (module docstring)."""
        return start_solutions(self.system, lambda rng: random_rpc(self.kinds, rng, 1),
                               self.generic_count)


def rpc_loop(mech: Mechanism) -> RPCLoop:
    """The R/P/C axes formulation of the single loop ``mech`` (a CapabilityError where it does
    not take it: module docstring)."""
    off = [j.name for j in mech.joints if j.seat_offset is not None]
    if off:
        raise CapabilityError(f"{mech.name}: joints {', '.join(off)} are made off their drawing "
                              "(a seat offset); the R/P/C axes formulation reads the loop from "
                              "its drawing, so it does not take them")
    general = general_loop(mech)
    kinds = general.kinds
    loop_count(kinds)
    p_dh = general.parameters(np.zeros((1, len(mech.inputs))))
    best, best_sine = -1, PARALLEL
    for r in range(len(kinds)):
        shifted = kinds[r:] + kinds[:r]
        if shifted[-1] == "P":
            continue
        quadric_layout(shifted)
        sine = float(related_sines(shifted, shift_parameters(kinds, r, p_dh))[0])
        if sine >= WELL_APART:
            best = r
            break
        if sine >= best_sine:
            best, best_sine = r, sine
    if best >= 0:
        shifted = kinds[best:] + kinds[:best]
        return RPCLoop(mech, shifted, best, rpc_system(shifted), general)
    raise CapabilityError(f"{mech.name}: in every labelling of the loop ({kinds}) two axes that "
                          "the R/P/C axes formulation relates are parallel (a link of zero "
                          "twist between turning joints, or a run of P joints whose end axes "
                          "are parallel)")
