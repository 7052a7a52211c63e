"""The numba kernels of :mod:`.compiled` (imported by it on first use only, so that importing
screwkit does not import numba). Module-level functions, so that numba's disk cache (next to
this module) is found again by the next process; see :mod:`.compiled` for the algorithm."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

# fastmath without nnan/ninf: the NaN and infinity tests of the step control stay exact;
# the numpy error model: no zero-division checks (a zero pivot is caught before dividing)
njit = numba.njit(cache=True, nogil=True, error_model="numpy",
                  fastmath={"contract", "reassoc", "nsz", "arcp"})
#: the step, inlined into the path loop by numba (as it was before the two were split)
njit_inline = numba.njit(cache=True, nogil=True, error_model="numpy",
                         fastmath={"contract", "reassoc", "nsz", "arcp"}, inline="always")


@njit
def evaluate(vals: Any, ck: Any, ci: Any, cl: Any, K: int,
             L: Any, linear: Any, patch: Any, y: Any, sigma: complex, dsigma: complex,
             want_t: bool, V: Any, pw: Any, H: Any, J: Any, Ht: Any) -> None:
    """H, J (and ∂H/∂τ when want_t) of one path at y, σ; vals (m, C) its instance's
    Qt, L (K_L, N_L, m) its linear forms."""
    m = y.shape[0]
    n = m - 1
    C = V.shape[0]
    for c in range(C):
        V[c] = 0.0
    for j in range(m):  # V = y·Qt, Qt (m, C) dense: a contiguous inner loop
        yj = y[j]
        for c in range(C):
            V[c] += yj * vals[j, c]
    pw[0] = 1.0
    for k in range(1, K):
        pw[k] = pw[k - 1] * sigma
    for i in range(n):
        H[i] = 0.0
        Ht[i] = 0.0
        for j in range(m):
            J[i, j] = 0.0
    for c in range(V.shape[0]):
        k, i, l_ = ck[c], ci[c], cl[c]
        v = V[c]
        H[i] += pw[k] * y[l_] * v
        J[i, l_] += 2.0 * pw[k] * v
        if want_t and k > 0:
            Ht[i] += k * pw[k - 1] * dsigma * y[l_] * v
    KL = L.shape[0]
    for e in range(linear.shape[0]):
        r = linear[e]
        for j in range(m):
            form = 0.0j
            for k in range(KL):
                form += pw[k] * L[k, e, j]
            H[r] += form * y[j]
            J[r, j] += form
            if want_t:
                for k in range(1, KL):
                    Ht[r] += k * pw[k - 1] * dsigma * L[k, e, j] * y[j]
    s = -1.0 + 0.0j
    for j in range(m):
        s += patch[j] * y[j]
        J[n, j] = patch[j]
    H[n] = s
    Ht[n] = 0.0


@njit
def solve(J: Any, A: Any, piv: Any, b: Any) -> bool:
    """LU of J (copied into A, partial pivoting); b (m, r) overwritten by J⁻¹b. False
    (b filled with NaN) when a pivot is zero or not finite."""
    m = J.shape[0]
    for i in range(m):
        for j in range(m):
            A[i, j] = J[i, j]
    for col in range(m):
        best, p = -1.0, col
        for i in range(col, m):
            a = abs(A[i, col])
            if a > best:
                best, p = a, i
        if not (best > 0.0) or not np.isfinite(best):
            b[:, :] = np.nan
            return False
        piv[col] = p
        if p != col:
            for j in range(m):
                A[col, j], A[p, j] = A[p, j], A[col, j]
            for r in range(b.shape[1]):
                b[col, r], b[p, r] = b[p, r], b[col, r]
        inv = 1.0 / A[col, col]
        for i in range(col + 1, m):
            f = A[i, col] * inv
            if f != 0:
                for j in range(col + 1, m):
                    A[i, j] -= f * A[col, j]
                for r in range(b.shape[1]):
                    b[i, r] -= f * b[col, r]
    for r in range(b.shape[1]):
        for i in range(m - 1, -1, -1):
            s = b[i, r]
            for j in range(i + 1, m):
                s -= A[i, j] * b[j, r]
            b[i, r] = s / A[i, i]
    return True


@njit
def curve(kind: int, radius: float, tau: float) -> tuple[complex, complex]:
    if kind == 0:
        return tau + 0.0j, 1.0 + 0.0j
    turn = radius * np.exp(1j * tau)
    return 1.0 - turn, -1j * turn


@njit
def velocity(vals: Any, ck: Any, ci: Any, cl: Any, K: int,
             L: Any, linear: Any, patch: Any, y: Any, kind: int, radius: float,
             tau: float, out: Any, V: Any, pw: Any, H: Any, J: Any, Ht: Any, A: Any,
             piv: Any, b: Any) -> None:
    sigma, dsigma = curve(kind, radius, tau)
    evaluate(vals, ck, ci, cl, K, L, linear, patch, y, sigma, dsigma, True,
             V, pw, H, J, Ht)
    for i in range(y.shape[0]):
        b[i, 0] = Ht[i]
    solve(J, A, piv, b[:, :1])
    for i in range(y.shape[0]):
        out[i] = -b[i, 0]


@njit_inline
def step(vp: Any, ck: Any, ci: Any, cl: Any, K: int, L: Any, linear: Any, patch: Any,
         kind: int, r: float, y: Any, v: Any, tau: float, hs: float, k2: Any, k3: Any,
         k4: Any, z: Any, yp: Any, y1: Any, V: Any, pw: Any, H: Any, J: Any, Ht: Any, A: Any,
         piv: Any, b: Any) -> tuple[float, float, bool]:
    """One predictor–corrector step of one path from y (velocity v) at τ over hs: the
    corrected point in z, dy/dτ there in −b[:, 1]; the ∞-norms of both Newton corrections
    (NaN when not finite) and whether z is finite."""
    m = y.shape[0]
    # RK4 predictor (k1 = v, the velocity kept from the last corrector)
    for i in range(m):
        z[i] = y[i] + 0.5 * hs * v[i]
    velocity(vp, ck, ci, cl, K, L, linear, patch, z, kind, r,
             tau + 0.5 * hs, k2, V, pw, H, J, Ht, A, piv, b)
    for i in range(m):
        z[i] = y[i] + 0.5 * hs * k2[i]
    velocity(vp, ck, ci, cl, K, L, linear, patch, z, kind, r,
             tau + 0.5 * hs, k3, V, pw, H, J, Ht, A, piv, b)
    for i in range(m):
        z[i] = y[i] + hs * k3[i]
    velocity(vp, ck, ci, cl, K, L, linear, patch, z, kind, r,
             tau + hs, k4, V, pw, H, J, Ht, A, piv, b)
    for i in range(m):
        yp[i] = y[i] + hs / 6.0 * (v[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    # two Newton corrections at τ + h; the second evaluation also gives dy/dτ
    sigma, dsigma = curve(kind, r, tau + hs)
    evaluate(vp, ck, ci, cl, K, L, linear, patch, yp, sigma, dsigma,
             False, V, pw, H, J, Ht)
    for i in range(m):
        b[i, 0] = H[i]
    solve(J, A, piv, b[:, :1])
    first = 0.0
    for i in range(m):
        y1[i] = yp[i] - b[i, 0]
        a = abs(b[i, 0])
        first = a if (a > first or np.isnan(a)) and not np.isnan(first) else first
    evaluate(vp, ck, ci, cl, K, L, linear, patch, y1, sigma, dsigma,
             True, V, pw, H, J, Ht)
    for i in range(m):
        b[i, 0] = H[i]
        b[i, 1] = Ht[i]
    solve(J, A, piv, b)
    second = 0.0
    finite = True
    for i in range(m):
        z[i] = y1[i] - b[i, 0]
        a = abs(b[i, 0])
        second = a if (a > second or np.isnan(a)) and not np.isnan(second) \
            else second
        finite = finite and np.isfinite(z[i].real) and np.isfinite(z[i].imag)
    return first, second, finite


@njit
def track(vals: Any, ck: Any, ci: Any, cl: Any, K: int,
          Ls: Any, linear: Any, patch: Any, instance: Any, linear_of: Any, y0: Any,
          tau0: Any, tau1: Any, kind: int, radius: Any, initial_step: float,
          max_step: float, min_step: float, max_steps: int, ptol: float, ctol: float,
          contraction: float) -> tuple[Any, Any, Any]:
    P, m = y0.shape
    C = ck.shape[0]
    y_out = y0.copy()
    reached = np.zeros(P, dtype=np.bool_)
    steps = np.zeros(P, dtype=np.int64)
    V = np.empty(C, dtype=np.complex128)
    pw = np.empty(max(K, Ls.shape[1]), dtype=np.complex128)
    H = np.empty(m, dtype=np.complex128)
    Ht = np.empty(m, dtype=np.complex128)
    J = np.empty((m, m), dtype=np.complex128)
    A = np.empty((m, m), dtype=np.complex128)
    piv = np.empty(m, dtype=np.int64)
    b = np.empty((m, 2), dtype=np.complex128)
    y = np.empty(m, dtype=np.complex128)
    v = np.empty(m, dtype=np.complex128)
    k2 = np.empty(m, dtype=np.complex128)
    k3 = np.empty(m, dtype=np.complex128)
    k4 = np.empty(m, dtype=np.complex128)
    z = np.empty(m, dtype=np.complex128)
    yp = np.empty(m, dtype=np.complex128)
    y1 = np.empty(m, dtype=np.complex128)
    for p in range(P):
        vp = vals[instance[p]]
        L = Ls[linear_of[p]]
        r = radius[p]
        for i in range(m):
            y[i] = y0[p, i]
        tau = tau0[p]
        span = abs(tau1[p] - tau)
        h = min(initial_step, max_step)
        if span == 0.0:
            reached[p] = True
            continue
        velocity(vp, ck, ci, cl, K, L, linear, patch, y, kind, r, tau, v,
                 V, pw, H, J, Ht, A, piv, b)
        floor = min_step * max(span, 1.0)
        while True:
            left = tau1[p] - tau
            hs = min(h, left)
            last = hs >= left
            first, second, finite = step(vp, ck, ci, cl, K, L, linear, patch, kind, r, y, v,
                                         tau, hs, k2, k3, k4, z, yp, y1, V, pw, H, J, Ht, A,
                                         piv, b)
            big = 0.0
            for i in range(m):
                big = max(big, abs(y[i]))
            scale = 1.0 + big
            first /= scale
            second /= scale
            accept = (first <= ptol and second <= ctol
                      and (second <= contraction * first or first <= 1e-12) and finite)
            ratio = 0.6 * (ptol / max(first, 1e-300)) ** 0.2
            if not np.isfinite(ratio):
                ratio = 0.25
            if accept:
                for i in range(m):
                    y[i] = z[i]
                    v[i] = -b[i, 1]
                tau = tau1[p] if last else tau + hs
                h = min(max(hs, h) * min(max(ratio, 1.0), 2.0), max_step)
            else:
                h = hs * min(max(ratio, 0.25), 0.5)
            steps[p] += 1
            if accept and last:
                reached[p] = True
                break
            if h < floor or steps[p] >= max_steps:
                break
        for i in range(m):
            y_out[p, i] = y[i]
    return y_out, reached, steps
