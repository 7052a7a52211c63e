"""Two folds of the RSRC quartic inside one sample step (issue 27: every birth and
death reported, "a motion never switches mode silently"), as graph/step_folds.py finds them for
dyads; used by ``rsrc_motion``'s events and by the graph route (graph/quartic_steps.py).

The count of the quartic's real roots (Bagci 1969 eq. 3.63) is 4 or 0 where its discriminant
Δ(θ0) is positive, 2 where it is negative, and changes at its zeros (folds: a double root).
Between samples k and k+1 with the same count, Δ can still cross zero twice: a pair of roots
vanishes and comes back (a gap: the input must turn back at the first fold) or a pair is born
and dies (an island: roots on no sample). Such a pair is bracketed as in graph/step_folds.py by
Δ's values and slopes at the two samples (one sign at both, slopes by differences over
``SLOPE_STEP`` of the step pointing to an extremum inside); the extremum t* is located on a grid
narrowed round by round, and where the count there differs from the samples', the two folds are
where the count changes on [0, t*] and on [t*, 1] (sections, to 2⁻⁵⁰ of the step). Every root
at sample k is then followed forward over the step and every root at k+1 backward
(folds.py's ``follow``: ``rsrc_motion``'s own matching section by section): a branch whose
root dies inside the step, or whose root at k+1 is born inside it, is cut there (its runs before
and after are two modes), and the roots at t* that neither reaches are an island.

Seen: one dip or hump of Δ inside a step whose slopes at the samples point inside, in the
general case of the RSRC (δ0 not a multiple of π/2). Not seen: two or more extrema of Δ inside
one step whose slopes do not point inside, and the special cases δ0 = nπ/2 (quadratics).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.rsrc.branches import RSRCMotion
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions
from screwkit.kinematics.closed_forms.rsrc.folds import features, follow
from screwkit.kinematics.closed_forms.rsrc.positions import quartic_discriminant, rsrc_positions

Array = NDArray[np.float64]


@dataclass(frozen=True)
class QuarticStep:
    """Two folds inside the step k → k+1 of the rows given (at the fractions ``t`` of the
    step): the modes (``solve_motion``'s order: the branches of ``rsrc_motion`` that assemble
    somewhere over the sweep, in their order) whose root at k dies inside the step
    (``dies``: mode → fraction), whose root at k+1 is born inside it (``born``), and how many
    roots assemble between the folds only (``island``: born at t[0], dying at t[1])."""

    k: int
    t: tuple[float, float]
    dies: dict[int, float]
    born: dict[int, float]
    island: int


def hidden_steps(dims: RSRCDimensions, mot: RSRCMotion, first: int, last: int
                 ) -> list[QuarticStep]:
    """Every step k → k+1 of the sweep of ``mot`` (``rsrc_motion``'s branches) with
    ``first`` ≤ k < ``last`` that hides two folds (module docstring)."""
    from screwkit.kinematics.graph.step_folds import (
        EXTREMUM_ROUNDS,
        EXTREMUM_SECTIONS,
        FOLD_ROUNDS,
        SECTIONS,
        SLOPE_STEP,
    )

    if dims.special_case != "general" or last <= first:
        return []
    theta = mot.theta0
    cols = np.flatnonzero(mot.assembles.any(axis=0))
    count = mot.assembles.sum(axis=1)
    ks = np.arange(first, last)
    ks = ks[count[ks] == count[ks + 1]]
    if ks.size == 0:
        return []
    at = quartic_discriminant(dims, theta[first:last + 1])  # at the samples
    g0, g1 = at[ks - first], at[ks + 1 - first]
    sign = np.sign(g0)
    ks, g0, g1, sign = (v[np.sign(g1) == sign] for v in (ks, g0, g1, sign))
    th0, th1 = theta[ks], theta[ks + 1]
    h = SLOPE_STEP
    s0 = (quartic_discriminant(dims, th0 + h * (th1 - th0)) - g0) / h
    s1 = (g1 - quartic_discriminant(dims, th1 - h * (th1 - th0))) / h
    pick = (sign * s0 < 0) & (sign * s1 > 0)
    if not pick.any():
        return []
    ks, th0, th1, sign = ks[pick], th0[pick], th1[pick], sign[pick]
    t_star = _extremum(dims, th0, th1, sign, EXTREMUM_SECTIONS, EXTREMUM_ROUNDS)

    def real(t: Array) -> NDArray[np.intp]:
        return np.asarray(rsrc_positions(dims, th0 + t * (th1 - th0)).n_assemblies)

    mid = real(t_star)
    hidden = mid != count[ks]
    if not hidden.any():
        return []
    ks, th0, th1, t_star, mid = ks[hidden], th0[hidden], th1[hidden], t_star[hidden], mid[hidden]
    t1 = _change(dims, th0, th1, np.zeros(ks.size), t_star, count[ks], SECTIONS, FOLD_ROUNDS)
    t2 = _change(dims, th0, th1, t_star, np.ones(ks.size), mid, SECTIONS, FOLD_ROUNDS)
    out = []
    length = dims.length_scale
    for i, k in enumerate(ks):
        at_k = np.flatnonzero(mot.assembles[k, cols])
        at_k1 = np.flatnonzero(mot.assembles[k + 1, cols])
        fwd, reach, _ = follow(dims, np.full(at_k.size, th0[i]), np.full(at_k.size, th1[i]),
                               features(mot, np.full(at_k.size, k), cols[at_k], length))
        bwd, _, _ = follow(dims, np.full(at_k1.size, th1[i]), np.full(at_k1.size, th0[i]),
                           features(mot, np.full(at_k1.size, k + 1), cols[at_k1], length))
        born = 1.0 - bwd
        alive = int(np.sum(fwd > t_star[i]) + np.sum(born < t_star[i]) - np.sum(reach))
        out.append(QuarticStep(int(k), (float(t1[i]), float(t2[i])),
                               {int(m): float(t) for m, t in zip(at_k, fwd, strict=True)
                                if t < 1.0},
                               {int(m): float(t) for m, t in zip(at_k1, born, strict=True)
                                if t > 0.0},
                               max(int(mid[i]) - alive, 0)))
    return out


def _extremum(dims: RSRCDimensions, th0: Array, th1: Array, sign: Array, sections: int,
              rounds: int) -> Array:
    """Where ``sign`` × Δ is least on each step (one extremum, bracketed by the slopes): the
    grid's least point, its bracket narrowed to its two neighbours each round."""
    T = th0.size
    lo, hi = np.zeros(T), np.ones(T)
    frac = np.arange(sections + 1) / sections
    r = np.arange(T)
    best = np.full(T, 0.5)
    for _ in range(rounds):
        ts = lo[:, None] + (hi - lo)[:, None] * frac
        v = sign[:, None] * quartic_discriminant(
            dims, (th0[:, None] + ts * (th1 - th0)[:, None]).reshape(-1)).reshape(T, -1)
        i = np.argmin(v, axis=1)
        best = ts[r, i]
        lo = ts[r, np.maximum(i - 1, 0)]
        hi = ts[r, np.minimum(i + 1, sections)]
    return best


def _change(dims: RSRCDimensions, th0: Array, th1: Array, lo: Array, hi: Array,
            at_lo: NDArray[np.intp], sections: int, rounds: int) -> Array:
    """Where the count of real roots first leaves ``at_lo`` on [lo, hi] (fractions of the
    steps th0 → th1), to 2⁻⁵⁰ of the step: the first of ``sections`` points where it
    differs, each round."""
    T = th0.size
    frac = np.arange(1, sections) / sections
    r = np.arange(T)
    for _ in range(rounds):
        ts = lo[:, None] + (hi - lo)[:, None] * frac
        n = rsrc_positions(dims, (th0[:, None] + ts * (th1 - th0)[:, None]).reshape(-1)
                           ).n_assemblies.reshape(T, -1)
        changed = n != at_lo[:, None]
        first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), sections - 1)
        new_lo = np.where(first > 0, ts[r, np.maximum(first - 1, 0)], lo)
        hi = np.where(first < sections - 1, ts[r, np.minimum(first, sections - 2)], hi)
        lo = new_lo
    return 0.5 * (lo + hi)
