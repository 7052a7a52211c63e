"""The generic loop solver: every assembly mode of any single loop over an input sweep.

Assembly modes are continuous branches (``../shared/DESIGN.md``), found by continuation
(:mod:`screwkit.kinematics.tracker.continuation`), not by a root search at every sample:

1. a global root search runs at the first sample and at a coarse stride of *anchor* samples
   (every :data:`ANCHOR_SPAN` rad of input, or that fraction of the length scale for a sliding
   input): where a polynomial formulation fits the loop, every real solution of one batched
   parameter homotopy over those samples (:mod:`screwkit.kinematics.tracker.algebraic_roots`,
   issue 27; the stretches next to an anchor with a complex root are searched again every
   :data:`DENSE_SPAN`, and a sample where the homotopy's count falls short is searched by random
   starts too), otherwise Newton from many random starts
   (:func:`~screwkit.kinematics.tracker.solve.find_assemblies`; half as many at the anchors,
   as a safety net) — :class:`RootEngine`;
2. every root not on a known branch seeds a new branch, which is followed forwards and
   backwards to where it ends (so a mode born after the first sample is found over all of its
   life, not from the anchor that found it);
3. where a branch ends between two samples (the corrector says it dies: a limit position or
   dead centre) the root search runs again at both samples, since a branch may be born where
   another dies, and Newton looks for the root the branch meets at the fold along the passive
   Jacobian's null direction (:func:`_seed_fold_partners`);
4. a continuum of closed configurations at one input (a motion left free with the input
   fixed) is one degenerate set, seeded once (:mod:`screwkit.kinematics.tracker.degenerate`), and
   branches that turn out to be the same (found from two anchors) are merged; where the
   homotopy finds a sample on a continuum (a curve of solutions at that input), no mode holds
   it (:func:`_off_continua`).

Rates, accelerations, link frames and singular samples then follow from the loop's rate
equations (:mod:`screwkit.kinematics.tracker.mode_frames`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.motion import (
    AssemblyError,
    ModeMotion,
    Motion,
    as_input_array,
    format_inputs,
    per_sample,
)
from screwkit.kinematics.tracker.algebraic_roots import (
    AlgebraicRoots,
    LoopFormulation,
    algebraic_roots,
    loop_formulation,
)
from screwkit.kinematics.tracker.branch_merge import (
    SAME_ROOT,
    attach_lone_ends,
    attach_turning_points,
    merge_duplicates,
    order_key,
    pair_ends,
    track_signatures,
    without_singular_shadows,
)
from screwkit.kinematics.tracker.continuation import Tracker
from screwkit.kinematics.tracker.degenerate import seeds_off_continua
from screwkit.kinematics.tracker.loop import (
    Array,
    Configuration,
    Layout,
    apply_increment,
    forward,
    layout,
)
from screwkit.kinematics.tracker.mode_frames import (
    build_progress,
    expect_modes,
    mode_from_configuration,
)
from screwkit.kinematics.tracker.rates import rate_equations
from screwkit.kinematics.tracker.solve import (
    Assemblies,
    assemblies_from,
    find_assemblies,
    set_inputs,
)
from screwkit.kinematics.tracker.tracks import Track
from screwkit.model.linkage import Linkage

#: input movement between two anchor samples of the safety-net root search (rad; × the length
#: scale for a sliding input)
ANCHOR_SPAN = np.radians(15.0)
#: input movement between two samples searched by the homotopy inside a stretch between anchors
#: where a pair of complex roots may turn real (:meth:`RootEngine.between`; rad, or × the
#: length scale): an island of modes at least this long is seen by a search
DENSE_SPAN = np.radians(1.0)
#: ... or wider, so that those searches track at most this many homotopy paths in all (a 6R
#: loop's 16 paths a sample: 2.8° over a whole turn)
DENSE_PATHS = 2048
#: a sweep at least this long shows a progress bar on a terminal (when no callback is given)
PROGRESS_SAMPLES = 50_000
#: ... or a solve estimated (solve_motion.motion_seconds) to take this long, seconds
PROGRESS_SECONDS = 1.0

Progress = Callable[[int, int], None]


def anchor_samples(linkage: Linkage, X: Array, every: float = ANCHOR_SPAN) -> NDArray[np.intp]:
    """The first and last samples and every sample where the inputs have moved another
    ``every`` (:data:`ANCHOR_SPAN`) since the previous anchor (measured along the sweep)."""
    N = X.shape[0]
    if N == 1:
        return np.array([0])
    span = _input_span(linkage, X)
    marks = np.searchsorted(span, np.arange(0.0, span[-1], every))
    return np.unique(np.concatenate([[0], marks, [N - 1]]).clip(0, N - 1))


def _input_span(linkage: Linkage, X: Array) -> Array:
    """How far the inputs have moved (N,) from the first sample, along the sweep: the largest
    input step each time (rad, or fraction of the length scale for a slide)."""
    L = linkage.length_scale
    scale = np.array([1.0 / L if n.endswith(".s") else 1.0 for n in linkage.inputs])
    steps = np.max(np.abs(np.diff(X, axis=0)) * scale, axis=1) if X.shape[0] > 1 else []
    return np.concatenate([[0.0], np.cumsum(steps)])


@contextmanager
def progress_reporter(progress: Progress | bool | None, N: int,
                      label: str = "following assembly modes",
                      seconds: float = 0.0) -> Iterator[Progress | None]:
    """The progress callback to use: the caller's, none, or a rich bar (``label``) on stderr
    for a sweep of :data:`PROGRESS_SAMPLES` samples or more, or estimated to take
    :data:`PROGRESS_SECONDS` or more (``seconds``), on a terminal."""
    if callable(progress):
        yield progress
        return
    long = N >= PROGRESS_SAMPLES or seconds >= PROGRESS_SECONDS
    if progress is False or (progress is None and (not long or not sys.stderr.isatty())):
        yield None
        return
    from rich.console import Console
    from rich.progress import Progress as Bar

    with Bar(console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(label, total=N)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        yield update


def generic_motion(
    linkage: Linkage,
    input_values: Array | list[float],
    input_rates: Array | list[float] | float = 1.0,
    input_accelerations: Array | list[float] | float = 0.0,
    starts: int = 48,
    seed: int = 0,
    progress: Progress | bool | None = None,
    homotopy: bool = True,
) -> Motion:
    """Positions, velocities and accelerations of every freedom and link over an input sweep,
    in every assembly mode (generic solver; works for any single loop; module docstring).
    ``homotopy=False`` searches roots by random starts alone, also where a polynomial
    formulation fits the loop (the solver before issue 27; for comparisons).

    ``starts`` random starts per root search and their ``seed``; ``progress`` a callback
    ``(samples done, samples to do)`` (the samples followed, then each mode's build counting
    every sample; ``done`` never decreases and ends equal to the total, which is revised as
    modes are found and merged), ``False`` for none, or ``None``: a progress bar on stderr
    for a sweep of 50 000 samples or more on a terminal."""
    lay = layout(linkage)
    X = as_input_array(linkage, input_values, "input values")
    N = X.shape[0]
    Xd = per_sample(linkage, input_rates, "input rates", X)
    Xdd = per_sample(linkage, input_accelerations, "input accelerations", X)
    with progress_reporter(progress, N) as report:
        reached = [0]

        def tracking(done: int, total: int) -> None:
            reached[0] = max(reached[0], done)
            if report is not None:
                report(done, total)

        engine = RootEngine(linkage, lay, starts, seed, algebraic=homotopy)
        tracks = all_branches(linkage, lay, X, starts, seed,
                               tracking if report is not None else None, engine=engine)
        if not tracks:
            raise closes_nowhere(linkage, X, engine.continuum_samples)

        def building(done: int, total: int) -> None:  # after the samples followed
            if report is not None:
                report(reached[0] + done, reached[0] + total)

        def build(tracks: list[Track], progress: Progress | None) -> list[ModeMotion]:
            with build_progress(progress, N):
                expect_modes(len(tracks))
                return [mode_from_configuration(linkage, lay, tr.configuration(),
                                                tr.mask.copy(), X, Xd, Xdd,
                                                _events(linkage, X, tr)) for tr in tracks]

        modes = build(tracks, building if report is not None else None)
        continua = engine.singular_continua(X, modes)
        if continua:  # rare: a sample on a continuum that no root search had looked at
            tracks = _off_continua(tracks, continua)
            if not tracks:
                raise closes_nowhere(linkage, X, engine.continuum_samples)
            modes = build(tracks, None)
    modes = [replace(md, index=k, label=f"branch {k}") for k, md in enumerate(modes)]
    return Motion(linkage, X, Xd, Xdd, tuple(modes), method="generic",
                  solver="generic loop solver: continuation along the input (second-order "
                         "predictor, Newton corrector) from root searches at the first sample, "
                         f"at anchors and where branches end, {engine.how()} "
                         "(docs/kinematics.md)", notes=engine.notes())


def closes_nowhere(linkage: Linkage, X: Array, continua: set[int] | None = None
                   ) -> AssemblyError:
    """The error of a sweep where the generic solver finds no closed configuration at all (or,
    with ``continua``, only continua of them: curves of closures at single inputs)."""
    if continua:
        at = sorted(continua)
        return AssemblyError(
            f"{linkage.name}: the loop closes only on continua of configurations (a curve of "
            f"closures with the input held, no assembly mode) at {len(at)} of the "
            f"{X.shape[0]} inputs, first at {format_inputs(linkage, X[at[0]])}; move the "
            "inputs off them, or check the dimensions")
    return AssemblyError(
        f"{linkage.name}: the loop does not close at any of the {X.shape[0]} inputs "
        f"(from {format_inputs(linkage, X[0])} to {format_inputs(linkage, X[-1])}); "
        "check the dimensions")


def _events(linkage: Linkage, X: Array, tr: Track) -> list[str]:
    """Where a branch starts and stops assembling, from its mask."""
    m = tr.mask
    events = []
    for k in np.nonzero(m[1:] & ~m[:-1])[0] + 1:
        events.append(f"starts assembling at input {format_inputs(linkage, X[k])} (limit "
                      f"position or dead centre after {format_inputs(linkage, X[k - 1])})")
    for k in np.nonzero(m[:-1] & ~m[1:])[0]:
        events.append(f"stops assembling after input {format_inputs(linkage, X[k])} (limit "
                      f"position or dead centre before {format_inputs(linkage, X[k + 1])})")
    return events


def _new_seeds(linkage: Linkage, lay: Layout, tracker: Tracker, samples: NDArray[np.intp],
               asm: Assemblies, first_only: bool = False,
               ) -> list[tuple[int, int, Configuration]]:
    """The roots of a root search at ``samples`` that are on no known branch, per row of the
    search (its index, its sample and the roots); of
    the roots on a continuum (a motion free with the input fixed) one, and none where a known
    branch is on a continuum already (:mod:`screwkit.kinematics.tracker.degenerate`)."""
    K = asm.found.shape[1]
    known = [(tr, tr.mask[samples]) for tr in tracker.tracks]
    known_sig = [track_signatures(linkage, lay, tr, samples[m]) if m.any() else None
                 for tr, m in known]
    out = []
    for r, s in enumerate(samples.tolist()):
        found = np.nonzero(asm.found[r])[0]
        if found.size == 0:
            continue
        sig, radius = asm.signature[r][found], asm.radius[r][found]
        new = np.ones(found.size, dtype=bool)
        here = []
        for (tr, m), ks in zip(known, known_sig, strict=True):
            if ks is not None and m[r]:
                own = ks[int(np.sum(m[:r]))]
                new &= np.max(np.abs(sig - own), axis=1) >= np.maximum(radius, SAME_ROOT)
                here.append(tr)
        if not new.any():
            continue
        conf = asm.conf.take(r * K + found[new])
        seen = Configuration(np.stack([tr.scalars[s] for tr in here]),
                             np.stack([tr.spherical[s] for tr in here])) if here \
            else conf.take(np.array([], dtype=int))
        keep = seeds_off_continua(linkage, lay, seen, conf)
        if keep.any():
            out.append((r, s, conf.take(np.nonzero(keep)[0])))
            if first_only:
                break
    return out


class RootEngine:
    """The root searches of one sweep: every real solution of the polynomial homotopy where a
    formulation fits the loop (:mod:`screwkit.kinematics.tracker.algebraic_roots`), Newton from
    random starts (:func:`root_search`) where none does; it keeps count of what it found for
    the Motion's solver string and notes."""

    def __init__(self, linkage: Linkage, lay: Layout, starts: int, seed: int,
                 algebraic: bool = True) -> None:
        self.linkage, self.lay, self.starts, self.seed = linkage, lay, starts, seed
        self.algebraic = algebraic
        self.formulation: LoopFormulation | None = (
            loop_formulation(linkage, lay, seed) if algebraic else None)
        self.rows = self.roots = self.uncertified = self.continua = self.fallback = 0
        self.generic_count = 0
        #: searched samples on a continuum of closed configurations (no mode there)
        self.continuum_samples: set[int] = set()
        self.searched: set[int] = set()
        #: searched samples with a root that is not real (a complex pair that may turn real)
        self.nonreal: set[int] = set()

    def search(self, X: Array, samples: NDArray[np.intp], seed: int
               ) -> tuple[NDArray[np.intp], Assemblies]:
        """Every root at ``samples`` (one batched solve): the sample of each row, the roots."""
        if self.formulation is None:
            return root_search(self.linkage, X, samples, self.starts, seed)
        found: AlgebraicRoots = algebraic_roots(self.formulation, self.linkage, self.lay,
                                                X[samples])
        self.rows += samples.size
        self.searched.update(samples.tolist())
        self.roots += int(found.assemblies.found.sum())
        self.uncertified += int(np.sum(found.assemblies.found & ~found.certified))
        self.continua += int(found.continuum.sum())
        self.continuum_samples.update(samples[found.continuum].tolist())
        self.nonreal.update(samples[found.found > found.assemblies.found.sum(axis=1)].tolist())
        self.generic_count = found.generic_count
        short = np.flatnonzero(~found.complete)
        if short.size == 0:
            return samples, found.assemblies
        # where the homotopy's count falls short (a non-generic mechanism), random starts too
        self.fallback += short.size
        rows, asm = root_search(self.linkage, X, samples[short], self.starts, seed)
        first = len(rows) - short.size  # sample 0's extra copies come first (root_search)
        B = samples.size
        extra = np.zeros((B, asm.found.shape[1]), dtype=bool)
        extra[short] = asm.found[first:]
        return samples, merged(found.assemblies, Assemblies(
            _rows_conf(asm, first, short, B, found.assemblies), extra,
            _rows_array(asm.signature, first, short, B),
            _rows_array(asm.radius, first, short, B, 1.0)))

    def between(self, X: Array, anchors: NDArray[np.intp]) -> NDArray[np.intp]:
        """The samples to search next: every :data:`DENSE_SPAN` of input (or wider, within
        :data:`DENSE_PATHS`) within each stretch
        between two anchors where either anchor has a root that is not real (a complex pair,
        which can turn real at a fold in between: an island of modes between anchors, which
        meets no known branch); none without a formulation, or where every root is real."""
        if self.formulation is None or not self.nonreal:
            return np.zeros(0, dtype=np.intp)
        flagged = np.isin(anchors, np.array(sorted(self.nonreal)))
        # the stretches' input movement, and a spacing that keeps their paths within budget
        span = _input_span(self.linkage, X)
        lo, hi = anchors[:-1], anchors[1:]
        near = flagged[:-1] | flagged[1:]
        moved = float(np.sum((span[hi] - span[lo])[near]))
        every = max(DENSE_SPAN, moved * max(self.generic_count, 1) / DENSE_PATHS)
        fine = anchor_samples(self.linkage, X, every)
        stretch = np.searchsorted(anchors, fine)  # fine sample in (anchors[k-1], anchors[k]]
        near2 = flagged[np.clip(stretch, 0, len(anchors) - 1)] | flagged[
            np.clip(stretch - 1, 0, len(anchors) - 1)]
        todo = fine[near2 & ~np.isin(fine, np.array(sorted(self.searched), dtype=np.intp))]
        return np.asarray(todo, dtype=np.intp)

    def singular_continua(self, X: Array, modes: list[ModeMotion]) -> set[int]:
        """The samples, singular on some mode and not searched yet, that the homotopy finds on
        a continuum of closed configurations (a branch followed through one: a 4R deltoid's
        crank on its frame between two anchors); none without a formulation."""
        if self.formulation is None:
            return set()
        singular = np.any([md.singular & md.assembles for md in modes], axis=0)
        todo = np.array(sorted(set(np.flatnonzero(singular).tolist()) - self.searched),
                        dtype=np.intp)
        if todo.size == 0:
            return set()
        before = set(self.continuum_samples)
        self.search(X, todo, self.seed)
        return self.continuum_samples - before

    def _why(self) -> str:
        return ("no polynomial formulation takes this loop" if self.algebraic
                else "the homotopy was not asked for")

    def how(self) -> str:
        """How the roots were searched, for the Motion's solver string."""
        if self.formulation is None:
            return f"by Newton from {self.starts} random starts ({self._why()})"
        return (f"by every real solution of the {self.formulation.name} polynomial homotopy "
                f"(generic count {self.generic_count})")

    def notes(self) -> tuple[str, ...]:
        """The Motion's notes on the root searches."""
        if self.formulation is None:
            return (f"root searches: Newton from random starts ({self._why()}), which cannot "
                    "promise every mode",)
        out = [f"root searches: {self.formulation.name} polynomial homotopy at {self.rows} "
               f"samples, {self.roots} real roots ({self.roots - self.uncertified} certified "
               "by Smale's alpha test), every one closing the loop to 1e-9"]
        if self.fallback:
            out.append(f"at {self.fallback} samples the homotopy's paths did not end at the "
                       f"generic count of distinct finite solutions (a non-generic mechanism): "
                       "Newton from random starts searched there too")
        if self.continua:
            out.append(f"{self.continua} searched samples lie on a continuum of closed "
                       "configurations (a curve of solutions): no mode is reported there")
        return tuple(out)


