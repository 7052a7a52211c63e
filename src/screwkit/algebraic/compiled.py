"""The predictor–corrector loop of :func:`.path.track`, compiled by numba, for homotopies of
quadrics evaluated densely (:mod:`.quadrics`).

The algorithm is the one of :mod:`.path`, step for step (its module docstring): a fourth-order
Runge–Kutta predictor on dy/dτ = −J⁻¹·∂H/∂τ, two Newton corrections at the new τ, the same
acceptance test (predictor error, corrector error, contraction) and the same step-size rule.
Only the order of work differs: numpy runs one step for every active path at a time (~100
numpy calls per step, each over the paths); here each path runs from τ0 to τ1 in one compiled
loop, with the evaluation

    F_i(y; σ) = Σ_k σ^k yᵀ Q_ik y + L_i(σ)·y,   ∂F_i/∂y = Σ_k σ^k 2 Q_ik y + L_i(σ)

(:mod:`.quadrics`) from V = y·Qt over the columns of Qt with a nonzero entry (one contiguous
loop per unknown, in real arithmetic on Qt's real and imaginary parts apart, which the compiler
vectorises), then W_il = Σ_k σ^k (Q_ik y)_l per cell, so F_i = Σ_l W_il y_l and
∂F_i/∂y_l = 2 W_il; and the (n+1)×(n+1) solves by Gaussian elimination in place with partial
pivoting on |re| + |im| (Golub & Van Loan, *Matrix Computations*, 4th ed., 2013, §3.4; the
pivot LAPACK's zgetrf picks). Measured on the Stewart system (9 × 128 columns): ~1 µs per
evaluation, ~0.7 µs per solve, ~8 µs per step (5 of each), against ~11 µs before (complex V,
a scatter per column into F and J, |·| by hypot in the pivot search). The arithmetic is the same up
to rounding, so both routes reach the same end points (to the Newton polish's accuracy) with the
same statuses; tests/algebraic/test_compiled.py checks it. A call of many paths from the main
thread runs in interleaved parts on a pool of one thread per core (:func:`track_compiled`; the
kernel releases the GIL, and each path's arithmetic is its own, so the result is the same bit
for bit), with BLAS held at one thread around the homotopy (:func:`threads_held`).

The same module compiles three per-point passes over a term table
(:class:`.polynomial.PolynomialSystem`), each the numpy route's arithmetic one point at a time
(issue 27, the 6R eigen route alone): the Newton polish (:func:`newton_terms`), the fast α-test
of :func:`.certify.certify` (:func:`alpha_test`: F, Σ|terms|, J⁻¹ by one LU per point, the
Frobenius bounds and the verdicts) and the Bombieri–Weyl norm (:func:`bombieri_weyl`);
tests/algebraic/test_compiled.py checks them against the numpy route. For a system of quadrics
given as dense symmetric matrices (F_i = zᵀ Q_i z, z = (x, 1)), the polish and the α-test also
run from those (:func:`newton_quadrics`, :func:`alpha_test_quadrics`: the Stewart route's 9 × 9
matrices instead of its 489-term table in 42 parameters; tests/kinematics/test_stewart_dense.py
checks them against the term table's).

numba is optional (the ``fast`` extra): :data:`AVAILABLE` is False without it, and the tracker
then runs the numpy route. The kernels are compiled on first use (a few seconds, cached on disk
by numba next to this module when the folder is writable).
"""

from __future__ import annotations

import importlib.util
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.quadrics import DenseQuadrics

Index = NDArray[np.intp]

#: numba is installed (and not turned off by SCREWKIT_NO_NUMBA); it is imported on the first
#: compiled track only, so that importing screwkit does not pay for it
AVAILABLE = (importlib.util.find_spec("numba") is not None
             and not os.environ.get("SCREWKIT_NO_NUMBA"))

#: the curves σ(τ) the kernel knows: the straight segment σ = τ and the endgame's circle
#: σ = 1 − r·e^{iτ} (:func:`.path.line`, :func:`.path.circle`)
LINE, CIRCLE = 0, 1


@dataclass(frozen=True)
class Columns:
    """The (k, i, l) of each column c of :attr:`DenseQuadrics.Qt` (``ck`` and the cell
    ``cu`` = i·m + l): (y·Qt[b])_c = (Q_ik y)_l of instance b; and Qt's real and imaginary
    parts apart (``qr``, ``qi``, (B, m, C)), as the kernel reads them."""

    ck: Index
    cu: Index
    qr: NDArray[np.float64]
    qi: NDArray[np.float64]

    @staticmethod
    def of(dense: DenseQuadrics) -> Columns:
        ck, rest = np.divmod(dense.columns, dense.N * dense.m)
        return Columns(ck.astype(np.int64), rest.astype(np.int64),
                       np.ascontiguousarray(dense.Qt.real), np.ascontiguousarray(dense.Qt.imag))


