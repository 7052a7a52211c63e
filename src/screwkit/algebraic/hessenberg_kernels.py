"""The numba kernel of :mod:`.hessenberg_eig` (imported by it on first use only, so that
importing screwkit does not import numba): eigenvalues and chosen rows of the right
eigenvectors of real matrices, LAPACK's reduction and QR iteration called from compiled code
(through :func:`call_lapack`, the routines' addresses passed in as integers), the eigenvectors
by one step of inverse iteration on the Hessenberg form. Module-level functions, so that numba's
disk cache (next to this module) is found again by the next process: the addresses are
arguments, not globals (a function holding a ctypes pointer is not cached, and compiling this
one takes seconds)."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

njit = numba.njit(cache=True, nogil=True, error_model="numpy")
#: with reassociation and contraction (fastmath without nnan/ninf): the row operations and the
#: back substitution's sums vectorised; deterministic for a given n all the same
njit_fast = numba.njit(cache=True, nogil=True, error_model="numpy",
                       fastmath={"contract", "reassoc", "nsz", "arcp"})
#: LAPACK's routines in the order of :func:`eig_rows`' ``fn``
ROUTINES = ("dgebal", "dgehrd", "dhseqr")
#: a solution entry this large rescales the solution (no overflow in the back substitution)
BIG = 1e150


@intrinsic
def call_lapack(typingctx: Any, address: Any, args: Any) -> Any:
    """Call the Fortran routine at ``address`` (int64) with ``args``, a tuple of int64
    addresses (every LAPACK argument is a pointer), for its effects."""
    arity = len(args)
    sig = types.void(address, args)

    def codegen(context: Any, builder: Any, signature: Any, llargs: Any) -> Any:
        ptr = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [ptr] * arity)
        fn = builder.inttoptr(llargs[0], fnty.as_pointer())
        values = cgutils.unpack_tuple(builder, llargs[1], arity)
        builder.call(fn, [builder.inttoptr(v, ptr) for v in values])
        return context.get_dummy_value()

    return sig, codegen


@njit
def eig_rows(A: Any, rows: Any, fn: Any, vals: Any, V: Any, ok: Any) -> None:
    """Per matrix A[g] (n × n, real): its eigenvalues vals[g] (n,) in LAPACK's order (a complex
    pair as λ, λ̄, adjacent) and the entries ``rows`` of its right eigenvectors, V[g] (m, n),
    column k for vals[g, k]; ok[g] False where LAPACK fails (the others untouched).

    The eigenvalues are LAPACK's dgeev's without vectors (dgebal with permutation and
    scaling, dgehrd, dhseqr 'E'; bit for bit numpy's eigvals), the vectors by inverse
    iteration on the Hessenberg form H = QᵀDAD⁻¹Q (LAPACK's dhsein/dlaein's scheme, Wilkinson
    1965, ch. 9; :func:`solve_shifted`), then v = D·Q·x at the rows wanted (dgebak's scaling
    and swaps followed back, :func:`sources`). Only λ with Im λ ≥ 0 are solved: λ̄'s vector is
    the conjugate (exact conjugate pairs), a real λ's is real."""
    G, n, _ = A.shape
    m = rows.shape[0]
    a = np.empty((n, n))  # column-major: a[j, i] is entry (i, j)
    h = np.empty((n, n))
    hq = np.empty((n, n))
    tau, scale, wr, wi = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    work = np.empty(64 * n)
    iv = np.empty(6, dtype=np.int32)  # n, ilo, ihi, info, lwork, ldz
    ch, z = np.empty(3, dtype=np.uint8), np.empty(1)
    hr = np.empty((n, n))  # H row-major
    Qr = np.empty((m, n))
    B = np.empty((2, n, n))
    x = np.empty((2, n))
    src = np.empty(m, dtype=np.int64)
    fac = np.empty(m)
    for g in range(G):
        if not np.isfinite(A[g]).all():  # (older LAPACKs' dgebal may loop forever on a NaN)
            ok[g] = False
            continue
        norm = reduce(A[g], fn, a, h, hq, tau, scale, wr, wi, work, iv, ch, z)
        if iv[3] != 0 or not np.isfinite(norm):
            ok[g] = False
            continue
        sources(rows, scale, iv[1] - 1, iv[2] - 1, src, fac)
        for i in range(n):
            for j in range(n):
                hr[i, j] = h[j, i]
        q_rows(a, tau, iv[1] - 1, iv[2] - 1, src, Qr)
        eps3 = max(norm, 1e-290) * 2.220446049250313e-16  # LAPACK dlaein: ε‖H‖
        k = 0
        while k < n:
            lam = complex(wr[k], wi[k])
            solve_shifted(hr, lam, eps3, B, x)
            rows_of(Qr, x, fac, V[g, :, k])
            vals[g, k] = lam
            if wi[k] > 0 and k + 1 < n:
                vals[g, k + 1] = complex(wr[k + 1], wi[k + 1])
                for r in range(m):
                    V[g, r, k + 1] = V[g, r, k].conjugate()
                k += 2
            else:
                if wi[k] == 0:
                    for r in range(m):
                        V[g, r, k] = V[g, r, k].real
                k += 1
        ok[g] = True


@njit
def reduce(A: Any, fn: Any, a: Any, h: Any, hq: Any, tau: Any, scale: Any, wr: Any, wi: Any,
           work: Any, iv: Any, ch: Any, z: Any) -> float:
    """LAPACK on one matrix A (n × n): balanced (dgebal 'B'), reduced to Hessenberg form h
    (dgehrd; column-major, zero below the subdiagonal; its reflectors left in a and tau for
    :func:`q_rows`), the eigenvalues
    wr + i·wi of h (dhseqr 'E', on the copy hq); ilo, ihi and info in iv[1:4] (info ≠ 0: a
    routine failed); ch (3,) and z (1,) workspace (the caller's: every array LAPACK reads must
    outlive the call, and numba frees a local after its last use in the code, which here is
    taking its address). Returns max |h_ij| (not finite: A was not)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            a[j, i] = A[i, j]
    iv[0], iv[3], iv[4], iv[5] = n, 0, work.shape[0], 1
    ch[0], ch[1], ch[2] = ord("B"), ord("E"), ord("N")
    N, ILO, IHI, INFO, LWORK, LDZ = (iv[0:].ctypes.data, iv[1:].ctypes.data,
                                     iv[2:].ctypes.data, iv[3:].ctypes.data,
                                     iv[4:].ctypes.data, iv[5:].ctypes.data)
    call_lapack(fn[0], (ch.ctypes.data, N, a.ctypes.data, N, ILO, IHI, scale.ctypes.data,  # type: ignore[call-arg]
                        INFO))
    if iv[3] != 0:
        return np.nan
    call_lapack(fn[1], (N, ILO, IHI, a.ctypes.data, N, tau.ctypes.data, work.ctypes.data,  # type: ignore[call-arg]
                        LWORK, INFO))
    norm = 0.0
    for j in range(n):
        for i in range(n):
            h[j, i] = a[j, i] if i <= j + 1 else 0.0
            norm = max(norm, abs(h[j, i]))
    hq[:, :] = h
    call_lapack(fn[2], (ch[1:].ctypes.data, ch[2:].ctypes.data, N, ILO, IHI, hq.ctypes.data,  # type: ignore[call-arg]
                        N, wr.ctypes.data, wi.ctypes.data, z.ctypes.data, LDZ,
                        work.ctypes.data, LWORK, INFO))
    return norm


@njit_fast
def q_rows(a: Any, tau: Any, ilo: int, ihi: int, src: Any, Qr: Any) -> None:
    """The rows src of Q (Qr (m, n)) from dgehrd's reflectors in a (column-major) and tau:
    Q = H(ilo) ⋯ H(ihi − 1), H(i) = I − τ_i v vᵀ with v_{i+1} = 1 and v below it in column
    i of a (LAPACK's dgehrd, 0-based), so that e_rᵀ Q is e_r's row times each H(i) in turn
    (O(m n²) in place of dorghr's whole Q, 4/3 n³)."""
    n = a.shape[0]
    for r in range(src.shape[0]):
        y = Qr[r]
        for j in range(n):
            y[j] = 0.0
        y[src[r]] = 1.0
        for i in range(ilo, ihi):
            col = a[i]  # column i of A: the reflector's entries below row i + 1
            d = y[i + 1]
            for k in range(np.uint64(i + 2), np.uint64(ihi + 1)):
                d += y[k] * col[k]
            d *= tau[i]
            y[i + 1] -= d
            for k in range(np.uint64(i + 2), np.uint64(ihi + 1)):
                y[k] -= d * col[k]


@njit
def sources(rows: Any, scale: Any, ilo: int, ihi: int, src: Any, fac: Any) -> None:
    """dgebak backwards: the eigenvector's row rows[r] is the balanced one's row src[r] times
    fac[r] (dgebak scales rows ilo..ihi (0-based) by scale, then swaps row i with
    scale[i] − 1 for i = ilo − 1 down to 0, then for i = ihi + 1 up to n − 1)."""
    n = scale.shape[0]
    for r in range(rows.shape[0]):
        i = rows[r]
        for k in range(n - 1, ihi, -1):  # the swaps undone in reverse order
            if i == k:
                i = int(scale[k]) - 1
            elif i == int(scale[k]) - 1:
                i = k
        for k in range(ilo):
            if i == k:
                i = int(scale[k]) - 1
            elif i == int(scale[k]) - 1:
                i = k
        src[r] = i
        fac[r] = scale[i] if ilo <= i <= ihi else 1.0


@njit_fast
def solve_shifted(h: Any, lam: complex, eps3: float, B: Any, x: Any) -> None:
    """One step of inverse iteration: x with (H − λI) x ≈ L·(1, …, 1), H = h (row-major,
    upper Hessenberg): the LU of H − λI with partial pivoting (rows i and i + 1; a zero pivot
    replaced by ``eps3``), then U x = (1, …, 1) (LAPACK's dlaein skips L's solve: the start
    is arbitrary); rescaled on the way if it grows past :data:`BIG`. Complex numbers as
    real and imaginary parts (B (2, n, n) and x (2, n) real), indices unsigned (no negative
    index wraparound), so that the row operations and sums are vector operations (1.95
    against 2.46 µs per shift at n = 40, measured)."""
    n = h.shape[0]
    R, I = B[0], B[1]
    lr, li = lam.real, lam.imag
    for i in range(n):  # H − λI, its Hessenberg part
        ri, ii, hi = R[i], I[i], h[i]
        for j in range(np.uint64(max(i - 1, 0)), np.uint64(n)):
            ri[j] = hi[j]
            ii[j] = 0.0
        R[i, i] -= lr
        I[i, i] = -li
    for i in range(n - 1):
        if R[i + 1, i] ** 2 + I[i + 1, i] ** 2 > R[i, i] ** 2 + I[i, i] ** 2:
            r0, r1, i0, i1 = R[i], R[i + 1], I[i], I[i + 1]
            for j in range(np.uint64(i), np.uint64(n)):
                t = r0[j]
                r0[j] = r1[j]
                r1[j] = t
            for j in range(np.uint64(i), np.uint64(n)):
                t = i0[j]
                i0[j] = i1[j]
                i1[j] = t
        if R[i, i] == 0 and I[i, i] == 0:
            R[i, i] = eps3
        d = R[i, i] ** 2 + I[i, i] ** 2
        fr = (R[i + 1, i] * R[i, i] + I[i + 1, i] * I[i, i]) / d
        fi = (I[i + 1, i] * R[i, i] - R[i + 1, i] * I[i, i]) / d
        r0, r1, i0, i1 = R[i], R[i + 1], I[i], I[i + 1]
        for j in range(np.uint64(i + 1), np.uint64(n)):
            r1[j] -= fr * r0[j] - fi * i0[j]
            i1[j] -= fr * i0[j] + fi * r0[j]
    if R[n - 1, n - 1] == 0 and I[n - 1, n - 1] == 0:
        R[n - 1, n - 1] = eps3
    xr, xi = x[0], x[1]
    for i in range(n - 1, -1, -1):
        sr, si = 1.0, 0.0
        ri, ii = R[i], I[i]
        for j in range(np.uint64(i + 1), np.uint64(n)):
            sr -= ri[j] * xr[j] - ii[j] * xi[j]
            si -= ri[j] * xi[j] + ii[j] * xr[j]
        d = R[i, i] ** 2 + I[i, i] ** 2
        xr[i] = (sr * R[i, i] + si * I[i, i]) / d
        xi[i] = (si * R[i, i] - sr * I[i, i]) / d
        size = abs(xr[i]) + abs(xi[i])
        if size > BIG:
            c = 1.0 / size
            for j in range(i, n):
                xr[j] *= c
                xi[j] *= c


@njit_fast
def rows_of(Qr: Any, x: Any, fac: Any, out: Any) -> None:
    """out[r] = fac[r]·(Qr[r] · x) (x as real and imaginary parts (2, n))."""
    xr, xi = x[0], x[1]
    for r in range(Qr.shape[0]):
        q = Qr[r]
        sr, si = 0.0, 0.0
        for j in range(np.uint64(0), np.uint64(q.shape[0])):
            sr += q[j] * xr[j]
            si += q[j] * xi[j]
        out[r] = complex(sr * fac[r], si * fac[r])
