"""The 6R elimination of :mod:`.sixr_elimination` compiled by numba, for real instances.

The method is the numpy route's (Raghavan & Roth, J. Mech. Des. 115, 1993; Manocha & Canny,
IEEE T-RA 10(5), 1994; the module docstring of :mod:`.sixr_elimination`), step for step, with
the same LAPACK drivers; only the order of work differs. numpy runs each step over the batch
(~250 array calls per elimination, ~1,000 µs-scale calls per instance when solving one
instance at a time); here two compiled loops run one instance at a time and numpy's batched
eigensolver sits between them:

1. :func:`.sixr_kernels.companion`: the Denavit–Hartenberg chain, the 14 quantities at the
   fixed sample angles, the fit (times the fixed pseudo-inverses of :func:`.sample_design`),
   the null space of the θ1θ2 products' coefficients (SVD), the 12 × 12 pencil Σ(x3) and the
   24 × 24 companion matrix (cond of the leading matrix by its singular values, the solve by
   LU: the numpy route's checks);
2. ``numpy.linalg.eig`` of the companion matrices (LAPACK's real driver, so that a real
   instance's roots come in exact conjugate pairs, as :mod:`.loop6r_solve` relies on), and the
   8 spurious roots nearest ±i dropped by the same sort;
3. :func:`.sixr_kernels.solutions`: x4, x5 from each eigenvector, θ1, θ2 by the
   least-squares solve, θ6 by closure when relabelled, the axes z2..z5.

The results equal the numpy route's to round-off (tests/kinematics/test_sixr_compiled.py).
numba is optional (the ``fast`` extra): without it, or with SCREWKIT_NO_NUMBA set,
:data:`AVAILABLE` is False and :func:`.sixr_elimination.eliminate` runs the numpy route; the
kernels are compiled on first use and cached on disk next to their module.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.algebraic import compiled
from screwkit.kinematics.modes.sixr_elimination import (
    OFFSETS,
    SAMPLES,
    monomial_map,
    sample_design,
)

#: numba is there and not turned off (the flag of algebraic/compiled.py)
AVAILABLE = compiled.AVAILABLE
#: points at least per thread of :func:`settled` (~0.15 µs a point of 40 per instance; a
#: thread costs ~0.1 ms to start)
SETTLED_POINTS = 8192

Complex = NDArray[np.complex128]
Array = NDArray[np.float64]


@lru_cache(maxsize=1)
def _plan() -> tuple[Any, ...]:
    """The fixed arrays the kernels read, contiguous: the sample angles' cosines and sines
    (left, right), the two pseudo-inverses, the monomial map and the offsets."""
    D = sample_design(SAMPLES)
    return tuple(np.ascontiguousarray(v, dtype=float) for v in (
        D["cos_left"], D["sin_left"], D["cos_right"], D["sin_right"], D["left_pinv"],
        D["right_pinv"], monomial_map(), np.asarray(OFFSETS)))


def eliminate_real(p: Array, shift: int) -> tuple[Complex, Complex, Array]:
    """:func:`.sixr_elimination.eliminate` of real parameters (B, 23) (checked by it),
    compiled: the 16 solutions (B, 16, 12), their x3 (B, 16), cond of Σ's leading matrix (B,)."""
    from screwkit.kinematics.modes import sixr_kernels

    cl, sl, cr, sr, left_pinv, right_pinv, mono, offsets = _plan()
    p = np.ascontiguousarray(p, dtype=float)
    B = len(p)
    comp = np.empty((B, 24, 24))
    L = np.empty((B, 14, 27))
    pinv = np.empty((B, 8, 14))
    cos_a, sin_a = np.empty((B, 6)), np.empty((B, 6))
    R0 = np.empty((B, 3, 3))
    cond = np.empty(B)
    bad = np.empty(B, dtype=np.bool_)
    sixr_kernels.companion(p, shift, cl, sl, cr, sr, left_pinv, right_pinv, mono, comp, L,
                           pinv, cos_a, sin_a, R0, cond, bad)
    lam, W = np.linalg.eig(comp)
    lam, W = lam.astype(complex, copy=False), W.astype(complex, copy=False)
    idx = np.argsort(np.minimum(np.abs(lam - 1j), np.abs(lam + 1j)), 1)[:, 8:]
    axes = np.empty((B, 16, 12), dtype=complex)
    x3 = np.empty((B, 16), dtype=complex)
    sixr_kernels.solutions(lam, W, idx, L, pinv, cos_a, sin_a, R0, bad, shift, offsets, axes,
                           x3)
    return axes, x3, cond


def settled(xs: Complex, inst: NDArray[np.intp], finite: NDArray[np.bool_], newton: Complex,
            certified: NDArray[np.bool_], radius: Array, B: int, m: int, converged: float,
            distinct: float, threads: int = 1) -> NDArray[np.bool_]:
    """loop6r_solve's verdict per instance (B,) on its points xs (P, n) sorted by ``inst``,
    compiled (:func:`.sixr_kernels.settled`); on up to ``threads`` threads over contiguous
    parts of whole instances (the kernel releases the GIL and decides each instance on its
    own: the same verdicts), at least :data:`SETTLED_POINTS` points a thread."""
    from screwkit.kinematics.modes import sixr_kernels

    P = len(xs)
    x, nw, cert, rad, fin, ins = (np.ascontiguousarray(a) for a in (xs, newton, certified,
                                                                    radius, finite, inst))

    def part(a: int, b: int) -> NDArray[np.bool_]:
        ok = np.zeros(B, dtype=np.bool_)  # (the kernel clears it: one per part)
        if b > a:
            sixr_kernels.settled(x[a:b], nw[a:b], cert[a:b], rad[a:b], fin[a:b], ins[a:b], m,
                                 converged, distinct, ok)
        return ok

    parts = min(threads, P // SETTLED_POINTS)
    if parts <= 1:
        return part(0, P)
    # cuts at the first point of an instance
    cuts = [0] + [int(np.searchsorted(ins, ins[P * t // parts]))
                  for t in range(1, parts)] + [P]
    with ThreadPoolExecutor(parts) as pool:
        oks = list(pool.map(part, cuts[:-1], cuts[1:]))
    return np.logical_or.reduce(oks)
