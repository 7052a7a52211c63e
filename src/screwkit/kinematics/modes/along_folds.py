"""Folds and path jumps along the motion (issue 27, "a motion never switches mode silently"):
the pose comparison, the fold search between two samples and the shared-configuration check
of kinematics/modes/along.py.

A continuation step that spans a fold (the branch stops assembling inside the step while another
branch holds at the step's end, e.g. a gap or an island inside one sample step) can converge onto
that other branch: graph/follow.py's contraction and step-halving tests see only the step's ends.
Such a jump is caught where it lands on a mode already known: two modes at one configuration at a
sample (every body pose equal to along.py's MATCH_TOLERANCE) are one mode counted twice, so one
of them jumped. :func:`unshare` finds which: the one whose step into the shared samples, from its
own configuration next to them, meets a fold (:func:`fold_in_step`, the bracket search of
:func:`fold_between`, as graph/closed_modes.py locates a dyad's fold between samples). It is cut
at that fold (it dies, or is born, there: an event says so, and the fold is kept for
:func:`fold_meetings`). Where neither step meets a fold the later-found mode is cut at the
shared samples, with an event saying that one of the two jumped and which could not be told.
A jump onto a mode no other track holds is caught where it leaves a fold with no partner (two
real roots merge at a fold, so two modes meet there): :func:`partner_folds` bisects the steps of
the modes that cross that fold's step and splits the one that meets a fold. Not caught: a jump
onto a mode no track finds whose fold partner no track finds either (the anchors' matching,
along.py, catches a jump only at an anchor then).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout, graph_forward
from screwkit.kinematics.graph.follow import SMALLEST_STEP, graph_system, reach
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

_PIECE = ("a piece of a track that went on past samples where it was at another mode's "
          "configuration: its ends are where that track was cut or ended")

#: a birth or death between two samples is located to 2⁻²⁶ of the step (the halvings of a
#: bisection)
FOLD_STEPS = 26
#: the fold search probes this fraction of the distance to σ²'s extrapolated zero short of and
#: beyond it (:func:`fold_between`)
FOLD_PROBE = 0.05
#: ... for this many pairs at most, then bisects
FOLD_ROUNDS = 8
#: until a trial fails, the trials head for the step's end, each gap to it the square of the
#: last (:func:`fold_between`); False: halvings of the bracket, as bisection (a benchmark's
#: side-by-side)
HEAD_FOR_END = True
#: a bisection step's continuation may split it down to this fraction of its length
FOLD_SPLIT = 8
#: ... once the half is this short (rad, or fraction of the length scale): a half wrongly
#: refused then moves the fold by less than its length
FINE_HALF = 1e-4
#: two folds are one where their inputs agree to this (rad, or fraction of the length scale)
SAME_FOLD = 1e-6
#: ... and the two modes' body poses next to it to this
FOLD_POSES = 1e-2

@dataclass
class Chain:
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



def pose_vectors(mech: Mechanism, lay: GraphLayout, conf: Configuration) -> Array:
    """Every body's pose as one row per sample (rotation entries, positions / length). A body
    that can spin idly about its own line (a rod held by two balls, a strut held by a C joint
    and a ball on its axis: graph/idle.py ``spin_lines``) has that spin set differently by the
    tracker's corrector and by a formulation's decoding: its rotation R is written as
    (R u) uᵀ (u its drawn unit line) and its position as a point of the line, which that spin
    does not change."""
    from screwkit.kinematics.graph.idle import spin_lines

    if conf.size == 0:  # (every_mode's empty rows have no columns either)
        return np.zeros((0, 12 * (len(mech.bodies) + 1)))
    fr = graph_forward(mech, lay, conf)
    n = conf.size
    R, p = fr.R, fr.p
    idle = spin_lines(mech)
    if idle:
        R, p = R.copy(), p.copy()
        for body, c, u in idle:
            b = lay.body_of[body]
            p[:, b] = p[:, b] + R[:, b] @ c  # a point of the spin's line
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
    to ``x_to`` (which it does not reach): a bracket [lo, hi] of the segment (lo reached, hi
    not) shrunk to 2⁻:data:`FOLD_STEPS` of it, each trial point reached by continuation from
    lo (graph/follow.py ``reach``, in steps down to the tracker's smallest while the way is
    longer than :data:`FINE_HALF`, then to 1/:data:`FOLD_SPLIT` of it); the input at the
    bracket's middle and the configuration at lo.

    The trial points: towards the step's end until one fails, each trial's gap to the end the
    square of the last one's (1/2, 1/4, 1/16, 2⁻⁸, 2⁻¹⁶, then 2⁻:data:`FOLD_STEPS`: a step
    with no fold is crossed in 6 reaches, not bisection's 26, each reach at most twice as
    long as bisection's at the same point; no σ² wanted there), then where σ² (σ_r/σ₁ of the
    passive Jacobian, squared, which falls to 0 linearly in the input at a quadratic fold)
    extrapolates to 0 from the last three points reached (a parabola through them; a line through two), probed short of it and beyond it,
    each by :data:`FOLD_PROBE` of its distance from lo or by twice the guess's move since
    the last pair, whichever is more (Keller's fold is a regular zero of σ² along the branch:
    Allgower & Georg 1990, *Numerical Continuation Methods*, §9); a halving of the bracket
    where that zero is not inside it, and for good after :data:`FOLD_ROUNDS` pairs or after
    two pairs in a row that did not put the fold between them (a stop that is not a
    quadratic fold: σ² does not fall to 0 there). Each probe is at least a quarter of the
    final width from the guess. Every trial keeps
    the bracket, so it ends as narrow as bisection's; on the gapped six-bar of
    tests/graphs/test_step_folds.py it takes 16–17 reaches against bisection's 26
    (tests/graphs/test_fold_search.py). A trial within ~1e-7 of the fold can fail short of
    it (the corrector next to it); then the fold moves by less than that, as with bisection's
    last halves."""
    x0 = np.asarray(x_from, dtype=float)
    dx = np.asarray(x_to, dtype=float) - x0
    length = float(np.max(np.abs(dx) / input_scale(lay)))
    system = graph_system(mech, lay)
    lo, hi, goal = 0.0, 1.0, 2.0 ** -FOLD_STEPS
    seen: list[tuple[float, float]] = []  # (t, σ²) reached, once a trial has failed

    def trial(t: float) -> None:
        nonlocal lo, hi, conf
        h = (t - lo) * length
        # a way that ends just short of the fold needs steps as short as its distance to it:
        # down to the tracker's smallest while it is long, 1/FOLD_SPLIT of it after
        got = reach(mech, lay, conf, x0 + lo * dx, x0 + t * dx,
                    SMALLEST_STEP if h > FINE_HALF else max(h / FOLD_SPLIT, 1e-12))
        if got is None:
            if not seen:  # a fold (or a stop) in the step: σ² from here on
                seen.append((lo, float(system.sigma(conf)[0]) ** 2))
            hi = t
        else:
            lo, conf = t, got
            if seen:
                seen.append((t, float(system.sigma(got)[0]) ** 2))

    last = None
    rounds = misses = 0
    while hi - lo > goal:
        if not seen and HEAD_FOR_END:  # no trial failed yet (hi is the step's end): the gap
            # to the end squared
            gap = hi - lo
            trial(hi - max(min(0.5 * gap, gap * gap), goal))
            continue
        guess = _sigma_zero(seen) if rounds < FOLD_ROUNDS and misses < 2 else None
        if guess is None or not lo < guess < hi:
            trial(0.5 * (lo + hi))
            continue
        rounds += 1
        before = (lo, hi)
        # the probes as far from the guess as it moved since the last one (its error, for a
        # guess converging faster than linearly), at least FOLD_PROBE of its distance
        d = max(FOLD_PROBE * (guess - lo), 0.25 * goal,
                0.0 if last is None else 2.0 * abs(guess - last))
        last = guess
        short, far = guess - d, guess + d
        if lo < short:
            trial(short)
        if lo < far < hi and hi - lo > goal:  # (not where the short probe failed)
            trial(far)
        # a pair that did not put the fold between its probes (both reached, or the short
        # one not): two in a row and σ² is no guide here (the fold is not quadratic)
        bracketed = lo >= short and hi == far and before != (lo, hi)
        misses = 0 if bracketed else misses + 1
    return np.asarray(x0 + 0.5 * (lo + hi) * dx), conf


