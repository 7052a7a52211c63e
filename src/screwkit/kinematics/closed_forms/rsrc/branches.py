"""Continuous assembly-mode branches of the RSRC over a sweep of the input angle (Bagci 1969, §3.4).

Bagci's inversion labels are root orderings at each theta0; `rsrc_motion` matches the roots of
consecutive samples by continuity and reports where a branch stops or starts assembling.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache
from itertools import permutations
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import wrap_angle, wrap_angle_near
from screwkit.errors import InputError
from screwkit.kinematics.closed_forms.quartic import DEFAULT_DOUBLE_ROOT_TOL
from screwkit.kinematics.closed_forms.rsrc.dimensions import (
    RSRCDimensions,
    check_input_angles,
    check_input_rate,
)
from screwkit.kinematics.closed_forms.rsrc.positions import RSRCPositions, rsrc_positions
from screwkit.kinematics.closed_forms.rsrc.rates import RSRCRates, rsrc_kinematics

__all__ = ["BranchEvent", "RSRCMotion", "rsrc_motion"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class BranchEvent:
    """A branch of an `RSRCMotion` stops or starts assembling between two samples.

    Attributes
    ----------
    branch : column of the motion arrays.
    kind : "stops" (the branch merges with another one: a limit position / dead centre of the
        input, beyond which the loop does not close on it) or "starts".
    theta0 : input angle of the event: where the branch's own root stops assembling (folds.py:
        followed section by section from the sample where it assembles, to 2⁻⁵⁰ of the step,
        the last point where it still assembles),
        else (none expected) where the count of roots changes, bisected to about 1e-15 rad on
        the side where the branch assembles.
    sample : index of the first sample after the event.
    partner : the branch (column) that meets it there (its own search ends at the same place
        in the same step), None where that root assembles at neither sample or the event was
        placed by the count.
    """

    branch: int
    kind: Literal["stops", "starts"]
    theta0: float
    sample: int
    partner: int | None = None


@dataclass(frozen=True)
class RSRCMotion:
    """Continuous assembly-mode branches over a sweep of theta0 (see `rsrc_motion`).

    Attributes
    ----------
    theta0 : (N,) the sweep.
    phi0 : (N, 4) output rotation, unwrapped (continuous) along each run of valid samples of a
        column; NaN where ``~assembles``.
    chi0, S : (N, 4) coupler angle (in (-pi, pi]) and output translation.
    assembles : (N, 4) bool.
    inversion_label : (N, 4) program label (1..4, see `RSRCPositions`) of the entry at each
        sample, 0 where it does not assemble.  Along a branch the label can change: labels are
        root orderings, branches are continuous.
    events : where branches stop or start.
    rates : velocities and accelerations of phi0, chi0 and S along the same columns, for the
        ``theta0_dot`` and ``theta0_ddot`` given to `rsrc_motion` (by default 1 and 0: the
        first and second derivatives with respect to theta0), with their masks
        (eqs. 3.77-3.82).
    """

    theta0: FloatArray
    phi0: FloatArray
    chi0: FloatArray
    S: FloatArray
    assembles: BoolArray
    inversion_label: IntArray
    events: tuple[BranchEvent, ...]
    rates: RSRCRates


@cache
def _permutations(k: int) -> tuple[IntArray, IntArray, int]:
    """The k! permutations of k columns ((k!, k) array), their composition table
    ``compose[a, b]`` = index of slot -> perms[a][perms[b][slot]], and the identity's index."""
    perms = np.array(list(permutations(range(k))), dtype=np.int64).reshape(-1, k)
    index = {tuple(int(v) for v in q): i for i, q in enumerate(perms)}
    compose = np.array(
        [[index[tuple(int(perms[a][perms[b][s]]) for s in range(k))] for b in range(len(perms))]
         for a in range(len(perms))], dtype=np.int64)
    return perms, compose, index[tuple(range(k))]


_UNMATCHED_COST = 2.0  # cost of leaving a root unmatched: |unit-vector difference|^2 for 90 deg
_BLOCK = 8192  # samples matched at once: the (n, k, k) costs stay in cache


