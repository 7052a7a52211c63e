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
def evaluate(qr: Any, qi: Any, ck: Any, cu: Any, K: int,
             L: Any, linear: Any, patch: Any, y: Any, sigma: complex, dsigma: complex,
             want_t: bool, Vr: Any, Vi: Any, pw: Any, W: Any, T: Any, H: Any, J: Any,
             Ht: Any) -> None:
    """H, J (and ∂H/∂τ when want_t) of one path at y, σ; qr + i·qi (m, C) its instance's
    Qt, L (K_L, N_L, m) its linear forms. V = y·Qt in real arithmetic (the real and imaginary
    parts apart: a contiguous loop the compiler vectorises), then W_il = Σ_k σ^k (Q_ik y)_l
    (column c adds to the cell cu[c] = i·m + l), so ∂F_i/∂y_l = 2 W_il and F_i = Σ_l W_il y_l;
    likewise T_il = Σ_k k σ^(k−1) (Q_ik y)_l and ∂F_i/∂σ = Σ_l T_il y_l."""
    m = y.shape[0]
    n = m - 1
    C = Vr.shape[0]
    for c in range(C):
        Vr[c] = 0.0
        Vi[c] = 0.0
    for j in range(m):  # V = y·Qt, Qt (m, C) dense: a contiguous inner loop
        yr = y[j].real
        yi = y[j].imag
        for c in range(C):
            a = qr[j, c]
            b = qi[j, c]
            Vr[c] += yr * a - yi * b
            Vi[c] += yr * b + yi * a
    pw[0] = 1.0
    for k in range(1, K):
        pw[k] = pw[k - 1] * sigma
    for u in range(n * m):
        W[u] = 0.0
        T[u] = 0.0
    for c in range(C):
        k = ck[c]
        v = complex(Vr[c], Vi[c])
        W[cu[c]] += pw[k] * v
        if want_t and k > 0:
            T[cu[c]] += k * pw[k - 1] * v
    for i in range(n):
        f = 0.0j
        t = 0.0j
        for j in range(m):
            w = W[i * m + j]
            f += w * y[j]
            J[i, j] = 2.0 * w
            if want_t:
                t += T[i * m + j] * y[j]
        H[i] = f
        Ht[i] = t * dsigma
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
def solve(A: Any, b: Any) -> bool:
    """LU of A in place (partial pivoting on |re| + |im|, LAPACK's choice in zgetrf); b (m, r)
    overwritten by A⁻¹b. False (b filled with NaN) when a pivot is zero or not finite."""
    m = A.shape[0]
    for col in range(m):
        best, p = -1.0, col
        for i in range(col, m):
            a = abs(A[i, col].real) + abs(A[i, col].imag)
            if a > best:
                best, p = a, i
        if not (best > 0.0) or not np.isfinite(best):
            b[:, :] = np.nan
            return False
        if p != col:
            for j in range(col, m):
                A[col, j], A[p, j] = A[p, j], A[col, j]
            for r in range(b.shape[1]):
                b[col, r], b[p, r] = b[p, r], b[col, r]
        inv = 1.0 / A[col, col]
        for i in range(col + 1, m):
            f = A[i, col] * inv
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
def velocity(qr: Any, qi: Any, ck: Any, cu: Any, K: int,
             L: Any, linear: Any, patch: Any, y: Any, kind: int, radius: float,
             tau: float, out: Any, ws: Any, b: Any) -> None:
    Vr, Vi, pw, W, T, H, J, Ht = ws
    sigma, dsigma = curve(kind, radius, tau)
    evaluate(qr, qi, ck, cu, K, L, linear, patch, y, sigma, dsigma, True,
             Vr, Vi, pw, W, T, H, J, Ht)
    for i in range(y.shape[0]):
        b[i, 0] = Ht[i]
    solve(J, b[:, :1])
    for i in range(y.shape[0]):
        out[i] = -b[i, 0]


