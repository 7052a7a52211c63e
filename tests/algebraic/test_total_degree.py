"""The total-degree homotopy and monodromy: Bézout counts of dense systems, a pair of circles
with two solutions at infinity, Katsura-3, monodromy against total degree, and the refusal of
too many paths."""

from __future__ import annotations

import numpy as np
import pytest

from homotopy_helpers import dense_family, dense_system, generic_point, monomials
from screwkit.algebraic.monodromy import MonodromyOptions, monodromy_solve
from screwkit.algebraic.polynomial import Poly, compile_system
from screwkit.algebraic.total_degree import solve_total_degree
from screwkit.algebraic.track import PathStatus
from screwkit.errors import InputError


def _same_sets(a: np.ndarray, b: np.ndarray, tol: float = 1e-8) -> bool:
    if len(a) != len(b):
        return False
    gaps = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    return bool((gaps.min(axis=1) <= tol).all() and (gaps.min(axis=0) <= tol).all())


@pytest.mark.parametrize(("n", "seed"), [(2, 0), (2, 1), (3, 2)])
def test_dense_quadrics_have_the_bezout_number_of_solutions(n, seed):
    # random dense quadrics: 2^n isolated solutions (Bézout's bound, attained generically)
    system = dense_system(n, 2, seed)
    result = solve_total_degree(system, np.zeros(0))
    assert result.counts()["regular"] == 2**n
    assert np.nanmax(result.residual) < 1e-10
    x = result.x[result.regular]
    assert np.abs(x[:, None] - x[None]).max(axis=2)[~np.eye(len(x), dtype=bool)].min() > 1e-6


def test_two_circles_meet_twice_and_twice_at_infinity():
    # x² + y² = 1 and (x − 1)² + y² = 2 meet at (0, ±1); both pass through the circular
    # points (1 : ±i : 0) at infinity, the other two of Bézout's four
    x, y = Poly.variable(0), Poly.variable(1)
    system = compile_system([x * x + y * y - 1, (x - 1) ** 2 + y * y - 2], ["x", "y"])
    result = solve_total_degree(system, np.zeros(0))
    assert result.counts() == {"regular": 2, "singular": 0, "at_infinity": 2, "failed": 0}
    finite = result.x[result.regular]
    assert _same_sets(finite, np.array([[0, 1], [0, -1]], dtype=complex), 1e-12)
    y_end = result.y[result.status == PathStatus.AT_INFINITY]
    assert np.abs(y_end[:, 2] ** 2 + y_end[:, 1] ** 2).max() < 1e-8  # the direction (1, ±i)


def test_katsura_3_has_eight_solutions():
    # Katsura-3 (Katsura 1990; the PoSSo/Bertini test suites): 8 isolated solutions, the
    # Bézout number 1·2·2·2
    u = [Poly.variable(i) for i in range(4)]

    def U(i: int) -> Poly:
        return u[abs(i)] if abs(i) <= 3 else Poly.constant(0)

    equations = [u[0] + 2 * (u[1] + u[2] + u[3]) - 1]
    for m in range(3):
        equations.append(sum((U(k) * U(m - k) for k in range(-3, 4)), Poly.constant(0)) - u[m])
    system = compile_system(equations, ["u0", "u1", "u2", "u3"])
    result = solve_total_degree(system, np.zeros(0))
    assert result.counts()["regular"] == 8
    assert np.nanmax(result.residual) < 1e-12


def test_monodromy_finds_the_total_degree_solutions():
    system = dense_family(3)
    p0, x0 = generic_point(system, len(monomials(3, 2)), seed=5)
    _, found, stats = monodromy_solve(system, p0, x0, MonodromyOptions(seed=1))
    assert stats.stopped_by == "stabilised" and stats.found == 8
    reference = solve_total_degree(system, p0)
    assert _same_sets(found, reference.x[reference.regular])
    _, _, early = monodromy_solve(system, p0, x0, MonodromyOptions(expected=8, seed=1))
    assert early.stopped_by == "expected count" and early.found == 8
    assert early.loops < stats.loops


def test_monodromy_refuses_a_point_that_is_not_a_solution():
    system = dense_family(2)
    p0, x0 = generic_point(system, len(monomials(2, 2)), seed=0)
    with pytest.raises(InputError, match="x0 does not solve the system at p0"):
        monodromy_solve(system, p0, x0 + 1.0)


def test_too_many_paths_are_refused_naming_the_bezout_number():
    xs = [Poly.variable(i) for i in range(13)]
    system = compile_system([v * v - 1 for v in xs], [f"x{i}" for i in range(13)])
    with pytest.raises(InputError, match="8192 paths"):
        solve_total_degree(system, np.zeros(0))
