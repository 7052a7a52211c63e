"""Monodromy: every solution at a generic parameter point from one known solution.

Over the complement of the discriminant in parameter space, the solutions form a covering; a
closed loop of parameters starting and ending at p0 carries the solution set at p0 to itself by
a permutation, and for an irreducible solution variety the loops' permutations act
transitively, so random loops reach every solution (Duff, Hill, Jensen, Lee, Leykin &
Sommars, "Solving polynomial systems via homotopy continuation and monodromy", IMA J. Numer.
Anal. 39(3), 2019). Each loop here is a random triangle p0 → p1 → p2 → p0 through two fresh
random complex parameter points; a few such loops run together, every solution known so far
tracked around each of them in one batched call of the tracker per edge.

The stopping rule is the paper's heuristic: stop when a given expected count is reached, or
after ``stale_loops`` loops in a row that found nothing new. Without an expected count the
result is every solution reached by those loops: a lower bound on the generic count, not a
proof of it (the trace test, :mod:`.trace_test`, decides whether it is all).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.track import PathStatus, same_points, track_parameter_homotopy
from screwkit.errors import InputError


@dataclass(frozen=True)
class MonodromyOptions:
    """``stale_loops``: loops in a row without a new solution before stopping (when no count
    is expected); ``expected``: stop as soon as this many are known; ``max_loops``: a hard cap;
    ``parallel_loops``: loops run together (the stale count grows by a whole batch);
    ``seed`` for the random loop points."""

    stale_loops: int = 6
    #: loops (random triangles) tracked together in one batch
    parallel_loops: int = 3
    expected: int | None = None
    max_loops: int = 200
    seed: int = 0
    #: draw each loop point's parameter at that parameter's own size (|p0_i|, at least 1)
    #: rather than all at the largest one's: systems whose parameters differ in size by an
    #: order or more (point coordinates and the coefficients of points carried by them,
    #: modes/spatial_points.py) lose every path on loops drawn at the largest size
    each_own_size: bool = False
    track: TrackOptions = field(default_factory=TrackOptions)


@dataclass(frozen=True)
class MonodromyStats:
    """How the search ended: the solutions found, the loops run, why it stopped
    ("expected count", "stabilised" or "loop limit"), the paths tracked (one per solution
    per edge) and how many of those failed."""

    found: int
    loops: int
    stopped_by: str
    paths_tracked: int
    failed_paths: int


def _loops(system: PolynomialSystem, p0: Complex, x: Complex, count: int,
           rng: np.random.Generator, options: TrackOptions, each_own_size: bool = False
           ) -> tuple[Complex, int, int]:
    """Track x (m, n) around ``count`` random triangles p0 → p1 → p2 → p0 at once (one
    batched call per edge); the regular end points, the paths tracked and those that failed."""
    m = len(x)
    scale = np.maximum(1.0, np.abs(p0)) if each_own_size else \
        max(1.0, float(np.abs(p0).max(initial=0.0)))
    shape = (count, system.k)
    p1, p2 = (scale * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
              for _ in range(2))
    corners = [np.tile(p0, (count, 1)), p1, p2, np.tile(p0, (count, 1))]
    loop = np.repeat(np.arange(count), m)
    points = np.tile(x, (count, 1))
    tracked = failed = 0
    # no detour for failed paths: a loop's failed path is dropped (other loops reach its
    # solutions), and the detour's extra random point only reshuffles which loops are taken
    options = replace(options, detour=False)
    for a, b in zip(corners[:-1], corners[1:], strict=True):
        result = track_parameter_homotopy(system, a[loop], b[loop], points, options)
        ok = result.status == PathStatus.REGULAR
        tracked += len(points)
        failed += int((~ok).sum())
        points, loop = result.x[ok], loop[ok]
        if not len(points):
            break
    return points, tracked, failed


def monodromy_solve(system: PolynomialSystem, p0: Complex, x0: Complex,
                    options: MonodromyOptions | None = None
                    ) -> tuple[Complex, Complex, MonodromyStats]:
    """Every solution of F(x; p0) = 0 reachable by monodromy loops from the known solutions
    x0 ((n,) or (m, n)); p0 (k,) must be generic (random complex). Returns (p0, the solutions
    (M, n), :class:`MonodromyStats`)."""
    options = options or MonodromyOptions()
    p0 = np.asarray(p0, dtype=complex)
    x = np.atleast_2d(np.asarray(x0, dtype=complex))
    if p0.shape != (system.k,):
        raise InputError(f"p0 must have shape ({system.k},); got {p0.shape}")
    if x.shape[1:] != (system.n,):
        raise InputError(f"x0 must have shape ({system.n},) or (m, {system.n}); got "
                         f"{np.shape(x0)}")
    if system.k == 0:
        raise InputError("monodromy needs parameters to loop around; this system has none "
                         "(use solve_total_degree)")
    F, _, _ = system.evaluate(x, p0, want_jp=False)
    scale = 1.0 + np.abs(system.coef).max(initial=0.0) * (1.0 + np.abs(x).max()) ** max(
        system.degrees, default=1)
    if np.abs(F).max(initial=0.0) > 1e-8 * scale:
        raise InputError("x0 does not solve the system at p0 (residual "
                         f"{np.abs(F).max():.3g}); build p0 so that F(x0; p0) = 0")
    rng = np.random.default_rng(options.seed)
    known = x[same_points(x, np.zeros(len(x), dtype=np.intp), 1e-8) == np.arange(len(x))]
    stale = loops = tracked = failed = 0
    stopped = "loop limit"
    while loops < options.max_loops:
        if options.expected is not None and len(known) >= options.expected:
            stopped = "expected count"
            break
        # with a proven count to reach, stale loops do not stop the search (only max_loops
        # does): a few loops in a row without a new solution are common by chance
        if stale >= options.stale_loops and options.expected is None:
            stopped = "stabilised"
            break
        batch = min(options.parallel_loops, options.max_loops - loops)
        ends, used, lost = _loops(system, p0, known, batch, rng, options.track,
                                  options.each_own_size)
        loops, tracked, failed = loops + batch, tracked + used, failed + lost
        merged = np.concatenate([known, ends])
        label = same_points(merged, np.zeros(len(merged), dtype=np.intp), 1e-8)
        new = merged[(label == np.arange(len(merged))) & (np.arange(len(merged)) >= len(known))]
        stale = 0 if len(new) else stale + batch
        known = np.concatenate([known, new])
    return p0, known, MonodromyStats(len(known), loops, stopped, tracked, failed)
