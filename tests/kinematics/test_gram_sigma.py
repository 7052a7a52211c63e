"""newton.gram_sigma: singular values from the Gram matrix's eigenvalues, the SVD's near
singular. Checked against matrices built from known singular values (U diag(σ) Vᵀ)."""

from __future__ import annotations

import numpy as np

from screwkit.kinematics.graph.newton import GRAM_REFINE, gram_sigma


def _built(rng: np.random.Generator, sigma: np.ndarray, rows: int) -> np.ndarray:
    """Matrices (N, rows, k) with the singular values ``sigma`` (N, k)."""
    N, k = sigma.shape
    U = np.linalg.qr(rng.standard_normal((N, rows, k)))[0]
    V = np.linalg.qr(rng.standard_normal((N, k, k)))[0]
    return np.asarray(U * sigma[:, None, :] @ np.swapaxes(V, 1, 2))


def test_regular_matrices_to_round_off() -> None:
    rng = np.random.default_rng(7)
    sigma = np.sort(rng.uniform(0.05, 3.0, (200, 6)), axis=1)[:, ::-1]
    for rows in (6, 12, 18):  # tall and square; the wide case through the transpose
        A = _built(rng, sigma, rows)
        assert np.allclose(gram_sigma(A), sigma, rtol=1e-12, atol=0)
        assert np.allclose(gram_sigma(np.swapaxes(A, 1, 2)), sigma, rtol=1e-12, atol=0)


def test_near_singular_samples_take_the_svd() -> None:
    """A σ_k of 1e-9·σ₁ is lost to the Gram route (its error there is ~ε·σ₁² / σ_k ≈ 1e-7·σ₁)
    but kept to 1e-6 relative through the SVD; a rank-deficient matrix's zero σ stays tiny."""
    rng = np.random.default_rng(8)
    sigma = np.tile([2.0, 1.5, 1.0, 0.7, 0.3, 1e-9], (50, 1))
    sigma[::2, -1] = 0.2  # every other sample regular
    A = _built(rng, sigma, 12)
    s = gram_sigma(A)
    assert np.allclose(s[:, :-1], sigma[:, :-1], rtol=1e-12, atol=0)
    assert np.allclose(s[:, -1], sigma[:, -1], rtol=1e-6, atol=0)
    assert GRAM_REFINE > 1e-7  # every singular flag (σ_r/σ₁ < 1e-7) sees the SVD's values


def test_rank_argument_and_non_finite_samples() -> None:
    rng = np.random.default_rng(9)
    sigma = np.tile([2.0, 1.0, 0.5, 0.0], (10, 1))  # rank 3
    A = _built(rng, sigma, 8)
    s = gram_sigma(A, rank=3)
    assert np.allclose(s[:, :3], sigma[:, :3], rtol=1e-12, atol=0)
    assert np.all(s[:, 3] < 1e-7)
    A[3, 0, 0] = np.nan
    s = gram_sigma(A, rank=3)
    assert np.all(np.isnan(s[3])) and np.all(np.isfinite(np.delete(s, 3, axis=0)))
    assert gram_sigma(np.zeros((0, 4, 3))).shape == (0, 3)
