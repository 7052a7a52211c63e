"""Every isolated solution of F(x; p) = 0 for one or many parameter vectors p.

The front of the engine: :func:`solve_all` tracks the stored generic solutions
(:class:`StartSolutions`, found once per system by the total-degree homotopy or by monodromy)
to each target by a parameter homotopy (:mod:`.track`; Sommese & Wampler 2005, ch. 7), then
certifies the regular end points by Smale's α-test (:mod:`.certify`), drops duplicates and sorts
the real solutions first. Only as many paths as the generic root count run per target, and all
targets run in one batch.

What is and is not guaranteed. With p_start generic, every isolated solution at the target is
the end of one path (probability one), so a complete start set and paths that all end
(none failed) give every isolated solution. The start set's completeness is as good as the
method that found it: a total-degree solve is complete when no path failed; monodromy is
complete when it reached an expected count or the trace test shows it complete
(:mod:`.trace_test`; otherwise it stopped when loops stopped finding new solutions, a
heuristic). Solutions on positive-dimensional components are not
reported as isolated solutions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.certify import Certificate, certify, distinct
from screwkit.algebraic.monodromy import MonodromyOptions, monodromy_solve
from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.total_degree import bezout_number, solve_total_degree
from screwkit.algebraic.track import PathStatus, track_parameter_homotopy
from screwkit.errors import InputError

#: the words with which ``how_found`` marks a count that monodromy may have left short
LOWER_BOUND = "a lower bound on the generic count"


@dataclass(frozen=True)
class StartSolutions:
    """Every solution x (m, n) of the system at one generic complex parameter vector p (k,):
    the start of every later parameter homotopy of this system (cache it per topology).
    ``generic_count`` is m; ``how_found`` says by which method and how complete it is;
    ``paths`` counts the paths tracked to find them; ``count_check`` the verdict of the trace
    test on them (:mod:`.trace_test`: "complete", "incomplete" or "inconclusive"; "" when it
    has not run)."""

    p: Complex
    x: Complex
    generic_count: int
    how_found: str
    paths: int = 0
    count_check: str = ""

    @property
    def lower_bound(self) -> bool:
        """Whether the count is only a lower bound: monodromy stopped without a known count
        and no trace test has shown the set complete."""
        return LOWER_BOUND in self.how_found and self.count_check != "complete"

    @staticmethod
    def by_total_degree(system: PolynomialSystem, seed: int = 0,
                        options: TrackOptions | None = None) -> StartSolutions:
        """Solve at a random complex p by the total-degree homotopy (Bézout-many paths)."""
        rng = np.random.default_rng(seed)
        p = (rng.standard_normal(system.k) + 1j * rng.standard_normal(system.k)).astype(complex)
        result = solve_total_degree(system, p, options, seed=seed)
        x = result.x[result.regular]
        counts = result.counts()
        how = (f"total-degree homotopy: {len(x)} regular of {bezout_number(system)} paths "
               f"({counts['at_infinity']} at infinity, {counts['singular']} singular, "
               f"{counts['failed']} failed)")
        return StartSolutions(p, x, len(x), how, bezout_number(system))

    @staticmethod
    def by_monodromy(system: PolynomialSystem, p0: ArrayLike, x0: ArrayLike,
                     options: MonodromyOptions | None = None) -> StartSolutions:
        """Solve at the generic p0 by monodromy from the known solution(s) x0."""
        p, x, stats = monodromy_solve(system, np.asarray(p0, dtype=complex),
                                      np.asarray(x0, dtype=complex), options)
        how = (f"monodromy: {stats.found} solutions after {stats.loops} loops, stopped by "
               f"{stats.stopped_by}" + (f" ({LOWER_BOUND}: no proof that none is missing)"
                                        if stats.stopped_by != "expected count" else ""))
        return StartSolutions(p, x, stats.found, how, stats.paths_tracked)


@dataclass(frozen=True)
class Solutions:
    """The distinct finite solutions of B instances, flat and sorted per instance (real first,
    then certified, then the rest).

    Per solution (M,): ``x`` (M, n), ``instance``, ``status`` (:class:`PathStatus`: regular
    or singular), ``certified`` (α-test passed), ``certified_real``, ``real`` (imaginary part
    ≤ 1e-8 relative: certified or not), ``alpha``, ``beta``, ``gamma``, ``radius`` (a true zero
    lies within it), ``residual`` (‖F(x)‖∞ relative to the largest Σ|terms| of an equation at x,
    or to 1), ``multiplicity`` (paths ending there). Per instance (B,): ``found`` (distinct
    complex solutions), ``real_count``, ``certified_real_count``, ``at_infinity``, ``failed``
    (paths). ``generic_count`` and ``how_found`` come from the start solutions; ``route`` names,
    per instance, the method that ran (the parameter homotopy, or an elimination solver that
    falls back to it)."""

    x: Complex
    instance: NDArray[np.intp]
    status: NDArray[np.int8]
    certified: NDArray[np.bool_]
    certified_real: NDArray[np.bool_]
    real: NDArray[np.bool_]
    alpha: NDArray[np.float64]
    beta: NDArray[np.float64]
    gamma: NDArray[np.float64]
    radius: NDArray[np.float64]
    residual: NDArray[np.float64]
    multiplicity: NDArray[np.int64]
    found: NDArray[np.int64]
    real_count: NDArray[np.int64]
    certified_real_count: NDArray[np.int64]
    at_infinity: NDArray[np.int64]
    failed: NDArray[np.int64]
    generic_count: int
    how_found: str
    #: per instance, the method that found its solutions
    route: tuple[str, ...] = ()

    def of(self, b: int) -> Complex:
        """The solutions (m_b, n) of instance b, in the sorted order."""
        return self.x[self.instance == b]


def _instances(system: PolynomialSystem, p_target: ArrayLike) -> Complex:
    p = np.asarray(p_target, dtype=complex)
    if p.ndim not in (1, 2) or p.shape[-1] != system.k:
        raise InputError(f"p_target must have shape ({system.k},) or (B, {system.k}) for the "
                         f"parameters {', '.join(system.parameters) or '(none)'}; got {p.shape}")
    if not np.isfinite(p).all():
        raise InputError("p_target must be finite")
    return p.reshape(-1, system.k)


def solve_all(system: PolynomialSystem, p_target: ArrayLike,
              start: StartSolutions | None = None,
              options: TrackOptions | None = None) -> Solutions:
    """Every isolated solution of F(x; p) = 0 for p_target (k,) or each row of (B, k), by a
    parameter homotopy from ``start`` (found by the total-degree homotopy when None)."""
    targets = _instances(system, p_target)
    start = start or StartSolutions.by_total_degree(system)
    B, m = len(targets), len(start.x)
    if start.x.shape[1:] != (system.n,) or start.p.shape != (system.k,):
        raise InputError(f"start solutions of shape {start.x.shape} at p {start.p.shape} do not "
                         f"fit the system of {system.n} unknowns and {system.k} parameters")
    instance = np.repeat(np.arange(B), m)
    result = track_parameter_homotopy(system, start.p, np.repeat(targets, m, axis=0),
                                      np.tile(start.x, (B, 1)), options, instance=instance)
    finite = np.flatnonzero((result.status == PathStatus.REGULAR)
                            | (result.status == PathStatus.SINGULAR))

    def paths(status: PathStatus) -> NDArray[np.int64]:
        return np.bincount(instance[result.status == status], minlength=B).astype(np.int64)

    return collect_solutions(system, targets, result.x[finite], instance[finite],
                             result.status[finite], result.multiplicity[finite],
                             paths(PathStatus.AT_INFINITY), paths(PathStatus.FAILED),
                             start.generic_count, start.how_found)


def collect_solutions(system: PolynomialSystem, targets: Complex, x: Complex,
                      instance: NDArray[np.intp], status: NDArray[np.int8],
                      multiplicity: NDArray[np.int64], at_infinity: NDArray[np.int64],
                      failed: NDArray[np.int64], generic_count: int, how_found: str,
                      route: tuple[str, ...] | None = None,
                      cert: Certificate | None = None,
                      label: NDArray[np.intp] | None = None) -> Solutions:
    """:class:`Solutions` from finite points x (M, n) of instances ``instance`` (M,) with
    parameters ``targets`` (B, k), each REGULAR or SINGULAR: certified (α-test), duplicates
    dropped, sorted per instance (real, then certified, first). ``at_infinity`` and ``failed``
    count paths per instance; ``route`` names the method per instance (the parameter
    homotopy when None); ``cert`` the points' α-test and ``label`` their duplicate labels
    (:func:`~screwkit.algebraic.certify.distinct`) when the caller has them."""
    B = len(targets)
    if cert is None:
        cert = certify(system, x, targets[instance])
    regular = status == int(PathStatus.REGULAR)  # (an int: an IntEnum costs numpy µs)
    if label is None:
        radius = np.where(regular & cert.certified, cert.radius,
                          1e-6 * (1.0 + np.abs(x).max(axis=1, initial=0.0)))
        label = distinct(x, radius, instance)
    keep = label == np.arange(len(x))
    assert cert.value is not None and cert.terms is not None
    with np.errstate(all="ignore"):
        residual = np.abs(cert.value).max(axis=1, initial=0.0) / np.maximum(
            1.0, cert.terms.max(axis=1, initial=0.0))
    real = np.abs(x.imag).max(axis=1, initial=0.0) <= 1e-8 * (1.0 + np.abs(x).max(
        axis=1, initial=0.0))
    certified = cert.certified & regular
    order = np.lexsort((~certified, ~(real | cert.real), instance))
    order = order[keep[order]]
    inst = instance[order]

    def per_instance(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
        return np.bincount(inst[mask], minlength=B).astype(np.int64)

    cert_real = (cert.real & certified)[order]
    return Solutions(x[order], inst, status[order], certified[order], cert_real,
                     real[order], cert.alpha[order], cert.beta[order], cert.gamma[order],
                     cert.radius[order], residual[order], multiplicity[order],
                     np.bincount(inst, minlength=B).astype(np.int64),
                     per_instance(real[order]), per_instance(cert_real), at_infinity, failed,
                     generic_count, how_found,
                     route if route is not None else ("parameter homotopy",) * B)
