"""Every assembly mode of a mechanism that decomposes into closed-form sub-chains
(graph/subchains.py, graph/dyads.py).

A mode is one combination of dyad branches σ (one ±1 per two-branch dyad): 2^D modes for D such
dyads. Each is a continuous branch over the inputs wherever every discriminant of its dyads is
positive; it is born or dies where one crosses zero (a fold: that dyad's links in line), which
is located between the two samples around it by bisection along the segment joining their
inputs (:func:`fold_inputs`). The drawn mode is the combination of the drawing's branches; as
with the continuation (graph/follow.py) it is followed from the drawing and stops at its first fold;
where the drawn combination assembles again later over the inputs, those later runs are one more
mode (graph/motion.py's ``_closed_form_motion``), so that every run of every combination is
held by a mode and none switches branch.
Rates and accelerations come from the closure Jacobian (graph/motion.py's ``build_mode``).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphFrames, GraphLayout, joint_screws
from screwkit.kinematics.graph.dyads import (
    Placement,
    configuration,
    discriminants,
    place,
    place_every,
)
from screwkit.kinematics.graph.step_folds import HiddenPair
from screwkit.kinematics.graph.subchains import Decomposition
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

if TYPE_CHECKING:
    from screwkit.kinematics.graph.motion import MechanismMode

Array = NDArray[np.float64]

#: bisection steps locating a fold between two samples (2⁻⁶⁰ of their input step)
FOLD_STEPS = 60
#: the largest input step (rad, or this fraction of the length scale for a slide) on the path
#: from the drawing to the first sample, where turning angles are counted
APPROACH_STEP = 0.05


@dataclass(frozen=True)
class EveryMode:
    """The poses of every mode: ``signs[k]`` the branch of each dyad (M, D) and
    ``placement`` over the M·N samples, mode-major; ``drawn`` the drawn mode's index."""

    signs: Array
    placement: Placement
    drawn: int

    @property
    def count(self) -> int:
        return int(self.signs.shape[0])

    def assembles(self, N: int) -> NDArray[np.bool_]:
        """(M, N) where each mode assembles."""
        return self.placement.assembles.reshape(self.count, N)


def branch_combinations(dec: Decomposition) -> Array:
    """Every combination of dyad branches (M, D): ±1 for each two-branch dyad (the drawn
    sign first), +1 for a one-branch dyad; the drawing's combination is row 0."""
    choices = [(d.drawn_branch, -d.drawn_branch) if d.branches == 2 else (1,)
               for d in dec.dyads]
    return np.array(list(itertools.product(*choices)), dtype=float).reshape(-1, len(choices))


def drawn_combination(dec: Decomposition) -> Array:
    """The drawing's branch of every sub-chain (1, D): row 0 of :func:`branch_combinations`,
    without listing the others."""
    return np.array([[float(d.drawn_branch) for d in dec.dyads]]).reshape(1, len(dec.dyads))


def every_mode(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array) -> EveryMode:
    """The body poses of every mode at every input row, in one batched evaluation."""
    return EveryMode(branch_combinations(dec), place_every(mech, lay, dec, X), 0)


def mode_configuration(mech: Mechanism, lay: GraphLayout, R: Array, p: Array, X: Array,
                       mask: NDArray[np.bool_], start: Array | None = None) -> Configuration:
    """Joint variables of one mode (N samples): the inputs as given, every angle counted
    continuously along each run of samples where the mode assembles (``start``: the angles
    at the run's first sample, when known from the drawing)."""
    whole = bool(mask.all())  # every sample assembles: the poses as they are, not copied
    conf = configuration(mech, lay, R if whole else np.where(mask[:, None, None, None], R,
                                                             np.eye(3)),
                         p if whole else np.where(mask[:, None, None], p, 0.0))
    q = conf.scalars
    turning = [lay.scalar_col[f] for f in range(lay.m)
               if not lay.is_translation[f] and lay.scalar_col[f] >= 0]
    for a, b in assembling_runs(mask):
        run = q[a:b, turning]
        if a == 0 and start is not None:
            run = np.vstack([start[None, turning], run])
            q[a:b, turning] = np.unwrap(run, axis=0)[1:]
        else:
            q[a:b, turning] = np.unwrap(run, axis=0)
    q[~mask] = 0.0
    for k, f in enumerate(lay.inputs):
        q[:, lay.scalar_col[f]] = X[:, k]
    return conf