def _rows_array(a: Array, first: int, rows: NDArray[np.intp], B: int, fill: float = 0.0
                ) -> Array:
    """Rows ``first:`` of a search's per-row array placed at ``rows`` of B rows."""
    out = np.full((B,) + a.shape[1:], fill)
    out[rows] = a[first:]
    return out


def _rows_conf(asm: Assemblies, first: int, rows: NDArray[np.intp], B: int,
               filler: Assemblies) -> Configuration:
    """The configurations of rows ``first:`` of a search placed at ``rows`` of B rows (the
    other slots hold ``filler``'s first configuration, marked not found)."""
    K = asm.found.shape[1]
    n, m = filler.conf.scalars.shape[1], filler.conf.spherical.shape[1]
    q = np.repeat(filler.conf.scalars[:1], B * K, axis=0).reshape(B, K, n)
    s = np.repeat(filler.conf.spherical[:1], B * K, axis=0).reshape(B, K, m, 3, 3)
    q[rows] = asm.conf.scalars[first * K:].reshape(rows.size, K, n)
    s[rows] = asm.conf.spherical[first * K:].reshape(rows.size, K, m, 3, 3)
    return Configuration(q.reshape(B * K, n), s.reshape(B * K, m, 3, 3))


def merged(a: Assemblies, b: Assemblies) -> Assemblies:
    """Two searches of the same rows as one: each row's slots of ``a``, then of ``b``."""
    B, Ka, Kb = a.found.shape[0], a.found.shape[1], b.found.shape[1]

    def join(x: Array, y: Array) -> Array:
        tail = x.shape[1:]
        return np.concatenate([x.reshape((B, Ka) + tail), y.reshape((B, Kb) + tail)],
                              axis=1).reshape((B * (Ka + Kb),) + tail)

    return Assemblies(Configuration(join(a.conf.scalars, b.conf.scalars),
                                    join(a.conf.spherical, b.conf.spherical)),
                      np.concatenate([a.found, b.found], axis=1),
                      np.concatenate([a.signature, b.signature], axis=1),
                      np.concatenate([a.radius, b.radius], axis=1))


