"""Every solution of 6R loops (6R arm inverse kinematics, 7R loops at one input): elimination
first, the parameter homotopy where elimination cannot promise all 16.

:func:`solve_loop6r` runs the eigenvalue solver of :mod:`.sixr_elimination` (Raghavan & Roth
1993; Manocha & Canny 1994) on every instance of a batch, polishes its 16 solutions by Newton's
method on the polynomial system of :mod:`.loop6r` (the axes z2..z5; Sommese & Wampler 2005,
ch. 9) and certifies them by Smale's α-test (algebraic/certify.py). An instance whose 16 are
not all settled and distinct (a special geometry: a singular leading matrix, a double root, a
solution at a shifted half-angle of ∞, fewer than 16 finite solutions; :func:`eigen_route`)
is eliminated again with the loop relabelled cyclically, and what is still unsettled is
solved by the parameter homotopy from the stored start solutions (algebraic/solve.py), which
finds every isolated solution there is. The result is the homotopy's :class:`Solutions`, the
same layout and checks for either route, with ``route`` naming per instance the method that
ran.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.certify import Certificate
from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex
from screwkit.algebraic.solve import Solutions
from screwkit.errors import InputError
from screwkit.kinematics.modes import eigen_first
from screwkit.kinematics.modes.loop6r import (
    LOOP6R_GENERIC_COUNT,
    PARAMETER_NAMES,
    loop6r_start,
    loop6r_system,
)
from screwkit.kinematics.modes.sixr_elimination import eliminate

#: the cyclic relabellings of the loop tried in turn on the instances still unsettled
SHIFTS = (0, 1, 5, 2, 4, 3)
ELIMINATION = "elimination (Raghavan & Roth; 24 × 24 eigenproblem)"
HOMOTOPY = "parameter homotopy (elimination did not settle 16 distinct solutions)"


def _targets(params: ArrayLike) -> Complex:
    p = np.asarray(params, dtype=complex)
    k = len(PARAMETER_NAMES)
    if p.ndim not in (1, 2) or p.shape[-1] != k:
        raise InputError(f"6R parameters must have shape ({k},) or (B, {k}); got {p.shape}")
    if not np.isfinite(p).all():
        raise InputError("6R parameters must be finite")
    return p.reshape(-1, k)


def _eliminate(targets: Complex, shift: int) -> tuple[Complex, Complex]:
    x, x3, _ = eliminate(targets, shift)
    return x, x3


@lru_cache(maxsize=1)
def loop6r_route() -> eigen_first.EigenRoute:
    """The 6R loop's eigen route (module docstring): the 24 × 24 eigenproblem, keyed by x3,
    relabelled cyclically by :data:`SHIFTS`."""
    return eigen_first.EigenRoute(loop6r_system(), LOOP6R_GENERIC_COUNT, _eliminate, SHIFTS,
                                  loop6r_start, ELIMINATION, HOMOTOPY)


def eigen_route(params: ArrayLike
                ) -> tuple[Complex, NDArray[np.intp], NDArray[np.bool_], Certificate]:
    """The polished eigen-route solutions (P, 12) of the 6R instances (B, 23) it settles,
    sorted by their instance (P,); whether each instance is settled (B,); the α-test of every
    point (:func:`.eigen_first.eigen_route`: a geometry that makes the 12 × 12 pencil
    singular in one labelling, two consecutive axes that meet, say, may not in another)."""
    return eigen_first.eigen_route(loop6r_route(), _targets(params))


def solve_loop6r(params: ArrayLike, options: TrackOptions | None = None) -> Solutions:
    """Every isolated solution of 6R instances (23,) or (B, 23) (:mod:`.loop6r`'s parameters):
    the eigen route, the parameter homotopy (``options``) for the instances it does not
    settle (module docstring). ``route`` says which ran for each instance."""
    return eigen_first.solve_eigen_first(loop6r_route(), _targets(params), options)