def _branch_features(
    phi: FloatArray, chi: FloatArray, s: FloatArray, length: float
) -> tuple[FloatArray, ...]:
    """The 5 features compared when matching roots, each shaped like ``phi``: unit vectors of
    phi0, chi0 and S/L (NaN where a root does not assemble: those costs are replaced)."""
    return np.cos(phi), np.sin(phi), np.cos(chi), np.sin(chi), s * (1.0 / length)


def _advanced(value: FloatArray, rate: FloatArray, step: FloatArray, limit: float) -> FloatArray:
    """``value`` moved by its rate over the step, where that move is below ``limit``."""
    delta = rate * step
    return np.where(np.abs(delta) < limit, value + delta, value)


def _identity_is_best(prev: tuple[FloatArray, ...], nxt: tuple[FloatArray, ...],
                      valid_prev: BoolArray, valid_next: BoolArray, length: float) -> BoolArray:
    """(m,) True where keeping every column is certainly the best assignment, tested without
    trigonometry: each root's (predicted) distance to its own column, δ, measured in angles
    (wrapped φ0 and χ0 differences, S/L), is below σ/π, with σ the smallest such distance
    between two roots at the next sample, and δ² < 2 (the cost of leaving a root unmatched).
    The chord distance of the cost is ≤ the angle distance and ≥ 2/π times it, so then every
    root's nearest root is its own column (triangle inequality): the identity attains each
    row's minimum. The few steps left are scored in full."""
    (pp, pc, ps), (np_, nc, ns) = prev, nxt
    inv_l = 1.0 / length
    dp, dc, ds = wrap_angle_near(np_ - pp), wrap_angle_near(nc - pc), (ns - ps) * inv_l
    delta2 = dp * dp + dc * dc + ds * ds  # NaN where a root does not assemble
    k = pp.shape[1]
    bound = np.full(pp.shape[0], 2.0)
    for i in range(k):
        for j in range(i + 1, k):
            a = wrap_angle_near(np_[:, i] - np_[:, j])
            b = wrap_angle_near(nc[:, i] - nc[:, j])
            c = (ns[:, i] - ns[:, j]) * inv_l
            bound = np.fmin(bound, (a * a + b * b + c * c) * (1.0 / np.pi**2))
    close = delta2 < bound[:, None]
    return np.all((valid_prev == valid_next) & (close | ~valid_next), axis=1)


def _match_consecutive(
    pos: RSRCPositions, rates: RSRCRates, length: float, k: int
) -> IntArray:
    """Best permutation (index into ``_permutations(k)``) from the first k columns at sample
    i-1 to those at i, for every i.

    The roots at i-1 are first advanced by their rates (d/d theta0 times the step) when that
    step is small. Where keeping every column is certainly optimal (`_identity_is_best`, cheap)
    nothing more is done; at the other steps every one of the k! assignments is scored at once
    (vectorised) by the summed squared distances of (cos phi0, sin phi0, cos chi0, sin chi0,
    S/L). Works in blocks of samples (the temporaries stay in cache).
    """
    perms, _, identity = _permutations(k)
    n = pos.theta0.shape[0] - 1
    best = np.full(max(n, 0), identity, dtype=np.int64)
    cols = slice(0, k)
    for start in range(0, n, _BLOCK):
        i0 = slice(start, min(start + _BLOCK, n))
        i1 = slice(start + 1, i0.stop + 1)
        step = (pos.theta0[i1] - pos.theta0[i0])[:, None]
        prev = (_advanced(pos.phi0[i0, cols], rates.phi0_dot[i0, cols], step, 0.5),
                _advanced(pos.chi0[i0, cols], rates.chi0_dot[i0, cols], step, 0.5),
                _advanced(pos.S[i0, cols], rates.S_dot[i0, cols], step, 0.5 * length))
        nxt = (pos.phi0[i1, cols], pos.chi0[i1, cols], pos.S[i1, cols])
        valid_prev, valid_next = pos.assembles[i0, cols], pos.assembles[i1, cols]
        rows = np.flatnonzero(~_identity_is_best(prev, nxt, valid_prev, valid_next, length))
        if not rows.size:
            continue
        f_prev = _branch_features(prev[0][rows], prev[1][rows], prev[2][rows], length)
        f_next = _branch_features(nxt[0][rows], nxt[1][rows], nxt[2][rows], length)
        # squared distances |p − q|², (m, k, k), feature by feature
        cost = np.zeros((rows.size, k, k))
        for a, b in zip(f_prev, f_next, strict=True):
            diff = a[:, :, None] - b[:, None, :]
            cost += diff * diff
        vp, vn = valid_prev[rows], valid_next[rows]
        both = vp[:, :, None] & vn[:, None, :]
        one = vp[:, :, None] ^ vn[:, None, :]
        cost = np.where(both, cost, np.where(one, _UNMATCHED_COST, 0.0))
        diagonal = np.diagonal(cost, axis1=1, axis2=2)
        other = np.nonzero(~np.all(diagonal <= cost.min(axis=2), axis=1))[0]
        if other.size:
            total = cost[other][:, np.arange(k), perms].sum(axis=-1)  # (m, k!)
            best[start + rows[other]] = np.argmin(total, axis=1)
    return best


