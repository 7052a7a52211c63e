"""Folds hidden inside one sample step of a closed-form mode (issue 27: every birth and death
reported, "a motion never switches mode silently").

A mode of closed-form sub-chains assembles where every discriminant of its sub-chains is
non-negative (graph/dyads.py, graph/legs.py). Where it assembles at both samples k and k+1 (or
at neither), a discriminant g(t) along the input segment x(t) = X[k] + t (X[k+1] − X[k]) may
still cross zero twice inside the step: a dip below zero (the mode dies and is born again: its
runs before and after are two modes, the input must turn back at the first fold) or, from
below, a hump above it (an island: the mode is born and dies inside the step, no sample on it).
Such a pair is bracketed by the discriminant's values and slopes at the two samples: of one
sign at both ends, with slopes that point to an extremum inside (g > 0 with g'(0) < 0 < g'(1):
a minimum; g < 0 with g'(0) > 0 > g'(1): a maximum; by Rolle's theorem a single dip or hump
between samples of one sign has such slopes). The extremum t* is located as the least
(greatest) value on a grid of :data:`EXTREMUM_SECTIONS` points narrowed round by round to its
neighbours (one batched evaluation per round), and where the mode's assembling at t* differs
from the samples', its two folds are located by sectioning its assembling on [0, t*] and
[t*, 1] to 2⁻⁵⁰ of the step (as graph/closed_modes.py's ``fold_inputs`` bisects between samples
that differ). Slopes are one-sided differences over :data:`SLOPE_STEP` of the step. The folding
sub-chain at each fold is the first, in placing order, that does not assemble just past it.

Seen: a dip or hump of a discriminant inside one step whose slopes at the samples point inside,
down to a depth of ~1e-12 of the discriminant's second derivative over the step (the extremum
is located to ~1e-6 of the step). Not seen: a discriminant with two or more extrema inside one
step whose slopes at the samples do not point inside (a wiggle shorter than the step), and an
island of a sub-chain placed on one that does not assemble at either sample (its discriminant
is not defined there).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: slopes by differences over this fraction of the step
SLOPE_STEP = 1e-7
#: points per round of the extremum's search (one batched evaluation per round): its bracket
#: shrinks EXTREMUM_SECTIONS/2 times a round
EXTREMUM_SECTIONS = 64
#: rounds locating the extremum (to 32⁻⁴ ≈ 1e-6 of the step: the discriminant there is its
#: extremum's to ~1e-12 of its second derivative over the step)
EXTREMUM_ROUNDS = 4
#: points per round of a fold's search: its bracket shrinks SECTIONS times a round
SECTIONS = 32
#: rounds locating each of the two folds (to 2⁻⁵⁰ of the step)
FOLD_ROUNDS = 10
#: two pairs found from different discriminants are one where their folds agree to this
#: fraction of the step
SAME_PAIR = 1e-9

#: the sub-chains' discriminants (T, S) and where the mode assembles (T,) at the fractions t
#: (T,) of the steps ``k`` (T,) of the modes ``rows`` (T,)
Evaluate = Callable[[NDArray[np.intp], NDArray[np.intp], Array], tuple[Array, NDArray[np.bool_]]]


@dataclass(frozen=True)
class HiddenPair:
    """Two folds of mode ``row`` inside the step k → k+1, at the fractions ``t`` of the step,
    the sub-chain folding at each (``stages``); ``gap`` True where the mode assembles at the
    samples and not between the folds, False for an island (assembling between them only)."""

    row: int
    k: int
    t: tuple[float, float]
    stages: tuple[int, int]
    gap: bool


def hidden_fold_text(dies: bool, at: str, first: bool, lo: str, hi: str, gap: bool) -> str:
    """The event of a loop mode at one of two folds inside one step (a gap where it
    ``assembles`` at both samples, an island where it does not); ``at``, ``lo`` and ``hi`` the
    fold's and the step's samples' inputs as text."""
    return (f"{'dies' if dies else 'is born'} at {at}: the loop folds (two of its assembly modes "
            f"meet; {'the first' if first else 'the second'} of two folds between the samples "
            f"at {lo} and {hi}, where it {'assembles' if gap else 'does not assemble'})")


