"""Continuation of the drawn assembly mode along the inputs, in batched waves.

From the drawn configuration (every freedom 0 at inputs 0) the mode is followed to the first
sample and then along the sweep. A wave predicts up to K samples at once from the last accepted
one by the second-order Taylor expansion of the closure (rates and the velocity-product term
along each sample's input increment), corrects them all by one batched Newton solve, and keeps the
longest run that (a) closes and (b) is consistent with its own rates: consecutive samples must
differ by the trapezoid rule's ½(q̇ₖ + q̇ₖ₊₁)Δx up to a fraction of the step, which a jump onto
another branch cannot meet. K doubles after a full wave and shrinks after a short one; where a
single sample fails, the input step is halved where it fails, down to 1e-7 rad (or 1e-7 of the
length scale), before the mode is declared to stop assembling there (a fold: the branch turns back, a dead centre or limit position).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphFrames, GraphLayout, body_twists, loop_bias
from screwkit.kinematics.graph.newton import (
    CLOSURE_TOL,
    Linearised,
    column_scale,
    difference,
    increment,
    linearise,
    newton,
    rates,
    row_scale,
)
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

MAX_WAVE = 512
#: a step is consistent when its trapezoid-rule error is below this fraction of the step
CONSISTENCY = 0.05
#: a failed step is halved until its sub-steps are this small (rad, or this fraction of the
#: length scale for a slide): a step that starts next to a fold needs many halvings there
SMALLEST_STEP = 1e-7
MAX_SPLIT_DEPTH = 60


@dataclass
class _Point:
    conf: Configuration  # one sample
    x: Array  # (n_in,)
    lin: Linearised


def _predict(mech: Mechanism, lay: GraphLayout, at: _Point, X: Array) -> Configuration:
    """Second-order Taylor prediction from ``at`` to every input row of ``X`` (K, n_in)."""
    K = X.shape[0]
    d = X - at.x[None, :]
    lin = Linearised(at.lin.frames, np.broadcast_to(at.lin.J, (K, *at.lin.J.shape[1:])),
                     np.broadcast_to(at.lin.Jp, (K, *at.lin.Jp.shape[1:])), at.lin.sigma,
                     np.broadcast_to(at.lin.pinv, (K, *at.lin.pinv.shape[1:])))
    qd = rates(mech, lay, lin, d)
    screws = np.broadcast_to(at.lin.frames.screws, (K, *at.lin.frames.screws.shape[1:]))
    _, bias = body_twists(mech, lay, screws, qd)
    L = len(mech.topology.loops)
    rhs = -loop_bias(mech, bias) * row_scale(lay, L)
    cs = column_scale(lay)
    qdd = np.zeros_like(qd)
    qdd[:, list(lay.passive)] = lin.solve(rhs) * cs[list(lay.passive)]
    start = Configuration(np.repeat(at.conf.scalars, K, 0), np.repeat(at.conf.spherical, K, 0))
    return increment(start, qd + 0.5 * qdd, lay)


def _consistent(mech: Mechanism, lay: GraphLayout, prev: _Point, conf: Configuration,
                X: Array, lin: Linearised) -> NDArray[np.bool_]:
    """Whether each sample follows from the one before it by the trapezoid rule."""
    K = conf.size
    before = Configuration(np.concatenate([prev.conf.scalars, conf.scalars[:-1]]),
                           np.concatenate([prev.conf.spherical, conf.spherical[:-1]]))
    Xb = np.concatenate([prev.x[None, :], X[:-1]])
    piv = np.concatenate([prev.lin.pinv, lin.pinv[:-1]])
    Jb = np.concatenate([prev.lin.J, lin.J[:-1]])
    Jpb = np.concatenate([prev.lin.Jp, lin.Jp[:-1]])
    d = X - Xb
    cs = column_scale(lay)
    rate_after = rates(mech, lay, lin, d)
    rate_before = rates(mech, lay, Linearised(lin.frames, Jb, Jpb, lin.sigma, piv), d)
    actual = difference(conf, before, lay) / cs
    trap = 0.5 * (rate_after + rate_before) / cs
    passive = list(lay.passive)
    miss = (actual - trap)[:, passive]
    # idle freedoms (null directions of J_p) may move freely: compare off the null space
    proj = np.einsum("nij,njk->nik", lin.pinv, lin.J[:, :, passive])
    miss = np.einsum("nij,nj->ni", proj, miss)
    size = np.linalg.norm(actual[:, passive], axis=1)
    ok = np.linalg.norm(miss, axis=1) <= CONSISTENCY * size + 1e-9
    return np.asarray(ok[:K])


def _wave(mech: Mechanism, lay: GraphLayout, at: _Point, X: Array
          ) -> tuple[int, Configuration, Linearised]:
    """Predict and correct the samples ``X``; the count of the leading run that is kept."""
    pred = _predict(mech, lay, at, X)
    conf, err, lin = newton(mech, lay, pred, X, max_iter=6, exact=False)
    ok = err <= CLOSURE_TOL * 10
    if ok.any():
        ok &= _consistent(mech, lay, at, conf, X, lin)
    bad = np.nonzero(~ok)[0]
    return (int(bad[0]) if bad.size else X.shape[0]), conf, lin


def _split_step(mech: Mechanism, lay: GraphLayout, at: _Point, x: Array, depth: int,
                smallest: float = SMALLEST_STEP) -> _Point | None:
    """Reach input ``x`` from ``at`` in 2, then 4 … sub-steps, halving where a sub-step fails
    until it is ``smallest`` long; None where it cannot (a fold in between)."""
    scale = np.where(np.array([lay.is_translation[f] for f in lay.inputs]), lay.length, 1.0)
    if depth > MAX_SPLIT_DEPTH or float(np.max(np.abs(x - at.x) / scale)) < smallest:
        return None
    mid = 0.5 * (at.x + x)
    for target in (mid, x):
        count, conf, lin = _wave(mech, lay, at, target[None, :])
        if count == 1:
            at = _Point(conf, target, lin)
            continue
        reached = _split_step(mech, lay, at, target, depth + 1, smallest)
        if reached is None:
            return None
        at = reached
    return at


@dataclass(frozen=True)
class Followed:
    """The drawn mode over the samples: configurations (N), where they hold, and the input
    where the mode stops assembling (None if it assembles throughout)."""

    conf: Configuration
    mask: NDArray[np.bool_]
    stopped_after: int | None
    #: the body poses, screws, joint centres and axes at every sample reached (the corrector's
    #: last evaluation, at the closed configuration), for the motion build to reuse
    frames: GraphFrames | None = None
    #: where the first sample is not reached: the last input on the straight way there from
    #: the drawing that assembles (the drawing, 0, if no step does)
    reached: Array | None = None
    #: the continuation that followed it, for the motion's solver string
    solver: str = "continuation from the drawn configuration on the stacked loop closure"


def follow_drawn_mode(mech: Mechanism, lay: GraphLayout, X: Array,
                      progress: object = None, start: Configuration | None = None,
                      start_inputs: Array | None = None) -> Followed:
    """Follow the drawn configuration (inputs 0) to ``X[0]`` and along every row of ``X``;
    ``start`` replaces the drawing (one closed sample at inputs ``start_inputs``, 0 if not
    given: a mechanism re-assembled near its drawing, motion.reassemble_drawing; a mode found
    at an anchor, kinematics/modes/along.py)."""
    N, n_in = X.shape
    conf0 = start if start is not None else Configuration(
        np.zeros((1, lay.n_scalar)), np.broadcast_to(np.eye(3), (1, lay.n_spherical, 3, 3)).copy())
    x0 = np.zeros(n_in) if start_inputs is None else np.asarray(start_inputs, dtype=float)
    at = _Point(conf0, x0, linearise(mech, lay, conf0, exact=False))
    scal = np.zeros((N, lay.n_scalar))  # samples it does not reach keep the drawing (finite)
    sph = np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy()
    mask = np.zeros(N, dtype=bool)
    if np.any(X[0] != x0):
        reached, furthest = _approach(mech, lay, at, X[0])
        if reached is None:
            return Followed(Configuration(scal, sph), mask, -1, reached=furthest)
        at = reached
        scal[0], sph[0], mask[0] = at.conf.scalars[0], at.conf.spherical[0], True
        k = 1
    else:
        scal[0], sph[0], mask[0] = conf0.scalars[0], conf0.spherical[0], True
        k = 1
    frames = _frame_store(at.lin.frames, N)
    _store(frames, 0, at.lin.frames, 0)
    wave = 8
    report = progress if callable(progress) else None
    while k < N:
        X_wave = X[k:k + wave]
        count, conf, lin = _wave(mech, lay, at, X_wave)
        if count == 0:
            if wave > 1:
                wave = max(1, wave // 4)
                continue
            reached = _split_step(mech, lay, at, X[k], 1)
            if reached is None:
                return Followed(Configuration(scal, sph), mask, k - 1, frames)
            conf, lin, count = reached.conf, reached.lin, 1
        scal[k:k + count] = conf.scalars[:count]
        sph[k:k + count] = conf.spherical[:count]
        mask[k:k + count] = True
        _store(frames, k, lin.frames, count)
        last = count - 1
        at = _Point(conf.take(slice(last, last + 1)), X[k + last].copy(),
                    lin.take(slice(last, last + 1)))
        k += count
        wave = min(2 * wave, MAX_WAVE) if count == X_wave.shape[0] else max(1, count)
        if report is not None:
            report(k, N)
    return Followed(Configuration(scal, sph), mask, None, frames)


def _frame_store(like: GraphFrames, N: int) -> GraphFrames:
    def new(a: Array) -> Array:
        out = np.zeros((N, *a.shape[1:]))
        if a.ndim == 4:  # rotations: the identity where no sample is reached
            out[:] = np.eye(3)
        return out

    return GraphFrames(*(new(a) for a in (like.R, like.p, like.screws, like.residual,
                                          like.centres, like.axes)))


def _store(store: GraphFrames, k: int, frames: GraphFrames, count: int) -> None:
    """Samples k … k + count − 1 of ``store`` from the first ``count`` of ``frames`` (count 0:
    sample k from frames' first)."""
    n = max(count, 1)
    for a, b in zip((store.R, store.p, store.screws, store.residual, store.centres, store.axes),
                    (frames.R, frames.p, frames.screws, frames.residual, frames.centres,
                     frames.axes), strict=True):
        a[k:k + n] = b[:n]


def _approach(mech: Mechanism, lay: GraphLayout, at: _Point, x: Array
              ) -> tuple[_Point | None, Array]:
    """From the drawing to the first sample in steps of at most ~3° (or 5 % of the length
    scale) of input travel; where it fails, None and the last input reached (to a twentieth
    of a step, by bisection)."""
    span = np.abs(x - at.x) / np.where(np.array([lay.is_translation[f] for f in lay.inputs]),
                                       0.05 * lay.length, 0.05)
    steps = max(1, int(np.ceil(span.max())))
    path = at.x[None, :] + (x - at.x)[None, :] * (np.arange(1, steps + 1) / steps)[:, None]
    for target in path:
        count, conf, lin = _wave(mech, lay, at, target[None, :])
        if count == 1:
            at = _Point(conf, target, lin)
            continue
        reached = _split_step(mech, lay, at, target, 1)
        if reached is None:
            return None, _furthest(mech, lay, at, target)
        at = reached
    return at, x


def _furthest(mech: Mechanism, lay: GraphLayout, at: _Point, target: Array) -> Array:
    """The furthest input towards ``target`` reached from ``at`` (bisection, 5 halvings)."""
    good, bad = at.x, target
    for _ in range(5):
        mid = 0.5 * (good + bad)
        end = _split_step(mech, lay, at, mid, 1)
        if end is None:
            bad = mid
        else:
            at, good = end, mid
    return np.asarray(good, dtype=float)


def reach(mech: Mechanism, lay: GraphLayout, conf: Configuration, x_from: Array, x_to: Array,
          smallest: float = SMALLEST_STEP) -> Configuration | None:
    """The configuration at inputs ``x_to`` on the branch through ``conf`` (one sample, closed
    at ``x_from``), followed by continuation in steps no shorter than ``smallest``; None where
    the branch does not get there."""
    at = _Point(conf, np.asarray(x_from, dtype=float), linearise(mech, lay, conf, exact=False))
    x_to = np.asarray(x_to, dtype=float)
    count, reached, _ = _wave(mech, lay, at, x_to[None, :])
    if count == 1:
        return reached
    end = _split_step(mech, lay, at, x_to, 1, smallest)
    return None if end is None else end.conf
