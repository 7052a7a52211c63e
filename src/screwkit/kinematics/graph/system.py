"""The stacked loop closure of a mechanism as a closure system for the loop engine's
continuation (tracker/system.py, :class:`~screwkit.kinematics.tracker.continuation.Tracker`):
one continuation engine for a loop and for a mechanism of several loops (issue 26).

The closure is every independent loop's F_l(q) = I stacked (graph/closure.py), linearised as
the scaled screw Jacobian J = [J_in J_p] (graph/newton.py). The predictor's directional jets
along an input move d are one rate solve J_p q̇_p = −J_in d and one acceleration solve
J_p q̈_p = −bias(q̇) (the loops' velocity-product terms, the Lie brackets of the joint screws:
graph/closure.py ``loop_bias``), minimum-norm where J_p is rank deficient (idle freedoms,
redundant constraints). The corrector is the loop engine's (tracker/solve.py ``correct``:
minimum-norm Gauss–Newton on the passive freedoms, Deuflhard's contraction test) on the stacked
residual; the σ ratio σ_r/σ_1 is the passive block's at its regular rank r (the drawing's,
idle freedoms and redundant constraints excluded), relative to its value at the drawing: the
tracker's fold and step-halving tests read it as nearness to a singular configuration.

The body poses and joint screws of every configuration the corrector linearised or the fill
checked are kept (by the configuration's exact values, the last MEMO_ROWS): the fronts' jets,
the step-halving signatures and the build's frames at those configurations reuse them instead
of evaluating the forward map again (the same numbers: it is a function of the configuration).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import (
    GraphFrames,
    GraphLayout,
    graph_forward,
    zero_configuration,
)
from screwkit.kinematics.graph.newton import (
    RANK_CUTOFF,
    Linearised,
    accelerations,
    column_scale,
    difference,
    increment,
    linearise,
    rates,
    scaled_residual,
    set_inputs,
)
from screwkit.kinematics.tracker.loop import Array, Configuration
from screwkit.kinematics.tracker.solve import (
    CLOSURE_TOL,
    Correction,
    polish_verdict,
    step_verdict,
)
from screwkit.kinematics.tracker.system import ball_freedoms
from screwkit.kinematics.tracker.tracks import TrackRates
from screwkit.model.mechanism import Mechanism

#: a drawing whose σ ratio is below this is (nearly) singular: not the reference of the others
SIGMA_REFERENCE = 1e-4
#: configurations whose poses and screws are kept for reuse (module docstring), at most
MEMO_ROWS = 1 << 14


class GraphSystem:
    """A mechanism's stacked loop closure (module docstring)."""

    def __init__(self, mech: Mechanism, lay: GraphLayout) -> None:
        self.mech, self.lay = mech, lay
        self.n_scalar, self.n_spherical, self.m = lay.n_scalar, lay.n_spherical, lay.m
        self.col_scale = 1.0 / column_scale(lay)
        self.in_scale = self.col_scale[list(lay.inputs)]
        self.idle_spin = False  # idle freedoms stay still: minimum-norm steps and rates
        self.balls = ball_freedoms(lay.joint_of, lay.spherical_of_joint)
        # an interpolated sample is kept where it closes to the corrector's tolerance (as the
        # graph's build takes every sample: its rates from the stacked Jacobian there)
        self.fill_tol = CLOSURE_TOL
        self.passive = list(lay.passive)
        s = linearise(mech, lay, zero_configuration(lay)).sigma[0]
        self.rank = int(np.sum(s > RANK_CUTOFF * max(float(s[0]) if s.size else 0.0, 1e-300)))
        # the σ ratio is measured against the drawing's: a stack of many loops is worse
        # conditioned than one loop by its size and scaling alone (a Delta robot's is ~0.004
        # at its drawing), which says nothing of a singularity near; a drawing that is itself
        # (nearly) singular is not a reference
        self.sigma_unit = 1.0
        # redundant constraints or idle freedoms (J_p rank deficient): the jets by the SVD's
        # pseudo-inverse, which the regularised normal equations give to ~1e-7 only there
        self.redundant = self.rank < min(len(self.passive), int(s.size))
        drawn = float(self._ratio_of(s[None, :])[0]) if s.size else 1.0
        if SIGMA_REFERENCE < drawn < 1.0:
            self.sigma_unit = drawn
        self.memo: dict[bytes, tuple[GraphFrames, int]] = {}

    def forget(self) -> None:
        """Drop the kept poses and screws (a new sweep starts)."""
        self.memo.clear()

    def _keys(self, conf: Configuration) -> list[bytes]:
        rows = np.concatenate([conf.scalars,
                               conf.spherical.reshape(conf.size, 9 * self.n_spherical)], axis=1)
        return [r.tobytes() for r in np.ascontiguousarray(rows)]

    def _keep(self, conf: Configuration, fr: GraphFrames) -> None:
        """Keep the poses and screws ``fr`` of ``conf`` (module docstring)."""
        if len(self.memo) + conf.size > MEMO_ROWS:
            self.memo.clear()
        for k, key in enumerate(self._keys(conf)):
            self.memo[key] = (fr, k)

    def frames(self, conf: Configuration) -> GraphFrames:
        """graph_forward's body poses and screws at ``conf`` (its first-order residual),
        reused where kept."""
        found = [self.memo.get(key) for key in self._keys(conf)]
        miss = np.array([i for i, f in enumerate(found) if f is None], dtype=np.intp)
        if miss.size == conf.size:
            fr = graph_forward(self.mech, self.lay, conf, exact=False)
            self._keep(conf, fr)
            return fr
        fields = ("R", "p", "screws", "residual", "centres", "axes")
        first = next(f for f in found if f is not None)[0]
        out = {n: np.empty((conf.size, *getattr(first, n).shape[1:])) for n in fields}
        if miss.size:
            fresh = graph_forward(self.mech, self.lay, conf.take(miss), exact=False)
            self._keep(conf.take(miss), fresh)
            for n in fields:
                out[n][miss] = getattr(fresh, n)
        sources: dict[int, tuple[GraphFrames, list[int], list[int]]] = {}
        for i, f in enumerate(found):
            if f is not None:
                entry = sources.setdefault(id(f[0]), (f[0], [], []))
                entry[1].append(i)
                entry[2].append(f[1])
        for kept, rows, at in sources.values():
            for n in fields:
                out[n][rows] = getattr(kept, n)[at]
        return GraphFrames(**out)

    def _ratio_of(self, s: Array) -> Array:
        if self.rank == 0 or s.shape[1] == 0:
            return np.ones(s.shape[0])
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(np.nan_to_num(s[:, self.rank - 1] / s[:, 0]))

    def _ratio(self, lin: Linearised) -> Array:
        """σ_r/σ_1 of the passive block, relative to the drawing's (``sigma_unit``)."""
        return self._ratio_of(lin.sigma) / self.sigma_unit

    def polished(self, conf: Configuration) -> Configuration:
        return conf  # a drawing, or a mode's sample closed by the corrector already

    def residual(self, conf: Configuration) -> tuple[Array, Any]:
        fr = graph_forward(self.mech, self.lay, conf, exact=False)
        self._keep(conf, fr)
        return np.max(np.abs(scaled_residual(self.mech, self.lay, fr)), axis=-1), fr

    def sigma(self, conf: Configuration) -> Array:
        return self._ratio(linearise(self.mech, self.lay, conf))

    def jets(self, conf: Configuration, D: Array, exact_sigma: bool = True,
             ) -> tuple[Array, Array, Array, Array]:
        """q' and q'' along ``D`` (module docstring): one rate and one acceleration solve."""
        lin = linearise(self.mech, self.lay, conf, self.frames(conf),
                        exact=exact_sigma or self.redundant)
        qd = rates(self.mech, self.lay, lin, D)
        qdd = accelerations(self.mech, self.lay, lin, qd, np.zeros_like(D))[0]
        sigma = self._ratio(lin) if exact_sigma else np.full(conf.size, np.nan)
        return qd, qdd, sigma, lin.Jp

    def set_inputs(self, conf: Configuration, X: Array) -> Configuration:
        return set_inputs(conf, self.lay, X)

    def increment(self, conf: Configuration, delta: Array) -> Configuration:
        return increment(conf, delta, self.lay)

    def difference(self, a: Configuration, b: Configuration) -> Array:
        return difference(a, b, self.lay)

    def correct(self, conf: Configuration, reach: Array, contraction: float | Array,
                max_iter: int = 7) -> Correction:
        """tracker/solve.py ``correct`` on the stacked closure: Newton on the passive freedoms
        (minimum-norm, scaled), accepted where it converges to CLOSURE_TOL with its first step
        within ``reach``, all within 1.5 ``reach`` and the second at most ``contraction`` times
        the first (Deuflhard)."""
        mech, lay, P = self.mech, self.lay, self.passive
        cs = column_scale(lay)[P]
        N = conf.size
        q, sph = conf.scalars.copy(), conf.spherical.copy()
        limit = np.broadcast_to(np.asarray(contraction, dtype=float), (N,))
        first = np.zeros(N)
        total = np.zeros((N, len(P)))
        done = np.zeros(N, dtype=bool)
        last = np.full(N, np.inf)
        todo = np.arange(N)
        for it in range(max_iter + 1):
            at = Configuration(q[todo], sph[todo])
            lin = linearise(mech, lay, at, exact=False)
            self._keep(at, lin.frames)
            xi = scaled_residual(mech, lay, lin.frames)
            r = np.max(np.abs(xi), axis=-1)
            keep = polish_verdict(r, todo, last, done, CLOSURE_TOL)
            if it == max_iter or not keep.any():
                break
            done[todo[keep]] = False  # a polishing step must succeed too
            todo = todo[keep]
            step = -lin.take(np.flatnonzero(keep)).solve(xi[keep])
            hopeful = step_verdict(it, step, todo, total, first, reach, limit)
            if not hopeful.all():
                todo, step = todo[hopeful], step[hopeful]
                if todo.size == 0:
                    break
            delta = np.zeros((len(todo), lay.m))
            delta[:, P] = step * cs
            moved = increment(Configuration(q[todo], sph[todo]), delta, lay)
            q[todo], sph[todo] = moved.scalars, moved.spherical
        return Correction(Configuration(q, sph), done)

    def signature(self, conf: Configuration) -> Array:
        """Joint centres (/ length scale) and non-spherical axes: one per assembly."""
        fr = self.frames(conf)
        ax = [fr.axes[:, i] for i, j in enumerate(self.mech.joints) if j.kind != "S"]
        return np.concatenate([fr.centres.reshape(conf.size, -1) / self.lay.length, *ax], -1)

    def sample_rates(self, checked: Any, closed: NDArray[np.bool_],
                     near: tuple[Array, Array] | None, Xd: Array, Xdd: Array) -> TrackRates:
        raise NotImplementedError("a graph's rates come from its motion build (graph/motion.py)")


__all__ = ["GraphSystem"]
