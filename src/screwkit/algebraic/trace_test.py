"""The trace test: whether a set of solutions at a generic parameter point is all of them.

Monodromy (:mod:`.monodromy`) stops when its loops stop finding new solutions, so without a
count known in advance its set is a lower bound. The trace test decides it (Leykin, Rodriguez
& Sottile, "Trace test", Arnold Math. J. 4, 2018; for a parametrised system in the form of
del Campo & Rodriguez, "Critical points via monodromy and local methods", J. Symb. Comput. 79,
2017, which HomotopyContinuation.jl's ``verify_solution_completeness`` also uses).

Take a random complex direction v in parameter space and a random affine function
ℓ(x) = a·x − 1, and the system in the unknowns (x, λ) with the pencil value t:

    F(x; p0 + λ v) = 0,      ℓ(x)·λ + t = 0.

Over t = 0 its solutions are two witness sets of the curve C = {(x, λ): F(x; p0 + λ v) = 0}:
the solutions W0 at p0 (λ = 0), and the points W1 of C on the hyperplane ℓ(x) = 0. As t moves,
they move together on C, cut by the (1, 1)-forms ℓ(x)·λ = −t; the sum of all of them, the
trace, is then an affine function of t, and the sum of a proper part of the solutions of an
irreducible curve is not (Leykin, Rodriguez & Sottile 2018). So the test tracks
W0 ∪ W1 from t = 0 to two pencil values t1, t2 and checks that the three traces lie on a line:

    Σ_i δ_i = 0,   δ_i = (z_i(t1) − z_i(0))/t1 − (z_i(t2) − z_i(0))/t2,   z = (x, λ).

W1 is found here as well: points of C from W0 tracked to p0 + v (λ = 1), put on a hyperplane
through them and carried to the random one, then monodromy loops on the slice system
F(x; p + λ v) = 0, ℓ(x) = 0. An incomplete W1 fails the test just as an incomplete W0 does, so
W1 gets more loops until the test passes or the rounds run out.

What it decides, honestly. The deviation |Σ δ_i| is compared with an error bound: the end
points' distances to their true solutions (2β, Newton's step, bounded by Smale's α-test where
it certifies them: :mod:`.certify`) and the rounding of the sum. A deviation above the bound
means the true traces are not collinear, so a point is missing from W0 or from W1
("incomplete": the W1 rounds above make the second less likely, and a caller that can run
more monodromy loops on W0 and finds nothing new should read it as inconclusive, as the count
check of docs/kinematics.md does). Within the bound, the verdict weighs the deviation against
the least share ‖δ_i‖ / Σ‖δ_j‖ of any given solution: a missing solution would add its own
share, so a deviation at most 10⁻³ of the least share, with the bound at most half of it, is
"complete" (a missing solution as nonlinear as the least one found would show at least half
its share through any error within the bound; it would take one a thousand times less
nonlinear than every one found to hide); otherwise, when two ends' error balls meet, or when
paths are lost, "inconclusive". The bound, with the α-test's rounding margins, is pessimistic
for far-out ill-conditioned witnesses (10⁴ times the Newton step on the 3-RPS).
Like monodromy itself, the test sees only the irreducible components of the solution variety
that hold some of the given solutions: a component none of them lies on is beyond it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from screwkit.algebraic.certify import UNIT_ROUNDOFF, certify, distinct
from screwkit.algebraic.monodromy import MonodromyOptions, monodromy_solve
from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, Poly, PolynomialSystem, compile_system
from screwkit.algebraic.track import PathStatus, same_points, track_parameter_homotopy
from screwkit.errors import InputError

#: the verdicts of :class:`Completeness`
COMPLETE, INCOMPLETE, INCONCLUSIVE = "complete", "incomplete", "inconclusive"


@dataclass(frozen=True)
class TraceOptions:
    """``pencil``: |t| of the two pencil values (a value where a path fails is replaced by
    one in another direction, up to ``tries`` times, a fifth the size each time: a shorter
    segment passes fewer of the pencil's branch points, at the price of a larger error
    bound); ``rounds`` of monodromy loops for the second witness set, each stopped after
    ``stale_loops`` loops in a row found nothing new; ``separation``: "complete" needs the
    deviation at most this fraction of the least share of any given solution (module
    docstring); ``hyperplanes`` tried for the slice; ``seed`` for v, ℓ and the loops."""

    pencil: float = 0.5
    tries: int = 3
    rounds: int = 4
    stale_loops: int = 6
    separation: float = 1e-3
    #: random hyperplanes a·x = 1 tried for the slice, the best kept (:func:`_best_hyperplane`)
    hyperplanes: int = 4
    seed: int = 0
    track: TrackOptions = field(default_factory=TrackOptions)

    def __post_init__(self) -> None:
        checks = {"pencil": self.pencil > 0, "tries": self.tries >= 0,
                  "rounds": self.rounds >= 1, "stale_loops": self.stale_loops >= 1,
                  "hyperplanes": self.hyperplanes >= 1, "separation": 0 < self.separation < 1}
        wrong = [name for name, ok in checks.items() if not ok]
        if wrong:
            raise InputError(f"TraceOptions: {', '.join(wrong)} out of range (pencil > 0, "
                             "tries ≥ 0, rounds, stale_loops and hyperplanes ≥ 1, "
                             "0 < separation < 1)")


@dataclass(frozen=True)
class Completeness:
    """The trace test's verdict (:data:`COMPLETE`, :data:`INCOMPLETE` or
    :data:`INCONCLUSIVE`) on ``solutions`` solutions; ``deviation`` |Σδ_i| / Σ|δ_i| and
    ``bound``, the error bound on it (NaN when no pencil was tracked); ``witnesses`` the points
    of the second witness set W1; ``certified`` how many of the tracked points the α-test
    certified (the others' errors are Newton's step, an estimate); ``paths`` tracked in all;
    ``reason`` in words; ``least_share`` the yardstick of "complete" (module docstring)."""

    verdict: str
    solutions: int
    deviation: float
    bound: float
    witnesses: int
    certified: int
    paths: int
    reason: str
    #: the least share ‖δ_i‖ / Σ‖δ_j‖ among the given solutions (NaN when none was traced)
    least_share: float = np.nan

    @property
    def complete(self) -> bool:
        return self.verdict == COMPLETE

    def __str__(self) -> str:
        return f"trace test: {self.verdict} ({self.reason})"


def trace_systems(system: PolynomialSystem) -> tuple[PolynomialSystem, PolynomialSystem]:
    """The slice system F(x; p + λ v) = 0, a·x − 1 = 0 (unknowns x, λ; parameters p, v, a)
    and the pencil system F(x; p + λ v) = 0, (a·x − 1)·λ + t = 0 (parameters t, p, v, a) of
    ``system`` (module docstring); built once and kept on the system."""
    kept = system.__dict__.get("_trace_systems")
    if kept is None:
        kept = (_build(system, pencil=False), _build(system, pencil=True))
        object.__setattr__(system, "_trace_systems", kept)
    return kept  # type: ignore[no-any-return]


def _build(system: PolynomialSystem, pencil: bool) -> PolynomialSystem:
    n, k = system.n, system.k
    lam = n
    first = n + 1 + int(pencil)  # p, then v, then a
    p_of, v_of, a_of = first, first + k, first + 2 * k
    lam_poly = Poly.variable(lam)
    powers: dict[tuple[int, int], Poly] = {}
    equations = [Poly() for _ in range(n)]
    for term in range(len(system.eq)):
        poly = Poly.constant(complex(system.coef[term]))
        for s, e in zip(system.sym[term].tolist(), system.pw[term].tolist(), strict=True):
            if e == 0:
                continue
            if s < n:
                poly = poly * Poly.variable(s) ** e
                continue
            j = s - n
            if (j, e) not in powers:
                powers[j, e] = (Poly.variable(p_of + j)
                                + lam_poly * Poly.variable(v_of + j)) ** e
            poly = poly * powers[j, e]
        e_ = int(system.eq[term])
        equations[e_] = equations[e_] + poly
    slice_ = sum((Poly.variable(a_of + i) * Poly.variable(i) for i in range(n)), Poly()) - 1.0
    equations.append(slice_ * lam_poly + Poly.variable(n + 1) if pencil else slice_)
    name = "lambda"
    while name in system.variables:
        name += "_"
    names = [*("t" for _ in range(int(pencil))), *(f"p.{q}" for q in system.parameters),
             *(f"v.{q}" for q in system.parameters), *(f"a.{q}" for q in system.variables)]
    return compile_system(equations, [*system.variables, name], names)


def trace_test(system: PolynomialSystem, p0: Complex, x0: Complex,
               options: TraceOptions | None = None) -> Completeness:
    """Whether the solutions x0 (m, n) of F(x; p0) = 0, p0 (k,) generic complex, are all of
    the isolated solutions there (module docstring)."""
    options = options or TraceOptions()
    p0 = np.asarray(p0, dtype=complex)
    x0 = np.atleast_2d(np.asarray(x0, dtype=complex))
    n, k, m = system.n, system.k, len(x0)
    if p0.shape != (k,) or x0.shape[1:] != (n,) or m == 0:
        raise InputError(f"the trace test needs p0 of shape ({k},) and at least one solution "
                         f"of shape ({n},); got {p0.shape} and {x0.shape}")
    if k == 0:
        raise InputError("the trace test moves the parameters; this system has none")
    _check_solutions(system, p0, x0)
    rng = np.random.default_rng(options.seed)
    slice_sys, pencil_sys = trace_systems(system)
    v = np.maximum(1.0, np.abs(p0)) * (rng.standard_normal(k) + 1j * rng.standard_normal(k))
    a = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    q = np.concatenate([p0, v, a])
    w1, paths = _seeds(system, slice_sys, p0, v, q, x0, options)
    failed = Completeness(INCONCLUSIVE, m, np.nan, np.nan, len(w1), 0, paths,
                          "no point of the curve reached the slice")
    result = failed
    for r in range(options.rounds):
        if not len(w1):
            break
        mono = MonodromyOptions(stale_loops=options.stale_loops, each_own_size=True,
                                seed=options.seed * 1000 + r, track=options.track)
        _, w1, stats = monodromy_solve(slice_sys, q, w1, mono)
        paths += stats.paths_tracked
        q, w1, moved = _best_hyperplane(slice_sys, pencil_sys, q, x0, w1, rng, options)
        paths += moved
        z0 = np.concatenate([np.column_stack([x0, np.zeros(m)]), w1])
        result = _pencil(pencil_sys, np.concatenate([[0.0], q]), z0, m, rng, options)
        result = replace(result, solutions=m, witnesses=len(w1),
                         paths=paths + result.paths)
        paths = result.paths
        if result.verdict != INCOMPLETE:
            break
    return result


def _check_solutions(system: PolynomialSystem, p0: Complex, x0: Complex) -> None:
    """Refuse, by name, solutions that are not finite, do not solve F(x; p0) = 0 (the
    residual test of :func:`.monodromy.monodromy_solve`) or repeat one another."""
    if not (np.isfinite(p0).all() and np.isfinite(x0).all()):
        raise InputError("the trace test needs finite p0 and solutions; got NaN or inf")
    F, _, _ = system.evaluate(x0, p0, want_jp=False)
    scale = 1.0 + np.abs(system.coef).max(initial=0.0) * (1.0 + np.abs(x0).max()) ** max(
        system.degrees, default=1)
    bad = np.flatnonzero(np.abs(F).max(axis=1) > 1e-8 * scale)
    if len(bad):
        raise InputError(f"solution(s) {bad.tolist()[:5]} do not solve the system at p0 "
                         f"(residual up to {np.abs(F[bad]).max():.3g}); give the solutions "
                         "at p0 itself")
    label = same_points(x0, np.zeros(len(x0), dtype=np.intp), 1e-8)
    twice = np.flatnonzero(label != np.arange(len(x0)))
    if len(twice):
        raise InputError(f"solution(s) {twice.tolist()[:5]} repeat earlier ones (to 1e-8); "
                         "give each solution once")


def _best_hyperplane(slice_sys: PolynomialSystem, pencil_sys: PolynomialSystem, q: Complex,
                     x0: Complex, w1: Complex, rng: np.random.Generator,
                     options: TraceOptions) -> tuple[Complex, Complex, int]:
    """Of the hyperplane in q and ``options.hyperplanes − 1`` more random ones (W1 carried to
    each along the slice system, kept only when every path arrives), the one whose points at
    t = 0 have the smallest summed error radius: a branch of C nearly parallel to the
    hyperplane meets it far out and ill-conditioned, and one such point can swamp the error
    bound. Returns (q, W1, paths tracked)."""
    n, m = len(x0[0]), len(x0)
    zero = np.column_stack([x0, np.zeros(m)])

    def error(qq: Complex, w: Complex) -> float:
        z = np.concatenate([zero, w])
        radius = certify(pencil_sys, z, np.concatenate([[0.0], qq])).radius
        return float(radius.sum()) if np.isfinite(radius).all() else np.inf

    best, best_error, paths = (q, w1), error(q, w1), 0
    for _ in range(options.hyperplanes - 1):
        other = q.copy()
        other[len(q) - n:] = rng.standard_normal(n) + 1j * rng.standard_normal(n)
        moved = track_parameter_homotopy(slice_sys, q, other, w1, options.track)
        paths += len(w1)
        if (moved.status != PathStatus.REGULAR).any():
            continue
        e = error(other, moved.x)
        if e < best_error:
            best, best_error = (other, moved.x), e
    return best[0], best[1], paths


def _seeds(system: PolynomialSystem, slice_sys: PolynomialSystem, p0: Complex, v: Complex,
           q: Complex, x0: Complex, options: TraceOptions) -> tuple[Complex, int]:
    """Points of the curve C on the slice a·x = 1 (q = (p0, v, a)): the solutions tracked to
    p0 + v (λ = 1), up to n linearly independent ones put on the hyperplane a'·x = 1 through
    them, and carried from a' to a along the slice system."""
    from scipy.linalg import qr

    n = system.n
    moved = track_parameter_homotopy(system, p0, p0 + v, x0, options.track)
    y = moved.x[moved.status == PathStatus.REGULAR]
    paths = len(x0)
    if not len(y):
        return np.empty((0, n + 1), dtype=complex), paths
    # up to n linearly independent points (a system symmetric under x ↦ −x has its solutions
    # in ± pairs, through which no hyperplane a'·x = 1 passes)
    _, r, pivot = qr(y.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    y = y[pivot[: int((diag > 1e-10 * diag[0]).sum())]] if diag[0] > 0 else y[:0]
    if not len(y):
        return np.empty((0, n + 1), dtype=complex), paths
    a_seed = np.linalg.lstsq(y, np.ones(len(y), dtype=complex), rcond=None)[0]
    q_seed = np.concatenate([q[: len(q) - n], a_seed])
    carried = track_parameter_homotopy(slice_sys, q_seed, q, np.column_stack(
        [y, np.ones(len(y))]), options.track)
    return carried.x[carried.status == PathStatus.REGULAR], paths + len(y)


def _pencil(pencil_sys: PolynomialSystem, q0: Complex, z0: Complex, m: int,
            rng: np.random.Generator, options: TraceOptions) -> Completeness:
    """Track z0 (the m solutions, then the slice's witnesses) from t = 0 to two pencil values
    and compare the traces (module docstring). A pencil value where a path is lost is
    replaced by another in a new direction, a fifth the size, up to ``options.tries`` times."""
    size = options.pencil
    paths, misses = 0, 0
    ts: list[complex] = []
    ends: list[Complex] = []
    while len(ts) < 2 and misses <= options.tries:
        t = complex(size * np.exp(2j * np.pi * rng.random()))
        q1 = q0.copy()
        q1[0] = t
        end, tracked = _track_pencil(pencil_sys, q0, q1, z0, options.track)
        paths += tracked
        if np.isfinite(end).all():
            ts.append(t)
            ends.append(end)
        else:
            misses += 1
            size /= 5
    if len(ts) < 2:
        return Completeness(INCONCLUSIVE, 0, np.nan, np.nan, 0, 0, paths,
                            f"paths of the pencil failed at {misses} pencil values")
    return _verdict(pencil_sys, q0, z0, m, np.array(ts), ends, paths, options)


def _track_pencil(pencil_sys: PolynomialSystem, q0: Complex, q1: Complex, z0: Complex,
                  track: TrackOptions) -> tuple[Complex, int]:
    """z0 tracked from q0 to q1: the ends (NaN rows for paths lost) and the paths tracked.
    A path that fails is tracked again alone with tighter steps, twice over (measured on the
    five-link suspension's pencil: 2 of 446 paths fail at the default steps and arrive at
    10× smaller ones); ends that then coincide with another path's are a jump, and lost."""
    moved = track_parameter_homotopy(pencil_sys, q0, q1, z0, track)
    end = np.where((moved.status == PathStatus.REGULAR)[:, None], moved.x, np.nan)
    paths = len(z0)
    for _ in range(2):
        bad = np.flatnonzero(~np.isfinite(end).all(axis=1))
        if not len(bad):
            break
        track = track.tighter()
        again = track_parameter_homotopy(pencil_sys, q0, q1, z0[bad], track)
        paths += len(bad)
        end[bad] = np.where((again.status == PathStatus.REGULAR)[:, None], again.x, np.nan)
    ok = np.flatnonzero(np.isfinite(end).all(axis=1))
    label = same_points(end[ok], np.zeros(len(ok), dtype=np.intp), track.same_point_tolerance)
    jumped = ok[np.isin(label, label[label != np.arange(len(ok))])]
    end[jumped] = np.nan
    return end, paths


def _verdict(pencil_sys: PolynomialSystem, q0: Complex, z0: Complex, m: int, ts: Complex,
             ends: list[Complex], paths: int, options: TraceOptions) -> Completeness:
    """The verdict from the points z0 at t = 0 and ``ends`` at ts (module docstring)."""
    points = [z0, *ends]
    params = [q0, *(np.concatenate([[t], q0[1:]]) for t in ts)]
    error, certified, overlap = [], 0, False
    for z, q in zip(points, params, strict=True):
        cert = certify(pencil_sys, z, q)
        error.append(cert.radius)
        certified += int(cert.certified.sum())
        # ends whose error balls meet may stand for one true solution: no certified verdict
        overlap |= bool((distinct(z, cert.radius, np.zeros(len(z), dtype=np.intp))
                         != np.arange(len(z))).any())
    delta = (ends[0] - z0) / ts[0] - (ends[1] - z0) / ts[1]
    spread = float(np.linalg.norm(delta, axis=1).sum())
    gap = float(np.linalg.norm(delta.sum(axis=0)))
    size = [np.linalg.norm(z, axis=1) for z in points]
    bound_abs = float(((error[0] + error[1]) / abs(ts[0])
                       + (error[0] + error[2]) / abs(ts[1])).sum()
                      + 4 * len(z0) * UNIT_ROUNDOFF * ((size[0] + size[1]) / abs(ts[0])
                                                       + (size[0] + size[2]) / abs(ts[1])).sum())
    if spread == 0.0:  # every point moves affinely: any part's trace would too
        return Completeness(INCONCLUSIVE, 0, np.nan, np.nan, 0, certified, paths,
                            "every traced point moves affinely with t, so no part of them "
                            "can be told from the whole")
    deviation, bound = gap / spread, bound_abs / spread
    least = float(np.linalg.norm(delta[:m], axis=1).min()) / spread
    said = (f"{m} solutions and {len(z0) - m} slice witnesses traced, deviation "
            f"{deviation:.1e} against an error bound {bound:.1e} and a least share of a "
            f"solution {least:.1e}")
    if overlap:
        verdict = INCONCLUSIVE
        reason = f"{said}: two traced points' error balls meet, so they may be one solution"
    elif gap > bound_abs:
        verdict = INCOMPLETE
        reason = f"{said}: the traces are not on a line, so a solution is missing"
    elif deviation <= options.separation * least and bound <= least / 2:
        verdict = COMPLETE
        reason = f"{said}: the traces are on a line"
    elif bound > least / 2:
        verdict = INCONCLUSIVE
        reason = (f"{said}: the bound exceeds half the least share, so rounding could hide a "
                  "missing solution")
    else:
        verdict = INCONCLUSIVE
        reason = (f"{said}: within the bound, but not {1 / options.separation:.0f} times below "
                  "the least share")
    return Completeness(verdict, 0, deviation, bound, 0, certified, paths, reason, least)
