"""The QP layer against brute force on small random problems; infeasibility messages."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from screwkit.balancing.errors import InfeasibleConstraintsError
from screwkit.balancing.qp import solve_qp


def brute_force(Q, q, A_le, b_le):
    """Enumerate active sets; the best feasible KKT point (Q positive definite)."""
    n = len(q)
    best = (np.inf, None)
    for r in range(len(b_le) + 1):
        for act in itertools.combinations(range(len(b_le)), r):
            A = A_le[list(act)]
            K = np.block([[2 * Q, A.T], [A, np.zeros((r, r))]])
            try:
                sol = np.linalg.solve(K, np.concatenate([-2 * q, b_le[list(act)]]))
            except np.linalg.LinAlgError:
                continue
            x = sol[:n]
            if np.all(A_le @ x <= b_le + 1e-10):
                f = x @ Q @ x + 2 * q @ x
                if f < best[0]:
                    best = (f, x)
    return best


@pytest.mark.parametrize("seed", range(12))
def test_random_qp_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    n, m = 3, 5
    M = rng.normal(size=(n + 2, n))
    Q = M.T @ M
    q = rng.normal(size=n)
    A = rng.normal(size=(m, n))
    b = rng.uniform(0.1, 1.0, size=m)  # x = 0 is feasible
    sol = solve_qp(Q, q, np.zeros((0, n)), np.zeros(0), A, b)
    f, x = brute_force(Q, q, A, b)
    # strictly convex: one optimum; the polished point equals the enumeration to round-off
    np.testing.assert_allclose(sol.x, x, atol=1e-8 * max(1.0, np.abs(x).max()))
    assert sol.objective == pytest.approx(f, rel=1e-9, abs=1e-12)
    # KKT
    assert np.all(sol.multipliers_le >= -1e-9)
    np.testing.assert_allclose(2 * Q @ sol.x + 2 * q + A.T @ sol.multipliers_le, 0.0,
                               atol=1e-7 * max(1.0, np.abs(q).max()))


def test_semidefinite_hessian_is_accepted():
    Q = np.diag([1.0, 0.0])
    q = np.array([-1.0, 0.0])
    A = np.array([[0.0, 1.0], [0.0, -1.0]])
    sol = solve_qp(Q, q, np.zeros((0, 2)), np.zeros(0), A, np.array([1.0, 1.0]))
    assert sol.x[0] == pytest.approx(1.0, abs=1e-9)
    assert abs(sol.x[1]) <= 1.0 + 1e-9


def test_infeasible_names_the_conflict():
    Q = np.eye(2)
    q = np.zeros(2)
    A = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]])
    b = np.array([1.0, -2.0, 5.0])  # x ≤ 1 and x ≥ 2 clash; y ≤ 5 is innocent
    with pytest.raises(InfeasibleConstraintsError) as exc:
        solve_qp(Q, q, np.zeros((0, 2)), np.zeros(0), A, b,
                 names_le=["x <= 1", "x >= 2", "y <= 5"])
    assert set(exc.value.conflicting) == {"x <= 1", "x >= 2"}
    assert "x <= 1" in str(exc.value) and "y <= 5" not in str(exc.value)