def _sigma_zero(seen: list[tuple[float, float]]) -> float | None:
    """Where σ² through the last three (t, σ²) reached (a parabola; the last two: a line)
    first meets 0 ahead of them (None where σ² does not fall towards 0 there)."""
    pts = seen[-3:]
    t, s = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    if len(pts) < 2 or not (np.isfinite(s).all() and np.all(np.diff(t) > 0)
                            and s[-2] > s[-1] > 0.0):
        return None
    line = t[-1] + s[-1] * (t[-1] - t[-2]) / (s[-2] - s[-1])
    if len(pts) < 3:
        return float(line)
    u = t - t[-1]  # Newton's divided differences at u = 0, u₂, u₁
    d32 = (s[1] - s[2]) / u[1]
    d321 = ((s[0] - s[1]) / (u[0] - u[1]) - d32) / u[0]
    roots = np.roots([d321, d32 - d321 * u[1], s[2]])  # σ² ≈ s₃ + d32 u + d321 u (u − u₂)
    # a double zero (σ linear in t) comes out as a pair with a small imaginary part
    ahead = [float(r.real) for r in roots if abs(r.imag) <= 1e-6 * abs(r) and r.real > 0]
    return t[-1] + min(ahead) if ahead else float(line)


def input_scale(lay: GraphLayout) -> Array:
    """Per input: 1 for an angle, the length scale for a slide."""
    return np.where(np.array([lay.is_translation[f] for f in lay.inputs]), lay.length, 1.0)