def root_search(linkage: Linkage, X: Array, samples: NDArray[np.intp], starts: int,
                 seed: int) -> tuple[NDArray[np.intp], Assemblies]:
    """Every root at ``samples`` by Newton from random starts, in one vectorised search:
    ``starts`` at the first sample of the sweep, half as many at the others (the safety net:
    there the known branches are found again by most starts, and a branch missed at one
    sample is found at the next). Returns the sample of each row of the search and the
    search."""
    half = max(starts // 2, 8)
    lead = int(samples[0] == 0) * max(starts // half - 1, 0)  # extra copies of sample 0
    rows = np.concatenate([np.zeros(lead, dtype=np.intp), samples])
    return rows, find_assemblies(linkage, X[rows], starts=half, seed=seed)


def _seed_from(linkage: Linkage, lay: Layout, tracker: Tracker, samples: NDArray[np.intp],
               X: Array, engine: RootEngine, seed: int) -> bool:
    """Root search at ``samples`` (vectorised over them; ``engine``'s); then, in the order of the samples,
    follow the roots on no known branch at the first sample that has some, and look again at
    the later samples — so a branch found at one sample is not seeded again at the next. True
    if any root was new."""
    if samples.size == 0:
        return False
    samples, asm = engine.search(X, samples, seed)
    return _seed_from_search(linkage, lay, tracker, samples, asm)


def _seed_from_search(linkage: Linkage, lay: Layout, tracker: Tracker,
                      samples: NDArray[np.intp], asm: Assemblies) -> bool:
    """Follow the roots of a search (row r at ``samples[r]``) that are on no known branch, in
    the order of the rows, looking again after each (:func:`_seed_from`)."""
    K = asm.found.shape[1]
    remaining = np.nonzero(asm.found.any(axis=1))[0]
    found_new = False
    while remaining.size:
        rows = (remaining[:, None] * K + np.arange(K)).ravel()
        sub = Assemblies(asm.conf.take(rows), asm.found[remaining], asm.signature[remaining],
                         asm.radius[remaining])
        seeds = _new_seeds(linkage, lay, tracker, samples[remaining], sub, first_only=True)
        if not seeds:
            break
        row, sample, conf = seeds[0]
        tracker.follow(tracker.add_seeds(sample, conf))
        found_new = True
        remaining = remaining[row + 1:]
    return found_new


def all_branches(linkage: Linkage, lay: Layout, X: Array, starts: int, seed: int,
                  report: Progress | None, rates: tuple[Array, Array] | None = None,
                  engine: RootEngine | None = None) -> list[Track]:
    """Every branch over the sweep (module docstring); with the inputs' ``rates`` and
    accelerations, each track also carries the rates the tracker found on the way
    (:class:`~screwkit.kinematics.tracker.continuation.TrackRates`). ``engine`` does the root
    searches (by default the homotopy where a formulation fits the loop: :class:`RootEngine`)."""
    N = X.shape[0]
    engine = engine or RootEngine(linkage, lay, starts, seed)
    done = [0]

    def count(n: int) -> None:
        done[0] += n
        if report is not None:
            report(done[0], N * max(1, len(tracker.tracks)))

    tracker = Tracker(linkage, lay, X, count if report is not None else None, rates)
    anchors = anchor_samples(linkage, X)
    _seed_from(linkage, lay, tracker, anchors, X, engine, seed)
    _seed_from(linkage, lay, tracker, engine.between(X, anchors), X, engine, seed)
    searched: set[int] = set()
    partnered: set[tuple[int, int]] = set()
    for round_ in range(4):  # births where branches die; rarely more than one round
        ends: set[int] = set()
        for tr in tracker.tracks:
            for k, _ in tr.stops:
                ends.update((k, k + 1))
            for k, _ in tr.starts:
                ends.update((k - 1, k))
        todo = np.array(sorted(s for s in ends - searched if 0 <= s < N), dtype=np.intp)
        searched |= set(todo.tolist())
        found = _seed_from(linkage, lay, tracker, todo, X, engine, seed + 1 + round_)
        if not (_seed_fold_partners(linkage, lay, tracker, X, partnered) or found):
            break
    tracks = attach_turning_points(linkage, lay, merge_duplicates(linkage, lay, tracker.tracks))
    tracks = without_singular_shadows(linkage, lay, tracks)
    tracks = _off_continua(tracks, engine.continuum_samples)
    tracks = attach_lone_ends(linkage, lay, tracks)
    pair_ends(linkage, lay, tracks)
    return sorted(tracks, key=lambda tr: order_key(linkage, lay, tr))


def _off_continua(tracks: list[Track], samples: set[int]) -> list[Track]:
    """The tracks without the ``samples`` the homotopy found on a continuum of closed
    configurations (a curve of solutions at one input, as a 4R deltoid with its crank on the
    frame): there a branch followed by continuation passes through one point of the curve,
    which is no mode (the closed forms report none there either); tracks left empty go."""
    if not samples:
        return tracks
    idx = np.array(sorted(samples), dtype=np.intp)
    for tr in tracks:
        tr.mask[idx] = False
    return [tr for tr in tracks if tr.mask.any()]


#: steps (scaled freedoms) along the passive Jacobian's null direction from a branch's last
#: sample before a fold, where Newton looks for the root it meets there
PARTNER_STEPS = (1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0)


def _seed_fold_partners(linkage: Linkage, lay: Layout, tracker: Tracker, X: Array,
                        done: set[tuple[int, int]]) -> bool:
    """Where a branch ends between two samples (a fold: it turns back in the input), the root it
    meets there lies next to its last sample, along the passive Jacobian's null direction:
    Newton from steps ±PARTNER_STEPS along it at that sample looks for it, and a root on no
    known branch seeds one. (Random starts can miss a root whose basin is small — an island of
    two modes that lives over a short stretch of input.) ``done`` holds the (track, sample)
    ends already looked at; True if any root was new."""
    ends = [(i, k) for i, tr in enumerate(tracker.tracks)
            for k in [k for k, _ in tr.stops] + [k for k, _ in tr.starts]
            if (i, k) not in done and tr.mask[k]]
    done.update(ends)
    if not ends:
        return False
    samples = np.array([k for _, k in ends], dtype=np.intp)
    base = Configuration(np.stack([tracker.tracks[i].scalars[k] for i, k in ends]),
                         np.stack([tracker.tracks[i].spherical[k] for i, k in ends]))
    eq = rate_equations(linkage, lay, forward(linkage, base, lay))
    k_rows, m_p = eq.passive.shape[1:]
    if m_p == 0 or m_p > k_rows:
        return False
    null = np.linalg.svd(eq.passive)[2][:, -1, :]  # (B, m_p) scaled passive freedoms
    steps = np.array([s * d for s in PARTNER_STEPS for d in (1.0, -1.0)])
    per = len(steps)
    delta = np.zeros((len(ends) * per, len(lay.names)))
    delta[:, eq.p_idx] = (np.repeat(null, per, axis=0) * np.tile(steps, len(ends))[:, None]
                          * eq.cols[eq.p_idx])
    starts = set_inputs(apply_increment(base.take(np.repeat(np.arange(len(ends)), per)), delta,
                                        lay), lay, linkage.inputs, np.repeat(X[samples], per,
                                                                             axis=0))
    order = np.argsort(samples, kind="stable")
    asm = assemblies_from(linkage, starts.take(
        (order[:, None] * per + np.arange(per)).ravel()), per)
    return _seed_from_search(linkage, lay, tracker, samples[order], asm)


__all__ = ["ANCHOR_SPAN", "RootEngine", "all_branches", "closes_nowhere", "anchor_samples", "generic_motion", "progress_reporter"]