def _column_map(best: IntArray, k: int) -> IntArray | None:
    """(N, k) raw column of each branch at every sample, composing the per-step permutations
    (a loop over the steps that change the order only); None when no step does."""
    perms, compose, identity = _permutations(k)
    changes = np.flatnonzero(best != identity)
    if changes.size == 0:
        return None
    current, values = identity, [identity]
    for step in changes.tolist():
        current = int(compose[best[step], current])
        values.append(current)
    # the order set at step i applies from sample i + 1 until the next change
    lengths = np.diff(np.concatenate([[0], changes + 1, [best.shape[0] + 1]]))
    return perms[np.repeat(np.array(values), lengths)]


def _unwrap_runs(angle: FloatArray, valid: BoolArray) -> FloatArray:
    """Unwrap each column of ``angle`` along its runs of valid samples (NaN elsewhere)."""
    n = angle.shape[0]
    whole = valid.all(axis=0)
    if np.all(whole | ~valid.any(axis=0)):  # one run per column (the common case)
        out = np.full_like(angle, np.nan)
        cols = np.flatnonzero(whole)
        a = angle[:, cols]
        out[:1, cols] = a[:1]
        out[1:, cols] = np.cumsum(wrap_angle_near(a[1:] - a[:-1]), axis=0) + a[:1]
        return out
    prev_valid = np.vstack([np.zeros((1, angle.shape[1]), dtype=bool), valid[:-1]])
    start = valid & ~prev_valid
    diff = np.zeros_like(angle)
    diff[1:] = wrap_angle(np.nan_to_num(angle[1:] - angle[:-1]))
    diff = np.where(valid & ~start, diff, 0.0)
    csum = np.cumsum(diff, axis=0)
    # index of the start of the current run, per column
    run_start = np.where(start, np.arange(n)[:, None], 0)
    run_start = np.maximum.accumulate(run_start, axis=0)
    cols = np.arange(angle.shape[1])[None, :]
    base = angle[run_start, cols] - csum[run_start, cols]
    return np.where(valid, base + csum, np.nan)


def _refine_events(
    dims: RSRCDimensions,
    theta: FloatArray,
    n_assemblies: IntArray,
    samples: IntArray,
    tol: float,
    iterations: int = 60,
) -> FloatArray:
    """Bisect each interval (theta[k-1], theta[k]) for where the number of inversions changes.

    Returns, per event, the end of the final bracket (about 1e-15 wide) on the side with more
    inversions, i.e. the limit configuration itself (the double root) still assembles there.
    """
    lo = theta[samples - 1].copy()
    hi = theta[samples].copy()
    count_lo = n_assemblies[samples - 1]
    more_on_lo = count_lo > n_assemblies[samples]
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        same = rsrc_positions(dims, mid, double_root_tol=tol).n_assemblies == count_lo
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return np.where(more_on_lo, lo, hi)