def fold_in_step(mech: Mechanism, lay: GraphLayout, conf: Configuration, x_from: Array,
                 x_to: Array) -> tuple[Array, Configuration] | None:
    """Where the branch through ``conf`` (closed at ``x_from``) stops assembling on the
    straight way to ``x_to``: :func:`fold_between`'s input and configuration, or None where
    its search reaches ``x_to`` (to 2¹⁻:data:`FOLD_STEPS` of the step: a fold closer to the
    step's end than that is not told from none; with no trial failing, the search heads for
    the step's end in 6 reaches). (The whole step is not tried first: a continuation over a long step can land
    across a fold on another branch, where the bisection's halves stop at the fold.)"""
    at, near = fold_between(mech, lay, conf, x_from, x_to)
    scale = input_scale(lay)
    step = float(np.max(np.abs(np.asarray(x_to) - x_from) / scale))
    if float(np.max(np.abs(at - x_to) / scale)) <= 2.0 ** (1 - FOLD_STEPS) * step:
        return None
    return at, near


def shared_at(poses: list[Array], masks: list[NDArray[np.bool_]], mine: Array,
              held: NDArray[np.bool_], tol: float) -> NDArray[np.bool_]:
    """Where (N,) a mode whose body poses are ``mine`` (N, P), holding at ``held``, is at the
    configuration of one of the modes ``poses``/``masks`` (to ``tol``)."""
    out = np.zeros(held.size, dtype=bool)
    for p, m in zip(poses, masks, strict=True):
        both = held & m
        if both.any():
            out[both] |= np.abs(p[both] - mine[both]).max(axis=1) <= tol
    return out


def unshare(mech: Mechanism, lay: GraphLayout, X: Array, chains: list[Chain], tol: float,
            write: Callable[[Array], str]) -> int:
    """Cut every run of samples where two modes share a configuration from the one that jumped
    onto it (module docstring); the count of runs cut."""
    poses = [pose_vectors(mech, lay, Configuration(c.scalars, c.spherical)) for c in chains]
    cuts = 0
    a = 0
    while a < len(chains):
        b = a + 1
        while b < len(chains):
            same = shared_at([poses[a]], [chains[a].mask], poses[b], chains[b].mask, tol)
            if not same.any():
                b += 1
                continue
            n0 = int(np.argmax(same))
            n1 = n0 + (int(np.argmin(same[n0:])) if not same[n0:].all() else same.size - n0) - 1
            _cut(mech, lay, X, chains, poses, (a, b), (n0, n1), write)
            cuts += 1
        a += 1
    return cuts


