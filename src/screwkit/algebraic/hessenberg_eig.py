"""Eigenvalues and a few rows of the right eigenvectors of many real matrices, cheaper than a
full eigendecomposition: LAPACK's eigenvalues without vectors, the vectors by inverse
iteration on the Hessenberg form, only at the rows asked for (issue 27: the Stewart
template's 40 × 40 action matrices, whose eigenvectors are read at 8 of their 40 entries).

numpy's ``eig`` (LAPACK dgeev with right vectors) accumulates the Schur vectors through the
QR iteration and then solves and back-transforms all n eigenvectors; here the QR iteration
runs without them (dhseqr 'E': numpy's ``eigvals``, the same eigenvalues bit for bit), only
the wanted rows of Q of the Hessenberg reduction are formed (from dgehrd's reflectors, not
dorghr's whole Q), and each eigenvector is one solve with the LU of the Hessenberg H − λI
(O(n²); Wilkinson 1965, *The Algebraic Eigenvalue Problem*, ch. 9; LAPACK's dhsein), mapped
back at the wanted rows only. Inverse iteration with LAPACK's
eigenvalue is backward stable like dgeev's vectors (a residual ~ε‖A‖). Measured on 512
Stewart action matrices (40 × 40, CPU per matrix, one process, alternating, load 2.2–2.5):
0.219–0.224 ms against 0.281–0.287 by ``eig`` and 0.178–0.183 by ``eigvals`` (so ~0.04 for
Q's rows and the vectors at 8 rows); the polished and certified Stewart poses are the same
(docs/kinematics.md). LAPACK is scipy's
(``scipy.linalg.cython_lapack``), called from the compiled kernel
(:mod:`.hessenberg_kernels`); without numba the caller uses numpy's ``eig``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic import compiled

#: numba is there (the kernel is compiled); else the caller keeps numpy's eig
AVAILABLE = compiled.AVAILABLE


@lru_cache(maxsize=1)
def _routines() -> NDArray[np.int64]:
    """The addresses of LAPACK's dgebal, dgehrd and dhseqr in scipy's cython_lapack."""
    from numba.extending import get_cython_function_address

    from screwkit.algebraic import hessenberg_kernels as kernels

    return np.array([get_cython_function_address("scipy.linalg.cython_lapack", name)
                     for name in kernels.ROUTINES], dtype=np.int64)


def eig_rows(A: NDArray[np.float64], rows: NDArray[np.intp]
             ) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.bool_]]:
    """The eigenvalues (B, n) of the real matrices A (B, n, n), LAPACK's order (a complex
    pair adjacent, λ then λ̄: exact conjugates, a real one with imaginary part 0), their right
    eigenvectors' entries ``rows`` (B, m, n) (column k for eigenvalue k; any scale, exact
    conjugates for a pair, real for a real eigenvalue), and whether LAPACK succeeded for each
    (the others' values and vectors NaN). Module docstring: how."""
    from screwkit.algebraic import hessenberg_kernels as kernels

    A = np.ascontiguousarray(A, dtype=float)
    B, n, _ = A.shape
    vals = np.full((B, n), np.nan, dtype=complex)
    V = np.full((B, len(rows), n), np.nan, dtype=complex)
    ok = np.zeros(B, dtype=bool)
    kernels.eig_rows(A, np.ascontiguousarray(rows, dtype=np.int64), _routines(), vals, V, ok)
    return vals, V, ok


def prepare() -> None:
    """The kernel compiled (or loaded from numba's cache) before a batch's threads start."""
    eig_rows(np.eye(2)[None], np.arange(1))
