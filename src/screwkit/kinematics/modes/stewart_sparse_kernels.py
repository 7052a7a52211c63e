"""The numba kernel of :mod:`.stewart_sparse` (imported by it on first use only, so that
importing screwkit does not import numba): the Stewart template's sparse elimination with a
fixed pivot sequence, row by row, for a group of instances side by side (the instance the
innermost, contiguous index, so that every operation is one vector operation across the group).
Module-level functions, so that numba's disk cache (next to this module) is found again."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

njit = numba.njit(cache=True, nogil=True, error_model="numpy")


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
