"""Where each branch of :func:`~screwkit.kinematics.closed_forms.rsrc.rsrc_motion` is born or
dies, attributed to the two branches that meet there (issue 27: "births and deaths at folds are
reported", "a motion never switches mode silently").

The RSRC's positions at one input are the real roots of its quartic in tan(φ0/2) (Bagci 1969
eq. 3.63; its planar 4R case has two), and its branches are those roots matched from sample to
sample (branches.py's ``rsrc_motion``: each root advanced by its rate, the assignment of least
summed squared distance of (cos φ0, sin φ0, cos χ0, sin χ0, S/L) among all permutations, a root
left unmatched where the count of roots changes and that is cheaper than a 90° jump). A branch
is born or dies at a fold, where two of its roots meet (a double root) and turn complex. Where
two pairs of branches fold inside one sample step, the count of real roots changes twice there,
so bisecting the count finds the first change for every branch that is born or dies in the
step, which can be the other pair's fold.

Here each branch's own existence is bisected instead: from the sample where it assembles
towards the other, the step is cut into :data:`SECTIONS` sections, the roots at the section
points are matched point to point by the same ``rsrc_motion`` (called with ``events=False``: no
events, no recursion), the branch is the root nearest its last known root at the first point,
and its fold lies in the first section where that root is left unmatched; the section is cut
again, :data:`ROUNDS` rounds (to 32⁻¹⁰ = 2⁻⁵⁰ of the step). Its partner is the branch whose own
search ends at the same place in the same step, from the same sample (the two roots that
coincide at the fold vanish together); a branch whose partner assembles at neither sample (a
root born and dead inside the step) has none. Both ``rsrc_motion``'s events and the graph
route (graph/quartic_folds.py, graph/quartic_steps.py) use this one search.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.closed_forms.quartic import DEFAULT_DOUBLE_ROOT_TOL
from screwkit.kinematics.closed_forms.rsrc.dimensions import RSRCDimensions

if TYPE_CHECKING:
    from screwkit.kinematics.closed_forms.rsrc.branches import RSRCMotion

Array = NDArray[np.float64]

#: sections of a step per round (one closed-form call per round for every fold at once)
SECTIONS = 32
#: rounds locating each fold: to SECTIONS⁻ROUNDS = 2⁻⁵⁰ of the step
ROUNDS = 10
#: two branches' folds in one step are one fold where their places agree to this fraction of
#: the step (both searches end in the same last section: they agree exactly)
SAME_FOLD = 1e-12


@dataclass(frozen=True)
class BranchFold:
    """Column ``branch`` of an ``RSRCMotion`` is born or dies (``dies``) between samples k and
    k+1 of its sweep, at the fraction ``t`` of that step, the input ``theta0`` (the last point
    of its search where its root assembles, within 2⁻⁵⁰ of the step of the fold); ``partner``
    the column that meets it there (None: a root that assembles at neither sample)."""

    branch: int
    k: int
    dies: bool
    t: float
    partner: int | None
    theta0: float


def branch_folds(dims: RSRCDimensions, mot: RSRCMotion,
                 double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL) -> list[BranchFold]:
    """Every birth and death of ``mot``'s branches (its columns) between consecutive samples of
    its sweep, each at its own root's fold, with the branch it meets (module docstring)."""
    theta = mot.theta0
    ok = mot.assembles
    ks, ms = np.nonzero(ok[:-1] != ok[1:])
    if ks.size == 0:
        return []
    dies = ok[ks, ms]
    start = np.where(dies, ks, ks + 1)
    th0, th1 = theta[start], theta[2 * ks + 1 - start]
    t_from, _, _ = follow(dims, th0, th1, features(mot, start, ms, dims.length_scale),
                          double_root_tol)
    t = np.where(dies, t_from, 1.0 - t_from)
    at = th0 + t_from * (th1 - th0)  # as the search evaluated it
    out = []
    for i in range(ks.size):
        mate = [j for j in range(ks.size) if j != i and ks[j] == ks[i] and dies[j] == dies[i]
                and abs(t[j] - t[i]) <= SAME_FOLD]
        out.append(BranchFold(int(ms[i]), int(ks[i]), bool(dies[i]), float(t[i]),
                              int(ms[mate[0]]) if mate else None, float(at[i])))
    return out


def follow(dims: RSRCDimensions, th0: Array, th1: Array, ref: Array,
           double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL
           ) -> tuple[Array, NDArray[np.bool_], Array]:
    """The roots whose features (:func:`features`) at the inputs ``th0`` (T,) are ``ref``
    (T, 5), followed towards ``th1`` (module docstring): the fraction of the way where each
    stops assembling (the last point of the search where it still assembles, within 2⁻⁵⁰ of
    the fold; 1 where it reaches ``th1``), whether it reaches ``th1``, and its features at
    ``th1`` where it does."""
    from screwkit.kinematics.closed_forms.rsrc.branches import rsrc_motion

    length = max(dims.length_scale, np.finfo(float).tiny)
    T = th0.size
    lo, hi = np.zeros(T), np.ones(T)
    frac = np.arange(SECTIONS + 1) / SECTIONS
    r = np.arange(T)
    n = SECTIONS + 1
    reached = np.zeros(T, dtype=bool)
    at_end = np.full_like(ref, np.nan)
    for round_ in range(ROUNDS):
        u = lo[:, None] + (hi - lo)[:, None] * frac  # (T, n): u[:, 0] = lo, u[:, -1] = hi
        sweep = rsrc_motion(dims, (th0[:, None] + u * (th1 - th0)[:, None]).reshape(-1),
                            double_root_tol=double_root_tol, events=False)
        A = sweep.assembles.reshape(T, n, 4)
        F = _features(sweep.phi0, sweep.chi0, sweep.S, length).reshape(T, n, 4, -1)
        gap = np.sum((F[:, 0] - ref[:, None, :]) ** 2, axis=-1)  # (T, 4) at lo
        col = np.argmin(np.where(A[:, 0], np.nan_to_num(gap, nan=np.inf), np.inf), axis=1)
        alive = A[r, :, col]  # (T, n) the branch's root along the sections
        alive[:, 0] = True
        if round_ == 0:
            reached = np.asarray(alive.all(axis=1), dtype=bool)
            at_end[reached] = F[r, n - 1, col][reached]
        first = np.where(alive.all(axis=1), n - 1, np.argmax(~alive, axis=1))
        last = first - 1
        ref = F[r, last, col]
        lo, hi = u[r, last], u[r, first]
    return np.where(reached, 1.0, lo), reached, at_end


def features(mot: RSRCMotion, rows: NDArray[np.intp], cols: NDArray[np.intp],
             length: float) -> Array:
    """The features (:func:`_features`) of ``mot``'s roots at ``rows``, ``cols`` (T,)."""
    return _features(mot.phi0[rows, cols], mot.chi0[rows, cols], mot.S[rows, cols],
                     max(length, np.finfo(float).tiny))


def _features(phi: Array, chi: Array, s: Array, length: float) -> Array:
    """The matched quantities of ``rsrc_motion`` (cos φ0, sin φ0, cos χ0, sin χ0, S/L) along a
    new last axis (NaN where a root does not assemble)."""
    return np.stack([np.cos(phi), np.sin(phi), np.cos(chi), np.sin(chi), s / length], axis=-1)