def mode_frames(mech: Mechanism, lay: GraphLayout, R: Array, p: Array, ok: NDArray[np.bool_]
                ) -> GraphFrames:
    """A mode's closed-form body poses as the frames ``build_mode`` reuses (graph/motion.py),
    so that they are not computed a second time from the joint variables along the spanning
    tree: the identity (the drawing) where the mode does not assemble, as its configuration
    (every freedom 0) there; its joints' world screws, centres and axes from them. The loop
    residuals are left to ``build_mode``, which evaluates them anew from the configuration."""
    if not ok.all():  # where every sample assembles the poses are used as they are
        R = np.where(ok[:, None, None, None], R, np.eye(3))
        p = np.where(ok[:, None, None], p, 0.0)
    screws, centres, axes = joint_screws(mech, lay, R, p)
    return GraphFrames(R, p, screws, np.zeros((R.shape[0], 1, 6)), centres, axes)


def assembling_runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """The [start, stop) index ranges where ``mask`` holds."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.nonzero(edges == 1)[0].tolist(), np.nonzero(edges == -1)[0].tolist(),
                    strict=True))


def drawn_start(mech: Mechanism, lay: GraphLayout, dec: Decomposition, x0: Array
                ) -> Array | None:
    """The drawn mode's joint angles at the first input row ``x0``, counted from the drawing
    (every angle 0) along the straight input path; None where the mode folds before it."""
    scale = np.array([lay.length if lay.is_translation[f] else 1.0 for f in lay.inputs])
    steps = max(1, int(np.ceil(float(np.max(np.abs(x0) / scale)) / APPROACH_STEP)))
    path = np.linspace(0.0, 1.0, steps + 1)[:, None] * x0[None, :]
    signs = drawn_combination(dec)
    pl = place(mech, lay, dec, path, np.repeat(signs, path.shape[0], axis=0))
    if not pl.assembles.all():
        return None
    conf = mode_configuration(mech, lay, pl.R, pl.p, path, pl.assembles,
                              np.zeros(lay.n_scalar))
    return np.asarray(conf.scalars[-1])


def fold_inputs(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                signs: Array, k: NDArray[np.intp]) -> tuple[Array, NDArray[np.intp]]:
    """Where the modes of branches ``signs`` (T, D) are born or die between samples k and
    k+1 (T,; exactly one of the two assembles): the input rows at the folds (T, n_in), by
    bisection on each segment X[k] → X[k+1] (all at once), and the index of the dyad whose
    discriminant crosses zero there (T,): the first in placing order past the fold that does
    not assemble (a dyad placed on a dyad that failed has no discriminant, NaN)."""
    T = k.shape[0]
    x0, x1 = X[k], X[k + 1]
    lo, hi = np.zeros(T), np.ones(T)
    ok_lo = place(mech, lay, dec, x0, signs).assembles
    for _ in range(FOLD_STEPS):
        mid = 0.5 * (lo + hi)
        same = place(mech, lay, dec, x0 + mid[:, None] * (x1 - x0), signs).assembles == ok_lo
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    bad = np.where(ok_lo, hi, lo)
    disc = place(mech, lay, dec, x0 + bad[:, None] * (x1 - x0), signs).discriminant
    # the first sub-chain, in placing order, that does not assemble (negative or NaN): those
    # placed on its bodies are NaN only because it failed
    folding = np.argmax(~(disc >= 0.0), axis=1)
    return x0 + (0.5 * (lo + hi))[:, None] * (x1 - x0), folding


def mode_label(mech: Mechanism, dec: Decomposition, signs: Array) -> str:
    """The branch of each two-branch dyad, e.g. ``"A–B–OB +, E–G–F −"`` (+: the drawing's)."""
    parts = []
    for d, s in zip(dec.dyads, signs, strict=True):
        if d.branches == 2:
            names = "–".join(mech.joints[k].name for k in d.joints)
            parts.append(f"{names} {'+' if s == d.drawn_branch else '−'}")
    return ", ".join(parts)


def drawn_with_events(mech: Mechanism, lay: GraphLayout, mode: MechanismMode, X: Array,
                      stop: int, folds: list[str]) -> MechanismMode:
    """The drawn mode labelled, with its end: where it stops assembling (``stop`` < N) and its
    first fold (the drawn mode ends there), before its own events."""
    from screwkit.kinematics.graph.motion import input_text, with_events

    events = folds[:1]
    if stop < X.shape[0]:
        events.insert(0, f"stops assembling after input {input_text(mech, lay, X[stop - 1])} (a "
                         f"limit position or dead centre before {input_text(mech, lay, X[stop])})")
    return replace(with_events(mode, [*events, *mode.events]), label="drawn")


#: labels of the modes a branch combination holds after its first run
DRAWN_AGAIN = " (the drawn branches again, after the drawn mode's fold)"
SAME_AGAIN = " (the same branches again, after two folds inside one sample step)"
ISLAND = " (an island inside one sample step: no sample on it)"


@dataclass(frozen=True)
class HeldModes:
    """The modes of a closed-form motion: each one's branch combination (``rows``, into the
    combinations' ``ok`` (M, N)), samples (``masks`` (M', N)) and label tail; the drawn
    mode's end ``stop`` (its first sample past its first fold); the fold pairs hidden inside
    one step (graph/step_folds.py), and which modes are islands on no sample (mode → pair)."""

    rows: list[int]
    masks: NDArray[np.bool_]
    labels: list[str]
    stop: int
    ok: NDArray[np.bool_]
    pairs: list[HiddenPair]
    islands: dict[int, HiddenPair]


def held_modes(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array, signs: Array,
               ok: NDArray[np.bool_], disc: Array, every: bool) -> HeldModes:
    """The modes of the branch combinations ``signs`` (M, D), assembling at ``ok`` (M, N) with
    discriminants ``disc`` (M, N, D): the drawn mode (row 0) up to its first fold, a fold
    hidden inside one step included; with ``every`` each other combination's samples, cut
    where it dies and is born again inside one step (two modes: the input must turn back at
    the first fold), the drawn combination's later samples cut the same way, and each island
    inside one step (graph/step_folds.py) as a mode on no sample."""
    from screwkit.kinematics.graph.step_folds import hidden_pairs

    N = X.shape[0]

    def evaluate(rows: NDArray[np.intp], ks: NDArray[np.intp], t: Array
                 ) -> tuple[Array, NDArray[np.bool_]]:
        pl = place(mech, lay, dec, X[ks] + t[:, None] * (X[ks + 1] - X[ks]), signs[rows])
        return pl.discriminant, pl.assembles

    def slopes(rows: NDArray[np.intp], ks: NDArray[np.intp], t: Array) -> Array:
        return discriminants(mech, lay, dec, X[ks] + t[:, None] * (X[ks + 1] - X[ks]),
                             signs[rows])

    pairs = hidden_pairs(evaluate, ok, disc, slopes) if N > 1 else []
    gaps: dict[int, list[int]] = {}
    for pr in pairs:
        if pr.gap:
            gaps.setdefault(pr.row, []).append(pr.k)
    stop = int(np.argmin(ok[0])) if not ok[0].all() else N
    stop = min([stop, *(k + 1 for k in gaps.get(0, []))])
    idx = np.arange(N)
    rows, masks, labels = [0], [idx < stop], [""]

    def pieces(m: int, mask: NDArray[np.bool_], first: str, later: str) -> None:
        cuts = [k + 1 for k in sorted(gaps.get(m, [])) if mask[k] and mask[k + 1]]
        for j, (a, b) in enumerate(zip([0, *cuts], [*cuts, N], strict=True)):
            piece = mask & (idx >= a) & (idx < b)
            if piece.any():
                rows.append(m)
                masks.append(piece)
                labels.append(first if j == 0 else later)

    islands: dict[int, HiddenPair] = {}
    if every:
        for m in range(1, ok.shape[0]):
            pieces(m, ok[m], "", SAME_AGAIN)
        pieces(0, ok[0] & (idx >= stop), DRAWN_AGAIN, DRAWN_AGAIN)
        for pr in pairs:
            if not pr.gap:
                islands[len(rows)] = pr
                rows.append(pr.row)
                masks.append(np.zeros(N, dtype=bool))
                labels.append(ISLAND)
    return HeldModes(rows, np.array(masks), labels, stop, ok, pairs, islands)


def fold_events(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array, signs: Array,
                held: HeldModes) -> tuple[list[list[str]], list[tuple[int, int]]]:
    """Each mode's births and deaths at folds, in input order: between samples where its
    combination's assembling changes (located by :func:`fold_inputs`, all at once), at a fold
    pair hidden inside one step and at an island's two ends (graph/step_folds.py); and the
    pairs of modes that meet at a fold (the same sub-chain folding between the same samples,
    their branches differing in that sub-chain alone; a hidden fold at the same place too)."""
    from screwkit.kinematics.graph.motion import input_text

    masks, rows = held.masks, np.array(held.rows, dtype=np.intp)
    i, k = np.nonzero(masks[:, :-1] != masks[:, 1:])
    m = rows[i]
    regular = held.ok[m, k] != held.ok[m, k + 1]
    #: (mode, sub-chain, sample k, fraction of the step or NaN for a regular fold, dies, text)
    points: list[tuple[int, int, int, float, bool, str]] = []
    if regular.any():
        x, folding = fold_inputs(mech, lay, dec, X, signs[m[regular]], k[regular])
        for ii, kk, xx, d in zip(i[regular], k[regular], x, folding, strict=True):
            points.append((int(ii), int(d), int(kk), np.nan, bool(masks[ii, kk]),
                           f"at {input_text(mech, lay, xx)}: the {_folding(mech, dec, int(d))} "
                           "folds (its two branches meet)"))

    def hidden(ii: int, pr: HiddenPair, end: int) -> None:
        t = pr.t[end]
        x = X[pr.k] + t * (X[pr.k + 1] - X[pr.k])
        where = (f"{'the first' if end == 0 else 'the second'} of two folds between the "
                 f"samples at {input_text(mech, lay, X[pr.k])} and "
                 f"{input_text(mech, lay, X[pr.k + 1])}, where it "
                 f"{'assembles' if pr.gap else 'does not assemble'}")
        points.append((ii, pr.stages[end], pr.k, t, (end == 0) == pr.gap,
                       f"at {input_text(mech, lay, x)}: the "
                       f"{_folding(mech, dec, pr.stages[end])} folds (its two branches meet; "
                       f"{where})"))

    for ii, kk in zip(i[~regular], k[~regular], strict=True):
        pr = next(p for p in held.pairs if p.gap and p.row == rows[ii] and p.k == kk)
        hidden(int(ii), pr, 0 if masks[ii, kk] else 1)
    for ii, pr in held.islands.items():
        hidden(ii, pr, 0)
        hidden(ii, pr, 1)
    points.sort(key=lambda q: (q[2], 0.0 if np.isnan(q[3]) else q[3]))
    events: list[list[str]] = [[] for _ in range(masks.shape[0])]
    for ii, _, _, _, dies, text in points:
        events[ii].append(("dies " if dies else "is born ") + text)
    joins = []
    for ii, d, kk, t, _, _ in points:
        other = signs[rows[ii]].copy()
        other[d] = -other[d]
        match = [jj for jj, dd, k2, t2, _, _ in points
                 if jj != ii and dd == d and k2 == kk and np.all(signs[rows[jj]] == other)
                 and (np.isnan(t) and np.isnan(t2) or abs(t - t2) <= 1e-9)]
        if match:
            joins.append((match[0], ii))
    return events, joins


def _folding(mech: Mechanism, dec: Decomposition, d: int) -> str:
    """The sub-chain ``d`` for a fold event, e.g. "RRR dyad A–B–D"."""
    dyad = dec.dyads[d]
    return f"{dyad.kind} {dyad.word} " + "–".join(mech.joints[i].name for i in dyad.joints)
