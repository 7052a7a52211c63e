"""A single loop of R, P and C joints with six free freedoms from a mechanism, solved in its
joint axes (:mod:`.rpc_quadrics`; issue 27): the formulation that
:func:`~screwkit.kinematics.modes.every_mode.closure_formulation` routes such loops to.

The loop is read as :mod:`.general_loop` reads it (driven freedoms folded into the links, the
Denavit–Hartenberg values of each free joint from the drawing, :class:`.GeneralLoop`); its
parameters are turned into the quadrics' (:func:`.rpc_parameters`), and each solution back into
the general system's unknowns (:func:`.general_unknowns`) and from there into the graph
tracker's joint values (:meth:`.GeneralLoop.configuration`).

Start solutions per topology come from monodromy (:mod:`.starts`, kept on disk) stopped at the
system's generic count: the loop's count (:data:`LOOP_COUNTS`) times 2^#P, since each P joint's
angle enters as its cosine and the system also holds the mirror loops (θ → −θ at a P joint).
:meth:`RPCLoop.solve` drops the mirrors' solutions (:func:`.mirrored`), so the result counts
the loop's solutions and names the loop's generic count. A loop is refused (CapabilityError;
the generic solver then searches it by random starts) where two consecutive moving axes are
parallel (k = a / sin α; :data:`.rpc_quadrics.PARALLEL`), where a P joint's angle is within
:data:`MIRROR_GAP` of 0 or π (the loop's solutions and its mirror's meet: double roots), and
where fewer than three joints turn (such a loop closes only for special dimensions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import Solutions, StartSolutions, solve_all
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.modes.general_loop import GeneralLoop, general_loop
from screwkit.kinematics.modes.rpc_quadrics import (
    general_unknowns,
    mirrored,
    quadric_layout,
    random_rpc,
    rpc_parameters,
    rpc_system,
)
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: the generic number of assemblies of a loop, by its free joints up to rotation and reversal
#: (:func:`canonical`). Loops of R and P joints: 5R1P 16, 4R2P 8, 3R3P 2 (Kohli & Osvatic 1993;
#: Mavroidis & Roth 1994). Loops with C joints: measured here (docs/kinematics.md, "A single
#: loop of R, P and C joints"): monodromy of this system from two seeds and a total-degree
#: homotopy at a third point agree on every one (CRCR: 4, below the 8 of the 4R2P it
#: specialises).
LOOP_COUNTS = {
    "PRRRRR": 16, "PPRRRR": 8, "PRPRRR": 8, "PRRPRR": 8, "PPPRRR": 2, "PPRPRR": 2,
    "PRPRPR": 2, "CCC": 2, "CCRR": 8, "CCPR": 2, "CRCR": 4, "CPCR": 2, "CRRRR": 16,
    "CPRRR": 8, "CRPRR": 8, "CPPRR": 2, "CPRRP": 2, "CPRPR": 2, "CRPPR": 2,
}
#: a P joint's |sin θ| below this: its loop and mirror are too close to tell apart (refused)
MIRROR_GAP = 1e-3


def canonical(kinds: str) -> str:
    """``kinds`` up to cyclic rotation and reversal: the smallest of those strings."""
    turns = [kinds[i:] + kinds[:i] for i in range(len(kinds))]
    return min(turns + [t[::-1] for t in turns])


def loop_count(kinds: str) -> int:
    """The generic count of assemblies of a loop of free joints ``kinds`` (:data:`LOOP_COUNTS`);
    a CapabilityError where fewer than three joints turn or the topology has no count."""
    quadric_layout(kinds)  # six freedoms of R, P and C
    if sum(k in "RC" for k in kinds) < 3:
        raise CapabilityError(f"a loop of free joints {kinds} turns at fewer than three joints; "
                              "it closes only for special dimensions, which the R/P/C axes "
                              "formulation does not take")
    key = canonical(kinds)
    if key not in LOOP_COUNTS:
        raise CapabilityError(f"no generic count is known for a loop of free joints {kinds}")
    return LOOP_COUNTS[key]


def without(sol: Solutions, keep: NDArray[np.bool_], generic_count: int,
            how_found: str) -> Solutions:
    """``sol`` with only the solutions ``keep`` (per-instance counts recounted), and the given
    generic count and how-found text."""
    B = len(sol.found)

    def count(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
        return np.bincount(sol.instance[keep & mask], minlength=B).astype(np.int64)

    every = np.ones(len(keep), dtype=bool)
    return Solutions(sol.x[keep], sol.instance[keep], sol.status[keep], sol.certified[keep],
                     sol.certified_real[keep], sol.real[keep], sol.alpha[keep],
                     sol.beta[keep], sol.gamma[keep], sol.radius[keep], sol.residual[keep],
                     sol.multiplicity[keep], count(every), count(sol.real),
                     count(sol.certified_real), sol.at_infinity, sol.failed, generic_count,
                     how_found, sol.route)


@dataclass(frozen=True)
class RPCLoop:
    """A single R/P/C loop (:func:`rpc_loop`) as a formulation over rows of inputs."""

    mechanism: Mechanism
    kinds: str
    system: PolynomialSystem
    general: GeneralLoop
    #: the formulation's name in a Motion's solver text
    kind: str = "R/P/C loop"

    @property
    def generic_count(self) -> int:
        """The loop's generic count of assemblies (:func:`loop_count`)."""
        return loop_count(self.kinds)

    def parameters(self, input_values: ArrayLike) -> Array:
        """The quadrics' parameters (B, k) at rows of inputs (B, n_inputs); a CapabilityError
        where a row's geometry is refused (module docstring)."""
        p_dh = self.general.parameters(input_values)
        p = rpc_parameters(self.kinds, p_dh)
        lay = quadric_layout(self.kinds)
        for j, c in enumerate(lay.c):
            if c < 0:
                continue
            cos_t = np.real(p[:, c] - p[:, lay.cos_a[j - 1]] * p[:, lay.cos_a[j]])
            if (np.abs(p[:, lay.v[j]]) <= MIRROR_GAP * np.hypot(np.abs(p[:, lay.v[j]]),
                                                                 np.abs(cos_t))).any():
                raise CapabilityError(
                    f"{self.mechanism.name}: the angle at P joint {j} of the loop {self.kinds} "
                    "is 0 or π, where the axes formulation cannot tell the loop from its "
                    "mirror (double roots)")
        return np.real(p)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """The graph tracker's configurations (N) of real solutions (N, n), at one row of
        inputs (n_inputs,) or one row per solution (N, n_inputs)."""
        X = np.atleast_2d(np.asarray(solutions))
        n_in = len(self.mechanism.inputs)
        rows = np.asarray(input_values, dtype=float).reshape(-1, n_in)
        rows = np.broadcast_to(rows, (len(X), n_in)) if len(rows) == 1 else rows
        distinct, back = np.unique(rows, axis=0, return_inverse=True)
        back = back.reshape(-1)
        scalars, lay = None, None
        for r, row in enumerate(distinct):
            at = np.flatnonzero(back == r)
            p_dh = self.general.parameters(row[None, :])
            x_dh = general_unknowns(self.kinds, X[at], rpc_parameters(self.kinds, p_dh), p_dh)
            conf, lay = self.general.configuration(np.real(x_dh), row)
            if scalars is None:
                scalars = np.zeros((len(X), conf.scalars.shape[1]))
            scalars[at] = conf.scalars
        if lay is None:
            conf, lay = self.general.configuration(np.zeros((0, self.general.system.n)),
                                                   np.zeros(n_in))
            return conf, lay
        assert scalars is not None
        return Configuration(scalars, np.zeros((len(X), 0, 3, 3))), lay

    def start(self) -> StartSolutions:
        """Every solution of the system at a generic complex point (cached per topology):
        monodromy stopped at the loop's count times 2^#P (module docstring)."""
        return start_solutions(self.system, lambda rng: random_rpc(self.kinds, rng, 1),
                               self.generic_count * 2 ** self.kinds.count("P"))

    def solve(self, p: ArrayLike) -> Solutions:
        """Every solution of the loop at parameter rows p: the parameter homotopy from
        :meth:`start`, the mirrors' solutions dropped."""
        P = np.atleast_2d(np.asarray(p, dtype=float))
        start = self.start()
        sol = solve_all(self.system, P, start)
        keep = ~mirrored(self.kinds, sol.x, P[sol.instance])
        n_p = self.kinds.count("P")
        how = start.how_found + (
            f"; the {2 ** n_p - 1} mirror loop(s) of the {n_p} P joint(s) dropped"
            if n_p else "")
        return without(sol, keep, self.generic_count, how)


def rpc_loop(mech: Mechanism) -> RPCLoop:
    """The R/P/C axes formulation of the single loop ``mech`` (a CapabilityError where it does
    not take it: module docstring)."""
    general = general_loop(mech)
    loop_count(general.kinds)
    return RPCLoop(mech, general.kinds, rpc_system(general.kinds), general)
