"""Islands inside one sample step on the homotopy route (issue 27, "every mode is known at
every sample ...; births and deaths at folds are reported"), from the input's folds.

Anchored tracking (modes/along.py) sees a mode only where it holds at a sample or meets a
known mode's fold next to one; an island of modes that lives only between two samples meets
neither. The input's folds are found first, all of them, as the critical points of the
configuration curve's projection onto the input (modes/planar_folds.py, one homotopy per
mechanism). A mode is a branch over an interval between folds, so every island inside a
step lies over an interval between two consecutive fold inputs inside that step: the
homotopy (modes/every_mode.py) is solved at the middle of each such interval, and a mode
there whose continuation reaches neither of the step's samples (the fold search of each
half, modes/along_folds.py ``fold_in_step``) is an island. Its birth and death are the
critical inputs next to the search's (within :data:`SNAP`; the search's own value, with a
note, where none is).

Taken: a formulation with an ``input_folds`` method (the planar R formulation,
modes/planar.py) and a motion in which one input varies (the others constant). Not taken
(a note says so, and the anchored tracking alone runs as before): other formulations,
several inputs varying at once, kernel systems of more than :data:`MAX_PATHS` start paths.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.total_degree import bezout_number
from screwkit.errors import ScrewkitError
from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.follow import reach
from screwkit.kinematics.modes.along_folds import Chain, fold_in_step, pose_distance
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: two critical inputs are one fold input where they agree to this (rad): the two branches
#: of a sub-chain that does not fold give two critical points at one input
SAME_INPUT = 1e-9
#: a bisected birth or death is the critical input within this (rad) of it
SNAP = 1e-6
#: kernel systems whose total-degree start would track more paths are not solved
MAX_PATHS = 4096
#: two island modes found at two interval middles are one where their poses agree to this
SAME_MODE = 1e-6


def fold_values(mech: Mechanism, X: Array) -> tuple[int, Array | None, str]:
    """The varying input (column of ``X``) and every fold input of it (sorted, radians, one
    turn from the first sample's; None where they are not searched), and a note of how they
    were found or why not."""
    varying = np.flatnonzero(np.ptp(X, axis=0) > 0) if X.shape[0] > 1 else np.zeros(0, int)
    if varying.size != 1:
        return -1, None, (f"{varying.size} inputs vary along the motion; the folds are "
                          "found as critical points of one varying input only")
    j = int(varying[0])
    form = closure_formulation(mech)
    method = getattr(form, "input_folds", None)
    system = getattr(form, "fold_system", None)
    if not callable(method) or not callable(system):
        return j, None, (f"the {type(form).__name__} has no critical-point system of its "
                         "input (only the planar R formulation has one)")
    try:  # (a formulation that cannot write its input's circle: the system raises too)
        paths = bezout_number(system(j))
        if paths > MAX_PATHS:
            return j, None, (f"its critical-point system would start from {paths} "
                             f"total-degree paths, more than {MAX_PATHS}")
        folds = method(X[0], j)
    except ScrewkitError as err:
        return j, None, str(err)
    vals = np.sort(np.mod(folds.inputs - X[0, j], 2 * np.pi) + X[0, j])
    note = (f"{vals.size} real critical point(s) of {mech.inputs[j]} (folds; "
            f"{int(folds.certified.sum())} certified real by Smale's α-test) of "
            f"{folds.found} complex, generic count {folds.generic_count} ({folds.how_found})"
            + (f"; {folds.singular} singular real end point(s) not taken as folds"
               if folds.singular else ""))
    return j, vals, note


def folds_in_steps(x: Array, vals: Array) -> list[tuple[int, Array]]:
    """Each step k (samples k → k+1 of the input ``x``) with two or more distinct fold inputs
    strictly inside it, and those inputs in sample order (unwrapped to the step's turn)."""
    out = []
    for k in range(x.size - 1):
        lo, hi = sorted((float(x[k]), float(x[k + 1])))
        first = np.ceil((lo - vals.max(initial=0.0)) / (2 * np.pi)) - 1
        turns = np.arange(first, np.floor((hi - vals.min(initial=0.0)) / (2 * np.pi)) + 2)
        cand = (vals[None, :] + 2 * np.pi * turns[:, None]).reshape(-1)
        inside = np.sort(cand[(cand > lo + SAME_INPUT) & (cand < hi - SAME_INPUT)])
        if inside.size:
            inside = inside[np.concatenate([[True], np.diff(inside) > SAME_INPUT])]
        if inside.size >= 2:
            out.append((k, inside if x[k + 1] > x[k] else inside[::-1]))
    return out


def run_samples(x: Array, vals: Array, anchors: NDArray[np.intp]) -> NDArray[np.intp]:
    """One sample (the middle) of each run of consecutive samples of the input ``x`` with no
    fold input ``vals`` (one turn) between them, where the run holds no anchor. Over such a
    run no mode is born or dies, so a mode at any of its samples is at all of them: the
    homotopy there finds every mode of the run."""
    below = np.floor((x[:, None] - vals[None, :]) / (2 * np.pi)).sum(axis=1)  # folds ≤ x
    cut = np.flatnonzero(below[1:] != below[:-1]) + 1
    held = set(anchors.tolist())
    out = []
    for a, b in zip([0, *cut.tolist()], [*cut.tolist(), x.size], strict=True):
        if not held & set(range(a, b)):
            out.append((a + b - 1) // 2)
    return np.array(out, dtype=np.intp)


def step_islands(mech: Mechanism, lay: GraphLayout, X: Array, write: Callable[[Array], str],
                 folds: tuple[int, Array | None, str]) -> tuple[list[Chain], tuple[str, ...]]:
    """The island modes inside one sample step (module docstring), each a :class:`Chain` on
    no sample with its birth and death, and the notes; ``folds`` is :func:`fold_values`."""
    j, vals, note = folds
    if vals is None:
        return [], (f"folds inside one step: not searched as critical points ({note}): an "
                    "island inside one sample step that meets no known mode is not seen",)
    steps = folds_in_steps(X[:, j], vals)
    mids, where = [], []
    for k, inside in steps:
        for a, b in zip(inside[:-1], inside[1:], strict=True):
            row = X[k].copy()
            row[j] = 0.5 * (a + b)
            mids.append(row)
            where.append((k, inside))
    chains: list[Chain] = []
    seen: list[tuple[Chain, Array, Configuration]] = []  # each island, where it was found
    if mids:
        solved = every_mode(mech, np.array(mids))
        for r, (k, inside) in enumerate(where):
            there = solved.configurations[r]
            for m in range(there.size):
                conf = there.take(slice(m, m + 1))
                if _known(mech, lay, seen, conf, mids[r], j):
                    continue
                chain = _island(mech, lay, X, k, conf, mids[r], inside, j, write)
                if chain is not None:
                    chain.anchors_met, chain.anchors_certified = 1, int(solved.certified[r][m])
                    chains.append(chain)
                    seen.append((chain, mids[r], conf))
    return chains, (f"folds inside one step: {note}; {len(steps)} step(s) hold two or more, "
                    f"the homotopy at the {len(mids)} input(s) between them finds "
                    f"{len(chains)} island mode(s) on no sample",)


def unreported(X: Array, folds: tuple[int, Array | None, str],
               chains: list[Chain], write: Callable[[Array], str]) -> tuple[str, ...]:
    """A note on whether every fold input strictly inside the motion's steps is a birth or
    death some mode reports (to :data:`SNAP`): two real branches meet at a fold, so one that
    no mode reports means a mode is missing there or a track crossed it (none when the folds
    are not known)."""
    j, vals, _ = folds
    if vals is None or X.shape[0] < 2:
        return ()
    x = X[:, j]
    reported = np.array([at[j] for c in chains for at, _ in c.folds])
    missing, count = [], 0
    for k in range(x.size - 1):
        lo, hi = sorted((float(x[k]), float(x[k + 1])))
        turns = np.arange(np.floor((lo - vals.max(initial=0.0)) / (2 * np.pi)),
                          np.floor((hi - vals.min(initial=0.0)) / (2 * np.pi)) + 1)
        cand = (vals[None, :] + 2 * np.pi * turns[:, None]).reshape(-1)
        cand = np.unique(np.round(cand[(cand > lo) & (cand < hi)] / SAME_INPUT)) * SAME_INPUT
        for v in cand.tolist():
            count += 1
            if reported.size == 0 or np.abs(reported - v).min() > SNAP:
                row = X[k].copy()
                row[j] = v
                missing.append(write(row))
    if not missing:
        return (f"every one of the {count} fold input(s) inside the motion's steps is a birth "
                "or death of the modes reported",)
    return (f"{len(missing)} of the {count} fold input(s) inside the motion's steps are no "
            f"reported mode's birth or death ({'; '.join(missing[:4])}"
            f"{' …' if len(missing) > 4 else ''}): a mode may be missing there, or a track "
            "crossed the fold",)


def _known(mech: Mechanism, lay: GraphLayout, seen: list[tuple[Chain, Array, Configuration]],
           conf: Configuration, x: Array, j: int) -> bool:
    """Whether an island already found (at another interval's middle) is the mode ``conf``
    at ``x``: reached from where it was found, the same poses."""
    for c, at, there in seen:
        (lo, _), (hi, _) = c.folds
        if min(lo[j], hi[j]) < x[j] < max(lo[j], hi[j]):
            got = reach(mech, lay, there, at, x)
            if got is not None and pose_distance(mech, lay, got, conf)[0, 0] <= SAME_MODE:
                return True
    return False


def _snap(at: Array, inside: Array, j: int) -> tuple[Array, bool]:
    near = inside[np.argmin(np.abs(inside - at[j]))]
    if abs(near - at[j]) > SNAP:
        return at, False
    out = at.copy()
    out[j] = near
    return out, True


def _island(mech: Mechanism, lay: GraphLayout, X: Array, k: int, conf: Configuration,
            x: Array, inside: Array, j: int, write: Callable[[Array], str]) -> Chain | None:
    """The mode ``conf`` at ``x`` inside step k as an island (its birth towards sample k, its
    death towards k + 1), or None where it reaches either sample."""
    born = fold_in_step(mech, lay, conf, x, X[k])
    dies = fold_in_step(mech, lay, conf, x, X[k + 1])
    if born is None or dies is None:
        return None
    N = X.shape[0]
    chain = Chain(np.zeros((N, lay.n_scalar)),
                  np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy(),
                  np.zeros(N, dtype=bool))
    how = ("(a fold: a critical point of the input found by the homotopy with every other, "
           "and the end of this mode's continuation)")
    for (at, near), word in ((born, "is born"), (dies, "dies")):
        fixed, snapped = _snap(at, inside, j)
        chain.folds.append((fixed, near))
        verb = "starts" if word == "is born" else "stops"
        chain.events.append(
            f"{word} at {write(fixed)}: it {verb} assembling there "
            + (how if snapped else "(a fold located between samples; no critical "
               "point of the input within 1e-6 rad of it)"))
    chain.events.append(f"found by the homotopy at {write(x)}, between two folds inside the "
                        f"step from {write(X[k])} to {write(X[k + 1])}: an island inside one "
                        "sample step, no sample on it")
    return chain
