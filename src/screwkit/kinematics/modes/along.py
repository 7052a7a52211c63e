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
the fold is located by bisection of that step (:func:`fold_between`, as graph/closed_modes.py
does for dyads). A tracked mode that stops assembling dies there, located the same way.
Then the homotopy is solved again at the samples on both sides of every birth and death: a
mode there that no known mode holds (an island between two anchors that meets a known mode at
a fold) is tracked both ways to its own birth and death (:func:`_islands`).

Guaranteed: every isolated real mode at every anchor (the homotopy's promise), continuity in
between (the tracker's checks), no silent switch at an anchor. Not guaranteed: an island
between two anchors that meets no known mode's fold next to a sample is not seen.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout, graph_forward
from screwkit.kinematics.graph.follow import SMALLEST_STEP, follow_drawn_mode, reach
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
from screwkit.kinematics.modes.every_mode import MechanismModes, every_mode
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: a tracked configuration is an anchor's mode when every body pose agrees to this (rotation
#: entries, and positions relative to the length scale)
MATCH_TOLERANCE = 1e-6
#: sub-steps per sample when a segment is tracked again after a suspected path jump
REFINE = 8
#: bisection steps locating a birth or death between two samples (2⁻²⁶ of the step)
FOLD_STEPS = 26
#: a bisection step's continuation may split it down to this fraction of its length
FOLD_SPLIT = 8
#: ... once the half is this short (rad, or fraction of the length scale): a half wrongly
#: refused then moves the fold by less than its length
FINE_HALF = 1e-4
#: two folds are one where their inputs agree to this (rad, or fraction of the length scale)
SAME_FOLD = 1e-6
#: ... and the two modes' body poses next to it to this
FOLD_POSES = 1e-2
#: anchors are at most this many samples apart
ANCHOR_SPACING = 8
#: measured homotopy time per anchor and generic solution (rounded up; ~0.1 s per 6R instance)
SECONDS_PER_ANCHOR_ROOT = 5e-3


@dataclass
class _Chain:
    """One mode over the samples: joint variables, where it holds, its events, and at how
    many anchors it was met and certified."""

    scalars: Array
    spherical: Array
    mask: NDArray[np.bool_]
    events: list[str] = field(default_factory=list)
    anchors_met: int = 0
    anchors_certified: int = 0
    #: where it is born or dies: the input there and the configuration next to it
    folds: list[tuple[Array, Configuration]] = field(default_factory=list)

    def conf_at(self, k: int) -> Configuration:
        return Configuration(self.scalars[k:k + 1].copy(), self.spherical[k:k + 1].copy())

    def put(self, idx: NDArray[np.intp], conf: Configuration) -> None:
        self.scalars[idx] = conf.scalars
        self.spherical[idx] = conf.spherical
        self.mask[idx] = True


@dataclass(frozen=True)
class ModesAlong:
    """Every mode found along the inputs: ``configurations[k]`` (N samples) where
    ``masks[k]`` holds, with ``events[k]``; ``anchors`` the anchor samples; ``notes`` what was
    found and how; ``meets`` the pairs of modes that meet at a fold (:func:`fold_meetings`)."""

    configurations: tuple[Configuration, ...]
    masks: tuple[NDArray[np.bool_], ...]
    events: tuple[tuple[str, ...], ...]
    anchors: NDArray[np.intp]
    notes: tuple[str, ...]
    solved: MechanismModes
    meets: tuple[tuple[int, int], ...] = ()


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


def pose_vectors(mech: Mechanism, lay: GraphLayout, conf: Configuration) -> Array:
    """Every body's pose as one row per sample (rotation entries, positions / length). A rod
    held by two balls (graph/idle.py) has an idle spin about its own line, which the tracker's
    corrector and a formulation's decoding set differently: its rotation R is written as
    (R u) uᵀ (u its drawn unit line) and its position as its first ball's centre, which that
    spin does not change."""
    from screwkit.kinematics.graph.idle import rods

    if conf.size == 0:  # (every_mode's empty rows have no columns either)
        return np.zeros((0, 12 * (len(mech.bodies) + 1)))
    fr = graph_forward(mech, lay, conf)
    n = conf.size
    R, p = fr.R, fr.p
    idle = rods(mech)
    if idle:
        R, p = R.copy(), p.copy()
        for body, j1, j2 in idle:
            c = mech.joints[j1].at
            u = mech.joints[j2].at - c
            u = u / np.linalg.norm(u)
            b = lay.body_of[body]
            p[:, b] = p[:, b] + R[:, b] @ c  # the first ball's centre, on the spin's line
            R[:, b] = np.einsum("ni,j->nij", R[:, b] @ u, u)
    return np.concatenate([R.reshape(n, -1), p.reshape(n, -1) / lay.length], axis=1)


def pose_distance(mech: Mechanism, lay: GraphLayout, a: Configuration, b: Configuration
                  ) -> Array:
    """(n_a, n_b) largest pose difference between configurations ``a`` and ``b``."""
    if a.size == 0 or b.size == 0:
        return np.zeros((a.size, b.size))
    pa, pb = pose_vectors(mech, lay, a), pose_vectors(mech, lay, b)
    return np.asarray(np.abs(pa[:, None, :] - pb[None, :, :]).max(axis=2))


def fold_between(mech: Mechanism, lay: GraphLayout, conf: Configuration, x_from: Array,
                 x_to: Array) -> tuple[Array, Configuration]:
    """Where the branch through ``conf`` (closed at ``x_from``) stops assembling on the way
    to ``x_to`` (which it does not reach): bisection of the segment, :data:`FOLD_STEPS`
    halvings, each half reached by continuation (graph/follow.py ``reach``, in steps down to
    the tracker's smallest while a half is longer than :data:`FINE_HALF`, then to
    1/:data:`FOLD_SPLIT` of the half); the input there and the last configuration reached."""
    lo, hi = np.asarray(x_from, dtype=float), np.asarray(x_to, dtype=float)
    scale = np.where(np.array([lay.is_translation[f] for f in lay.inputs]), lay.length, 1.0)
    for _ in range(FOLD_STEPS):
        mid = 0.5 * (lo + hi)
        h = float(np.max(np.abs(mid - lo) / scale))
        # a half that ends just short of the fold needs steps as short as its distance to
        # it: down to the tracker's smallest while the half is long, 1/FOLD_SPLIT of it after
        got = reach(mech, lay, conf, lo, mid, SMALLEST_STEP if h > FINE_HALF
                    else max(h / FOLD_SPLIT, 1e-12))
        if got is None:
            hi = mid
        else:
            lo, conf = mid, got
    return np.asarray(0.5 * (lo + hi)), conf


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
    solved = every_mode(mech, X[anchors])
    chains: list[_Chain] = []
    active: dict[int, int] = {}  # mode index at the current anchor → chain
    first = solved.configurations[0]
    for m in range(first.size):
        active[m] = _new_chain(chains, lay, N)
        chains[active[m]].put(np.array([anchors[0]]), first.take(slice(m, m + 1)))
        _met(chains[active[m]], solved, 0, m)
    for i in range(len(anchors) - 1):
        active = _segment(mech, lay, X, anchors, i, solved, chains, active, write)
    before = len(chains)
    extra = _islands(mech, lay, X, anchors, chains, write)
    notes = _notes(solved, anchors, len(chains))
    if extra:
        notes += (f"the homotopy also at the {extra} sample(s) next to a birth or death: "
                  f"{len(chains) - before} mode(s) found there that reach no anchor (islands)",)
    return ModesAlong(tuple(Configuration(c.scalars, c.spherical) for c in chains),
                      tuple(c.mask for c in chains),
                      tuple(tuple(c.events) + (_certificate_event(c),) for c in chains),
                      anchors, notes, solved,
                      fold_meetings(mech, lay, [c.folds for c in chains]))


def fold_meetings(mech: Mechanism, lay: GraphLayout,
                  folds: list[list[tuple[Array, Configuration]]]) -> tuple[tuple[int, int], ...]:
    """The pairs of modes (indices into ``folds``) that meet at a fold: born or dying at the
    same input (to :data:`SAME_FOLD` of a radian, or of the length scale) with body poses
    there within :data:`FOLD_POSES` (at 2⁻²⁶ of a step from a fold, where two branches differ
    by about the square root of that distance)."""
    scale = np.where(np.array([lay.is_translation[f] for f in lay.inputs]), lay.length, 1.0)
    flat = [(k, x, pose_vectors(mech, lay, c)[0]) for k, fs in enumerate(folds) for x, c in fs]
    out = set()
    for i, (a, xa, pa) in enumerate(flat):
        for b, xb, pb in flat[i + 1:]:
            if a != b and float(np.max(np.abs(xa - xb) / scale)) <= SAME_FOLD and \
                    float(np.max(np.abs(pa - pb))) <= FOLD_POSES:
                out.add((min(a, b), max(a, b)))
    return tuple(sorted(out))


def _islands(mech: Mechanism, lay: GraphLayout, X: Array, anchors: NDArray[np.intp],
             chains: list[_Chain], fmt: object) -> int:
    """Modes that reach no anchor but meet a known mode at a fold (an island between two
    anchors): the homotopy solved again at the samples on both sides of every birth and
    death, each mode there on no known mode tracked both ways (:func:`_island`). The count of
    samples solved."""
    near: set[int] = set()
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
            _island(mech, lay, X, n, conf, anchors, chains, fmt,
                    bool(solved.certified[r][j]))
    return int(rows.size)


def _island(mech: Mechanism, lay: GraphLayout, X: Array, n: int, conf: Configuration,
            anchors: NDArray[np.intp], chains: list[_Chain], fmt: object, certified: bool
            ) -> None:
    """A mode found at sample ``n`` between anchors, tracked to where it is born and where it
    dies (both located by bisection); dropped where it reaches an anchor (there it is a mode
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
                        "by bisection between samples)")
    k = int(fwd[mf][-1]) if mf.any() else n
    at, near = fold_between(mech, lay, chain.conf_at(k), X[k], X[k + 1])
    chain.folds.append((at, near))
    chain.events.append(f"dies at {write(at)}: it stops assembling there (a fold, located by "
                        f"bisection between samples); found by the homotopy at {write(X[n])}, "
                        "next to another mode's fold, between two anchors")


def _new_chain(chains: list[_Chain], lay: GraphLayout, N: int) -> int:
    chains.append(_Chain(np.zeros((N, lay.n_scalar)),
                         np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy(),
                         np.zeros(N, dtype=bool)))
    return len(chains) - 1


def _met(chain: _Chain, solved: MechanismModes, i: int, m: int) -> None:
    chain.anchors_met += 1
    chain.anchors_certified += int(bool(solved.certified[i][m]))


def _segment(mech: Mechanism, lay: GraphLayout, X: Array, anchors: NDArray[np.intp], i: int,
             solved: MechanismModes, chains: list[_Chain], active: dict[int, int],
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
                                "by bisection between samples)")
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
          chains: list[_Chain], fmt: object) -> int:
    """A mode found at anchor B that no mode tracked from anchor A reaches: tracked back to
    where it is born (a fold, by bisection), or to A where a path jump cut a mode there."""
    write = fmt if callable(fmt) else str
    c = _new_chain(chains, lay, X.shape[0])
    chain = chains[c]
    chain.put(np.array([B]), conf)
    back = np.arange(B - 1, A - 1, -1)
    got, mask, stop = _track(mech, lay, conf, X[B], X[back])
    chain.put(back[mask], got.take(np.flatnonzero(mask)))
    if stop is None:
        chain.events.append(f"starts at {write(X[A])}: tracked back from {write(X[B])} it does "
                            "not continue a mode of this anchor (a path jump was refused there)")
        return c
    k = int(back[mask][-1]) if mask.any() else B
    at, near = fold_between(mech, lay, chain.conf_at(k), X[k], X[k - 1])
    chain.folds.append((at, near))
    chain.events.append(f"is born at {write(at)}: it starts assembling there (a fold, located "
                        "by bisection between samples)")
    return c


def _certificate_event(chain: _Chain) -> str:
    return (f"certified by Smale's α-test at {chain.anchors_certified} of the "
            f"{chain.anchors_met} anchor(s) where the homotopy finds it")


def _notes(solved: MechanismModes, anchors: NDArray[np.intp], count: int) -> tuple[str, ...]:
    real = sum(c.size for c in solved.configurations)
    cert = sum(int(c.sum()) for c in solved.certified)
    found = (f"{int(solved.found.min())}" if solved.found.min() == solved.found.max()
             else f"{int(solved.found.min())}–{int(solved.found.max())}")
    notes = [f"every mode along the motion: the homotopy at {len(anchors)} anchor input(s) "
             f"(samples {', '.join(str(int(a)) for a in anchors[:6])}"
             f"{' …' if len(anchors) > 6 else ''}) finds {found} distinct complex solution(s) "
             f"per anchor, generic count {solved.generic_count} ({solved.how_found}); {real} "
             f"real mode(s) over the anchors, {cert} certified by Smale's α-test; {count} "
             "mode(s) tracked between anchors with jump checks (an island between two anchors "
             "is found only where it meets a known mode at a fold)"]
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
        elif m.any():
            other.append(k)
    modes = [replace(drawn, label="drawn")]
    index = {k: i for i, k in enumerate([mine, *other]) if k is not None}
    for k in other:
        md = build_mode(mech, lay, along.configurations[k], along.masks[k], X, Xd, Xdd)
        modes.append(replace(with_events(md, [*along.events[k], *md.events]),
                             label=f"mode {len(modes)} (homotopy at anchors, tracked between)",
                             index=len(modes)))
    joins = [(index[a], index[b]) for a, b in along.meets if a in index and b in index]
    notes = [*along.notes, "circuits (modes that meet at a fold, where the input must turn "
             "back to go on): " + ", ".join("{" + ", ".join(map(str, c)) + "}"
                                            for c in groups(len(modes), joins))]
    if mine is None:
        notes.append("the drawn mode is not among the modes the homotopy finds at the first "
                     "input: check the drawing closes")
    return tuple(modes), tuple(notes)
