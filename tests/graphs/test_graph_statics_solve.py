"""The LU routes of the graph statics (dynamics/graph_statics.py ``_lu_solve``) give the
least-norm least-squares solution the SVD gives (numpy's ``pinv``, an independent route):
square, wide (full row rank) and tall (full column rank) systems, and a batch holding a
singular sample, which falls back to the SVD."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.dynamics.graph_statics import _lu_solve


def _pinv_solution(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    return np.stack([np.linalg.pinv(a) @ b for a, b in zip(A, rhs, strict=True)])


@pytest.mark.parametrize("shape", [(12, 12), (9, 12), (12, 9)])
def test_lu_routes_equal_the_pseudo_inverse(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(4)
    A = rng.normal(size=(6, *shape))
    x = rng.normal(size=(6, shape[1], 2))
    rhs = A @ x  # consistent, so every route's residual is round-off
    y, res = _lu_solve(A, rhs)
    np.testing.assert_allclose(y, _pinv_solution(A, rhs), atol=1e-10)
    np.testing.assert_allclose(res, A @ y - rhs, atol=1e-12)
    assert np.abs(res).max() < 1e-10


def test_a_singular_sample_falls_back_to_the_svd() -> None:
    rng = np.random.default_rng(5)
    A = rng.normal(size=(4, 8, 8))
    A[2, 3] = A[2, 5]  # sample 2: two equal rows, LU is singular
    rhs = A @ rng.normal(size=(4, 8, 1))
    y, res = _lu_solve(A, rhs)
    np.testing.assert_allclose(y, _pinv_solution(A, rhs), atol=1e-9)
    assert np.abs(res).max() < 1e-9
