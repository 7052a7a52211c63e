"""Every pose of 6-6 Stewart–Gough platforms: the elimination template first, the parameter
homotopy where it cannot promise all 40 (issue 27).

:func:`solve_stewart` runs the template of :mod:`.stewart_template` (one block-triangular
solve of a 526 × 526 matrix and a 40 × 40 eigenproblem per instance) on every instance of a
batch, polishes its 40 points by Newton's method on modes/stewart.py's system and certifies
them by Smale's α-test (:mod:`.eigen_first`). An instance whose 40 are not all settled and
distinct (an ill-conditioned template, a double root, a pose far out, fewer than 40 finite
poses) is eliminated again in another affine chart of the Study coordinates (a pose far out
in one chart, ill-conditioned there, is near the middle of another), and what is still unsettled is solved by the parameter homotopy
from the stored start solutions (algebraic/solve.py), which finds every isolated solution
there is. The result is the homotopy's :class:`Solutions`, the same layout and checks for either
route, with ``route`` naming per instance the method that ran.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache, partial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic import compiled, hessenberg_eig
from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex
from screwkit.algebraic.solve import Solutions
from screwkit.errors import InputError
from screwkit.kinematics.modes import eigen_first, stewart_sparse
from screwkit.kinematics.modes.stewart import (
    PATCH,
    STEWART_GENERIC_COUNT,
    stewart_start,
    stewart_system,
)
from screwkit.kinematics.modes.stewart_template import (
    CHUNK,
    EITHER,
    LAPACK,
    SPARSE,
    THREADS,
    blas_controller,
    quadric_forms,
    quadrics,
    template_solve,
)

#: the template's passes, tried in turn on the instances still unsettled: (chart, route of
#: :func:`.stewart_template.template_solve`). A batch's sparse route leaves ~4 % unsettled in
#: chart 0 (a pivot fixed beforehand is small at that instance); chart 1's sparse route settles
#: ~80 % of those at an eighth of the LAPACK route's cost, and the LAPACK route in charts 1
#: and 2 the rest but a few in a thousand (docs/kinematics.md, "Speed"). A lone instance (no
#: whole group for the sparse route) skips the sparse pass: chart 0, 1 and 2 by LAPACK.
PASSES = ((0, EITHER), (1, SPARSE), (1, LAPACK), (2, LAPACK))
#: Newton steps at most per point: the template's points arrive within ~1e-8 (relative) at
#: the median, a few percent 1e-3..0.2 off (the block-triangular solve pivots within blocks
#: only); a point stops once its step is at round-off
NEWTON_STEPS = 6
TEMPLATE = "elimination template (526 × 526, block triangular; 40 × 40 eigenproblem)"
HOMOTOPY = "parameter homotopy (the template did not settle 40 distinct solutions)"


def _targets(params: ArrayLike) -> Complex:
    p = np.asarray(params, dtype=complex)
    if p.ndim not in (1, 2) or p.shape[-1] != 42:
        raise InputError(f"Stewart–Gough parameters must have shape (42,) or (B, 42); got "
                         f"{p.shape}")
    if not np.isfinite(p).all():
        raise InputError("Stewart–Gough parameters must be finite")
    return p.reshape(-1, 42)


def dense_quadrics(targets: Complex) -> tuple[Complex, Complex]:
    """The system's symmetric matrices (B, 8, 9, 9) at the instances (B, 42), F_i = zᵀ Q_i z
    with z = (x, y, 1): the Study quadric and the six legs (:func:`.stewart_template.quadrics`,
    Husty 1996) and the patch r·x − 1; and their term-wise moduli, |z|ᵀ |Q|_i |z| = Σ|terms|
    of F_i (the α-test's rounding scale): for the polish's dense Newton steps and α-test.
    Both in one compiled pass when numba is there (:func:`.stewart_kernels.dense_quadrics`:
    the same sums, equal to this numpy route's to rounding; a batch in parts on the
    template's threads)."""
    if compiled.AVAILABLE:
        from screwkit.kinematics.modes import stewart_kernels

        G, H, S, patch = _kernel_forms()
        Q = np.empty((len(targets), 8, 9, 9), dtype=complex)
        Qabs = np.empty_like(Q)
        t = np.ascontiguousarray(targets, dtype=complex)

        def part(a: int, b: int) -> None:
            stewart_kernels.dense_quadrics(t[a:b], G, H, S, patch, Q[a:b], Qabs[a:b])

        # a batch's instances in contiguous parts on the template's threads (the kernel
        # releases the GIL and goes instance by instance: the same values)
        parts = min(THREADS, len(t) // (2 * CHUNK))
        if parts <= 1:
            part(0, len(t))
            return Q, Qabs
        cuts = [len(t) * k // parts for k in range(parts + 1)]
        with ThreadPoolExecutor(parts) as pool:
            for f in [pool.submit(part, a, b) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]:
                f.result()
        return Q, Qabs
    out = []
    for absolute in (False, True):
        Q = np.zeros((len(targets), 8, 9, 9), dtype=complex)
        Q[:, :7, :8, :8] = quadrics(targets, absolute)
        Q[:, 7, :4, 8] = Q[:, 7, 8, :4] = 0.5 * (np.abs(PATCH) if absolute else PATCH)
        Q[:, 7, 8, 8] = 1.0 if absolute else -1.0
        out.append(Q)
    return out[0], out[1]


@lru_cache(maxsize=1)
def _kernel_forms() -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                             NDArray[np.float64]]:
    """G, H, S (:func:`.stewart_template.quadric_forms`) and the patch r, contiguous."""
    G, H, S = (np.ascontiguousarray(v, dtype=float) for v in quadric_forms())
    return G, H, S, np.ascontiguousarray(PATCH, dtype=float)


def eliminate_pass(params: Complex, label: int, threads: int | None = None
                   ) -> tuple[Complex, Complex]:
    """The template's points and keys (:func:`.stewart_template.template_solve`) of the
    instances (B, 42) in the pass ``label`` of :data:`PASSES`."""
    chart, route = PASSES[label]
    return template_solve(params, chart, threads, route)


@lru_cache(maxsize=1)
def stewart_route() -> eigen_first.EigenRoute:
    """The Stewart–Gough platform's eigen route (module docstring), keyed by ξ1; a batch's
    polish and fast α-test on the template's :data:`.stewart_template.THREADS` threads."""
    return eigen_first.EigenRoute(stewart_system(), STEWART_GENERIC_COUNT, eliminate_pass,
                                  tuple(range(len(PASSES))), stewart_start, TEMPLATE, HOMOTOPY,
                                  NEWTON_STEPS, dense_quadrics, THREADS,
                                  partial(eliminate_pass, threads=1), CHUNK)


def solve_stewart(params: ArrayLike, options: TrackOptions | None = None) -> Solutions:
    """Every isolated solution (Study coordinates, modes/stewart.py) of the instances (42,) or
    (B, 42) (:func:`.stewart.stewart_parameters`): the template, the parameter homotopy
    (``options``) for the instances it does not settle (module docstring). ``route`` says
    which ran for each instance."""
    targets = _targets(params)
    if len(targets) < 2 * CHUNK:
        return eigen_first.solve_eigen_first(stewart_route(), targets, options)
    # a batch runs on the cores in threads of its own (template_solve): BLAS's threads held at
    # one for the whole solve, not only the elimination (OpenBLAS's threads, woken by a later
    # small product, spin on the cores the batch's threads use)
    # the compiled kernels made (or loaded) once, before the parts' threads start
    if stewart_sparse.AVAILABLE:
        stewart_sparse.prepare()
    if hessenberg_eig.AVAILABLE:
        hessenberg_eig.prepare()
    with blas_controller().limit(limits=1, user_api="blas"):
        return eigen_first.solve_eigen_first(stewart_route(), targets, options)
