"""Eigenvalues and rows of eigenvectors by inverse iteration on the Hessenberg form
(algebraic/hessenberg_eig.py), checked against the eigen equation itself (the residual
A v − λ v), numpy's eigvals (the same LAPACK eigenvalues) and numpy's eig (the vectors of
well-separated eigenvalues)."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.algebraic import hessenberg_eig

pytestmark = pytest.mark.skipif(not hessenberg_eig.AVAILABLE, reason="the kernel needs numba")


def _matrices(seed: int, count: int, n: int) -> np.ndarray:
    """Random real matrices with an isolated eigenvalue at each end and a badly scaled row
    and column, so that the balancing permutes and scales (dgebal 'B')."""
    A = np.random.default_rng(seed).normal(size=(count, n, n))
    A[:, 3, :] = 0.0
    A[:, 3, 3] = 2.0  # a row zero but its diagonal: an eigenvalue isolated at the bottom
    A[:, :, 7] = 0.0
    A[:, 7, 7] = -1.5  # a column likewise: isolated at the top
    A[:, 2] *= 1e4
    A[:, :, 2] /= 1e4
    return A


def test_every_eigenpair_solves_the_eigen_equation() -> None:
    """Every column v of the full vectors (all rows asked) has A v − λ v within 20 ε ‖A‖ ‖v‖
    (a backward-stable eigenvector's residual; measured ≤ 2e-15 relative), the eigenvalues
    are numpy's eigvals' bit for bit, pairs are exact conjugates and real ones real."""
    A = _matrices(1, 40, 12)
    vals, V, ok = hessenberg_eig.eig_rows(A, np.arange(12))
    assert ok.all()
    eps = np.finfo(float).eps
    for g in range(len(A)):
        r = A[g] @ V[g] - V[g] * vals[g][None]
        scale = np.linalg.norm(A[g]) * np.linalg.norm(V[g], axis=0)
        assert np.all(np.linalg.norm(r, axis=0) <= 20 * eps * scale), g
        assert np.array_equal(np.sort_complex(vals[g]),
                              np.sort_complex(np.linalg.eigvals(A[g])))
        assert np.array_equal(np.sort_complex(vals[g]), np.sort_complex(vals[g].conj()))
        pair = vals[g].imag > 0
        k = np.flatnonzero(pair)
        assert np.array_equal(vals[g, k + 1], vals[g, k].conj())
        assert np.array_equal(V[g][:, k + 1], V[g][:, k].conj())
        assert np.all(V[g][:, vals[g].imag == 0].imag == 0)


def test_some_rows_are_those_rows_of_numpys_eigenvectors() -> None:
    """Rows asked in any order are those rows of numpy's eig vectors, up to each vector's
    scale (compared as ratios to one row; eigenvalues at least 1e-2 apart, well separated),
    to 1e-9."""
    A = _matrices(2, 30, 10)
    rows = np.array([7, 3, 0, 9, 2])
    vals, V, ok = hessenberg_eig.eig_rows(A, rows)
    assert ok.all()
    for g in range(len(A)):
        w, U = np.linalg.eig(A[g])
        for k in range(10):
            j = int(np.argmin(np.abs(w - vals[g, k])))
            if np.sort(np.abs(w - w[j]))[1] < 1e-2:
                continue
            a, b = V[g][:, k], U[rows, j]
            ref = int(np.argmax(np.abs(b)))
            assert np.abs(a / a[ref] - b / b[ref]).max() <= 1e-9, (g, k)


def test_a_matrix_lapack_cannot_take_is_marked() -> None:
    """A matrix that is not finite is marked (NaN out), the others are solved."""
    A = _matrices(3, 3, 8)
    A[1, 0, 0] = np.nan
    vals, V, ok = hessenberg_eig.eig_rows(A, np.arange(2))
    assert ok.tolist() == [True, False, True]
    assert np.isnan(vals[1]).all() and np.isnan(V[1]).all() and np.isfinite(vals[[0, 2]]).all()
