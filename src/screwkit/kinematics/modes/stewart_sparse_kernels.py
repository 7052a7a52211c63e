"""The numba kernel of :mod:`.stewart_sparse` (imported by it on first use only, so that
importing screwkit does not import numba): the Stewart template's sparse elimination with a
fixed pivot sequence, row by row, for a group of instances side by side (the instance the
innermost, contiguous index, so that every operation is one vector operation across the group).
Module-level functions, so that numba's disk cache (next to this module) is found again.

:func:`eliminate_vector` is :func:`eliminate` with its innermost operation, w[c] −= m·U[q] over
the group, written as one LLVM vector operation per entry (:func:`_subtract_rows`): numba's
loop over the lanes carries run-time trip-count and overlap checks per entry, which cost more
than the arithmetic (measured, wall time, load ~2.4: 0.22–0.27 against 0.38–0.47 ms per
instance in groups of 16; the same results bit for bit: the same multiply and subtract per
lane, no fused multiply-add)."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

njit = numba.njit(cache=True, nogil=True, error_model="numpy")
#: the instances of a group in :func:`eliminate_vector` (the vector width it is compiled for)
LANES = 16


@intrinsic
def _subtract_rows(typingctx: Any, w: Any, U: Any, u_col: Any, start: Any, stop: Any,
                   m: Any) -> Any:
    """w[u_col[q], :] −= m · U[q, :] for q in [start, stop), each row of :data:`LANES`
    float64 one vector load, multiply, subtract and store (LLVM IR)."""
    sig = types.void(w, U, u_col, start, stop, m)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        wt, ut, ct, st, et, mt = signature.args
        wa = context.make_array(wt)(context, builder, args[0])
        ua = context.make_array(ut)(context, builder, args[1])
        ca = context.make_array(ct)(context, builder, args[2])
        ma = context.make_array(mt)(context, builder, args[5])
        vec = ir.VectorType(ir.DoubleType(), LANES)
        lanes = ir.Constant(ir.IntType(64), LANES)
        lo = context.cast(builder, args[3], st, types.intp)
        hi = context.cast(builder, args[4], et, types.intp)
        mult = builder.load(builder.bitcast(ma.data, vec.as_pointer()), align=8)
        one = ir.Constant(ir.IntType(64), 1)
        with cgutils.for_range_slice(builder, lo, hi, one, inc=True) as (q, _):
            c = context.cast(builder, builder.load(builder.gep(ca.data, [q])), ct.dtype,
                             types.intp)
            wp = builder.bitcast(builder.gep(wa.data, [builder.mul(c, lanes)]),
                                 vec.as_pointer())
            up = builder.bitcast(builder.gep(ua.data, [builder.mul(q, lanes)]),
                                 vec.as_pointer())
            x = builder.load(wp, align=8)
            builder.store(builder.fsub(x, builder.fmul(mult, builder.load(up, align=8))), wp,
                          align=8)
        return context.get_dummy_value()

    return sig, codegen


@njit
def eliminate(cT: Any, init_ptr: Any, init_col: Any, init_src: Any, upd_ptr: Any,
              upd_step: Any, pivot_col: Any, u_ptr: Any, u_col: Any, out_col: Any,
              w: Any, U: Any, out: Any, big: Any) -> None:
    """The row-by-row (left-looking) Gaussian elimination of :mod:`.stewart_sparse`'s schedule
    on G instances at once (Gilbert & Peierls 1988, "Sparse partial pivoting in time
    proportional to arithmetic operations", SIAM J. Sci. Stat. Comput. 9(5), with the pivot
    sequence fixed beforehand).

    ``cT`` (equation coefficients, G): the template's coefficients of the group, instance last.
    Row t of the schedule (the pivot row of step t, then the rows left over) is scattered into
    the dense accumulator ``w`` (columns, G) from ``init_*``; each earlier step k that reaches it
    (``upd_step``) subtracts its multiplier, w[pivot_col[k]] / pivot, times step k's pivot row
    U[u_ptr[k] + 1 : u_ptr[k + 1]] (columns ``u_col``); a pivot row is then stored as U (its
    pivot's reciprocal first), a leftover row copied to ``out`` (leftover, columns out_col, G).
    The touched columns of ``w`` are zeroed after each row (``init_col`` holds, per row, every
    column of its filled pattern; those not in the template start at zero). ``big`` (G): the
    largest |multiplier| per instance, the pivot growth check of the caller."""
    G = w.shape[1]
    steps = len(pivot_col)
    rows = len(init_ptr) - 1
    mult = np.empty(G)
    for t in range(rows):
        for e in range(init_ptr[t], init_ptr[t + 1]):
            c, s = init_col[e], init_src[e]
            if s >= 0:
                for g in range(G):
                    w[c, g] = cT[s, g]
        for e in range(upd_ptr[t], upd_ptr[t + 1]):
            k = upd_step[e]
            jk = pivot_col[k]
            a = u_ptr[k]
            for g in range(G):
                mult[g] = w[jk, g] * U[a, g]
                big[g] = max(big[g], abs(mult[g]))
            for q in range(a + 1, u_ptr[k + 1]):
                c = u_col[q]
                for g in range(G):
                    w[c, g] -= mult[g] * U[q, g]
        if t < steps:
            a = u_ptr[t]
            for g in range(G):
                U[a, g] = 1.0 / w[pivot_col[t], g]
            for q in range(a + 1, u_ptr[t + 1]):
                c = u_col[q]
                for g in range(G):
                    U[q, g] = w[c, g]
        else:
            r = t - steps
            for q in range(out_col.shape[1]):
                c = out_col[r, q]
                for g in range(G):
                    out[r, q, g] = w[c, g]
        for e in range(init_ptr[t], init_ptr[t + 1]):
            c = init_col[e]
            for g in range(G):
                w[c, g] = 0.0


@njit
def eliminate_vector(cT: Any, init_ptr: Any, init_col: Any, init_src: Any, upd_ptr: Any,
                     upd_step: Any, pivot_col: Any, u_ptr: Any, u_col: Any, out_col: Any,
                     w: Any, U: Any, out: Any, big: Any) -> None:
    """:func:`eliminate` for groups of :data:`LANES` instances (w, U: (·, LANES)), the update
    of a row by an earlier pivot row in vector operations (:func:`_subtract_rows`)."""
    G = LANES
    assert w.shape[1] == LANES and U.shape[1] == LANES
    steps = len(pivot_col)
    rows = len(init_ptr) - 1
    mult = np.empty(G)
    for t in range(rows):
        for e in range(init_ptr[t], init_ptr[t + 1]):
            c, s = init_col[e], init_src[e]
            if s >= 0:
                for g in range(G):
                    w[c, g] = cT[s, g]
        for e in range(upd_ptr[t], upd_ptr[t + 1]):
            k = upd_step[e]
            jk = pivot_col[k]
            a = u_ptr[k]
            for g in range(G):
                mult[g] = w[jk, g] * U[a, g]
                big[g] = max(big[g], abs(mult[g]))
            _subtract_rows(w, U, u_col, a + 1, u_ptr[k + 1], mult)  # type: ignore[call-arg]
        if t < steps:
            a = u_ptr[t]
            for g in range(G):
                U[a, g] = 1.0 / w[pivot_col[t], g]
            for q in range(a + 1, u_ptr[t + 1]):
                c = u_col[q]
                for g in range(G):
                    U[q, g] = w[c, g]
        else:
            r = t - steps
            for q in range(out_col.shape[1]):
                c = out_col[r, q]
                for g in range(G):
                    out[r, q, g] = w[c, g]
        for e in range(init_ptr[t], init_ptr[t + 1]):
            c = init_col[e]
            for g in range(G):
                w[c, g] = 0.0
