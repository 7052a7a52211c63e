"""The numba kernel of :func:`.stewart_solve.dense_quadrics` (imported by it on first use only,
so that importing screwkit does not import numba): the symmetric matrices of the Stewart–Gough
system (Husty 1996: the Study quadric, the six leg quadrics of :func:`.stewart_template.quadrics`
and the patch r·x − 1) and their term-wise moduli, both in one pass per instance, the same sums
as the numpy route's (its docstring for the method). Module-level functions, so that numba's
disk cache (next to this module) is found again."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

njit = numba.njit(cache=True, nogil=True, error_model="numpy")


@njit
def _fill(par: Any, G: Any, H: Any, S: Any, patch: Any, sign: float, q: Any) -> None:
    """The eight 9 × 9 matrices q (8, 9, 9) of one instance's parameters ``par`` (42,), q
    zeroed: the Study quadric x·y (rows 0), leg i's |R b_i + t − a_i|² − L_i² in Study
    coordinates (rows 1..6: c_i I − 2 sign Σ_rs A_ir B_is S_rs on x x, 4 I on y y,
    2 Σ_r (B_ir G_r − sign A_ir H_r) on x y), the patch r·x − 1 (row 7). ``sign`` −1 with
    |par|, |G|, |H|, |S|, |r| gives the term-wise moduli (every − a +)."""
    for k in range(4):
        q[0, k, 4 + k] = 0.5
        q[0, 4 + k, k] = 0.5
    for i in range(6):
        a0, a1, a2 = par[3 * i], par[3 * i + 1], par[3 * i + 2]
        b0, b1, b2 = par[18 + 3 * i], par[19 + 3 * i], par[20 + 3 * i]
        c = (a0 * a0 + a1 * a1 + a2 * a2) + (b0 * b0 + b1 * b1 + b2 * b2) - sign * par[36 + i]
        e = 1 + i
        for k in range(4):
            for m in range(4):
                acc = 0j
                for r in range(3):
                    ar = par[3 * i + r]
                    for s in range(3):
                        acc += ar * par[18 + 3 * i + s] * S[k, m, r, s]
                q[e, k, m] = -sign * 2.0 * acc
                xy = 0j
                for r in range(3):
                    xy += par[18 + 3 * i + r] * G[r, k, m] - sign * par[3 * i + r] * H[r, k, m]
                q[e, k, 4 + m] = 2.0 * xy
                q[e, 4 + m, k] = 2.0 * xy
            q[e, k, k] += c
            q[e, 4 + k, 4 + k] = 4.0
    for k in range(4):
        q[7, k, 8] = 0.5 * patch[k]
        q[7, 8, k] = 0.5 * patch[k]
    q[7, 8, 8] = -sign


@njit
def dense_quadrics(params: Any, G: Any, H: Any, S: Any, patch: Any, Q: Any, Qabs: Any) -> None:
    """Q and Qabs (B, 8, 9, 9) of the instances params (B, 42) (:func:`_fill`, with the
    parameters, forms and patch as they are, then their moduli)."""
    aG, aH, aS, apatch = np.abs(G), np.abs(H), np.abs(S), np.abs(patch)
    apar = np.empty(params.shape[1], dtype=np.complex128)
    Q[:] = 0.0
    Qabs[:] = 0.0
    for b in range(params.shape[0]):
        _fill(params[b], G, H, S, patch, 1.0, Q[b])
        for j in range(params.shape[1]):
            apar[j] = abs(params[b, j])
        _fill(apar, aG, aH, aS, apatch, -1.0, Qabs[b])
