"""The trace test (algebraic/trace_test.py): a complete set of solutions passes, a set with any
one solution left out fails, the second witness set has the count that multi-homogeneous
Bézout gives for the curve, and bad input is refused by name."""

from __future__ import annotations

import numpy as np
import pytest

from homotopy_helpers import dense_family, generic_point, monomials
from screwkit.algebraic.monodromy import MonodromyOptions
from screwkit.algebraic.polynomial import Poly, compile_system
from screwkit.algebraic.solve import StartSolutions
from screwkit.algebraic.trace_test import (
    COMPLETE,
    INCOMPLETE,
    TraceOptions,
    trace_systems,
    trace_test,
)
from screwkit.errors import InputError


@pytest.fixture(scope="module")
def dense3() -> tuple:
    """Three dense quadrics in three unknowns, every coefficient a parameter: 8 solutions
    (Bézout, reached by monodromy with that count expected)."""
    system = dense_family(3)
    p0, x0 = generic_point(system, len(monomials(3, 2)), seed=2)
    start = StartSolutions.by_monodromy(system, p0, x0, MonodromyOptions(expected=8))
    assert start.generic_count == 8
    return system, start


def test_every_solution_passes_and_the_slice_holds_the_curves_degree(dense3):
    """F(x; p0 + λv) is of bidegree (2, 1) in (x, λ), so the curve meets a hyperplane
    a·x = 1 in the coefficient of X³Λ in (2X + Λ)³·X: 3·2² = 12 points. The traces of all
    8 + 12 points lie on a line to rounding, within the certified error bound and far below
    the least share of any one solution (the yardstick of "complete")."""
    system, start = dense3
    verdict = trace_test(system, start.p, start.x)
    assert verdict.verdict == COMPLETE and verdict.complete
    assert verdict.solutions == 8 and verdict.witnesses == 12
    assert verdict.deviation <= verdict.bound
    assert verdict.deviation <= TraceOptions().separation * verdict.least_share
    assert 1e-4 < verdict.least_share < 1 / 8
    assert verdict.deviation < 1e-11
    assert verdict.certified == 3 * 20  # every traced point, at t = 0, t1 and t2
    assert "complete" in str(verdict) and "on a line" in str(verdict)


@pytest.mark.parametrize("left_out", [0, 3, 7])
def test_a_set_missing_one_solution_fails(dense3, left_out):
    """The trace of a proper part of an irreducible curve's points is not affine in the
    pencil value: with one of the 8 left out the deviation is orders above the bound."""
    system, start = dense3
    x = np.delete(start.x, left_out, axis=0)
    verdict = trace_test(system, start.p, x, TraceOptions(rounds=1))
    assert verdict.verdict == INCOMPLETE and not verdict.complete
    assert verdict.solutions == 7 and verdict.witnesses == 12
    assert verdict.deviation > 1e3 * verdict.bound
    assert verdict.deviation > verdict.least_share / 10  # the missing one's share
    assert "a solution is missing" in str(verdict)


def test_a_circle_and_a_line():
    """x² + y² = 1 and a line with its three coefficients as parameters: 2 solutions, and the
    curve of the moving line meets a·x = 1 where the circle does (2 points)."""
    x, y = Poly.variable(0), Poly.variable(1)
    a, b, c = (Poly.variable(i) for i in (2, 3, 4))
    system = compile_system([x * x + y * y - 1.0, a * x + b * y + c], ["x", "y"],
                            ["a", "b", "c"])
    p0 = np.array([1.0 + 0.3j, 2.0 - 0.1j, 0.5 + 0.7j])
    # the two points: y from the line, x² + y² = 1 a quadratic in x
    A, B, C = p0
    roots = np.roots([1 + (A / B) ** 2, 2 * A * C / B ** 2, (C / B) ** 2 - 1])
    sols = np.column_stack([roots, -(A * roots + C) / B])
    verdict = trace_test(system, p0, sols)
    assert verdict.verdict == COMPLETE and verdict.witnesses == 2
    assert trace_test(system, p0, sols[:1]).verdict == INCOMPLETE