@njit_inline
def step(qr: Any, qi: Any, ck: Any, cu: Any, K: int, L: Any, linear: Any, patch: Any,
         kind: int, r: float, y: Any, v: Any, tau: float, hs: float, k2: Any, k3: Any,
         k4: Any, z: Any, yp: Any, y1: Any, ws: Any, b: Any) -> tuple[float, float, bool]:
    """One predictor–corrector step of one path from y (velocity v) at τ over hs: the
    corrected point in z, dy/dτ there in −b[:, 1]; the ∞-norms of both Newton corrections
    (NaN when not finite) and whether z is finite."""
    m = y.shape[0]
    # RK4 predictor (k1 = v, the velocity kept from the last corrector)
    for i in range(m):
        z[i] = y[i] + 0.5 * hs * v[i]
    velocity(qr, qi, ck, cu, K, L, linear, patch, z, kind, r, tau + 0.5 * hs, k2, ws, b)
    for i in range(m):
        z[i] = y[i] + 0.5 * hs * k2[i]
    velocity(qr, qi, ck, cu, K, L, linear, patch, z, kind, r, tau + 0.5 * hs, k3, ws, b)
    for i in range(m):
        z[i] = y[i] + hs * k3[i]
    velocity(qr, qi, ck, cu, K, L, linear, patch, z, kind, r, tau + hs, k4, ws, b)
    for i in range(m):
        yp[i] = y[i] + hs / 6.0 * (v[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    # two Newton corrections at τ + h; the second evaluation also gives dy/dτ
    Vr, Vi, pw, W, T, H, J, Ht = ws
    sigma, dsigma = curve(kind, r, tau + hs)
    evaluate(qr, qi, ck, cu, K, L, linear, patch, yp, sigma, dsigma,
             False, Vr, Vi, pw, W, T, H, J, Ht)
    for i in range(m):
        b[i, 0] = H[i]
    solve(J, b[:, :1])
    first = 0.0
    for i in range(m):
        y1[i] = yp[i] - b[i, 0]
        a = abs(b[i, 0])
        first = a if (a > first or np.isnan(a)) and not np.isnan(first) else first
    evaluate(qr, qi, ck, cu, K, L, linear, patch, y1, sigma, dsigma,
             True, Vr, Vi, pw, W, T, H, J, Ht)
    for i in range(m):
        b[i, 0] = H[i]
        b[i, 1] = Ht[i]
    solve(J, b)
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
def track(qrs: Any, qis: Any, ck: Any, cu: Any, K: int,
          Ls: Any, linear: Any, patch: Any, instance: Any, linear_of: Any, y0: Any,
          tau0: Any, tau1: Any, kind: int, radius: Any, initial_step: float,
          max_step: float, min_step: float, max_steps: int, ptol: float, ctol: float,
          contraction: float, converged: float) -> tuple[Any, Any, Any]:
    P, m = y0.shape
    C = ck.shape[0]
    y_out = y0.copy()
    reached = np.zeros(P, dtype=np.bool_)
    steps = np.zeros(P, dtype=np.int64)
    ws = (np.empty(C), np.empty(C), np.empty(max(K, Ls.shape[1]), dtype=np.complex128),
          np.empty(m * m, dtype=np.complex128), np.empty(m * m, dtype=np.complex128),
          np.empty(m, dtype=np.complex128), np.empty((m, m), dtype=np.complex128),
          np.empty(m, dtype=np.complex128))
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
        qr = qrs[instance[p]]
        qi = qis[instance[p]]
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
        velocity(qr, qi, ck, cu, K, L, linear, patch, y, kind, r, tau, v, ws, b)
        floor = min_step * max(span, 1.0)
        while True:
            left = tau1[p] - tau
            hs = min(h, left)
            last = hs >= left
            first, second, finite = step(qr, qi, ck, cu, K, L, linear, patch, kind, r, y, v,
                                         tau, hs, k2, k3, k4, z, yp, y1, ws, b)
            big = 0.0
            for i in range(m):
                big = max(big, abs(y[i]))
            scale = 1.0 + big
            first /= scale
            second /= scale
            accept = (first <= ptol and second <= ctol
                      and (second <= contraction * first
                           or max(first, second) <= converged) and finite)
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


@njit
def term_values(coef: Any, sym: Any, pw: Any, eq: Any, n: int, x: Any, p: Any, F: Any,
                J: Any) -> None:
    """F (B, N) and ∂F/∂x (B, N, n) of the term table at the points x (B, n), parameters
    p (B, k), added into the zeroed F and J: per term its factors' powers, their prefix and
    suffix products, and the derivative by each unknown factor (the sums of
    :meth:`.polynomial.PolynomialSystem.evaluate`, one point at a time)."""
    B = x.shape[0]
    T, w = sym.shape
    vals = np.empty(w, dtype=np.complex128)
    pre = np.empty(w + 1, dtype=np.complex128)
    suf = np.empty(w + 1, dtype=np.complex128)
    for b in range(B):
        for t in range(T):
            for f in range(w):
                s = sym[t, f]
                z = x[b, s] if s < n else p[b, s - n]
                v = 1.0 + 0.0j
                for _ in range(pw[t, f]):
                    v *= z
                vals[f] = v
            pre[0] = 1.0
            suf[w] = 1.0
            for f in range(w):
                pre[f + 1] = pre[f] * vals[f]
                suf[w - 1 - f] = suf[w - f] * vals[w - 1 - f]
            c = coef[t]
            i = eq[t]
            F[b, i] += c * pre[w]
            for f in range(w):
                s = sym[t, f]
                e = pw[t, f]
                if e > 0 and s < n:
                    zp = 1.0 + 0.0j
                    for _ in range(e - 1):
                        zp *= x[b, s]
                    J[b, i, s] += (c * e) * zp * pre[f] * suf[f + 1]


@njit_inline
def newton_step(J: Any, r: Any, x: Any, b: int, n: int, settled: float) -> bool:
    """One Newton step x[b] −= J⁻¹ r (r (N, 1) holds F, overwritten): whether to go on, i.e.
    the step was finite and J not singular, and the step was above ``settled`` relative to
    1 + max|x[b]| (:func:`newton`, :func:`newton_quadrics`)."""
    if not solve(J, r) or not np.isfinite(r).all():
        return False
    big, top = 0.0, 0.0
    for i in range(n):
        big = max(big, abs(r[i, 0]))
        top = max(top, abs(x[b, i]))
        x[b, i] -= r[i, 0]
    return big / (1.0 + top) > settled


@njit
def newton(coef: Any, sym: Any, pw: Any, eq: Any, n: int, x: Any, p: Any, steps: int,
           settled: float) -> None:
    """Up to ``steps`` Newton steps on the term table's F(·; p) from each point x (P, n) in
    place (p (P, k)), a point's steps ending once one is at most ``settled`` relative to
    1 + max|x|, or its F, ∂F/∂x or step is not finite, or ∂F/∂x is singular (the point is
    then left where it is): :func:`.loop6r_solve`'s polish, one point at a time."""
    P = x.shape[0]
    N = n
    F = np.empty((1, N), dtype=np.complex128)
    J = np.empty((1, N, n), dtype=np.complex128)
    r = np.empty((N, 1), dtype=np.complex128)
    for b in range(P):
        for _ in range(steps):
            F[:] = 0.0
            J[:] = 0.0
            term_values(coef, sym, pw, eq, n, x[b:b + 1], p[b:b + 1], F, J)
            if not (np.isfinite(F).all() and np.isfinite(J).all()):
                break
            for i in range(N):
                r[i, 0] = F[0, i]
            if not newton_step(J[0], r, x, b, n, settled):
                break


@njit
def newton_quadrics(Q: Any, inst: Any, x: Any, steps: int, settled: float) -> None:
    """:func:`newton` on symmetric quadrics Q (B, N, n + 1, n + 1) (point b's are
    Q[inst[b]]): F_i = zᵀ Q_i z, ∂F_i/∂x = 2 (Q_i z)[:n], z = (x, 1), the same stopping
    rules, x (P, n) in place."""
    P, n = x.shape
    N = Q.shape[1]
    z = np.empty(n + 1, dtype=np.complex128)
    J = np.empty((N, n), dtype=np.complex128)
    r = np.empty((N, 1), dtype=np.complex128)
    for b in range(P):
        q = Q[inst[b]]
        for _ in range(steps):
            for k in range(n):
                z[k] = x[b, k]
            z[n] = 1.0
            finite = True
            for i in range(N):
                f = 0j
                for j in range(n + 1):
                    s = 0j
                    for k in range(n + 1):
                        s += q[i, j, k] * z[k]
                    f += s * z[j]
                    if j < n:
                        J[i, j] = 2.0 * s
                r[i, 0] = f
                finite = finite and np.isfinite(f)
            if not (finite and np.isfinite(J).all()):
                break
            if not newton_step(J, r, x, b, n, settled):
                break


@njit
def alpha_terms(coef: Any, abs_coef: Any, sym: Any, pw: Any, eq: Any, n: int, x: Any, p: Any,
                delta: Any, F: Any, magnitude: Any, step: Any, stats: Any) -> None:
    """What the fast α-test (:func:`.certify.certify`, ``fast``) needs per point of x (P, n),
    p (P, k): F (P, N), Σ|terms| (P, N) (the table with |coef| at |x|, |p|; complex, real
    valued), the Newton step
    J⁻¹F (P, n), and ``stats`` (P, 4): finite (1/0), ‖J⁻¹‖_F, ‖J‖_F, ‖J⁻¹Δ‖_F (Δ = diag
    ``delta`` (P, n)), with J⁻¹ by one LU per point. A point with F or J not finite has
    finite 0 and J taken as I (and F as 0); an exactly singular J has ‖J⁻¹‖_F = ∞ and the
    step F (the numpy route's SVD fallback)."""
    P = x.shape[0]
    N = F.shape[1]
    J = np.empty((1, N, n), dtype=np.complex128)
    dummy = np.empty((1, N, n), dtype=np.complex128)
    inv = np.empty((n, n), dtype=np.complex128)
    ax = np.empty((1, n), dtype=np.complex128)
    ap = np.empty((1, p.shape[1]), dtype=np.complex128)
    for b in range(P):
        F[b] = 0.0
        J[:] = 0.0
        term_values(coef, sym, pw, eq, n, x[b:b + 1], p[b:b + 1], F[b:b + 1], J)
        for i in range(n):
            ax[0, i] = abs(x[b, i])
        for i in range(p.shape[1]):
            ap[0, i] = abs(p[b, i])
        magnitude[b] = 0.0
        dummy[:] = 0.0
        term_values(abs_coef, sym, pw, eq, n, ax, ap, magnitude[b:b + 1], dummy)
        point_stats(b, J[0], F, delta, inv, step, stats)


@njit
def point_stats(b: int, J: Any, F: Any, delta: Any, inv: Any, step: Any, stats: Any) -> None:
    """:func:`alpha_terms`' step and ``stats`` of point b from its F[b] and J (N, n), with
    ``inv`` (n, n) as workspace (squared moduli as re² + im², no temporaries)."""
    n = J.shape[1]
    finite = np.isfinite(F[b]).all() and np.isfinite(J).all()
    A = J.copy()
    if not finite:
        A[:] = 0.0
        for i in range(n):
            A[i, i] = 1.0
    norm_j = np.sqrt(np.sum(A.real * A.real + A.imag * A.imag))
    inv[:] = 0.0
    for i in range(n):
        inv[i, i] = 1.0
    ok = solve(A, inv)
    if not ok:
        for i in range(n):
            step[b, i] = F[b, i] if finite else 0.0
        stats[b, 0], stats[b, 1], stats[b, 2] = 1.0 if finite else 0.0, np.inf, norm_j
        stats[b, 3] = np.inf
        return
    scaled, total = 0.0, 0.0
    for i in range(n):
        s = 0j
        for j in range(n):
            if finite:
                s += inv[i, j] * F[b, j]
            v = inv[i, j].real * inv[i, j].real + inv[i, j].imag * inv[i, j].imag
            total += v
            scaled += v * (delta[b, j] * delta[b, j])
        step[b, i] = s
    stats[b, 0], stats[b, 1] = 1.0 if finite else 0.0, np.sqrt(total)
    stats[b, 2], stats[b, 3] = norm_j, np.sqrt(scaled)


@njit
def alpha_quadrics(Q: Any, Qabs: Any, inst: Any, x: Any, delta: Any, F: Any, magnitude: Any,
                   step: Any, stats: Any) -> None:
    """:func:`alpha_terms` for symmetric quadrics Q (B, N, n + 1, n + 1) of the instances
    ``inst`` (P,): F_i = zᵀ Q_i z, ∂F_i/∂x = 2 (Q_i z)[:n], Σ|terms| = |z|ᵀ Qabs_i |z|
    (z = (x, 1); Qabs the term-wise moduli, real valued)."""
    P, n = x.shape
    N = F.shape[1]
    J = np.empty((N, n), dtype=np.complex128)
    inv = np.empty((n, n), dtype=np.complex128)
    z = np.empty(n + 1, dtype=np.complex128)
    az = np.empty(n + 1)
    for b in range(P):
        q, qa = Q[inst[b]], Qabs[inst[b]]
        for k in range(n):
            z[k] = x[b, k]
            az[k] = abs(x[b, k])
        z[n], az[n] = 1.0, 1.0
        for i in range(N):
            f, m = 0j, 0.0
            for j in range(n + 1):
                s, t = 0j, 0.0
                for k in range(n + 1):
                    s += q[i, j, k] * z[k]
                    t += qa[i, j, k].real * az[k]
                f += s * z[j]
                m += t * az[j]
                if j < n:
                    J[i, j] = 2.0 * s
            F[b, i] = f
            magnitude[b, i] = m
        point_stats(b, J, F, delta, inv, step, stats)


@njit
def deltas(x: Any, degrees: Any) -> tuple[Any, Any]:
    """Δ (P, n) = √d_i·‖x‖₁^(d_i − 1) and ‖x‖₁ = √(1 + ‖x‖²) (P,) of the points x (P, n)."""
    P, n = x.shape
    delta = np.empty((P, n))
    norm1 = np.empty(P)
    for b in range(P):
        sq = 0.0
        for i in range(n):
            sq += abs(x[b, i]) ** 2
        norm1[b] = np.sqrt(1.0 + sq)
        for i in range(n):
            delta[b, i] = np.sqrt(degrees[i]) * norm1[b] ** (degrees[i] - 1.0)
    return delta, norm1


@njit
def alpha_test(coef: Any, abs_coef: Any, sym: Any, pw: Any, eq: Any, n: int, x: Any, p: Any,
               degrees: Any, factor: Any, norm_f: Any, real_p: Any, alpha0: float,
               alpha_real: float, unit: float, F: Any, magnitude: Any, newton: Any,
               bounds: Any, flags: Any) -> None:
    """The fast α-test (:func:`.certify.certify`, ``fast``; its module docstring for the
    bounds) of the points x (P, n) at p (P, k), each through :func:`alpha_terms`: F and
    Σ|terms| (P, N), the Newton points (P, n), ``bounds`` (P, 3) α, β, γ (∞ where the test
    cannot run) and ``flags`` (P, 3) certified, real, not real. ``degrees`` (N,) of the
    equations, ``factor`` (N,) the rounding allowance per Σ|terms|, ``norm_f`` (P,) ‖f‖,
    ``real_p`` (P,) whether the system is real at p."""
    delta, norm1 = deltas(x, degrees)
    step = np.empty((x.shape[0], n), dtype=np.complex128)
    stats = np.empty((x.shape[0], 4))
    alpha_terms(coef, abs_coef, sym, pw, eq, n, x, p, delta, F, magnitude, step, stats)
    verdicts(x, degrees, factor, norm_f, real_p, alpha0, alpha_real, unit, F, magnitude, step,
             stats, norm1, newton, bounds, flags)


@njit
def alpha_test_quadrics(Q: Any, Qabs: Any, inst: Any, x: Any, degrees: Any, factor: Any,
                        norm_f: Any, real_p: Any, alpha0: float, alpha_real: float,
                        unit: float, F: Any, magnitude: Any, newton: Any, bounds: Any,
                        flags: Any) -> None:
    """:func:`alpha_test` with F, ∂F/∂x and Σ|terms| from quadrics (:func:`alpha_quadrics`)."""
    delta, norm1 = deltas(x, degrees)
    step = np.empty(x.shape, dtype=np.complex128)
    stats = np.empty((x.shape[0], 4))
    alpha_quadrics(Q, Qabs, inst, x, delta, F, magnitude, step, stats)
    verdicts(x, degrees, factor, norm_f, real_p, alpha0, alpha_real, unit, F, magnitude, step,
             stats, norm1, newton, bounds, flags)


@njit
def verdicts(x: Any, degrees: Any, factor: Any, norm_f: Any, real_p: Any, alpha0: float,
             alpha_real: float, unit: float, F: Any, magnitude: Any, step: Any, stats: Any,
             norm1: Any, newton: Any, bounds: Any, flags: Any) -> None:
    """:func:`alpha_test`'s bounds and flags from F, Σ|terms|, the steps and ``stats``."""
    P, n = x.shape
    dmax = 1.0
    for i in range(degrees.shape[0]):
        dmax = max(dmax, degrees[i])
    for b in range(P):
        err, st, gap = 0.0, 0.0, 0.0
        for i in range(F.shape[1]):
            err += (magnitude[b, i].real * factor[i]) ** 2
        for i in range(n):
            st += abs(step[b, i]) ** 2
            gap += (2.0 * x[b, i].imag) ** 2
            newton[b, i] = x[b, i] - step[b, i]
        finite, inv_norm, norm_j, scaled = stats[b, 0] > 0, stats[b, 1], stats[b, 2], stats[b, 3]
        s_min = 1.0 / inv_norm
        margin = 1.0 + 10.0 * n * (norm_j * inv_norm) * unit
        beta = (np.sqrt(st) + np.sqrt(err) / s_min) * margin
        mu = norm_f[b] * scaled * margin
        if not (mu > 1.0 or np.isnan(mu)):
            mu = 1.0
        gamma = mu * dmax ** 1.5 / (2.0 * norm1[b])
        alpha = beta * gamma
        ok = finite and np.isfinite(alpha) and s_min > 0
        certified = ok and alpha < alpha0
        gap = np.sqrt(gap)
        flags[b, 0] = certified
        flags[b, 1] = certified and real_p[b] and alpha < alpha_real and gap < 1.0 / (20.0 * gamma)
        flags[b, 2] = certified and real_p[b] and gap > 4.0 * beta
        if ok:
            bounds[b, 0], bounds[b, 1], bounds[b, 2] = alpha, beta, gamma
        else:
            bounds[b, 0], bounds[b, 1], bounds[b, 2] = np.inf, np.inf, np.inf


@njit
def bombieri_weyl(coef: Any, sym: Any, pw: Any, n: int, order: Any, group: Any, weights: Any,
                  p: Any, out: Any) -> None:
    """‖f‖ (B,) at each parameter row of p (B, k) (:func:`.certify.bombieri_weyl_norm`): each
    term's coefficient times its parameters' powers, summed per monomial in x (the terms
    ``order``-ed by monomial, ``group`` (T,) the monomial of each term), then
    √(Σ |c|²·weight) over the monomials."""
    G = weights.shape[0]
    acc = np.empty(G, dtype=np.complex128)
    for b in range(p.shape[0]):
        acc[:] = 0.0
        for t in order:
            v = 1.0 + 0.0j
            for f in range(sym.shape[1]):
                s = sym[t, f]
                if s >= n:
                    for _ in range(pw[t, f]):
                        v *= p[b, s - n]
            acc[group[t]] += coef[t] * v
        total = 0.0
        for g in range(G):
            total += (acc[g].real ** 2 + acc[g].imag ** 2) * weights[g]
        out[b] = np.sqrt(total)
