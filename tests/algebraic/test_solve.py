"""solve_all: every root of random quintics against numpy.roots (real counts too), dense
quadrics against per-instance total-degree solves, a batch against one-at-a-time, the residual
bound on every real solution, and start solutions by monodromy."""

from __future__ import annotations

import numpy as np
import pytest

from homotopy_helpers import dense_family, generic_point, monomials, univariate
from screwkit.algebraic.monodromy import MonodromyOptions
from screwkit.algebraic.solve import StartSolutions, solve_all
from screwkit.algebraic.total_degree import solve_total_degree
from screwkit.errors import InputError


def _same_sets(a: np.ndarray, b: np.ndarray, tol: float = 1e-8) -> bool:
    if len(a) != len(b):
        return False
    gaps = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    return bool((gaps.min(axis=1) <= tol).all() and (gaps.min(axis=0) <= tol).all())


def test_quintics_match_numpy_roots_with_real_ones_first_and_certified():
    system = univariate(5)
    start = StartSolutions.by_total_degree(system)
    assert start.generic_count == 5
    targets = np.random.default_rng(7).standard_normal((30, 5))
    solutions = solve_all(system, targets, start)
    assert solutions.certified.all() and (solutions.failed == 0).all()
    for b, target in enumerate(targets):
        expected = np.roots(np.r_[1.0, target[::-1]])
        found = solutions.of(b)
        assert _same_sets(found, expected[:, None], 1e-9)
        n_real = int((np.abs(expected.imag) < 1e-9).sum())
        assert solutions.real_count[b] == solutions.certified_real_count[b] == n_real
        assert np.abs(found[:n_real].imag).max(initial=0.0) < 1e-9  # real first


def test_dense_quadrics_batch_matches_total_degree_and_one_at_a_time():
    system = dense_family(3)
    p0, x0 = generic_point(system, len(monomials(3, 2)), seed=2)
    start = StartSolutions.by_monodromy(system, p0, x0, MonodromyOptions(expected=8))
    assert start.generic_count == 8 and start.how_found.startswith("monodromy")
    targets = np.random.default_rng(3).standard_normal((12, system.k))
    batch = solve_all(system, targets, start)
    assert (batch.found == 8).all()
    reference = solve_total_degree(system, targets)
    for b in range(12):
        ref = reference.x[8 * b: 8 * b + 8]
        assert _same_sets(batch.of(b), ref[np.isfinite(ref).all(axis=1)])
        alone = solve_all(system, targets[b], start)
        assert np.abs(alone.x - batch.of(b)).max() < 1e-12
    # every real solution closes: ‖F‖∞ ≤ 1e-10 relative to the largest Σ|terms| at x
    assert batch.residual[batch.real].max() <= 1e-10
    assert batch.real_count.sum() == batch.certified_real_count.sum() > 0


def test_the_same_target_twice_in_one_batch_is_solved_twice():
    """A closed motion's first and last rows are the same instance. In one batch each copy is
    its own problem: its paths' equal ends are no jumps, and both copies find every root (the
    path-jump check once grouped the copies into one homotopy and failed all their paths)."""
    system = univariate(5)
    start = StartSolutions.by_total_degree(system)
    targets = np.random.default_rng(11).standard_normal((3, 5))
    batch = solve_all(system, targets[[0, 1, 0, 2, 0]], start)
    assert (batch.found == 5).all() and (batch.failed == 0).all()
    for b in (0, 2, 4):
        assert _same_sets(batch.of(b), batch.of(0), 1e-12)
    alone = solve_all(system, targets[0], start)
    assert _same_sets(alone.of(0), batch.of(4), 1e-12)


def test_a_wrong_target_shape_is_refused():
    system = univariate(3)
    start = StartSolutions.by_total_degree(system)
    with pytest.raises(InputError, match=r"p_target must have shape \(3,\) or \(B, 3\)"):
        solve_all(system, np.zeros((2, 4)), start)