def test_the_built_systems_hold_the_moved_parameters(dense3):
    """The slice and pencil systems are F(x; p + λv) with the slice a·x − 1 (= 0, or times λ
    plus t): evaluated against the system at p + λv at random points."""
    system, start = dense3
    slice_sys, pencil_sys = trace_systems(system)
    assert trace_systems(system)[0] is slice_sys  # kept on the system
    n, k = system.n, system.k
    assert (slice_sys.n, slice_sys.k, pencil_sys.k) == (n + 1, 2 * k + n, 2 * k + n + 1)
    rng = np.random.default_rng(5)
    z = rng.standard_normal((4, n + 1)) + 1j * rng.standard_normal((4, n + 1))
    p, v, a = (rng.standard_normal(size) + 1j * rng.standard_normal(size)
               for size in (k, k, n))
    t = 0.3 - 0.2j
    F_slice, _, _ = slice_sys.evaluate(z, np.concatenate([p, v, a]), want_jp=False)
    F_pencil, _, _ = pencil_sys.evaluate(z, np.concatenate([[t], p, v, a]), want_jp=False)
    F_moved = np.stack([system.evaluate(z[i:i + 1, :n], p + z[i, n] * v,
                                        want_jp=False)[0][0] for i in range(4)])
    ell = z[:, :n] @ a - 1.0
    np.testing.assert_allclose(F_slice[:, :n], F_moved, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(F_slice[:, n], ell, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(F_pencil[:, :n], F_moved, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(F_pencil[:, n], ell * z[:, n] + t, rtol=1e-12, atol=1e-12)


def test_bad_input_is_refused_by_name(dense3):
    system, start = dense3
    with pytest.raises(InputError, match="p0 of shape"):
        trace_test(system, start.p[:-1], start.x)
    with pytest.raises(InputError, match="at least one solution"):
        trace_test(system, start.p, start.x[:0])
    with pytest.raises(InputError, match=r"solution\(s\) \[2\] do not solve"):
        trace_test(system, start.p, np.vstack([start.x[:2], start.x[2] + 0.1]))
    with pytest.raises(InputError, match=r"solution\(s\) \[3\] repeat"):
        trace_test(system, start.p, np.vstack([start.x[:3], start.x[1]]))
    with pytest.raises(InputError, match="finite"):
        trace_test(system, np.where(np.arange(system.k) == 0, np.nan, start.p), start.x)
    with pytest.raises(InputError, match="pencil, rounds out of range"):
        TraceOptions(pencil=0.0, rounds=0)
    x = Poly.variable(0)
    bare = compile_system([x * x - 2.0], ["x"])
    with pytest.raises(InputError, match="has none"):
        trace_test(bare, np.zeros(0, dtype=complex), np.array([[np.sqrt(2.0)]]))


def test_a_lost_pencil_path_is_tracked_again_and_a_jump_is_not_trusted(dense3, monkeypatch):
    """A pencil path that fails is tracked again alone with tighter steps (the verdict stands,
    its paths counted); when the retrack lands on another path's end (a jump) it is lost at
    that pencil value, another value is drawn, and when every value loses it the verdict is
    inconclusive, not complete."""
    from dataclasses import replace as dc_replace

    import screwkit.algebraic.trace_test as tt
    from screwkit.algebraic.track import PathStatus

    system, start = dense3
    pencil_sys = trace_systems(system)[1]
    real = tt.track_parameter_homotopy
    calls: list[int] = []

    def first_path_fails(sys_, q0, q1, z, options=None):
        result = real(sys_, q0, q1, z, options)
        if sys_ is pencil_sys:
            calls.append(len(z))
        if sys_ is pencil_sys and len(z) > 1:
            status = result.status.copy()
            status[0] = PathStatus.FAILED
            return dc_replace(result, status=status)
        return result

    monkeypatch.setattr(tt, "track_parameter_homotopy", first_path_fails)
    verdict = trace_test(system, start.p, start.x)
    assert verdict.verdict == COMPLETE
    assert calls.count(1) == 2  # one retrack of one path at each of the two pencil values

    second = np.column_stack([start.x[1:2], np.zeros(1)])  # the second solution, λ = 0

    def retrack_jumps(sys_, q0, q1, z, options=None):
        result = first_path_fails(sys_, q0, q1, z, options)
        if sys_ is pencil_sys and len(z) == 1:
            return real(sys_, q0, q1, second, options)  # lands on the second path's end
        return result

    monkeypatch.setattr(tt, "track_parameter_homotopy", retrack_jumps)
    verdict = trace_test(system, start.p, start.x, TraceOptions(rounds=1))
    assert verdict.verdict == "inconclusive" and "failed at" in verdict.reason



def test_solutions_in_pairs_through_the_origin_still_seed_the_slice():
    """An even system (x ↦ −x maps solutions to solutions) has its 4 solutions in ± pairs;
    with a pair first, no hyperplane a'·x = 1 passes through the first two, so the seeds are
    taken among linearly independent points: all 4 complete, 3 of 4 incomplete, whatever the
    order."""
    from screwkit.algebraic.monodromy import monodromy_solve

    x1, x2 = Poly.variable(0), Poly.variable(1)
    c = [Poly.variable(2 + i) for i in range(6)]
    system = compile_system([x1 * x1 + c[0] * x1 * x2 + c[1] * x2 * x2 - c[2],
                             x1 * x1 + c[3] * x1 * x2 + c[4] * x2 * x2 - c[5]],
                            ["x1", "x2"], [f"c{i}" for i in range(6)])
    rng = np.random.default_rng(1)
    p = rng.standard_normal(6) + 1j * rng.standard_normal(6)
    x0 = rng.standard_normal(2) + 1j * rng.standard_normal(2)
    F, _, _ = system.evaluate(x0[None], p, want_jp=False)
    p[2] += F[0, 0]
    p[5] += F[0, 1]
    _, X, _ = monodromy_solve(system, p, x0, MonodromyOptions(expected=4))
    assert len(X) == 4
    partner = int(np.argmin(np.abs(X + X[0]).max(axis=1)))
    assert np.abs(X[partner] + X[0]).max() < 1e-10  # the pair (x, −x)
    order = [0, partner] + [i for i in range(4) if i not in (0, partner)]
    assert trace_test(system, p, X[order]).verdict == COMPLETE
    assert trace_test(system, p, X[order][:3]).verdict == INCOMPLETE