def _cut(mech: Mechanism, lay: GraphLayout, X: Array, chains: list[Chain],
         poses: list[Array], pair: tuple[int, int], run: tuple[int, int],
         write: Callable[[Array], str]) -> None:
    """Cut the shared samples ``run`` (first, last) from the mode of ``pair`` that jumped."""
    n0, n1 = run
    N = X.shape[0]
    for x in pair:
        for m, edge in ((n0 - 1, n0), (n1 + 1, n1)):
            if 0 <= m < N and chains[x].mask[m]:
                got = fold_in_step(mech, lay, chains[x].conf_at(m), X[m], X[edge])
                if got is not None:
                    if _drop(X, chains, x, run, m > n1, _PIECE):
                        poses.append(poses[x])
                    chain = chains[x]
                    chain.folds.append(got)
                    what = "is born" if m > n1 else "dies"
                    verb = "starts" if m > n1 else "stops"
                    chain.events.append(
                        f"{what} at {write(got[0])}: it {verb} assembling there (a fold, located "
                        f"between samples; tracked on across it, it landed on another "
                        f"mode's configuration at {write(X[edge])}, which is not taken)")
                    return
    # no fold next to the shared samples tells which jumped: the later-found mode is cut
    x = pair[1]
    if _drop(X, chains, x, run, False, _PIECE):
        poses.append(poses[x])
    chains[x].events.append(
        f"cut at {write(X[n0])} … {write(X[n1])}: there it is at another mode's configuration "
        "(one of the two jumped onto the other's path; no fold in the steps next to those "
        "samples tells which), so it is not counted twice")


def _drop(X: Array, chains: list[Chain], x: int, run: tuple[int, int], leftward: bool,
          lead: str) -> bool:
    """Clear the samples ``run`` (first, last; empty where last < first) of mode ``x``, which
    went through them ``leftward`` (towards lower samples) or not. What it held past them on
    that side (tracked on after the jump), joined to them, becomes a mode of its own, first
    event ``lead``, with the events and folds ``x`` had on that side; where it holds nothing
    there those are dropped (they told of an end it no longer has). Whether a piece was made."""
    n0, n1 = run
    chain = chains[x]
    chain.mask[n0:n1 + 1] = False
    side = ("is born", "starts at") if leftward else ("dies", "cut after")
    N = X.shape[0]
    edge, beyond = (X[n0], X[max(n0 - 1, 0)] - X[n0]) if leftward else \
        (X[n1], X[min(n1 + 1, N - 1)] - X[n1])
    past = [f for f in chain.folds if float(np.dot(f[0] - edge, beyond)) > 0]
    events = [e for e in chain.events if e.startswith(side)]
    chain.folds[:] = [f for f in chain.folds if all(f is not g for g in past)]
    chain.events[:] = [e for e in chain.events if not e.startswith(side)]
    far = np.arange(n0 - 1, -1, -1) if leftward else np.arange(n1 + 1, N)
    if far.size == 0 or not chain.mask[far[0]]:
        return False
    held = far[:int(np.argmin(chain.mask[far])) if not chain.mask[far].all() else far.size]
    piece = Chain(chain.scalars.copy(), chain.spherical.copy(), np.zeros_like(chain.mask),
                  [lead, *events], folds=past)
    piece.mask[held] = True
    chain.mask[held] = False
    chains.append(piece)
    return True