def columns_of(dense: DenseQuadrics) -> Columns:
    """The :class:`Columns` of ``dense``, built once and kept on it."""
    cols = dense.__dict__.get("_kernel_columns")
    if cols is None:
        cols = Columns.of(dense)
        object.__setattr__(dense, "_kernel_columns", cols)
    return cols


def evaluate_terms(coef: Complex, sym: Index, pw: Index, eq: Index, N: int, x: Complex,
                   p: Complex) -> tuple[Complex, Complex]:
    """F (B, N) and ∂F/∂x (B, N, n) of a term table (:class:`.polynomial.PolynomialSystem`'s
    ``coef``, ``sym``, ``pw``, ``eq``) at x (B, n), p (B, k) or (k,), compiled: the same sums
    as its numpy evaluation, one point and one term at a time, with no temporaries."""
    from screwkit.algebraic import compiled_kernels

    x = np.ascontiguousarray(x, dtype=complex)
    B, n = x.shape
    pb = np.ascontiguousarray(np.broadcast_to(np.asarray(p, dtype=complex), (B, p.shape[-1])))
    F = np.zeros((B, N), dtype=complex)
    J = np.zeros((B, N, n), dtype=complex)
    compiled_kernels.term_values(coef, sym.astype(np.int64), pw.astype(np.int64),
                                 eq.astype(np.int64), n, x, pb, F, J)
    return F, J


def _kernels() -> Any:
    """The compiled track function (numba imported and the kernels loaded on first use)."""
    from screwkit.algebraic import compiled_kernels

    return compiled_kernels.track


_TRACK: Any = None


