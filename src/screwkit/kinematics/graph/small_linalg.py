"""Batched linear algebra on many small matrices (a six-bar's 12×6 passive block at every
sample): the eigenvalues of Gram matrices and the least-squares inverse by QR, compiled by
numba one matrix at a time (graph/small_kernels.py), or by numpy's batched LAPACK calls.

- :func:`gram_eigenvalues`: λ(AᵀA) (or AAᵀ, the smaller), largest first, by Householder
  tridiagonalisation and the implicit QL iteration (Golub & Van Loan, Matrix Computations,
  4th ed., §8.3.1 and §8.3.3), as LAPACK's dsyev does; numpy: ``eigvalsh``.
- :func:`qr_inverse`: R⁻¹Q₁ᵀ for A = Q₁R of full column rank (Householder QR, Golub & Van
  Loan §5.2.2; the least-squares solution map, §5.3.3), and R's diagonal; numpy: ``qr``, then
  ``solve``.

Both routes are backward stable and agree to round-off (tests/kinematics/test_small_linalg.py).
For 6×6 and 7×7 matrices LAPACK's cost per matrix is mostly its calling overhead (workspace
queries, copies to column order); the compiled loops run ~3× faster here. numba is optional
(the ``fast`` extra): :data:`AVAILABLE` is False without it or with SCREWKIT_NO_NUMBA set, and
numpy then does the work. Loading them costs once per process what they save on some 10⁵
matrices (numba's import and the kernels' disk cache, ~0.5–1 s; compiling them the first time,
a few seconds, cached next to graph/small_kernels.py when the folder is writable), so a call
loads them only for a batch of at least :data:`LOAD_FROM` matrices (a motion of that many
samples), and every later call, large or small, uses them.
"""

from __future__ import annotations

import importlib.util
import os
import sys

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: numba is installed and not turned off by SCREWKIT_NO_NUMBA (imported on first use only)
AVAILABLE = (importlib.util.find_spec("numba") is not None
             and not os.environ.get("SCREWKIT_NO_NUMBA"))
#: matrices in one call from which the kernels are loaded (module docstring)
LOAD_FROM = 2000


def compiled(count: int) -> bool:
    """Whether a batch of ``count`` matrices runs compiled: numba is there and the kernels are
    loaded already or worth loading for it."""
    return AVAILABLE and count > 0 and (
        count >= LOAD_FROM or "screwkit.kinematics.graph.small_kernels" in sys.modules)


def gram_eigenvalues(A: Array) -> Array:
    """Eigenvalues (N, k), largest first, of the smaller Gram matrix of each A[s] (N, a, b):
    AᵀA if a ≥ b, else AAᵀ (k = min(a, b)); every value NaN at a sample with a non-finite
    entry."""
    N, a, b = A.shape
    k = min(a, b)
    if N == 0 or k == 0:
        return np.zeros((N, k))
    if compiled(N):
        from screwkit.kinematics.graph import small_kernels

        out = np.empty((N, k))
        small_kernels.gram_eigenvalues(np.asarray(A, dtype=float), out)  # any strides
        return out
    At = np.swapaxes(A, 1, 2)
    G = At @ A if a >= b else A @ At
    ok = np.isfinite(np.einsum("nii->n", G))  # Σ of A's squared entries
    if not ok.all():
        G[~ok] = np.eye(k)
    lam = np.linalg.eigvalsh(G)[:, ::-1]
    lam[~ok] = np.nan
    return np.ascontiguousarray(lam)


def qr_inverse(A: Array) -> tuple[Array, Array]:
    """R⁻¹Q₁ᵀ (N, b, a) for each A[s] = Q₁R (N, a, b), a ≥ b: x = R⁻¹Q₁ᵀ y solves A x = y in
    the least-squares sense where A has full column rank; and R's diagonal (N, b). Where R is
    singular the inverse is not finite (the caller takes another route there)."""
    N, a, b = A.shape
    if compiled(N):
        from screwkit.kinematics.graph import small_kernels

        P = np.empty((N, b, a))
        rdiag = np.empty((N, b))
        small_kernels.qr_inverse(np.asarray(A, dtype=float), P, rdiag)
        return P, rdiag
    Q, R = np.linalg.qr(A)
    rdiag = np.ascontiguousarray(np.diagonal(R, axis1=1, axis2=2))
    ok = np.all(rdiag != 0.0, axis=1)
    if not ok.all():
        R[~ok] = np.eye(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        P = np.linalg.solve(R, np.swapaxes(Q, 1, 2))
    P[~ok] = np.nan
    return P, rdiag
