"""The numba kernels of :mod:`.small_linalg` (imported by it on first use only, so that importing
screwkit does not import numba). Module-level functions, so that numba's disk cache (next to
this module) is found again by the next process; the algorithms are in :mod:`.small_linalg`'s
docstring. One matrix per loop iteration, every work array allocated once per call: for the
6×6 and 7×7 matrices of a six-bar this is what makes them cheaper than LAPACK, whose cost per
matrix is mostly its calling overhead."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

# no fastmath: the eigenvalues and solves keep IEEE arithmetic (the same round-off as the
# numpy route's order of operations allows); the numpy error model (no zero-division checks)
njit = numba.njit(cache=True, nogil=True, error_model="numpy")


@njit
def gram_eigenvalues(A: Any, out: Any) -> None:
    """out[s] (k,): the eigenvalues, largest first, of the smaller Gram matrix of A[s] (a, b)
    (AᵀA if a ≥ b, else AAᵀ; k = min(a, b)): Householder tridiagonalisation, then the implicit
    QL iteration with Wilkinson's shift (Golub & Van Loan §8.3; Numerical Recipes' tred2 and
    tqli, eigenvalues only); NaN for every eigenvalue of a sample with a non-finite entry."""
    N, ra, cb = A.shape
    tall = ra >= cb
    n = cb if tall else ra
    k = ra if tall else cb
    a = np.empty((n, n))
    d = np.empty(n)
    e = np.empty(n)
    for s in range(N):
        for i in range(n):
            for j in range(i + 1):
                acc = 0.0
                if tall:
                    for r in range(k):
                        acc += A[s, r, i] * A[s, r, j]
                else:
                    for r in range(k):
                        acc += A[s, i, r] * A[s, j, r]
                a[i, j] = acc
                a[j, i] = acc
        trace = 0.0
        for i in range(n):
            trace += a[i, i]
        if not np.isfinite(trace):  # Σ of A's squared entries: a non-finite entry
            for i in range(n):
                out[s, i] = np.nan
            continue
        tridiagonalise(a, d, e)
        ql_eigenvalues(d, e)
        for i in range(n):  # largest first (insertion sort: n is small)
            v = d[i]
            j = i - 1
            while j >= 0 and out[s, j] < v:
                out[s, j + 1] = out[s, j]
                j -= 1
            out[s, j + 1] = v


@njit
def tridiagonalise(a: Any, d: Any, e: Any) -> None:
    """Householder reduction of the symmetric a (n, n) (its lower triangle, overwritten) to
    the tridiagonal d (diagonal), e[1:] (sub-diagonal)."""
    n = a.shape[0]
    for i in range(n - 1, 0, -1):
        l = i - 1
        h = 0.0
        if l > 0:
            scale = 0.0
            for q in range(i):
                scale += abs(a[i, q])
            if scale == 0.0:
                e[i] = a[i, l]
            else:
                for q in range(i):
                    a[i, q] /= scale
                    h += a[i, q] * a[i, q]
                f = a[i, l]
                g = -np.sqrt(h) if f >= 0.0 else np.sqrt(h)
                e[i] = scale * g
                h -= f * g
                a[i, l] = f - g
                f = 0.0
                for j in range(i):
                    g = 0.0
                    for q in range(j + 1):
                        g += a[j, q] * a[i, q]
                    for q in range(j + 1, i):
                        g += a[q, j] * a[i, q]
                    e[j] = g / h
                    f += e[j] * a[i, j]
                hh = f / (h + h)
                for j in range(i):
                    f = a[i, j]
                    g = e[j] - hh * f
                    e[j] = g
                    for q in range(j + 1):
                        a[j, q] -= f * e[q] + g * a[i, q]
        else:
            e[i] = a[i, l]
    for i in range(n):
        d[i] = a[i, i]


@njit
def ql_eigenvalues(d: Any, e: Any) -> None:
    """The eigenvalues of the tridiagonal (d, e[1:]) into d (unordered), by the implicit QL
    iteration; a block that does not split in 60 iterations keeps its last values (NaN in,
    NaN out)."""
    n = d.shape[0]
    for i in range(1, n):
        e[i - 1] = e[i]
    e[n - 1] = 0.0
    for l in range(n):
        it = 0
        while True:
            m = l
            while m < n - 1:
                if abs(e[m]) <= 2.220446049250313e-16 * (abs(d[m]) + abs(d[m + 1])):
                    break
                m += 1
            if m == l or it >= 60:
                break
            it += 1
            g = (d[l + 1] - d[l]) / (2.0 * e[l])
            r = np.sqrt(g * g + 1.0)
            g = d[m] - d[l] + e[l] / (g + (r if g >= 0.0 else -r))
            sn = 1.0
            c = 1.0
            p = 0.0
            i = m - 1
            split = False
            while i >= l:
                f = sn * e[i]
                b = c * e[i]
                r = np.sqrt(f * f + g * g)
                e[i + 1] = r
                if r == 0.0:  # an exact split: deflate and go on
                    d[i + 1] -= p
                    e[m] = 0.0
                    split = True
                    break
                sn = f / r
                c = g / r
                g = d[i + 1] - p
                r = (d[i] - g) * sn + 2.0 * c * b
                p = sn * r
                d[i + 1] = g + p
                g = c * r - b
                i -= 1
            if not split:
                d[l] -= p
                e[l] = g
                e[m] = 0.0


@njit
def qr_inverse(A: Any, P: Any, rdiag: Any) -> None:
    """P[s] (b, a) = R⁻¹Q₁ᵀ for A[s] = Q₁R (a ≥ b, Householder QR; Golub & Van Loan §5.2):
    the least-squares solution map of A[s] x = y; rdiag[s] (b,) R's diagonal (a zero one makes
    P[s] non-finite: the caller takes another route there)."""
    N, a, b = A.shape
    W = np.empty((a, b))
    V = np.empty((b, a))  # Householder vectors, v_j[j:] (v_j[j] = 1 implied by beta)
    beta = np.empty(b)
    Qt = np.empty((b, a))
    for s in range(N):
        for i in range(a):
            for j in range(b):
                W[i, j] = A[s, i, j]
        for j in range(b):
            norm2 = 0.0
            for i in range(j, a):
                norm2 += W[i, j] * W[i, j]
            alpha = np.sqrt(norm2)
            if W[j, j] > 0.0:
                alpha = -alpha
            v0 = W[j, j] - alpha
            vv = norm2 - W[j, j] * W[j, j] + v0 * v0  # |v|² with v = x − αe₁
            V[j, j] = v0
            for i in range(j + 1, a):
                V[j, i] = W[i, j]
            beta[j] = 2.0 / vv if vv > 0.0 else 0.0
            W[j, j] = alpha
            for c in range(j + 1, b):  # H_j = I − β v vᵀ on the remaining columns
                t = 0.0
                for i in range(j, a):
                    t += V[j, i] * W[i, c]
                t *= beta[j]
                for i in range(j, a):
                    W[i, c] -= t * V[j, i]
        for j in range(b):  # row j of Q₁ᵀ = (H_0 ⋯ H_j e_j)ᵀ
            for i in range(a):
                Qt[j, i] = 0.0
            Qt[j, j] = 1.0
            for h in range(j, -1, -1):
                t = 0.0
                for i in range(h, a):
                    t += V[h, i] * Qt[j, i]
                t *= beta[h]
                for i in range(h, a):
                    Qt[j, i] -= t * V[h, i]
        for j in range(b):
            rdiag[s, j] = W[j, j]
        for i in range(a):  # back substitution R P[:, i] = Q₁ᵀ[:, i]
            for j in range(b - 1, -1, -1):
                t = Qt[j, i]
                for c in range(j + 1, b):
                    t -= W[j, c] * P[s, c, i]
                P[s, j, i] = t / W[j, j]
