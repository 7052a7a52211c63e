"""Continuous assembly-mode branches of the RSRC over a sweep of the input angle (Bagci 1969, §3.4).

Bagci's inversion labels are root orderings at each theta0; `rsrc_motion` matches the roots of
consecutive samples by continuity and reports where a branch stops or starts assembling.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dual.spatial import wrap_angle
from screwkit.kinematics.quartic import DEFAULT_DOUBLE_ROOT_TOL
from screwkit.kinematics.rsrc.dimensions import RSRCDimensions, check_input_angles
from screwkit.kinematics.rsrc.positions import RSRCPositions, rsrc_positions
from screwkit.kinematics.rsrc.rates import RSRCRates, rsrc_rates

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
    theta0 : input angle of the event, refined by bisection to about 1e-15 rad, on the side where
        the branch assembles (its two roots there are a double root to within the tolerance).
    sample : index of the first sample after the event.
    """

    branch: int
    kind: Literal["stops", "starts"]
    theta0: float
    sample: int


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
    """

    theta0: FloatArray
    phi0: FloatArray
    chi0: FloatArray
    S: FloatArray
    assembles: BoolArray
    inversion_label: IntArray
    events: tuple[BranchEvent, ...]


def _all_permutations() -> IntArray:
    from itertools import permutations

    return np.array(list(permutations(range(4))), dtype=np.int64)


_PERMS = _all_permutations()  # (24, 4)
_PERM_INDEX = {tuple(int(v) for v in p): i for i, p in enumerate(_PERMS)}
# _COMPOSE[a, b] = index of the permutation slot -> _PERMS[a][_PERMS[b][slot]]
_COMPOSE = np.array(
    [[_PERM_INDEX[tuple(int(_PERMS[a][_PERMS[b][s]]) for s in range(4))] for b in range(24)]
     for a in range(24)],
    dtype=np.int64,
)

_UNMATCHED_COST = 2.0  # cost of leaving a root unmatched: |unit-vector difference|^2 for 90 deg
_BLOCK = 8192  # samples matched at once: the (n, 4, 4) costs stay in cache


def _branch_features(
    phi: FloatArray, chi: FloatArray, s: FloatArray, length: float
) -> tuple[FloatArray, ...]:
    """The 5 features compared when matching roots, each shaped like ``phi``: unit vectors of
    phi0, chi0 and S/L; 0 where a root does not assemble (NaN)."""
    return tuple(np.where(np.isnan(f), 0.0, f) for f in (
        np.cos(phi), np.sin(phi), np.cos(chi), np.sin(chi), s / length))


def _advanced(value: FloatArray, rate: FloatArray, step: FloatArray, limit: float) -> FloatArray:
    """``value`` moved by its rate over the step, where that move is below ``limit``."""
    delta = rate * step
    return np.where(np.abs(delta) < limit, value + delta, value)


def _match_consecutive(
    pos: RSRCPositions, rates: RSRCRates, length: float
) -> IntArray:
    """Best permutation (index into _PERMS) from the columns at k-1 to those at k, for every k.

    The roots at k-1 are first advanced by their rates (d/d theta0 times the step) when that
    step is small, then every one of the 24 assignments is scored at once (vectorised) — only at
    the steps where keeping every column is not already optimal: where each root's nearest root
    at k is its own column, the identity costs the sum of the rows' minima, a lower bound of
    every assignment's cost. Works in blocks of samples (the (n, 4, 4) costs stay in cache).
    """
    n = pos.theta0.shape[0] - 1
    best = np.full(max(n, 0), _PERM_INDEX[(0, 1, 2, 3)], dtype=np.int64)
    for start in range(0, n, _BLOCK):
        k = slice(start, min(start + _BLOCK, n))
        k1 = slice(start + 1, k.stop + 1)
        step = (pos.theta0[k1] - pos.theta0[k])[:, None]
        prev = _branch_features(_advanced(pos.phi0[k], rates.phi0_dot[k], step, 0.5),
                                _advanced(pos.chi0[k], rates.chi0_dot[k], step, 0.5),
                                _advanced(pos.S[k], rates.S_dot[k], step, 0.5 * length), length)
        nxt = _branch_features(pos.phi0[k1], pos.chi0[k1], pos.S[k1], length)
        # squared distances |p − q|², (n, 4, 4), feature by feature
        cost = np.zeros((step.shape[0], 4, 4))
        for f_prev, f_next in zip(prev, nxt, strict=True):
            diff = f_prev[:, :, None] - f_next[:, None, :]
            cost += diff * diff
        valid_prev, valid_next = pos.assembles[k], pos.assembles[k1]
        both = valid_prev[:, :, None] & valid_next[:, None, :]
        one = valid_prev[:, :, None] ^ valid_next[:, None, :]
        cost = np.where(both, cost, np.where(one, _UNMATCHED_COST, 0.0))
        diagonal = np.diagonal(cost, axis1=1, axis2=2)
        other = np.nonzero(~np.all(diagonal <= cost.min(axis=2), axis=1))[0]
        if other.size:
            total = cost[other][:, np.arange(4), _PERMS].sum(axis=-1)  # (m, 24)
            best[start + other] = np.argmin(total, axis=1)
    return best


def _unwrap_runs(angle: FloatArray, valid: BoolArray) -> FloatArray:
    """Unwrap each column of ``angle`` along its runs of valid samples (NaN elsewhere)."""
    n = angle.shape[0]
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
    *,
    double_root_tol: float = DEFAULT_DOUBLE_ROOT_TOL,
) -> RSRCMotion:
    """Track every assembly mode continuously over a sweep of input angles (Bagci 1969, §3.4).

    Bagci's inversion labels are root orderings at each theta0 and are not continuous in general
    (§3.4 "Branch continuity").  Here the roots of consecutive samples are matched by continuity:
    each root at sample k-1 is advanced by its rate (3.77)-(3.79) times the step, and the
    assignment of the 4 columns that minimises the summed squared distance of
    (cos phi0, sin phi0, cos chi0, sin chi0, S/L) is chosen among all 24 (vectorised over the
    sweep; a root is left unmatched when that is cheaper than a 90-degree jump).  The per-step
    permutations are then composed along the sweep (a light loop over integers).  phi0 is
    unwrapped along each run of valid samples, and every place where a branch stops or starts
    assembling is reported with its input angle, refined by bisection.

    The sweep should be monotonic and fine enough that no root moves by more than about 30
    degrees between samples.

    Parameters
    ----------
    dims
        The mechanism.
    theta0_sweep
        Input angles (radians), shape (N,), N >= 2.
    double_root_tol
        As in `rsrc_positions`.
    """
    theta = check_input_angles(theta0_sweep, "theta0_sweep")
    if theta.shape[0] < 2:
        raise ValueError("theta0_sweep needs at least 2 samples to track branches")
    pos = rsrc_positions(dims, theta, double_root_tol=double_root_tol)
    rates = rsrc_rates(dims, pos)
    length = max(dims.length_scale, np.finfo(float).tiny)
    best = _match_consecutive(pos, rates, length)

    # compose the per-step permutations: slot -> raw column at each sample
    mapping = np.empty(theta.shape[0], dtype=np.int64)
    current = _PERM_INDEX[(0, 1, 2, 3)]
    mapping[0] = current
    compose = _COMPOSE.tolist()
    for k, step_perm in enumerate(best.tolist(), start=1):
        current = compose[step_perm][current]
        mapping[k] = current
    cols = _PERMS[mapping]  # (N, 4)

    def take(arr: np.ndarray) -> np.ndarray:
        return np.take_along_axis(arr, cols, axis=1)

    assembles = take(pos.assembles)
    phi = _unwrap_runs(take(pos.phi0), assembles)
    chi = take(pos.chi0)
    s = take(pos.S)
    labels = take(pos.inversion_label)

    # events: branch stops (valid -> invalid) or starts (invalid -> valid)
    change = assembles[1:] != assembles[:-1]
    k_idx, branch_idx = np.nonzero(change)
    samples = k_idx + 1
    events: list[BranchEvent] = []
    if samples.size:
        theta_event = _refine_events(dims, theta, pos.n_assemblies, samples, double_root_tol)
        for sample, branch, th in zip(samples.tolist(), branch_idx.tolist(),
                                      theta_event.tolist(), strict=True):
            kind: Literal["stops", "starts"] = (
                "stops" if bool(assembles[sample - 1, branch]) else "starts"
            )
            events.append(BranchEvent(branch, kind, th, sample))
    return RSRCMotion(theta, phi, chi, s, assembles, labels, tuple(events))
