"""graph/small_linalg.py: the compiled Gram eigenvalues and QR least-squares inverse against
matrices of known singular values and against LAPACK (numpy's route, which is also what runs
without numba), on tall, wide and square shapes, strided views, rank-deficient and non-finite
samples; and the Watt six-bar's drawn mode the same by both routes."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import numpy as np
import pytest

from screwkit.kinematics.graph import small_linalg
from screwkit.kinematics.graph.small_linalg import gram_eigenvalues, qr_inverse

ROOT = Path(__file__).resolve().parents[2]


def _built(rng: np.random.Generator, sigma: np.ndarray, rows: int) -> np.ndarray:
    """Matrices (N, rows, k) with the singular values ``sigma`` (N, k)."""
    N, k = sigma.shape
    U = np.linalg.qr(rng.standard_normal((N, rows, k)))[0]
    V = np.linalg.qr(rng.standard_normal((N, k, k)))[0]
    return np.asarray(U * sigma[:, None, :] @ np.swapaxes(V, 1, 2))


def _route(monkeypatch: pytest.MonkeyPatch, compiled: bool) -> None:
    """The compiled route for every batch, however small, or numpy's."""
    monkeypatch.setattr(small_linalg, "AVAILABLE", compiled)
    monkeypatch.setattr(small_linalg, "LOAD_FROM", 0)


def test_loaded_only_for_a_large_batch_or_once_loaded(monkeypatch: pytest.MonkeyPatch) -> None:
    name = "screwkit.kinematics.graph.small_kernels"
    kernels = importlib.import_module(name)
    monkeypatch.setattr(small_linalg, "AVAILABLE", True)
    monkeypatch.delitem(sys.modules, name)  # not loaded yet
    assert not small_linalg.compiled(small_linalg.LOAD_FROM - 1)
    assert not small_linalg.compiled(0)
    assert small_linalg.compiled(small_linalg.LOAD_FROM)
    monkeypatch.setitem(sys.modules, name, kernels)  # loaded
    assert small_linalg.compiled(1)
    monkeypatch.setattr(small_linalg, "AVAILABLE", False)
    assert not small_linalg.compiled(small_linalg.LOAD_FROM)


def test_numba_is_there_for_the_tests() -> None:
    """numba is in the dev extra: without it the comparisons below would compare the numpy
    route with itself."""
    assert small_linalg.AVAILABLE


@pytest.mark.parametrize("compiled", [True, False])
def test_gram_eigenvalues_are_the_squared_singular_values(monkeypatch: pytest.MonkeyPatch,
                                                          compiled: bool) -> None:
    _route(monkeypatch, compiled)
    rng = np.random.default_rng(11)
    for k, rows in ((1, 1), (1, 4), (3, 3), (6, 12), (7, 7), (7, 18), (9, 12)):
        sigma = np.sort(rng.uniform(0.05, 3.0, (100, k)), axis=1)[:, ::-1]
        A = _built(rng, sigma, rows)
        for M in (A, np.swapaxes(A, 1, 2)):  # tall and wide (AAᵀ), the latter a strided view
            lam = gram_eigenvalues(M)
            assert lam.shape == sigma.shape
            assert np.allclose(lam, sigma ** 2, rtol=1e-12, atol=0)


def test_gram_eigenvalues_compiled_as_lapack(monkeypatch: pytest.MonkeyPatch) -> None:
    """Random and rank-deficient matrices, the columns taken by index (the layout of the
    passive block J[:, :, passive]), a NaN and an inf sample: both routes agree to round-off
    of the largest eigenvalue and put NaN at the same samples."""
    rng = np.random.default_rng(12)
    J = rng.standard_normal((300, 12, 7))
    J[:50, :, 6] = J[:50, :, 0] - 2.0 * J[:50, :, 3]  # rank 6
    J[60, 2, 1] = np.nan
    J[61, 0, 2] = np.inf
    for A in (J, J[:, :, [1, 2, 3, 4, 5, 6]], J[:, :6, :]):
        _route(monkeypatch, True)
        got = gram_eigenvalues(A)
        _route(monkeypatch, False)
        ref = gram_eigenvalues(A)
        bad = np.isnan(ref[:, 0])
        assert bad[[60, 61]].all() and bad.sum() == 2
        assert np.isnan(got[bad]).all() and np.isfinite(got[~bad]).all()
        scale = ref[~bad, :1]
        assert np.all(np.abs(got[~bad] - ref[~bad]) <= 1e-13 * scale)
        assert np.all(np.diff(got[~bad], axis=1) <= 0.0)  # largest first


@pytest.mark.parametrize("compiled", [True, False])
def test_qr_inverse_is_the_least_squares_solution(monkeypatch: pytest.MonkeyPatch,
                                                  compiled: bool) -> None:
    """R⁻¹Q₁ᵀ against the SVD's pseudo-inverse (to round-off times the condition number) and
    R's diagonal against |R| from numpy's QR; a matrix with a zero column has no finite
    inverse."""
    _route(monkeypatch, compiled)
    rng = np.random.default_rng(13)
    for k, rows in ((1, 3), (6, 6), (6, 12), (7, 18)):
        sigma = np.sort(rng.uniform(0.1, 3.0, (80, k)), axis=1)[:, ::-1]
        A = _built(rng, sigma, rows)
        P, rdiag = qr_inverse(A)
        ref = np.linalg.pinv(A)
        assert np.abs(P - ref).max() <= 1e-12 * np.abs(ref).max()
        R = np.linalg.qr(A)[1]
        assert np.allclose(np.abs(rdiag), np.abs(np.diagonal(R, axis1=1, axis2=2)),
                           rtol=1e-12, atol=0)
    A = rng.standard_normal((5, 12, 6))
    A[2, :, 3] = 0.0
    P, _ = qr_inverse(A[:, :, [0, 1, 2, 3, 4, 5]])  # strided, as J[:, :, passive]
    assert not np.isfinite(P[2]).all()
    assert np.allclose(np.delete(P, 2, axis=0), np.linalg.pinv(np.delete(A, 2, axis=0)),
                       rtol=0, atol=1e-12 * np.abs(P[[0, 1, 3, 4]]).max())


def test_watt_drawn_mode_the_same_by_both_routes(monkeypatch: pytest.MonkeyPatch) -> None:
    """The Watt six-bar's drawn mode (the closed forms, rates and accelerations through the QR
    inverse, three condition numbers through the Gram eigenvalues) compiled and by numpy: the
    same to round-off."""
    import screwkit as sk
    from screwkit.kinematics.graph import solve_mechanism

    mech = sk.load_spec(ROOT / "examples" / "mechanisms" / "watt_sixbar.toml").mechanism
    theta = np.radians(np.arange(0.0, 360.0, 0.5))
    motion = {}
    for compiled in (True, False):
        _route(monkeypatch, compiled)
        motion[compiled] = solve_mechanism(mech, theta, rates=2.0, accelerations=0.5).modes[0]
    a, b = motion[True], motion[False]
    for name in a.velocities:
        for table in ("velocities", "accelerations"):
            x, y = getattr(a, table)[name], getattr(b, table)[name]
            assert np.abs(x - y).max() <= 1e-12 * max(1.0, np.abs(y).max()), (table, name)
    assert set(a.jacobian_condition) == {"passive", "closure", "platform_held"}
    for name, c in a.jacobian_condition.items():
        assert np.allclose(c, b.jacobian_condition[name], rtol=1e-10, atol=0), name
    assert (a.singular_class == b.singular_class).all()