def rsrc_motion(
    dims: RSRCDimensions,
    theta0_sweep: ArrayLike,
    theta0_dot: ArrayLike = 1.0,
    theta0_ddot: ArrayLike = 0.0,
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
    events: bool = True,
) -> RSRCMotion:
    """Track every assembly mode continuously over a sweep of input angles (Bagci 1969, §3.4),
    with the velocities and accelerations of every branch (eqs. 3.77-3.82).

    Bagci's inversion labels are root orderings at each theta0 and are not continuous in general
    (§3.4 "Branch continuity").  Here the roots of consecutive samples are matched by continuity:
    each root at sample k-1 is advanced by its rate (3.77)-(3.79) times the step, and the
    assignment of the columns that minimises the summed squared distance of
    (cos phi0, sin phi0, cos chi0, sin chi0, S/L) is chosen among all permutations of the
    columns that ever assemble over the sweep (vectorised; where the number of assemblies
    changes between two samples, a root is left unmatched when that is cheaper than a
    90-degree jump; where it does not, every root is matched, so a branch stops only where
    the count of roots changes).  The per-step permutations are then composed along the
    sweep (a loop over the steps that change the order only).  phi0 is unwrapped along each run
    of valid samples, and every place where a branch stops or starts assembling is reported
    with its input angle, where that branch's own root stops assembling, and the branch it
    meets there (folds.py's ``branch_folds``: two pairs of branches may fold inside one step).

    Positions and rates come from one pass of `rsrc_kinematics` (d/d theta0 and
    d²/d theta0²); the rates at ``theta0_dot``, ``theta0_ddot`` follow by the chain rule,
    x' theta0_dot and x'' theta0_dot² + x' theta0_ddot, which is what eqs. 3.77-3.82 give
    (they are linear in theta0-ddot and quadratic in theta0-dot).

    The sweep should be monotonic and fine enough that no root moves by more than about 30
    degrees between samples; on a coarser sweep the matching is a guess (tested against
    sweeps refined 200 times: mostly the right one), and it can depend on how many roots
    the sweep meets elsewhere.

    Parameters
    ----------
    dims
        The mechanism.
    theta0_sweep
        Input angles (radians), shape (N,), N >= 2.
    theta0_dot, theta0_ddot
        Input angular velocity (rad/s) and acceleration (rad/s²): scalars or shape (N,).
    double_root_tol
        As in `rsrc_positions`.
    events
        False: no events (the fold search's own sweeps, folds.py, which call this).
    """
    theta = check_input_angles(theta0_sweep, "theta0_sweep")
    n = theta.shape[0]
    if n < 2:
        raise InputError("theta0_sweep needs at least 2 samples to track branches")
    td = check_input_rate(theta0_dot, n, "theta0_dot")
    tdd = check_input_rate(theta0_ddot, n, "theta0_ddot")
    pos, deriv = rsrc_kinematics(dims, theta, 1.0, 0.0, double_root_tol=double_root_tol)
    used = np.flatnonzero(pos.assembles.any(axis=0))
    k = int(used.max()) + 1 if used.size else 1
    length = max(dims.length_scale, np.finfo(float).tiny)
    cols = _column_map(_match_consecutive(pos, deriv, length, k), k)

    def take(arr: np.ndarray) -> np.ndarray:
        """The columns in branch order (the trailing never-assembling columns stay put)."""
        if cols is None:
            return arr
        out = arr.copy()
        out[:, :k] = np.take_along_axis(arr[:, :k], cols, axis=1)
        return out

    assembles = take(pos.assembles)
    phi = _unwrap_runs(take(pos.phi0), assembles)
    rates = _branch_rates(deriv, take, td, tdd)
    labels = take(pos.inversion_label)

    out = RSRCMotion(theta, phi, take(pos.chi0), take(pos.S), assembles, labels, (), rates)
    if not events:
        return out
    return replace(out, events=_branch_events(dims, out, pos.n_assemblies, double_root_tol))


