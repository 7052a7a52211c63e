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
a minimum; g < 0 with g'(0) > 0 > g'(1): a maximum). The extremum t* is located by bisection on
the sign of g' (central differences of :data:`SLOPE_STEP` of the step), and where the mode's
assembling at t* differs from the samples', its two folds are located by bisection of its
assembling on [0, t*] and [t*, 1] (:data:`FOLD_STEPS` halvings each, as graph/closed_modes.py's
``fold_inputs`` does between samples that differ). The folding sub-chain at each is the first,
in placing order, that does not assemble just past it.

Seen: one dip or hump of each discriminant per step, of any depth (the slopes at the samples
bracket it). Not seen: a discriminant with two or more extrema inside one step whose slopes at
the samples do not point inside (a wiggle shorter than a step), and an island of a sub-chain
placed on one that does not assemble at either sample (its discriminant is not defined there).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: slopes by differences over this fraction of the step
SLOPE_STEP = 1e-7
#: bisection steps locating the extremum between two samples (on the sign of the slope)
EXTREMUM_STEPS = 40
#: bisection steps locating each of the two folds (2⁻⁵⁰ of the step)
FOLD_STEPS = 50
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


def hidden_pairs(evaluate: Evaluate, ok: NDArray[np.bool_], disc: Array) -> list[HiddenPair]:
    """Every fold pair hidden inside one step (module docstring) of the modes whose
    assembling at the samples is ``ok`` (M, N), their discriminants there ``disc`` (M, N, S);
    ``evaluate(rows, ks, t)`` gives both at interior points."""
    rows, ks = np.nonzero(ok[:, :-1] == ok[:, 1:])
    if rows.size == 0:
        return []
    g0, g1 = disc[rows, ks], disc[rows, ks + 1]  # (T, S)
    h = SLOPE_STEP
    s0 = (evaluate(rows, ks, np.full(rows.size, h))[0] - g0) / h
    s1 = (g1 - evaluate(rows, ks, np.full(rows.size, 1.0 - h))[0]) / h
    with np.errstate(invalid="ignore"):
        dip = ok[rows, ks][:, None] & (g0 > 0) & (g1 > 0) & (s0 < 0) & (s1 > 0)
        # a mode assembling at neither sample: the first sub-chain that fails there (the
        # same at both ends), rising and falling back
        first0 = np.argmax(~(g0 >= 0), axis=1)
        first1 = np.argmax(~(g1 >= 0), axis=1)
        hump = np.zeros_like(dip)
        r = np.arange(rows.size)
        hump[r, first0] = (~ok[rows, ks]) & (first0 == first1) & (g0[r, first0] < 0) & \
            (g1[r, first0] < 0) & (s0[r, first0] > 0) & (s1[r, first0] < 0)
    c, stage = np.nonzero(dip | hump)
    if c.size == 0:
        return []
    sign = np.where(dip[c, stage], 1.0, -1.0)  # +1: a minimum (g' from − to +)
    cr, ck = rows[c], ks[c]
    lo, hi = np.zeros(c.size), np.ones(c.size)
    for _ in range(EXTREMUM_STEPS):
        mid = 0.5 * (lo + hi)
        slope = (evaluate(cr, ck, mid + 0.5 * h)[0] - evaluate(cr, ck, mid - 0.5 * h)[0]) / h
        down = sign * slope[np.arange(c.size), stage] < 0  # still before the extremum
        lo, hi = np.where(down, mid, lo), np.where(down, hi, mid)
    t_star = 0.5 * (lo + hi)
    at_star = evaluate(cr, ck, t_star)[1]
    hidden = np.flatnonzero(at_star != ok[cr, ck])
    if hidden.size == 0:
        return []
    cr, ck, t_star = cr[hidden], ck[hidden], t_star[hidden]
    # the two folds: the assembling changes once on [0, t*] and once on [t*, 1]
    T = hidden.size
    rr, kk = np.concatenate([cr, cr]), np.concatenate([ck, ck])
    lo = np.concatenate([np.zeros(T), t_star])
    hi = np.concatenate([t_star, np.ones(T)])
    at_lo = np.concatenate([ok[cr, ck], ~ok[cr, ck]])
    for _ in range(FOLD_STEPS):
        mid = 0.5 * (lo + hi)
        same = evaluate(rr, kk, mid)[1] == at_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
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
