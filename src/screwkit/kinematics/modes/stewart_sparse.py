"""The Stewart template's R rows by a sparse elimination with one pivot sequence for every
instance, many instances side by side (issue 27: the batch route of :mod:`.stewart_template`).

Every instance's template [M_E M_R | M_B] (526 × 566, :func:`.stewart_template.layout`) has the
same sparsity pattern. The elimination needs only R = X_R in terms of the basis B, not the E
values: eliminating the E columns (Gaussian elimination, pivots only in E columns) leaves 29
rows in R and B alone, C_R·X_R + C_B = 0, solved densely (29 × 29, LAPACK with partial
pivoting). The pivot sequence is chosen once, from the pattern and one random real instance:
Markowitz's rule (the pivot with the least (row count − 1)·(column count − 1)), among the
entries at least :data:`THRESHOLD` times their column's largest (threshold partial pivoting;
Duff, Erisman & Reid, *Direct Methods for Sparse Matrices*, 2nd ed. 2017, on both).
The elimination with that sequence is then a fixed list of operations: 2.1 Mflop per instance
against ~30 Mflop for the block-triangular dense LUs (313 and 206). It runs row by row (each
row gathered in a dense accumulator, the earlier pivot rows subtracted from it in order:
Gilbert & Peierls 1988, the same operations in the same order as the right-looking
elimination), :data:`GROUP` instances side by side, the instance the innermost index
(:mod:`.stewart_sparse_kernels`): one vector operation per arithmetic operation of the
pattern, its indices read once for the whole group.

A pivot fixed beforehand can be small at another instance, and here it often is: the
multipliers reached 4e5 at the median instance, 6e8 at the 99th percentile (800 bench
instances, the sequence of seed 0), and the R rows are further from a dense partial-pivoting
LU of the whole template than the block-triangular LAPACK route's (relative, over 200
instances, :data:`PIVOT_SAMPLE`'s sequence: median 1e-7 against 1e-10, 90th percentile 2e-5
against 6e-9, 99th 1e-3 against 4e-7, the worst 0.5). The multiplier does not predict which (correlation of the logarithms 0.4). So the check that decides is the
caller's: the eigen route polishes every point by Newton's method and certifies the 40 by the
α-test (:mod:`.eigen_first`), and an instance not settled goes to the next pass: chart 1 by
this route, then charts 1 and 2 by the LAPACK route (modes/stewart_solve.py's ``PASSES``). Here an instance only fails (NaN rows, for the LAPACK route) when its
elimination is not finite, its largest multiplier is above :data:`GROWTH` (a pivot ~1e-12 of its
column: overflow on the way) or its 29 × 29 system is singular. On the 1,000 bench instances the
polished points equal the LAPACK route's to 4e-10 (relative), with the same 39,967 certified
points (tests/kinematics/test_stewart_sparse.py checks 200).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic import compiled
from screwkit.kinematics.modes import stewart_template_data as data

#: numba is there (the kernel is compiled); without it the caller keeps the LAPACK route
AVAILABLE = compiled.AVAILABLE
#: threshold partial pivoting: a pivot at least this fraction of its column's largest entry
#: (at the instance the sequence is chosen on); 1 is partial pivoting, smaller trades
#: stability for fill
THRESHOLD = 0.5
#: an instance with a larger multiplier is not used (the caller's LAPACK route solves it);
#: a guard against overflow, not an accuracy test (module docstring)
GROWTH = 1e12
#: the seed of the random real instance (modes/stewart.py's ``random_stewart``) the pivot
#: sequence is chosen at: Markowitz's rule with threshold pivoting fills differently at
#: different instances (2.1–5.4 Mflop per instance over seeds 0–79); seed 71 fills the least
#: but one (2.14 against 3.09 Mflop at seed 0) and leaves fewer instances unsettled (4.3 %
#: against 5.1 % of 3,000 in chart 0; docs/kinematics.md, "Speed")
PIVOT_SAMPLE = 71
#: instances eliminated side by side (:data:`.stewart_sparse_kernels.LANES`; two AVX-512
#: registers of float64: 0.22–0.27 ms per instance against 0.32–0.35 in groups of 8, measured)
GROUP = 16
#: the fewest real instances the sparse route alone (a retry pass after chart 0,
#: modes/stewart_solve.py's ``PASSES``) takes as a group, padded to :data:`GROUP`: a group
#: costs ~3 ms, the LAPACK route ~2.5 ms per instance (one lone instance stays with LAPACK)
FEWEST = 2
#: bytes the kernel's work arrays are aligned to (a cache line; :func:`aligned_zeros`)
ALIGN = 64

Index = NDArray[np.uint32]


def _pattern(layout: dict[str, Any]) -> tuple[NDArray[np.bool_], NDArray[np.intp],
                                               NDArray[np.intp], NDArray[np.intp]]:
    """The pattern (n, n + m) of [M_sq | M_B] and, per entry of the template, its row, column
    and source in the coefficients."""
    n, m = len(data.SQUARE), len(data.BASIS)
    r1, c1 = np.divmod(layout["sq_dst"], n)
    r2, c2 = np.divmod(layout["b_dst"], m)
    row = np.concatenate([r1, r2])
    col = np.concatenate([c1, n + c2])
    src = np.concatenate([layout["sq_src"], layout["b_src"]])
    P = np.zeros((n, n + m), dtype=bool)
    P[row, col] = True
    return P, row, col, src


def _pivots(P: NDArray[np.bool_], A: NDArray[np.float64], eliminated: NDArray[np.bool_]
            ) -> tuple[list[tuple[int, int]], NDArray[np.bool_]]:
    """The pivot sequence (row, column) over the columns ``eliminated`` by Markowitz's rule
    with threshold pivoting at the values A (module docstring), and the filled pattern. The
    search runs on the active block alone (its rows and columns in their original order, so
    that ties go to the first in row-major order, as over the whole matrix)."""
    filled = P.copy()
    rows, cols = np.arange(P.shape[0]), np.arange(P.shape[1])
    on, A, elim = P.copy(), np.where(P, A, 0.0), eliminated.copy()
    never = np.iinfo(np.int64).max
    seq = []
    for _ in range(int(eliminated.sum())):
        rc, cc = on.sum(1), on.sum(0)
        size = np.abs(A)
        top = size.max(0)
        ok = on & elim[None, :] & (size >= THRESHOLD * top[None, :]) & (top > 0)
        cost = np.where(ok, (rc[:, None] - 1) * (cc[None, :] - 1), never)
        i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
        if cost[i, j] == never:
            raise RuntimeError("the Stewart template is singular at the sample instance")
        L = np.flatnonzero(on[:, j])
        L = L[L != i]
        U = np.flatnonzero(on[i])
        U = U[U != j]
        A[np.ix_(L, U)] -= np.outer(A[L, j] / A[i, j], A[i, U])
        on[np.ix_(L, U)] = True
        filled[np.ix_(rows[L], cols[U])] = True
        seq.append((int(rows[i]), int(cols[j])))
        on, A = np.delete(np.delete(on, i, 0), j, 1), np.delete(np.delete(A, i, 0), j, 1)
        rows, cols, elim = np.delete(rows, i), np.delete(cols, j), np.delete(elim, j)
    return seq, filled


@lru_cache(maxsize=1)
def schedule() -> dict[str, Any]:
    """The fixed arrays of :func:`.stewart_sparse_kernels.eliminate` (its docstring), made
    once per process (~0.4 s, 0.2 of it the pivot search): the pivot sequence at one random
    real instance (:data:`PIVOT_SAMPLE`, chart 0), the
    filled pattern, and per row its columns and sources, the steps that reach it, per step
    its pivot column and its pivot row's columns; ``r_of``: the leftover rows' R columns'
    order (X_R's rows are R's order, :func:`.stewart_template.layout`'s ``r_pos``)."""
    from screwkit.kinematics.modes.stewart import random_stewart
    from screwkit.kinematics.modes.stewart_template import coefficients, layout

    lay = layout()
    n, m = len(data.SQUARE), len(data.BASIS)
    P, row, col, src = _pattern(lay)
    sample, _ = random_stewart(np.random.default_rng(PIVOT_SAMPLE), 1)
    c = coefficients(sample.real.astype(complex)).real.reshape(-1)
    A = np.zeros(P.shape)
    A[row, col] = c[src]
    eliminated = np.ones(n + m, dtype=bool)
    eliminated[lay["r_pos"]] = False
    eliminated[n:] = False
    seq, filled = _pivots(P, A, eliminated)
    steps = len(seq)
    step_of = np.full(n + m, steps + 1)  # a column's step (R and B: never)
    step_of[[j for _, j in seq]] = np.arange(steps)
    pivot_rows = [i for i, _ in seq]
    left = np.setdiff1d(np.arange(n), pivot_rows)
    source = np.full(P.shape, -1, dtype=np.intp)
    source[row, col] = src
    pivot_col = np.array([j for _, j in seq])
    init_ptr, init_col, init_src, upd_ptr, upd_step = [0], [], [], [0], []
    u_ptr, u_col = [0], []
    for t, i in enumerate(list(pivot_rows) + list(left)):
        cols = np.flatnonzero(filled[i])
        init_col += list(cols)
        init_src += list(source[i, cols])
        init_ptr.append(len(init_col))
        mine = step_of[cols]
        reach = np.sort(mine[mine < min(t, steps)])
        upd_step += list(reach)
        upd_ptr.append(len(upd_step))
        if t < steps:
            later = cols[(step_of[cols] > t)]
            u_col += [seq[t][1]] + list(later[later != seq[t][1]])
            u_ptr.append(len(u_col))
    out_col = np.concatenate([np.repeat(np.asarray(lay["r_pos"])[None], len(left), 0),
                              np.repeat(n + np.arange(m)[None], len(left), 0)], axis=1)

    def u32(v: Any) -> Index:  # unsigned: no negative-index wraparound in the kernel
        return np.ascontiguousarray(v, dtype=np.uint32)

    return {"init_ptr": u32(init_ptr), "init_col": u32(init_col),
            "init_src": np.ascontiguousarray(init_src, dtype=np.int32),
            "upd_ptr": u32(upd_ptr), "upd_step": u32(upd_step), "pivot_col": u32(pivot_col),
            "u_ptr": u32(u_ptr), "u_col": u32(u_col), "out_col": u32(out_col),
            "columns": n + m, "left": len(left), "flops": _flops(u_ptr, upd_step)}


def _flops(u_ptr: list[int], upd_step: list[int]) -> int:
    """The floating-point operations of one instance's elimination (a multiply and a
    subtract per entry of a pivot row, per row it reaches; one multiply per multiplier)."""
    length = np.diff(np.asarray(u_ptr)) - 1
    return int(np.sum(2 * length[np.asarray(upd_step, dtype=np.intp)] + 1))


def prepare() -> None:
    """The schedule made and the kernel compiled (or loaded from numba's cache), once per
    process: before a batch's threads start, so that they do not each make them."""
    _kernel()


@lru_cache(maxsize=1)
def _kernel() -> Any:
    """:func:`.stewart_sparse_kernels.eliminate_vector`, or its plain twin
    :func:`~.stewart_sparse_kernels.eliminate` (the same results, slower) where numba cannot
    compile the vector operation (its LLVM interface changes between versions)."""
    import numba

    from screwkit.kinematics.modes import stewart_sparse_kernels as kernels

    plan = schedule()
    G = kernels.LANES
    try:
        kernels.eliminate_vector(
            np.zeros((1, G)), plan["init_ptr"][:1], plan["init_col"], plan["init_src"],
            plan["upd_ptr"][:1], plan["upd_step"], plan["pivot_col"][:0], plan["u_ptr"],
            plan["u_col"], plan["out_col"], np.zeros((1, G)), np.zeros((1, G)),
            np.zeros((1, 1, G)), np.zeros(G))
    except (TypeError, numba.core.errors.NumbaError):
        return kernels.eliminate
    return kernels.eliminate_vector


def aligned_zeros(shape: tuple[int, int]) -> NDArray[np.float64]:
    """A zero array whose data start on a cache line (:data:`ALIGN` bytes), so that each row
    of :data:`GROUP` float64 (two lines) is one vector operation on two whole lines: numpy's
    arrays start 16 bytes past one (glibc's malloc), and each row's load and store then
    straddle three lines (the kernel measured 0.28 against 0.175 ms CPU per instance, 512
    bench instances, six runs each, alternating, load ~1.7; the same results bit for bit)."""
    size = shape[0] * shape[1]
    buf = np.zeros(size + ALIGN // 8)
    skip = (-buf.ctypes.data % ALIGN) // 8
    return buf[skip:skip + size].reshape(shape)


def r_rows(c: NDArray[np.float64], work: dict[str, Any] | None = None
           ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """X_R (B, 29, 40) of real instances' template coefficients c (B, 252) (module docstring),
    and whether each instance passed the growth check (the others' rows are NaN); ``work``:
    one thread's arrays kept from call to call."""
    plan = schedule()
    kernel = _kernel()
    B, G, left = len(c), GROUP, plan["left"]
    groups = -(-B // G)
    # instances padded to whole groups (copies of the last): each lane's arithmetic is the
    # same whatever else its group holds
    cp = np.concatenate([c, np.repeat(c[-1:], groups * G - B, axis=0)])
    cT = np.ascontiguousarray(cp.reshape(groups, G, -1).transpose(0, 2, 1))
    # the work arrays aligned (:func:`aligned_zeros`) and kept from call to call in ``work``
    # (one thread's): the kernel leaves w zero after each row and writes U before reading it
    work = {} if work is None else work
    if "sparse_w" not in work:
        work["sparse_w"] = aligned_zeros((plan["columns"], G))
        work["sparse_U"] = aligned_zeros((len(plan["u_col"]), G))
    w, U = work["sparse_w"], work["sparse_U"]
    out = np.empty((groups, left, plan["out_col"].shape[1], G))
    big = np.zeros((groups, G))
    for s in range(groups):
        kernel(cT[s], plan["init_ptr"], plan["init_col"], plan["init_src"],
                          plan["upd_ptr"], plan["upd_step"], plan["pivot_col"], plan["u_ptr"],
                          plan["u_col"], plan["out_col"], w, U, out[s], big[s])
    C = out.transpose(0, 3, 1, 2).reshape(groups * G, left, -1)[:B]
    ok = np.isfinite(C).all(axis=(1, 2)) & (big.reshape(-1)[:B] <= GROWTH)
    X = np.full((B, left, C.shape[2] - left), np.nan)
    CR = np.where(ok[:, None, None], C[..., :left], np.eye(left))
    CB = np.where(ok[:, None, None], C[..., left:], 0.0)
    try:
        X[ok] = -np.linalg.solve(CR[ok], CB[ok])
    except np.linalg.LinAlgError:  # one singular system stops LAPACK's stack: one by one
        for b in np.flatnonzero(ok):
            try:
                X[b] = -np.linalg.solve(CR[b], CB[b])
            except np.linalg.LinAlgError:
                ok[b] = False
    ok &= np.isfinite(X).all(axis=(1, 2))
    return X, ok