def track_compiled(dense: DenseQuadrics, instance: Index,
                   patch: Complex, y0: Complex, tau0: NDArray[np.float64],
                   tau1: NDArray[np.float64], kind: int, radius: NDArray[np.float64],
                   options: Any) -> tuple[Complex, NDArray[np.bool_], NDArray[np.int64]]:
    """:func:`.path.track` for paths of instances ``instance`` (P,) (rows of the quadrics),
    start points y0 (P, m) at tau0, to tau1, on the curve ``kind`` (``radius`` (P,) for the
    circle). Returns the end points, whether each reached tau1, and the steps taken."""
    global _TRACK
    if _TRACK is None:
        _TRACK = _kernels()
    Ls = dense.L
    inst = instance.astype(np.int64)
    linear_of = np.zeros(len(instance), dtype=np.int64) if len(Ls) == 1 else inst
    cols = columns_of(dense)
    per_path = (inst, linear_of, np.ascontiguousarray(y0, dtype=complex),
                np.ascontiguousarray(tau0, dtype=float), np.ascontiguousarray(tau1, dtype=float),
                np.ascontiguousarray(radius, dtype=float))

    def run(rows: Index | slice) -> tuple[Complex, NDArray[np.bool_], NDArray[np.int64]]:
        i, lin, y, t0, t1, r = (_part_of(a, rows) for a in per_path)
        out: tuple[Complex, NDArray[np.bool_], NDArray[np.int64]] = _TRACK(
            cols.qr, cols.qi, cols.ck, cols.cu, dense.K, np.ascontiguousarray(Ls),
            dense.linear.astype(np.int64), patch, i, lin, y, t0, t1, kind, r,
            float(options.initial_step), float(options.max_step), float(options.min_step),
            int(options.max_steps), float(options.predictor_tolerance),
            float(options.corrector_tolerance), float(options.contraction),
            float(options.converged))
        return out

    P = len(inst)
    count = min(P // PART_PATHS, PARTS_PER_THREAD * THREADS)
    if THREADS <= 1 or count < 2 or threading.current_thread() is not threading.main_thread():
        return run(slice(None))
    # the paths in interleaved parts, handed to the cores as they come free (a hard path takes
    # many times an easy one's steps): each path is tracked on its own (the kernel goes path
    # by path and releases the GIL), so the result is the same bit for bit
    parts = [np.arange(k, P, count) for k in range(count)]
    y = np.empty((P, y0.shape[1]), dtype=complex)
    reached = np.empty(P, dtype=bool)
    steps = np.empty(P, dtype=np.int64)
    try:
        futures = [_pool().submit(run, rows) for rows in parts]
    except RuntimeError:  # the interpreter shutting down: no new threads, so on this one
        return run(slice(None))
    try:
        for rows, f in zip(parts, futures, strict=True):
            y[rows], reached[rows], steps[rows] = f.result()
    except BaseException:  # (an interrupt): the parts not started are dropped
        for f in futures:
            f.cancel()
        raise
    return y, reached, steps


def _part_of(a: NDArray[Any], rows: Index | slice) -> NDArray[Any]:
    """The rows of a per-path array for a part of a track, read-only where ``a`` is: numba
    compiles a read-only array's kernel apart, and the two compilations may round apart
    (FMA contraction), so a part keeps the whole call's kernel and its result bit for bit."""
    out = np.ascontiguousarray(a[rows])
    if not a.flags.writeable and out.flags.writeable:
        out.setflags(write=False)
    return out


#: paths at least per part when a compiled track is spread over threads (a call with fewer
#: than two parts' worth runs on the calling thread: a hand-over to the pool costs ~50 µs, a
#: path ~0.1 ms or more), and parts at most per thread
PART_PATHS = 4
PARTS_PER_THREAD = 8
#: threads a compiled track of many paths runs on: the cores this process may use
THREADS = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
_POOL: ThreadPoolExecutor | None = None


def threads_held() -> AbstractContextManager[Any]:
    """Around a homotopy's tracks on the main thread, where :func:`track_compiled` spreads its
    paths over threads: BLAS held at one thread (algebraic/blas.py; its threads, woken by a
    small product between the tracks, would spin on the cores the tracks use, and a limit
    taken inside the tracks alone comes too late for them); elsewhere nothing. So a homotopy
    on the main thread rounds its BLAS products as on one thread, in another thread as BLAS
    is set there (the same to rounding)."""
    if not AVAILABLE or THREADS <= 1 or threading.current_thread() is not threading.main_thread():
        return nullcontext()
    from screwkit.algebraic.blas import one_blas_thread

    held: AbstractContextManager[Any] = one_blas_thread()
    return held


def _pool() -> ThreadPoolExecutor:
    """The threads of :func:`track_compiled` (made once per process; used from the main
    thread only, so that a track run inside another pool's thread never waits on this one)."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(THREADS, thread_name_prefix="screwkit-track")
    return _POOL


def _forget_pool() -> None:
    """In a forked child: the parent's pool has no threads here (a new one is made)."""
    global _POOL
    _POOL = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def newton_terms(system: PolynomialSystem, x: Complex, p: Complex, steps: int,
                 settled: float) -> Complex:
    """Up to ``steps`` Newton steps on F(·; p) from the points x (P, n), p (P, k), compiled
    (:func:`.compiled_kernels.newton`: a point stops once its step is at most ``settled``
    relative to 1 + max|x|, or where F, ∂F/∂x or the step is not finite or ∂F/∂x singular)."""
    from screwkit.algebraic import compiled_kernels

    x = np.array(x, dtype=complex, order="C")
    pb = np.ascontiguousarray(np.broadcast_to(np.asarray(p, dtype=complex),
                                              (len(x), system.k)))
    coef, _, sym, pw, eq = _term_table(system)
    compiled_kernels.newton(coef, sym, pw, eq, system.n, x, pb, int(steps), float(settled))
    return x


def newton_quadrics(Q: Complex, inst: Index, x: Complex, steps: int, settled: float
                    ) -> Complex:
    """:func:`newton_terms` on the symmetric quadrics Q (B, N, n + 1, n + 1) of the instances
    ``inst`` (P,) of the points x (P, n): F_i = zᵀ Q_i z, z = (x, 1), compiled
    (:func:`.compiled_kernels.newton_quadrics`)."""
    from screwkit.algebraic import compiled_kernels

    x = np.array(x, dtype=complex, order="C")
    compiled_kernels.newton_quadrics(np.ascontiguousarray(Q, dtype=complex),
                                     np.ascontiguousarray(inst, dtype=np.int64), x, int(steps),
                                     float(settled))
    return x


def alpha_test(system: PolynomialSystem, x: Complex, p: Complex, factor: NDArray[np.float64],
               norm_f: NDArray[np.float64], real_p: NDArray[np.bool_], alpha0: float,
               alpha_real: float, unit: float) -> tuple[Any, ...]:
    """The fast α-test of the points x (P, n) at p (P, k), compiled
    (:func:`.compiled_kernels.alpha_test`; ``factor`` (N,) the rounding allowance per
    Σ|terms|, ``norm_f`` (P,) ‖f‖, ``real_p`` (P,) whether the system is real at p, and the
    constants α₀, the real test's α and the unit round-off): the fields of a
    :class:`.certify.Certificate` in order."""
    from screwkit.algebraic import compiled_kernels

    x = np.ascontiguousarray(x, dtype=complex)
    P = len(x)
    pb = np.ascontiguousarray(np.broadcast_to(np.asarray(p, dtype=complex), (P, system.k)))
    F = np.empty((P, system.size), dtype=complex)
    magnitude = np.empty((P, system.size), dtype=complex)
    newton = np.empty((P, system.n), dtype=complex)
    bounds = np.empty((P, 3))
    flags = np.empty((P, 3), dtype=np.bool_)
    coef, abs_coef, sym, pw, eq = _term_table(system)
    compiled_kernels.alpha_test(coef, abs_coef, sym, pw, eq, system.n, x, pb,
                                np.asarray(system.degrees, dtype=float), factor,
                                np.ascontiguousarray(norm_f, dtype=float),
                                np.ascontiguousarray(real_p, dtype=np.bool_), alpha0,
                                alpha_real, unit, F, magnitude, newton, bounds, flags)
    return (flags[:, 0], bounds[:, 0], bounds[:, 1], bounds[:, 2], 2.0 * bounds[:, 1],
            flags[:, 1], flags[:, 2], newton, F, magnitude.real.copy())


def alpha_test_quadrics(system: PolynomialSystem, dense: tuple[Complex, Complex, Index],
                        x: Complex, factor: NDArray[np.float64], norm_f: NDArray[np.float64],
                        real_p: NDArray[np.bool_], alpha0: float, alpha_real: float,
                        unit: float) -> tuple[Any, ...]:
    """:func:`alpha_test` with F, ∂F/∂x and Σ|terms| from the system's quadrics ``dense`` =
    (Q, |Q|, inst): Q (B, N, n + 1, n + 1) symmetric, F_i = zᵀ Q_i z with z = (x, 1), |Q| the
    term-wise moduli (|z|ᵀ |Q|_i |z| = Σ|terms| of F_i), inst (P,) each point's instance
    (:func:`.compiled_kernels.alpha_test_quadrics`)."""
    from screwkit.algebraic import compiled_kernels

    x = np.ascontiguousarray(x, dtype=complex)
    P = len(x)
    F = np.empty((P, system.size), dtype=complex)
    magnitude = np.empty((P, system.size), dtype=complex)
    newton = np.empty((P, system.n), dtype=complex)
    bounds = np.empty((P, 3))
    flags = np.empty((P, 3), dtype=np.bool_)
    Q, Qabs, inst = dense
    compiled_kernels.alpha_test_quadrics(
        np.ascontiguousarray(Q, dtype=complex), np.ascontiguousarray(Qabs, dtype=complex),
        np.ascontiguousarray(inst, dtype=np.int64), x, np.asarray(system.degrees, dtype=float),
        factor, np.ascontiguousarray(norm_f, dtype=float),
        np.ascontiguousarray(real_p, dtype=np.bool_), alpha0, alpha_real, unit, F, magnitude,
        newton, bounds, flags)
    return (flags[:, 0], bounds[:, 0], bounds[:, 1], bounds[:, 2], 2.0 * bounds[:, 1],
            flags[:, 1], flags[:, 2], newton, F, magnitude.real.copy())


def _term_table(system: PolynomialSystem) -> tuple[Any, ...]:
    """coef, |coef|, sym, pw, eq of the system as the kernels read them, kept on it."""
    table = system.__dict__.get("_kernel_table")
    if table is None:
        table = (system.coef, np.abs(system.coef).astype(complex), system.sym.astype(np.int64),
                 system.pw.astype(np.int64), system.eq.astype(np.int64))
        object.__setattr__(system, "_kernel_table", table)
    return table  # type: ignore[no-any-return]


def bombieri_weyl(system: PolynomialSystem, p: Complex, order: NDArray[np.intp],
                  group: NDArray[np.intp], weights: NDArray[np.float64]) -> NDArray[np.float64]:
    """‖f‖ (B,) of the system at each row of p (B, k), compiled
    (:func:`.compiled_kernels.bombieri_weyl`; ``order``, ``group`` and ``weights`` the
    monomials of :meth:`.PolynomialSystem.coefficients_at` and their weights)."""
    from screwkit.algebraic import compiled_kernels

    coef, _, sym, pw, _ = _term_table(system)
    pb = np.ascontiguousarray(np.atleast_2d(np.asarray(p, dtype=complex)))
    out = np.empty(len(pb))
    compiled_kernels.bombieri_weyl(coef, sym, pw, system.n, order, group, weights, pb, out)
    return out
