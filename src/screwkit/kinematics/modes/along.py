"""Every assembly mode along a motion, for a mechanism that has a polynomial formulation but
does not decompose into closed-form sub-chains (issue 27, "Along the motion").

The homotopy (:func:`~screwkit.kinematics.modes.every_mode.every_mode`) solves the closure at
*anchor* samples only (the first, the last and every K-th, K from the time budget); between two
anchors each mode found at the first is followed sample by sample by the loop engine's
continuation on the stacked closure (graph/follow.py: Deuflhard's contraction test and the
step-halving test near singular configurations reject a jump onto another branch). Identities
are kept by matching the tracked end to the next anchor's modes by body poses
(:data:`MATCH_TOLERANCE`, relative to the length scale). A tracked end that meets no anchor mode,
or two that meet the same one, is a path jump: the segment is tracked again with
:data:`REFINE` sub-steps per sample, and where that still does not match uniquely the mode is cut
at the anchor before (an event says so) rather than switched. An anchor mode that no tracked
mode reaches is born in the segment: it is tracked backward to where it stops assembling, and
the fold is located within that step (:func:`fold_between`: a bracket narrowed by probes at
σ²'s extrapolated zero and by bisection). A tracked mode that stops assembling dies there,
located the same way.
A track must not continue onto another mode across a fold inside a step (modes/along_folds.py):
a backward track that reaches a known mode's configuration is not taken past it and the step is
bisected for its fold; after the segments, two modes at one configuration are cut at the fold
of the one that jumped (:func:`~screwkit.kinematics.modes.along_folds.unshare`), and a fold
that no other mode meets splits the track that crossed its step
(:func:`~screwkit.kinematics.modes.along_folds.partner_folds`).
Then the homotopy is solved again at the samples on both sides of every birth and death, and
where the input's folds are known as critical points (modes/step_islands.py, planar R graphs
with one varying input) at one sample of every run between fold inputs that holds no anchor:
a mode there that no known mode holds (an island between two anchors) is tracked both ways to
its own birth and death (:func:`_islands`), and both checks are run again. Last, the islands
inside one sample step are found between the folds (modes/step_islands.py).

Guaranteed: every isolated real mode at every anchor (the homotopy's promise), continuity in
between (the tracker's checks), no silent switch at an anchor, no two modes at one
configuration at a sample; with the folds known, every island (as far as the critical points'
start set is complete). Not guaranteed: without them (other formulations, several inputs
varying), an island between two anchors that meets no known mode's fold next to a sample is
not seen; a jump across a fold onto a mode that no track finds
and whose fold partner no track finds either is not seen (docs/kinematics.md, "Every mode along
the motion").
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.graph.motion import (
    MechanismMode,
    build_mode,
    check_cost,
    groups,
    input_text,
    misfits,
    with_events,
)
from screwkit.kinematics.graph.subchains import Decomposition
from screwkit.kinematics.modes.along_folds import (
    Chain,
    fold_between,
    fold_in_step,
    fold_meetings,
    partner_folds,
    pose_distance,
    pose_vectors,
    shared_at,
    unshare,
)
from screwkit.kinematics.modes.every_mode import MechanismModes, every_mode
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: a tracked configuration is an anchor's mode when every body pose agrees to this (rotation
#: entries, and positions relative to the length scale)
MATCH_TOLERANCE = 1e-6
#: sub-steps per sample when a segment is tracked again after a suspected path jump
REFINE = 8
#: anchors are at most this many samples apart
ANCHOR_SPACING = 8
#: measured homotopy time per anchor and generic solution (rounded up; ~0.1 s per 6R instance)
SECONDS_PER_ANCHOR_ROOT = 5e-3


@dataclass(frozen=True)
class ModesAlong:
    """Every mode found along the inputs: ``configurations[k]`` (N samples) where
    ``masks[k]`` holds, with ``events[k]``; ``anchors`` the anchor samples; ``notes`` what was
    found and how; ``meets`` the pairs of modes that meet at a fold (:func:`fold_meetings`);
    ``islands`` the modes inside one sample step (on no sample; modes/step_islands.py);
    ``folds[k]`` where mode k is born or dies (the input, the configuration next to it)."""

    configurations: tuple[Configuration, ...]
    masks: tuple[NDArray[np.bool_], ...]
    events: tuple[tuple[str, ...], ...]
    anchors: NDArray[np.intp]
    notes: tuple[str, ...]
    solved: MechanismModes
    meets: tuple[tuple[int, int], ...] = ()
    folds: tuple[tuple[tuple[Array, Configuration], ...], ...] = ()
    islands: tuple[int, ...] = ()


def anchor_samples(N: int, per_anchor: float) -> NDArray[np.intp]:
    """The anchor samples: first, last and every K-th, K the smallest of
    :data:`ANCHOR_SPACING` that keeps the anchors' estimated time (``per_anchor`` s each)
    within half the time limit (screwkit.budget)."""
    from screwkit.budget import check_time, time_limit

    check_time(2 * per_anchor, "the homotopy at the first and last input",
               "use a mechanism with fewer solutions or fewer inputs")
    affordable = max(2, int(0.5 * time_limit() / max(per_anchor, 1e-9)))
    K = max(ANCHOR_SPACING, int(np.ceil((N - 1) / max(affordable - 1, 1))))
    return np.unique(np.concatenate([np.arange(0, N, K), [N - 1]])).astype(np.intp)


def _track(mech: Mechanism, lay: GraphLayout, start: Configuration, x0: Array, X: Array,
           refine: int = 1) -> tuple[Configuration, NDArray[np.bool_], int | None]:
    """Follow the mode through ``start`` (at ``x0``) along the rows of ``X`` (with ``refine``
    sub-steps per row): configurations, where reached, and the last row reached before it
    stops (-1: not even the first; None: reached throughout)."""
    if refine > 1:
        t = np.arange(1, refine + 1) / refine
        prev = np.vstack([x0[None, :], X[:-1]])
        fine = (prev[:, None, :] + t[None, :, None] * (X - prev)[:, None, :]).reshape(-1,
                                                                                     X.shape[1])
        f = follow_drawn_mode(mech, lay, fine, start=start, start_inputs=x0)
        take = np.arange(refine - 1, fine.shape[0], refine)
        mask = f.mask[take]
        stop = None if mask.all() else int(np.argmin(mask)) - 1
        return f.conf.take(take), mask, stop
    f = follow_drawn_mode(mech, lay, X, start=start, start_inputs=x0)
    return f.conf, f.mask, f.stopped_after


def modes_along(mech: Mechanism, lay: GraphLayout, X: Array, fmt: object) -> ModesAlong:
    """Every mode of ``mech`` over the input rows ``X`` (module docstring); ``fmt(x)`` writes
    an input row for the events."""
    from screwkit.kinematics.modes.every_mode import closure_formulation, formulation_start

    write = fmt if callable(fmt) else str
    N = X.shape[0]
    form = closure_formulation(mech)
    roots = formulation_start(form).generic_count
    per_root = getattr(form, "seconds_per_root", SECONDS_PER_ANCHOR_ROOT)
    anchors = anchor_samples(N, per_root * roots)
    check_cost(mech, N * max(roots, 1))  # at most every generic solution tracked throughout
    from screwkit.kinematics.modes.step_islands import (
        fold_values,
        run_samples,
        step_islands,
        unreported,
    )

    folds = fold_values(mech, X)
    solved = every_mode(mech, X[anchors])
    chains: list[Chain] = []
    active: dict[int, int] = {}  # mode index at the current anchor → chain
    first = solved.configurations[0]
    for m in range(first.size):
        active[m] = _new_chain(chains, lay, N)
        chains[active[m]].put(np.array([anchors[0]]), first.take(slice(m, m + 1)))
        _met(chains[active[m]], solved, 0, m)
    for i in range(len(anchors) - 1):
        active = _segment(mech, lay, X, anchors, i, solved, chains, active, write)
    unshare(mech, lay, X, chains, MATCH_TOLERANCE, write)
    partner_folds(mech, lay, X, chains, write)
    before = len(chains)
    runs = run_samples(X[:, folds[0]], folds[1], anchors) if folds[1] is not None else \
        np.zeros(0, dtype=np.intp)
    extra = _islands(mech, lay, X, anchors, chains, write, runs)
    unshare(mech, lay, X, chains, MATCH_TOLERANCE, write)
    partner_folds(mech, lay, X, chains, write)
    islands, island_notes = step_islands(mech, lay, X, write, folds)
    first_island = len(chains)
    chains.extend(islands)
    notes = _notes(solved, anchors, first_island, folds[1] is not None)
    if extra:
        notes += (f"the homotopy also at the {extra} sample(s) next to a birth or death or "
                  "alone in a run of samples between two fold inputs with no anchor: "
                  f"{first_island - before} mode(s) found there that reach no anchor (islands)",)
    notes += island_notes + unreported(X, folds, chains, write)
    return ModesAlong(tuple(Configuration(c.scalars, c.spherical) for c in chains),
                      tuple(c.mask for c in chains),
                      tuple(tuple(c.events) + (_certificate_event(c),) for c in chains),
                      anchors, notes, solved,
                      fold_meetings(mech, lay, [c.folds for c in chains]),
                      tuple(tuple(c.folds) for c in chains),
                      tuple(range(first_island, len(chains))))


def _islands(mech: Mechanism, lay: GraphLayout, X: Array, anchors: NDArray[np.intp],
             chains: list[Chain], fmt: object, runs: NDArray[np.intp]) -> int:
    """Modes that reach no anchor (an island between two anchors): the homotopy solved again
    at the samples on both sides of every birth and death (an island that meets a known mode
    at a fold) and at ``runs``, one sample of each run between fold inputs that holds no
    anchor (modes/step_islands.py ``run_samples``: any island on samples), each mode there on
    no known mode tracked both ways (:func:`_island`). The count of samples solved."""
    runs_set = set(runs.tolist())
    near: set[int] = set(runs_set)
    for c in chains:
        for k in np.flatnonzero(c.mask[:-1] != c.mask[1:]).tolist():
            near.update((k, k + 1))
    rows = np.array(sorted(near - set(anchors.tolist())), dtype=np.intp)
    if rows.size == 0:
        return 0
    solved = every_mode(mech, X[rows])
    for r, n in enumerate(rows.tolist()):
        there = solved.configurations[r]
        for j in range(there.size):
            conf = there.take(slice(j, j + 1))
            known = [c for c in chains if c.mask[n]]
            if known and pose_distance(mech, lay, conf, Configuration(
                    np.stack([c.scalars[n] for c in known]),
                    np.stack([c.spherical[n] for c in known]))).min() <= MATCH_TOLERANCE:
                continue
            where = ("alone in a run of samples between two fold inputs"
                     if n in runs_set else "next to another mode's fold")
            _island(mech, lay, X, n, conf, anchors, chains, fmt, where,
                    bool(solved.certified[r][j]))
    return int(rows.size)


def _island(mech: Mechanism, lay: GraphLayout, X: Array, n: int, conf: Configuration,
            anchors: NDArray[np.intp], chains: list[Chain], fmt: object, where: str,
            certified: bool) -> None:
    """A mode found at sample ``n`` between anchors, tracked to where it is born and where it
    dies (both located by :func:`fold_between`); dropped where it reaches an anchor (there it is a mode
    already followed)."""
    write = fmt if callable(fmt) else str
    fwd = np.arange(n + 1, int(anchors[anchors > n].min()) + 1)
    back = np.arange(n - 1, int(anchors[anchors < n].max()) - 1, -1)
    gf, mf, sf = _track(mech, lay, conf, X[n], X[fwd])
    gb, mb, sb = _track(mech, lay, conf, X[n], X[back])
    if sf is None or sb is None:
        return
    chain = chains[_new_chain(chains, lay, X.shape[0])]
    chain.anchors_met, chain.anchors_certified = 1, int(certified)
    chain.put(np.array([n]), conf)
    chain.put(fwd[mf], gf.take(np.flatnonzero(mf)))
    chain.put(back[mb], gb.take(np.flatnonzero(mb)))
    k = int(back[mb][-1]) if mb.any() else n
    at, near = fold_between(mech, lay, chain.conf_at(k), X[k], X[k - 1])
    chain.folds.append((at, near))
    chain.events.append(f"is born at {write(at)}: it starts assembling there (a fold, located "
                        "between samples)")
    k = int(fwd[mf][-1]) if mf.any() else n
    at, near = fold_between(mech, lay, chain.conf_at(k), X[k], X[k + 1])
    chain.folds.append((at, near))
    chain.events.append(f"dies at {write(at)}: it stops assembling there (a fold, located by "
                        f"bisection between samples); found by the homotopy at {write(X[n])}, "
                        f"{where}, between two anchors")


def _new_chain(chains: list[Chain], lay: GraphLayout, N: int) -> int:
    chains.append(Chain(np.zeros((N, lay.n_scalar)),
                         np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy(),
                         np.zeros(N, dtype=bool)))
    return len(chains) - 1


def _met(chain: Chain, solved: MechanismModes, i: int, m: int) -> None:
    chain.anchors_met += 1
    chain.anchors_certified += int(bool(solved.certified[i][m]))


def _segment(mech: Mechanism, lay: GraphLayout, X: Array, anchors: NDArray[np.intp], i: int,
             solved: MechanismModes, chains: list[Chain], active: dict[int, int],
             write: object) -> dict[int, int]:
    """Carry the modes of anchor i to anchor i + 1 (module docstring); the modes active at
    anchor i + 1 (its mode index → chain)."""
    fmt = write if callable(write) else str
    A, B = int(anchors[i]), int(anchors[i + 1])
    rows = np.arange(A + 1, B + 1)
    there = solved.configurations[i + 1]
    ends: dict[int, tuple[Configuration, NDArray[np.bool_], int | None]] = {}
    for refine in (1, REFINE):
        pending = [c for c in active.values() if c not in ends]
        for c in pending:
            ends[c] = _track(mech, lay, chains[c].conf_at(A), X[A], X[rows], refine)
        claims = _claims(mech, lay, ends, there)
        jumped = [c for c, j in claims.items() if j is None or
                  sum(1 for k in claims.values() if k == j) > 1]
        if not jumped:
            break
        for c in jumped:
            del ends[c]
    nxt: dict[int, int] = {}
    for c, (conf, mask, stop) in ends.items():
        chain = chains[c]
        if stop is not None:  # stops assembling inside the segment: it dies there
            reached = rows[mask]
            chain.put(reached, conf.take(np.flatnonzero(mask)))
            k = int(reached[-1]) if reached.size else A
            at, near = fold_between(mech, lay, chain.conf_at(k), X[k], X[k + 1])
            chain.folds.append((at, near))
            chain.events.append(f"dies at {fmt(at)}: it stops assembling there (a fold, located "
                                "between samples)")
            continue
        j = claims[c]
        chain.put(rows, conf)
        if j is not None:
            nxt[j] = c
            _met(chain, solved, i + 1, j)
    for c in jumped:  # still no unique match after refining: cut, never switch
        chains[c].events.append(
            f"cut after {fmt(X[A])}: tracked on to {fmt(X[B])} it does not land on exactly one "
            "of the modes the homotopy finds there (a path jump), so the mode is not continued "
            "past this anchor rather than switched")
    for j in range(there.size):
        if j not in nxt:
            nxt[j] = _born(mech, lay, X, A, B, there.take(slice(j, j + 1)), chains, fmt)
            _met(chains[nxt[j]], solved, i + 1, j)
    return nxt


def _claims(mech: Mechanism, lay: GraphLayout,
            ends: dict[int, tuple[Configuration, NDArray[np.bool_], int | None]],
            there: Configuration) -> dict[int, int | None]:
    """The anchor mode each mode tracked through the segment lands on (None: on none)."""
    out: dict[int, int | None] = {}
    for c, (conf, _, stop) in ends.items():
        if stop is not None:
            continue
        d = pose_distance(mech, lay, conf.take(slice(conf.size - 1, conf.size)), there)
        close = np.flatnonzero(d[0] <= MATCH_TOLERANCE)
        out[c] = int(close[0]) if close.size == 1 else None
    return out


def _born(mech: Mechanism, lay: GraphLayout, X: Array, A: int, B: int, conf: Configuration,
          chains: list[Chain], fmt: object) -> int:
    """A mode found at anchor B that no mode tracked from anchor A reaches: tracked back to
    where it is born (a fold, :func:`fold_between`), or to A where a path jump cut a mode there."""
    write = fmt if callable(fmt) else str
    c = _new_chain(chains, lay, X.shape[0])
    chain = chains[c]
    chain.put(np.array([B]), conf)
    back = np.arange(B - 1, A - 1, -1)
    got, mask, stop = _track(mech, lay, conf, X[B], X[back])
    # a track that reaches a known mode's configuration jumped onto it in the step before
    # (along_folds.py): it is not taken past there, and the step is searched for the fold
    mine = pose_vectors(mech, lay, got)
    hit = shared_at([pose_vectors(mech, lay, Configuration(o.scalars[back], o.spherical[back]))
                     for o in chains[:c]], [o.mask[back] for o in chains[:c]], mine, mask,
                    MATCH_TOLERANCE)
    if hit.any():
        mask[int(np.argmax(hit)):] = False
    chain.put(back[mask], got.take(np.flatnonzero(mask)))
    if stop is None and not hit.any():
        chain.events.append(f"starts at {write(X[A])}: tracked back from {write(X[B])} it does "
                            "not continue a mode of this anchor (a path jump was refused there)")
        return c
    k = int(back[mask][-1]) if mask.any() else B
    found = fold_in_step(mech, lay, chain.conf_at(k), X[k], X[k - 1])
    if found is None:  # (only where it met a known mode: a track that stops meets a fold)
        chain.events.append(f"starts at {write(X[k])}: tracked back from {write(X[B])} it is "
                            f"at a known mode's configuration at {write(X[k - 1])} with no fold "
                            "in that step, so it is not taken past there")
        return c
    at, near = found
    chain.folds.append((at, near))
    chain.events.append(f"is born at {write(at)}: it starts assembling there (a fold, located "
                        "between samples)")
    return c


def _certificate_event(chain: Chain) -> str:
    return (f"certified by Smale's α-test at {chain.anchors_certified} of the "
            f"{chain.anchors_met} anchor(s) where the homotopy finds it")


def _notes(solved: MechanismModes, anchors: NDArray[np.intp], count: int, runs: bool
           ) -> tuple[str, ...]:
    real = sum(c.size for c in solved.configurations)
    cert = sum(int(c.sum()) for c in solved.certified)
    found = (f"{int(solved.found.min())}" if solved.found.min() == solved.found.max()
             else f"{int(solved.found.min())}–{int(solved.found.max())}")
    notes = [f"every mode along the motion: the homotopy at {len(anchors)} anchor input(s) "
             f"(samples {', '.join(str(int(a)) for a in anchors[:6])}"
             f"{' …' if len(anchors) > 6 else ''}) finds {found} distinct complex solution(s) "
             f"per anchor, generic count {solved.generic_count} ({solved.how_found}); {real} "
             f"real mode(s) over the anchors, {cert} certified by Smale's α-test; {count} "
             "mode(s) tracked between anchors with jump checks " + (
                 "(and the homotopy at one sample of every run of samples between two fold "
                 "inputs that holds no anchor: an island between two anchors is found)" if runs
                 else "(an island between two anchors is found only where it meets a known "
                 "mode at a fold)")]
    if solved.rejected.any():
        notes.append(f"at {int(np.count_nonzero(solved.rejected))} anchor(s) "
                     f"{int(solved.rejected.sum())} real solution(s) of the polynomial system "
                     "failed the graph closure check (1e-10 of the length scale) and are not "
                     "modes: the formulation read the mechanism inaccurately there (e.g. two "
                     "axes nearly parallel), so a mode may be missing")
    if solved.continuum.any():
        notes.append(f"at {int(solved.continuum.sum())} anchor(s) the solutions include a "
                     "continuum (a curve of assemblies), whose points are not isolated modes")
    return tuple(notes)


def every_mode_motion(mech: Mechanism, lay: GraphLayout, dec: Decomposition, X: Array,
                      Xd: Array, Xdd: Array, drawn: MechanismMode, conf: Configuration
                      ) -> tuple[tuple[MechanismMode, ...], tuple[str, ...]]:
    """Every mode of a mechanism that does not decompose (graph/motion.py's
    ``solve_mechanism`` with ``every_mode``), where a polynomial formulation takes it: the
    drawn mode ``drawn`` (its configurations ``conf``) first, then the others, labelled "mode
    1 (…)", "mode 2 (…)" …, and the notes with the circuits; only the drawn mode (a note says
    why) where no formulation takes it."""
    from screwkit.budget import ResourceLimitError
    from screwkit.errors import CapabilityError
    from screwkit.kinematics.graph.closed_modes import ISLAND

    only = "every mode: only the drawn mode is found for this mechanism: "
    if misfits(mech):
        return (drawn,), (only + "its parts are made off the drawing (seat offsets), which "
                          "the polynomial formulations do not model",)
    try:
        along = modes_along(mech, lay, X, lambda x: input_text(mech, lay, x))
    except (CapabilityError, ResourceLimitError) as err:
        return (drawn,), (only + "; ".join([*dec.describe(mech)[-1:], str(err)]),)
    pd = pose_vectors(mech, lay, conf)
    mine, other = None, []
    for k, (c, m) in enumerate(zip(along.configurations, along.masks, strict=True)):
        both = np.flatnonzero(m & drawn.assembles)
        gap = np.abs(pose_vectors(mech, lay, c.take(both)) - pd[both]).max(axis=1) \
            if both.size else np.zeros(0)
        if mine is None and m[0] and drawn.assembles[0] and gap[0] <= MATCH_TOLERANCE:
            mine = k
            events = list(along.events[k])
            far = gap > MATCH_TOLERANCE
            if np.any(far):
                events.append(f"the drawn mode parts from the anchored tracking at "
                              f"{input_text(mech, lay, X[both[int(np.argmax(far))]])}"
                              ": a possible branch switch of the drawn mode's tracker")
            drawn = with_events(drawn, [*drawn.events, *events])
        elif m.any() or k in along.islands:
            other.append(k)
    modes = [replace(drawn, label="drawn")]
    index = {k: i for i, k in enumerate([mine, *other]) if k is not None}
    for k in other:
        md = build_mode(mech, lay, along.configurations[k], along.masks[k], X, Xd, Xdd)
        how = (f"(homotopy between two folds inside one sample step){ISLAND}"
               if k in along.islands else "(homotopy at anchors, tracked between)")
        modes.append(replace(with_events(md, [*along.events[k], *md.events]),
                             label=f"mode {len(modes)} {how}", index=len(modes)))
    joins = [(index[a], index[b]) for a, b in along.meets if a in index and b in index]
    notes = [*along.notes, "circuits (modes that meet at a fold, where the input must turn "
             "back to go on): " + ", ".join("{" + ", ".join(map(str, c)) + "}"
                                            for c in groups(len(modes), joins))]
    if mine is None:
        notes.append("the drawn mode is not among the modes the homotopy finds at the first "
                     "input: check the drawing closes")
    return tuple(modes), tuple(notes)