def _meeting(mech: Mechanism, lay: GraphLayout, folds: list[list[tuple[Array, Configuration]]]
             ) -> tuple[list[int], set[tuple[int, int]]]:
    """The mode of every fold (flattened), and the pairs of folds (flat indices) that meet:
    born or dying at the same input (to :data:`SAME_FOLD` of a radian, or of the length
    scale) with body poses there within :data:`FOLD_POSES` (at 2⁻²⁶ of a step from a fold,
    where two branches differ by about the square root of that distance)."""
    scale = input_scale(lay)
    flat = [(k, x, pose_vectors(mech, lay, c)[0]) for k, fs in enumerate(folds) for x, c in fs]
    out = set()
    for i, (a, xa, pa) in enumerate(flat):
        for j in range(i + 1, len(flat)):
            b, xb, pb = flat[j]
            if a != b and float(np.max(np.abs(xa - xb) / scale)) <= SAME_FOLD and \
                    float(np.max(np.abs(pa - pb))) <= FOLD_POSES:
                out.add((i, j))
    return [k for k, _, _ in flat], out


def partner_folds(mech: Mechanism, lay: GraphLayout, X: Array, chains: list[Chain],
                  write: Callable[[Array], str]) -> int:
    """A fold that no other mode meets (two real roots merge at a fold, so two modes meet
    there): its other mode was carried across the fold's step by a track that jumped, onto a
    mode no other track holds (which :func:`unshare` does not see). Each mode holding at both
    samples of that step is searched both ways (:func:`fold_in_step`); one that meets a fold
    from the sample before is split there: it dies at that fold, and the rest is a mode of its
    own, born at the fold reached back from the sample after. The count of modes split."""
    owner, pairs = _meeting(mech, lay, [c.folds for c in chains])
    met = {i for p in pairs for i in p}
    flat = [f for c in chains for f in c.folds]
    scale = input_scale(lay)
    split = 0
    for i, (at, _) in enumerate(flat):
        if i in met:
            continue
        d = X[1:] - X[:-1]
        t = np.einsum("ki,ki->k", at - X[:-1], d) / np.maximum(np.einsum("ki,ki->k", d, d),
                                                                1e-300)
        off = np.abs(X[:-1] + t[:, None] * d - at) / scale
        for k in np.flatnonzero((t > 0) & (t < 1) & (off.max(axis=1) <= SAME_FOLD)).tolist():
            for o in range(len(chains)):
                if o != owner[i] and chains[o].mask[k] and chains[o].mask[k + 1]:
                    split += _split(mech, lay, X, chains, o, k, write)
    return split


def _split(mech: Mechanism, lay: GraphLayout, X: Array, chains: list[Chain], o: int, k: int,
           write: Callable[[Array], str]) -> int:
    """Split mode ``o`` between samples k and k+1 where its step from k meets a fold (1), or
    leave it (0) (:func:`partner_folds`)."""
    dies = fold_in_step(mech, lay, chains[o].conf_at(k), X[k], X[k + 1])
    if dies is None:
        return 0
    born = fold_in_step(mech, lay, chains[o].conf_at(k + 1), X[k + 1], X[k])
    how = ("(a fold, located between samples; its track had crossed it onto "
           "another branch, found from a mode that meets no other at a fold in that step)")
    lead = (f"is born at {write(born[0])}: it starts assembling there {how}" if born is not None
            else f"starts at {write(X[k + 1])}: it is a track that crossed a fold onto another "
            "branch in the step before (no fold is reached back from here), cut there")
    _drop(X, chains, o, (k + 1, k), False, lead)
    if born is not None:
        chains[-1].folds.append(born)
    chains[o].folds.append(dies)
    chains[o].events.append(f"dies at {write(dies[0])}: it stops assembling there {how}")
    return 1


def fold_meetings(mech: Mechanism, lay: GraphLayout,
                  folds: list[list[tuple[Array, Configuration]]]) -> tuple[tuple[int, int], ...]:
    """The pairs of modes (indices into ``folds``) that meet at a fold (:func:`_meeting`)."""
    owner, pairs = _meeting(mech, lay, folds)
    return tuple(sorted({(min(owner[i], owner[j]), max(owner[i], owner[j])) for i, j in pairs}))