def hidden_pairs(evaluate: Evaluate, ok: NDArray[np.bool_], disc: Array,
                 discriminants: Callable[[NDArray[np.intp], NDArray[np.intp], Array], Array]
                 | None = None) -> list[HiddenPair]:
    """Every fold pair hidden inside one step (module docstring) of the modes whose
    assembling at the samples is ``ok`` (M, N), their discriminants there ``disc`` (M, N, S);
    ``evaluate(rows, ks, t)`` gives both at interior points, ``discriminants(rows, ks, t)``,
    when given, the discriminants alone (the same values, for the slopes at every step)."""
    rows, ks = np.nonzero(ok[:, :-1] == ok[:, 1:])
    if rows.size == 0:
        return []
    g0, g1 = disc[rows, ks], disc[rows, ks + 1]  # (T, S)
    h = SLOPE_STEP
    T0 = rows.size
    both = (np.concatenate([rows, rows]), np.concatenate([ks, ks]),
            np.concatenate([np.full(T0, h), np.full(T0, 1.0 - h)]))
    near = evaluate(*both)[0] if discriminants is None else discriminants(*both)
    s0, s1 = (near[:T0] - g0) / h, (g1 - near[T0:]) / h
    with np.errstate(invalid="ignore"):
        dip = ok[rows, ks][:, None] & (g0 > 0) & (g1 > 0) & (s0 < 0) & (s1 > 0)
        # a mode assembling at neither sample: the first sub-chain that fails there (the
        # same at both ends), rising and falling back
        first0 = np.argmax(~(g0 >= 0), axis=1)
        first1 = np.argmax(~(g1 >= 0), axis=1)
        hump = np.zeros_like(dip)
        r = np.arange(T0)
        hump[r, first0] = (~ok[rows, ks]) & (first0 == first1) & (g0[r, first0] < 0) & \
            (g1[r, first0] < 0) & (s0[r, first0] > 0) & (s1[r, first0] < 0)
    c, stage = np.nonzero(dip | hump)
    if c.size == 0:
        return []
    sign = np.where(dip[c, stage], 1.0, -1.0)  # +1: a minimum
    cr, ck = rows[c], ks[c]
    t_star, at_star = _extremum(evaluate, cr, ck, stage, sign)
    hidden = np.flatnonzero(at_star != ok[cr, ck])
    if hidden.size == 0:
        return []
    cr, ck, t_star = cr[hidden], ck[hidden], t_star[hidden]
    # the two folds: the assembling changes once on [0, t*] and once on [t*, 1]
    T = hidden.size
    rr, kk = np.concatenate([cr, cr]), np.concatenate([ck, ck])
    at_lo = np.concatenate([ok[cr, ck], ~ok[cr, ck]])
    lo, hi = _change(evaluate, rr, kk, np.concatenate([np.zeros(T), t_star]),
                     np.concatenate([t_star, np.ones(T)]), at_lo)
    t = 0.5 * (lo + hi)
    # the side that does not assemble: past the first fold for a gap, before it for an island
    bad = np.where(np.concatenate([ok[cr, ck], ok[cr, ck]]),
                   np.concatenate([hi[:T], lo[T:]]), np.concatenate([lo[:T], hi[T:]]))
    folding = np.argmax(~(evaluate(rr, kk, bad)[0] >= 0.0), axis=1)
    out: list[HiddenPair] = []
    for i in np.argsort(ck * 2.0 + t[:T], kind="stable"):
        pair = HiddenPair(int(cr[i]), int(ck[i]), (float(t[i]), float(t[T + i])),
                          (int(folding[i]), int(folding[T + i])), bool(ok[cr[i], ck[i]]))
        if not any(p.row == pair.row and p.k == pair.k and abs(p.t[0] - pair.t[0]) <= SAME_PAIR
                   for p in out):
            out.append(pair)
    return out


def _extremum(evaluate: Evaluate, rows: NDArray[np.intp], ks: NDArray[np.intp],
              stage: NDArray[np.intp], sign: Array) -> tuple[Array, NDArray[np.bool_]]:
    """Where ``sign`` × the discriminant of ``stage`` is least on each step (T,), bracketed
    by the slopes (one extremum): the grid's least point, its bracket narrowed to its two
    neighbours each round; that point and whether the mode assembles there."""
    T = rows.size
    lo, hi = np.zeros(T), np.ones(T)
    n = EXTREMUM_SECTIONS
    frac = np.arange(n + 1) / n
    r = np.arange(T)
    for _ in range(EXTREMUM_ROUNDS):
        ts = lo[:, None] + (hi - lo)[:, None] * frac  # (T, n+1)
        g, ok = evaluate(np.repeat(rows, n + 1), np.repeat(ks, n + 1), ts.reshape(-1))
        v = sign[:, None] * g[np.arange(g.shape[0]), np.repeat(stage, n + 1)].reshape(T, -1)
        i = np.argmin(np.where(np.isnan(v), np.inf, v), axis=1)
        best, at = ts[r, i], ok.reshape(T, -1)[r, i]
        lo = ts[r, np.maximum(i - 1, 0)]
        hi = ts[r, np.minimum(i + 1, n)]
    return best, at


def _change(evaluate: Evaluate, rows: NDArray[np.intp], ks: NDArray[np.intp], lo: Array,
            hi: Array, at_lo: NDArray[np.bool_]) -> tuple[Array, Array]:
    """The bracket [lo, hi] (to 2⁻⁵⁰ of the step) where the mode's assembling first leaves
    ``at_lo``, its value at ``lo``: the first of :data:`SECTIONS` points where it differs, each
    round."""
    T = rows.size
    frac = np.arange(1, SECTIONS) / SECTIONS
    r = np.arange(T)
    for _ in range(FOLD_ROUNDS):
        ts = lo[:, None] + (hi - lo)[:, None] * frac  # (T, S−1)
        ok = evaluate(np.repeat(rows, SECTIONS - 1), np.repeat(ks, SECTIONS - 1),
                      ts.reshape(-1))[1].reshape(T, -1)
        changed = ok != at_lo[:, None]
        first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), SECTIONS - 1)
        new_lo = np.where(first > 0, ts[r, np.maximum(first - 1, 0)], lo)
        hi = np.where(first < SECTIONS - 1, ts[r, np.minimum(first, SECTIONS - 2)], hi)
        lo = new_lo
    return lo, hi