def _branch_events(dims: RSRCDimensions, mot: RSRCMotion, n_assemblies: IntArray,
                   tol: float) -> tuple[BranchEvent, ...]:
    """Where each branch of ``mot`` stops (valid -> invalid) or starts (invalid -> valid): at
    its own root's fold with its partner (folds.py), else (none expected: the branches are
    these roots) where the count of roots changes (`_refine_events`)."""
    from screwkit.kinematics.closed_forms.rsrc.folds import branch_folds

    theta, assembles = mot.theta0, mot.assembles
    k_idx, branch_idx = np.nonzero(assembles[1:] != assembles[:-1])
    samples = k_idx + 1
    hidden = _hidden_events(dims, mot)
    if not samples.size:
        return tuple(e for _, e in sorted(hidden, key=lambda x: x[0]))
    found = {(f.branch, f.k): f for f in branch_folds(dims, mot, tol) if 0.0 < f.t < 1.0}
    fold = [found.get((b, s - 1)) for b, s in zip(branch_idx.tolist(), samples.tolist(),
                                                   strict=True)]
    rest = np.array([f is None for f in fold])
    by_count = iter(_refine_events(dims, theta, n_assemblies, samples[rest], tol).tolist()
                    if rest.any() else [])
    events = hidden
    for sample, branch, f in zip(samples.tolist(), branch_idx.tolist(), fold, strict=True):
        kind: Literal["stops", "starts"] = (
            "stops" if bool(assembles[sample - 1, branch]) else "starts"
        )
        if f is None:
            ev = BranchEvent(branch, kind, next(by_count), sample)
        else:
            ev = BranchEvent(branch, kind, f.theta0, sample, f.partner)
        events.append(((sample, branch, 0.0 if f is None else f.t), ev))
    return tuple(e for _, e in sorted(events, key=lambda x: x[0]))


def _hidden_events(dims: RSRCDimensions, mot: RSRCMotion
                   ) -> list[tuple[tuple[int, int, float], BranchEvent]]:
    """Where a branch that assembles at both samples of a step is matched onto another root:
    its root dies inside the step and the root it is matched onto at the next sample is born
    inside it (two folds of the quartic inside one step, hidden_folds.py), each with its sort
    key (sample, branch, fraction of the step) and the branch its root meets there (the one
    whose root dies or is born at the same fraction; None: a root on neither sample)."""
    from screwkit.kinematics.closed_forms.rsrc.hidden_folds import hidden_steps

    theta = mot.theta0
    cols = np.flatnonzero(mot.assembles.any(axis=0))
    out: list[tuple[tuple[int, int, float], BranchEvent]] = []
    for s in hidden_steps(dims, mot, 0, theta.size - 1):
        sides: tuple[tuple[dict[int, float], Literal["stops", "starts"]], ...] = (
            (s.dies, "stops"), (s.born, "starts"))
        for what, kind in sides:
            for m, t in what.items():
                b = int(cols[m])
                if not (mot.assembles[s.k, b] and mot.assembles[s.k + 1, b]):
                    continue
                mate = [int(cols[n]) for n, u in what.items() if n != m and u == t]
                th = float(theta[s.k] + t * (theta[s.k + 1] - theta[s.k]))
                out.append(((s.k + 1, b, t),
                            BranchEvent(b, kind, th, s.k + 1, mate[0] if mate else None)))
    return out


def _branch_rates(deriv: RSRCRates, take: Callable[[np.ndarray], np.ndarray], td: FloatArray,
                  tdd: FloatArray) -> RSRCRates:
    """The d/d theta0 and d²/d theta0² of `rsrc_kinematics` in branch order, as time rates at
    theta0-dot ``td`` and theta0-ddot ``tdd`` ((N, 1) each): x' td and x'' td² + x' tdd."""
    unit = bool(np.all(td == 1.0) and np.all(tdd == 0.0))
    td2 = td * td

    def first(x: FloatArray) -> FloatArray:
        return take(x) if unit else take(x) * td

    def second(x: FloatArray, x1: FloatArray) -> FloatArray:
        return take(x) if unit else take(x) * td2 + take(x1) * tdd

    return replace(
        deriv,
        phi0_dot=first(deriv.phi0_dot), chi0_dot=first(deriv.chi0_dot),
        S_dot=first(deriv.S_dot),
        phi0_ddot=second(deriv.phi0_ddot, deriv.phi0_dot),
        chi0_ddot=second(deriv.chi0_ddot, deriv.chi0_dot),
        S_ddot=second(deriv.S_ddot, deriv.S_dot),
        locked=take(deriv.locked), chi_singular=take(deriv.chi_singular),
        valid=take(deriv.valid),
    )
