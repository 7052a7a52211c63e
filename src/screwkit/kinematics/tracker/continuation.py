"""Branch tracking by continuation: every assembly mode followed along the input sweep from one
closed configuration (a *seed*), forwards and backwards, with a second-order predictor and a
vectorised Newton corrector.

The sweep is a path in input space through the samples X_0 … X_{N−1}, straight between
neighbours (position t ∈ [0, N−1]). From a closed configuration at t the predictor is the
second-order Taylor expansion of the branch, q(X_t + d) ≈ q + q_X d + ½ q_XX(d, d), with the
exact first and second derivatives from the rate equations (:mod:`screwkit.kinematics.tracker.rates`;
where they are undefined, the secant through the last two points). A *front* (a branch end
moving in one direction) predicts a whole chunk of samples ahead at once, and all fronts'
predictions are corrected together (:func:`~screwkit.kinematics.tracker.solve.correct`, vectorised over
fronts and samples). A corrected sample is accepted when Newton converged and contracted fast
from a prediction close to the result (Deuflhard's test: a jump towards another branch does
not), and, where the passive Jacobian is near singular (another branch may be as close as a
step), when the same step taken in two halves converges and ends at the same root (a
step-halving test); a chunk is accepted up to its first rejected sample and the next chunk
doubles or shrinks accordingly. When even the next sample is rejected the front sub-steps
between samples with steps cut by four; when the step falls below 2⁻⁸ of the sample spacing it
tries once to step over the next sample to the one after (branches that cross — a bifurcation
— are passed that way, the crossing sample closed by Newton alone), and if that fails too the
branch ends there: a limit position or dead centre lies between the two samples (it *stops*,
or going backwards it *starts assembling*). Near a fold the passive Jacobian's smallest
singular value falls as the square root of the distance to it, σ² ∝ x* − x: where a step
fails and the σ measured at the front's last two points extrapolates to zero before the next
sample, the branch ends at once.

On a fine sweep a chunk is corrected only at every few samples (at most FILL_STRIDE samples
and FILL_SPAN of input apart); the samples in between are filled by quintic Hermite
interpolation between neighbouring corrected samples (:mod:`screwkit.kinematics.tracker.branch_fill`)
and kept where the loop closes there to round-off (the system's fill_tol), else corrected by Newton
with the same tests. Asked for rates, the tracker also solves the rate equations of those
samples from the screws of that closure check (:class:`~screwkit.kinematics.tracker.tracks.TrackRates`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.tracker.branch_fill import hermite_increments
from screwkit.kinematics.tracker.loop import Array, Configuration, Layout
from screwkit.kinematics.tracker.meeting import joins_another
from screwkit.kinematics.tracker.solve import CLOSURE_TOL, Correction
from screwkit.kinematics.tracker.system import ClosureSystem, LoopSystem
from screwkit.kinematics.tracker.tracks import (
    Front,
    Track,
    TrackRates,
    coarse_targets,
    input_at,
    sample_writer,
)
from screwkit.model.linkage import Linkage

MIN_SUBSTEP = 2.0 ** -8  # of the sample spacing: a front that cannot advance further ends
FOLD_SIGMA = 0.2  # σ_min/σ_max of J_p below which a failed step may be a fold ahead
MAX_CHUNK = 16384  # samples predicted at once by one front
MAX_SPAN = 1.5  # rad (or length scale) the inputs may move over one chunk
FIRST_STEP = 0.2  # largest Newton correction, relative to the predicted step
CONTRACTION = 0.5  # largest ratio of the second Newton step to the first
FILL_SPAN = 0.01  # rad (or length scale) of input between two corrected samples of a chunk
FILL_STRIDE = 128  # samples between two corrected samples of a chunk, at most


class Tracker:
    """Follows seeds along the sweep ``X`` (module docstring); ``tracks`` grows as seeds are
    added and followed."""

    def __init__(self, linkage: Linkage | None, lay: Layout | None, X: Array,
                 progress: Callable[[int], None] | None = None,
                 rates: tuple[Array, Array] | None = None,
                 system: ClosureSystem | None = None, smallest: float | None = None) -> None:
        """Follows a loop (``linkage`` in the layout ``lay``) or any closure ``system``
        (tracker/system.py: the stacked closure of a mechanism's loops, graph/system.py).
        ``smallest`` (scaled input distance): sub-steps go down to it, not MIN_SUBSTEP of the
        spacing, and a failed step does not end the branch on σ's extrapolation (a front that
        must get as near a fold as that: graph/follow.py ``reach``)."""
        if system is None:
            assert linkage is not None and lay is not None
            system = LoopSystem(linkage, lay)
        self.system, self.X = system, X
        # the inputs' rates and accelerations (N, n_in): then the rates of the samples filled
        # by interpolation are found from the closure check's screws (a loop without S–S
        # rods, whose poses a Motion's build turns)
        self.rates = rates if rates is not None and not system.idle_spin else None
        self.fill_tol = system.fill_tol
        self.N = X.shape[0]
        self.tracks: list[Track] = []
        self._met: dict[int, bool] = {}
        self.progress = progress
        self.smallest = smallest
        self.col_scale = system.col_scale
        self.in_scale = in_scale = system.in_scale
        steps = np.abs(np.diff(X, axis=0)) * in_scale if self.N > 1 else np.zeros((0, 1))
        self.span = np.concatenate([[0.0], np.cumsum(steps.max(axis=1))]) if self.N > 1 \
            else np.zeros(1)

    def add_seeds(self, sample: int, conf: Configuration) -> list[int]:
        """New tracks from closed configurations at one sample (polished by Newton to
        round-off, as every corrected sample is); returns their indices."""
        ids = []
        sys = self.system
        conf = sys.polished(conf)
        for k in range(conf.size):
            tr = Track(np.full((self.N, sys.n_scalar), np.nan),
                       np.tile(np.eye(3), (self.N, sys.n_spherical, 1, 1)),
                       np.zeros(self.N, dtype=bool), sample)
            if self.rates is not None:
                m = sys.m
                tr.rates = TrackRates(np.full((self.N, m), np.nan), np.full((self.N, m), np.nan),
                                      np.zeros(self.N, dtype=bool), np.zeros(self.N, dtype=bool))
            tr.set_sample(sample, conf.scalars[k], conf.spherical[k])
            self.tracks.append(tr)
            ids.append(len(self.tracks) - 1)
            self._met[ids[-1]] = False
            if self.progress is not None:
                self.progress(1)
        return ids

    def follow(self, ids: list[int]) -> None:
        """Follow the given (seeded) tracks forwards and backwards to their ends."""
        fronts = []
        if not ids:
            return
        seeds = Configuration(np.stack([self.tracks[i].scalars[self.tracks[i].seed] for i in ids]),
                              np.stack([self.tracks[i].spherical[self.tracks[i].seed]
                                        for i in ids]))
        sigma = self.system.sigma(seeds)
        for r, i in enumerate(ids):
            tr = self.tracks[i]
            row = seeds.take(np.array([r]))
            for direction in (1, -1):
                if 0 <= tr.seed + direction < self.N:
                    # a seed near a fold starts with sub-steps: its Taylor series is short there
                    fronts.append(Front(i, direction, float(tr.seed), row,
                                         substep=0.25 if sigma[r] < FOLD_SIGMA else 0.0))
        while fronts:
            fronts = self._wave(fronts)

    # ---------------------------------------------------------------------------------------

    def _position(self, t: float) -> float:
        """Input distance along the sweep at position ``t``."""
        k = min(int(np.floor(t)), self.N - 2) if self.N > 1 else 0
        return float(self.span[k] + (t - k) * (self.span[min(k + 1, self.N - 1)] - self.span[k]))

    def _fold_ahead(self, f: Front) -> bool:
        """Whether σ² of the front's last two points extrapolates to zero before the next
        sample (a fold of the branch in the input lies there)."""
        (s1, x1), (s0, x0) = f.sigma, f.sigma_before
        if not (s1 < FOLD_SIGMA and s0 > s1 and np.isfinite(x0)) or x0 == x1:
            return False
        fold = x1 + s1**2 * (x1 - x0) / (s0**2 - s1**2)
        nxt = np.floor(f.t) + 1 if f.direction > 0 else np.ceil(f.t) - 1
        return bool(abs(fold - x1) <= abs(self._position(float(np.clip(nxt, 0, self.N - 1)))
                                          - x1))

    def _targets(self, fr: Front) -> Array:
        if fr.jump:
            near = np.floor(fr.t) + 1 if fr.direction > 0 else np.ceil(fr.t) - 1
            return np.array([near, near + fr.direction])
        if fr.substep:
            nxt = np.floor(fr.t) + 1 if fr.direction > 0 else np.ceil(fr.t) - 1
            t = fr.t + fr.direction * fr.substep
            return np.array([min(t, nxt) if fr.direction > 0 else max(t, nxt)])
        k = int(round(fr.t))
        stop = self.N - 1 if fr.direction > 0 else 0
        count = min(fr.chunk, abs(stop - k))
        idx = k + fr.direction * np.arange(1, count + 1)
        # no more than MAX_SPAN of input movement in one chunk (always at least one sample)
        within = np.abs(self.span[idx] - self.span[k]) <= MAX_SPAN
        within[0] = True
        n = int(np.argmin(within)) if not within.all() else len(idx)
        return idx[:n].astype(float)

    def _along(self, conf: Configuration, v: Array, a: Array, u: Array, d: Array,
               ) -> tuple[Array, Array]:
        """Jets along the input moves ``d`` (T, n_in) at ``conf`` from the jets ``v``, ``a``
        along ``u`` there: s v and s² a where d = s u (a straight sweep: always), else formed
        afresh (a sweep that turns between samples)."""
        w = self.in_scale
        s = np.einsum("ti,ti->t", d * w, u * w) / np.maximum(
            np.einsum("ti,ti->t", u * w, u * w), 1e-300)
        off = np.linalg.norm((d - s[:, None] * u) * w, axis=1)
        v, a = s[:, None] * v, (s**2)[:, None] * a
        fresh = np.nonzero(~(off <= 1e-12 * np.linalg.norm(d * w, axis=1)))[0]
        if fresh.size:
            v[fresh], a[fresh], _, _ = self.system.jets(conf.take(fresh), d[fresh],
                                                        exact_sigma=False)
        return v, a

    def _predict(self, fronts: list[Front], owner: NDArray[np.intp], t: Array) -> Configuration:
        """Each front's targets by its Taylor series along the sweep: one directional jet per
        front, along its move to its furthest target (tracker/system.py)."""
        sys, X = self.system, self.X
        here = Configuration(np.concatenate([f.conf.scalars for f in fronts]),
                             np.concatenate([f.conf.spherical for f in fronts]))
        t_front = np.array([f.t for f in fronts])
        d = input_at(X, t) - input_at(X, t_front)[owner]
        u = d[np.cumsum(np.bincount(owner, minlength=len(fronts))) - 1]
        v, a, sigma, Jp = sys.jets(here, u)
        for k, (f, sg) in enumerate(zip(fronts, sigma.tolist(), strict=True)):
            f.derivatives = (v[k], a[k], u[k])
            f.passive = Jp[k]
            at = self._position(f.t)
            if at != f.sigma[1]:
                f.sigma_before, f.sigma = f.sigma, (sg, at)
        dv, da = self._along(here.take(owner), v[owner], a[owner], u[owner], d)
        delta = dv + 0.5 * da
        bad = ~np.all(np.isfinite(delta), axis=1)
        if bad.any():  # singular front: the secant through its last two points
            for r in np.nonzero(bad)[0]:
                f = fronts[owner[r]]
                if f.prev is None or f.t == f.prev_t:
                    delta[r] = 0.0
                else:
                    sec = sys.difference(f.conf, f.prev)[0]
                    delta[r] = sec * (t[r] - f.t) / (f.t - f.prev_t)
        return sys.set_inputs(sys.increment(here.take(owner), delta), input_at(X, t))

    def _step(self, here: Configuration, t_here: Array, t_to: Array) -> Correction:
        """Predict from closed configurations ``here`` (at positions ``t_here``) to ``t_to``
        and correct (the acceptance tests of a front's step)."""
        sys, X = self.system, self.X
        v, a, _, _ = sys.jets(here, input_at(X, t_to) - input_at(X, t_here))
        delta = v + 0.5 * a
        delta = np.where(np.isfinite(delta), delta, 0.0)
        pred = sys.set_inputs(sys.increment(here, delta), input_at(X, t_to))
        step = np.linalg.norm(sys.difference(pred, here) * self.col_scale, axis=1)
        return sys.correct(pred, FIRST_STEP * step + 1e-9, CONTRACTION)

    def _halves_agree(self, start: Configuration, t_start: Array, reached: Configuration,
                      t_reached: Array, sigma: Array) -> NDArray[np.bool_]:
        """The step-halving test of steps taken where the branch's passive Jacobian is near
        singular (another branch close by): the same step taken in two halves, each from a
        closer (so better) prediction, must end where the whole step did. A whole step that
        jumped onto a neighbouring branch ends elsewhere than the halves, which stay on the
        branch; it is rejected. So is a step whose halves do not converge (the half step from
        the start failing its contraction test is itself the sign of a close branch): the
        front then takes shorter steps, each tested the same way. Within the uncertainty of a
        root there, residual/σ, two ends count as one."""
        mid_t = 0.5 * (t_start + t_reached)
        mid = self._step(start, t_start, mid_t)
        conclusive = mid.accepted.copy()
        end = Configuration(reached.scalars.copy(), reached.spherical.copy())
        if conclusive.any():
            rows = np.nonzero(conclusive)[0]
            second = self._step(mid.conf.take(rows), mid_t[rows], t_reached[rows])
            conclusive[rows] = second.accepted
            end.scalars[rows] = second.conf.scalars
            end.spherical[rows] = second.conf.spherical
        # compared by signature (joint centres and axes): an S–S rod's idle spin is free
        miss = np.max(np.abs(self.system.signature(end) - self.system.signature(reached)),
                      axis=1)
        return np.asarray(conclusive & (miss <= np.maximum(1e-6, 1e-10 / np.maximum(
            sigma, 1e-300))))

    def _wave(self, fronts: list[Front]) -> list[Front]:
        """One predictor–corrector pass of every front; returns the fronts still moving. A
        long chunk is corrected at every few samples only (its *coarse* targets) and filled
        in between by interpolation (:meth:`_fill`)."""
        every = [self._targets(f) for f in fronts]
        strides = [self._fill_stride(f, tg) for f, tg in zip(fronts, every, strict=True)]
        targets = [tg if s == 1 else tg[coarse_targets(len(tg), s)]
                   for tg, s in zip(every, strides, strict=True)]
        owner = np.concatenate([np.full(len(tg), k) for k, tg in enumerate(targets)])
        t = np.concatenate(targets)
        pred = self._predict(fronts, owner, t)
        here = Configuration(np.concatenate([f.conf.scalars for f in fronts]),
                             np.concatenate([f.conf.spherical for f in fronts])).take(owner)
        step = np.linalg.norm(self.system.difference(pred, here) * self.col_scale, axis=1)
        # a jump's near target is the singular sample itself: Newton converges there only
        # linearly; it is accepted if it converges and the sample after it passes the test
        near = np.zeros(len(t), dtype=bool)
        near[np.cumsum([len(tg) for tg in targets]) - 2] = [f.jump for f in fronts]
        reach = np.where(near, np.inf, FIRST_STEP * step + 1e-9)
        res = self.system.correct(pred, reach, np.where(near, 1.0, CONTRACTION),
                                  max_iter=40 if near.any() else 7)
        ok = self._halving_test(fronts, targets, res.conf, res.accepted)
        alive = []
        fills: list[tuple[Front, Array, Array, Configuration, bool]] = []
        start = 0
        for k, f in enumerate(fronts):
            n = len(targets[k])
            sl = slice(start, start + n)
            start += n
            acc = ok[sl]
            p = n if acc.all() else int(np.argmin(acc))
            if f.jump:
                f.jump = False
                if not acc[1]:
                    if not self._end(f):
                        continue
                keep = np.nonzero(acc)[0]
                if self._advance(f, targets[k][keep], res.conf.take(sl.start + keep),
                                 full=False):
                    alive.append(f)
                continue
            reached = res.conf.take(np.arange(sl.start, sl.start + p))
            if strides[k] > 1:
                if p == 0:  # the first coarse target failed: retry with single samples
                    f.chunk = 1
                    alive.append(f)
                else:
                    fills.append((f, every[k], targets[k][:p], reached, p == n))
                continue
            f.plain = False
            if self._advance(f, targets[k][:p], reached, full=p == n):
                alive.append(f)
        for f, t_acc, conf, full, rates in self._fill(fills):
            if not full and f.plain:  # an interpolated sample failed: the next chunk is
                if not len(t_acc):    # corrected sample by sample, from here
                    alive.append(f)
                    continue
            if self._advance(f, t_acc, conf, full=full, rates=rates):
                alive.append(f)
        return alive

    def _fill_stride(self, f: Front, targets: Array) -> int:
        """Every how many samples a front's chunk is corrected (1: every sample): so that each
        interval between corrected samples spans at most FILL_SPAN of input and FILL_STRIDE
        samples; only for chunks of plain samples (not sub-steps or jumps)."""
        if f.jump or f.substep or f.plain or not f.fill or len(targets) < 4:
            return 1
        k = int(round(f.t))
        idx = targets.astype(int)
        spacing = np.abs(np.diff(self.span[np.concatenate([[k], idx])])).max()
        if spacing <= 0.0:
            return 1
        return int(np.clip(FILL_SPAN // spacing, 1, min(FILL_STRIDE, len(targets) // 2)))

    def _fill(self, fills: list[tuple[Front, Array, Array, Configuration, bool]],
              ) -> list[tuple[Front, Array, Configuration, bool, TrackRates | None]]:
        """The samples between a front and its accepted coarse targets, all fronts at once:
        predicted by quintic Hermite interpolation between neighbouring corrected samples of the
        branch (:mod:`screwkit.kinematics.tracker.branch_fill`, with the derivatives from the rate
        equations at both), accepted where the loop closes there to round-off (fill_tol)
        (the interpolation error is of sixth order in the interval); elsewhere corrected by
        Newton with the usual acceptance tests. A front keeps its samples up to the first one
        that fails. Returns, per front, the samples reached, their configurations, whether the
        whole chunk was, and (when the tracker was asked for them) their rates where found."""
        if not fills:
            return []
        sys, X = self.system, self.X
        starts = Configuration(np.concatenate([f.conf.scalars for f, *_ in fills]),
                               np.concatenate([f.conf.spherical for f, *_ in fills]))
        nodes = Configuration(np.concatenate([c.scalars for *_, c, _ in fills]),
                              np.concatenate([c.spherical for *_, c, _ in fills]))
        counts = [len(tc) for _, _, tc, _, _ in fills]
        first = np.cumsum([0, *counts[:-1]])  # each front's first node
        # interval j runs from node j − 1 (the front, for a front's first interval) to node j
        prev = np.arange(nodes.size) - 1
        is_first = np.zeros(nodes.size, dtype=bool)
        is_first[first] = True
        which = np.repeat(np.arange(len(fills)), counts)
        A = Configuration(np.where(is_first[:, None], starts.scalars[which],
                                   nodes.scalars[np.maximum(prev, 0)]),
                          np.where(is_first[:, None, None, None], starts.spherical[which],
                                   nodes.spherical[np.maximum(prev, 0)]))
        def at_starts(of_front: list[Array], of_nodes: Array) -> Array:
            """A quantity at each interval's start: the front's, or the node before."""
            front = np.stack(of_front)[which]
            return np.asarray(np.where(is_first.reshape(-1, *[1] * (front.ndim - 1)), front,
                                       of_nodes[np.maximum(prev, 0)]))

        tB = np.concatenate([tc for _, _, tc, _, _ in fills])
        tA = np.where(is_first, np.array([f.t for f, *_ in fills])[which], np.roll(tB, 1))
        dX = input_at(X, tB) - input_at(X, tA)
        # the jets along each interval: at its end directly, at its start from the front's
        # (this wave's, set by _predict) or the node before's, and the Jacobians there
        v1, a1, _, JB = sys.jets(nodes, dX, exact_sigma=False)
        v0, a0 = self._along(A, at_starts([f.derivatives[0] for f, *_ in fills], v1),  # type: ignore[index]
                             at_starts([f.derivatives[1] for f, *_ in fills], a1),  # type: ignore[index]
                             at_starts([f.derivatives[2] for f, *_ in fills], dX), dX)  # type: ignore[index]
        JA = at_starts([f.passive for f, *_ in fills], JB)  # type: ignore[misc]
        d1 = sys.difference(nodes, A)
        # the samples strictly inside each interval
        gap = np.abs(tB - tA).astype(int) - 1
        interval = np.repeat(np.arange(nodes.size), gap)
        offset = np.arange(interval.size) - np.repeat(np.cumsum(gap) - gap, gap) + 1
        direction = np.sign(tB - tA)
        t = tA[interval] + direction[interval] * offset
        # where the input lies between the interval's ends (projected on its chord: exact for
        # a straight sweep however unevenly sampled)
        scale = self.in_scale
        chord = dX[interval] * scale
        u = np.einsum("ti,ti->t", (input_at(X, t) - input_at(X, tA)[interval]) * scale, chord) \
            / np.maximum(np.einsum("ti,ti->t", chord, chord), 1e-300)
        delta = hermite_increments(sys.balls, d1, v0, a0, v1, a1, interval, u)
        line = ~np.all(np.isfinite(delta), axis=1)  # a singular end: the chord
        delta[line] = u[line, None] * d1[interval[line]]
        start_conf = A.take(interval)
        pred = sys.set_inputs(sys.increment(start_conf, delta), input_at(X, t))
        near = (JA[interval], np.asarray(np.linalg.svd(JA, compute_uv=False)[:, -1],
                                         dtype=float)[interval]) \
            if JA.shape[1] >= JA.shape[2] > 0 else None
        tol = self._fill_closure(starts, nodes, is_first, which, prev)
        conf, closed, rates, as_is = self._closed_or_corrected(pred, start_conf, t, near,
                                                        tol[interval])
        out = []
        for k, (f, _, tc, reached, full) in enumerate(fills):
            mine = np.nonzero(which[interval] == k)[0]
            t_all = np.concatenate([t[mine], tc])
            order = np.argsort(t_all * f.direction, kind="stable")
            ok = np.concatenate([closed[mine], np.ones(len(tc), dtype=bool)])[order]
            # most interpolated samples needed Newton: the front corrects every sample on
            f.fill = f.fill and not (len(mine) and 2 * int(as_is[mine].sum()) < len(mine))
            p = len(order) if ok.all() else int(np.argmin(ok))
            f.plain = p < len(order)
            keep = order[:p]
            here = Configuration(np.concatenate([conf.scalars[mine], reached.scalars])[keep],
                                 np.concatenate([conf.spherical[mine], reached.spherical])[keep])
            found = None
            if rates is not None:  # the coarse targets' rates are not known here
                pad = len(tc)
                found = TrackRates(*(np.concatenate([a[mine], np.full((pad, *a.shape[1:]),
                                                                      fill, a.dtype)])[keep]
                                     for a, fill in ((rates.qd, np.nan), (rates.qdd, np.nan),
                                                     (rates.singular, False),
                                                     (rates.known, False))))
            out.append((f, t_all[keep], here, full and p == len(order), found))
        return out

    def _fill_closure(self, starts: Configuration, nodes: Configuration,
                      is_first: NDArray[np.bool_], which: NDArray[np.intp],
                      prev: NDArray[np.intp]) -> Array:
        """The closure residual at which an interval's interpolated samples are kept as they
        are: about the round-off of the corrected samples on either side (each polished by
        Newton), at most the corrector's tolerance (which the stacked closure's fill_tol is)."""
        if self.fill_tol >= CLOSURE_TOL:
            return np.full(nodes.size, CLOSURE_TOL)
        res = self.system.residual(Configuration(
            np.concatenate([starts.scalars, nodes.scalars]),
            np.concatenate([starts.spherical, nodes.spherical])))[0]
        res_a = np.where(is_first, res[:starts.size][which], res[starts.size:][np.maximum(prev, 0)])
        return np.asarray(np.clip(8.0 * np.maximum(res_a, res[starts.size:]), self.fill_tol,
                                  CLOSURE_TOL))

    def _closed_or_corrected(self, pred: Configuration, start: Configuration, t: Array,
                             near: tuple[Array, Array] | None, tol: Array,
                             ) -> tuple[Configuration, NDArray[np.bool_], TrackRates | None,
                                        NDArray[np.bool_]]:
        """Interpolated samples (at positions ``t``) as they are where the loop closes to the
        corrector's tolerance, else corrected by Newton from them (accepted by the corrector's
        tests, the reach measured from the interval's start); with the rates of the samples
        kept as they are, from the same screws, when the tracker was asked for rates (their
        rank test helped by ``near``: each interval start's passive Jacobian and σ_min)."""
        sys = self.system
        residual, checked = sys.residual(pred)
        closed = residual <= tol
        rates = None
        if self.rates is not None:
            k = np.round(t).astype(int)
            rates = sys.sample_rates(checked, closed, near, self.rates[0][k], self.rates[1][k])
        if closed.all():
            return pred, closed, rates, closed
        as_is = closed.copy()
        bad = np.nonzero(~closed)[0]
        sub = pred.take(bad)
        step = np.linalg.norm(sys.difference(sub, start.take(bad)) * self.col_scale, axis=1)
        fixed = sys.correct(sub, FIRST_STEP * step + 1e-9, CONTRACTION)
        scalars, spherical = pred.scalars.copy(), pred.spherical.copy()
        scalars[bad], spherical[bad] = fixed.conf.scalars, fixed.conf.spherical
        closed[bad] = fixed.accepted
        return Configuration(scalars, spherical), closed, rates, as_is

    def _halving_test(self, fronts: list[Front], targets: list[Array], conf: Configuration,
                    accepted: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """``accepted`` less the steps that fail the step-halving test (:meth:`_halves_agree`):
        every accepted step longer than σ of a front near a singular configuration (σ below
        FOLD_SIGMA), each against the sample before it, all fronts at once. Steps over a
        singular sample (a jump) are not tested: they cross where two branches meet by design."""
        ok = accepted.copy()
        rows, starts, t_to, t_from, sigma = [], [], [], [], []
        first = 0
        for f, tg in zip(fronts, targets, strict=True):
            n = len(tg)
            if not f.jump and f.sigma[0] < FOLD_SIGMA:
                acc = accepted[first:first + n]
                p = n if acc.all() else int(np.argmin(acc))
                if p:
                    mine = np.arange(first, first + p)
                    rows.append(mine)
                    before = conf.take(mine[:-1])
                    starts.append(Configuration(np.concatenate([f.conf.scalars, before.scalars]),
                                                np.concatenate([f.conf.spherical,
                                                                before.spherical])))
                    t_to.append(tg[:p])
                    t_from.append(np.concatenate([[f.t], tg[:p - 1]]))
                    sigma.append(np.full(p, f.sigma[0]))
            first += n
        if not rows:
            return ok
        idx = np.concatenate(rows)
        start_conf = Configuration(np.concatenate([c.scalars for c in starts]),
                                   np.concatenate([c.spherical for c in starts]))
        reached = conf.take(idx)
        sig = np.concatenate(sigma)
        # only steps longer than σ (scaled freedoms): a root as close as the step lies within
        # ~σ of the branch only where the Jacobian is that near singular
        step = np.linalg.norm(self.system.difference(reached, start_conf) * self.col_scale,
                              axis=1)
        long = np.nonzero(step > sig)[0]
        if long.size:
            ok[idx[long]] = self._halves_agree(start_conf.take(long),
                                               np.concatenate(t_from)[long],
                                               reached.take(long), np.concatenate(t_to)[long],
                                               sig[long])
        return ok

    def _advance(self, f: Front, t: Array, conf: Configuration, full: bool,
                 rates: TrackRates | None = None) -> bool:
        """Move front ``f`` over its accepted targets (with their rates where known); False
        when it has ended."""
        tr = self.tracks[f.track]
        if len(t):
            whole = np.nonzero(t == np.round(t))[0]
            idx = t[whole].astype(int)
            put = sample_writer(idx, whole)
            put(tr.scalars, conf.scalars)
            put(tr.spherical, conf.spherical)
            tr.mask[idx] = True
            if tr.rates is not None:
                if rates is None:
                    tr.rates.known[idx] = False
                else:
                    for name in ("qd", "qdd", "singular", "known"):
                        put(getattr(tr.rates, name), getattr(rates, name))
            if self.progress is not None and len(idx):
                self.progress(len(idx))
            if len(self.tracks) > 1 and joins_another(self.system, self.tracks, self._met, f.track, idx,
                                                         conf.take(whole)):
                return False
            last = len(t) - 1
            if len(t) > 1:
                f.prev, f.prev_t = conf.take(np.array([last - 1])), float(t[last - 1])
            else:
                f.prev, f.prev_t = f.conf, f.t
            f.conf, f.t = conf.take(np.array([last])), float(t[last])
            if f.substep:
                if f.t == round(f.t):
                    f.substep, f.chunk = 0.0, 1
                else:
                    f.substep = min(4 * f.substep, 0.5)
            else:
                f.chunk = min(2 * f.chunk, MAX_CHUNK) if full else max(len(t), 1)
                f.jumped = False
        elif self.smallest is None and self._fold_ahead(f):
            return self._jump_or_end(f)
        elif f.substep:
            f.substep /= 4
            if f.substep < self._min_substep(f):
                return self._jump_or_end(f)
        else:
            f.substep = 0.25
        at_end = f.t == round(f.t) and not (0 <= round(f.t) + f.direction < self.N)
        return not at_end

    def _min_substep(self, f: Front) -> float:
        """The shortest sub-step (a fraction of the spacing to the next sample)."""
        if self.smallest is None:
            return MIN_SUBSTEP
        k = int(np.clip(np.floor(f.t) if f.direction > 0 else np.ceil(f.t) - 1, 0, self.N - 2))
        return self.smallest / max(float(self.span[k + 1] - self.span[k]), 1e-300)

    def _jump_or_end(self, f: Front) -> bool:
        """A front that cannot reach the next sample may be at a bifurcation (branches that
        cross), which it can step over: try once to land on the sample after the next (the
        next being the singular one); if that fails too, the branch ends (a fold)."""
        near = np.floor(f.t) + 1 if f.direction > 0 else np.ceil(f.t) - 1
        if f.jumped or not (0 <= near + f.direction < self.N):
            return self._end(f)
        f.jump = f.jumped = True
        f.substep = 0.0
        return True

    def _end(self, f: Front) -> bool:
        tr = self.tracks[f.track]
        last = int(np.floor(f.t)) if f.direction > 0 else int(np.ceil(f.t))
        if f.direction > 0:
            tr.stops.append((last, f.t))
        else:
            tr.starts.append((last, f.t))
        return False
