"""Start solutions per topology, found once per process and kept in memory (issue 27).

A parameter homotopy needs every solution of the system at one generic complex parameter
vector (:class:`~screwkit.algebraic.solve.StartSolutions`). Small systems get them from the
total-degree homotopy, which is complete when no path fails; the Stewart–Gough and 6R systems
(Bézout numbers 256 and 4,096) by monodromy from one random complex instance with a known
solution, stopped at the generic count the literature proves (40, 16), so that their start set
is complete as well. Nothing is stored on disk: a process finds them on first use.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable

import numpy as np

from screwkit.algebraic.monodromy import MonodromyOptions
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.solve import StartSolutions
from screwkit.algebraic.total_degree import bezout_number

#: systems with at most this many total-degree paths are started by the total-degree homotopy
TOTAL_DEGREE_PATHS = 64
_CACHE: dict[str, StartSolutions] = {}

RandomInstance = Callable[[np.random.Generator], tuple[Complex, Complex]]


def system_key(system: PolynomialSystem) -> str:
    """A digest of the system's terms: equal for the same topology, whatever the instance."""
    h = hashlib.sha256()
    for part in (system.eq, system.coef, system.sym, system.pw):
        h.update(np.ascontiguousarray(part).tobytes())
    h.update("|".join(system.variables + system.parameters).encode())
    return h.hexdigest()


def start_solutions(system: PolynomialSystem, random_instance: RandomInstance | None = None,
                    generic_count: int | None = None, seed: int = 0) -> StartSolutions:
    """Every solution of ``system`` at a generic complex parameter vector, cached per
    topology: by total degree for a Bézout number ≤ :data:`TOTAL_DEGREE_PATHS` (or when no
    random instance is given), otherwise by monodromy from ``random_instance(rng)`` (p (1, k),
    x (1, n), complex) until ``generic_count`` solutions are known."""
    key = system_key(system)
    if key not in _CACHE:
        if random_instance is None or bezout_number(system) <= TOTAL_DEGREE_PATHS:
            _CACHE[key] = _by_total_degree(system, seed)
        else:
            p0, x0 = random_instance(np.random.default_rng(seed))
            options = MonodromyOptions(expected=generic_count, seed=seed)
            _CACHE[key] = StartSolutions.by_monodromy(system, p0[0], x0[0], options)
    return _CACHE[key]


def _by_total_degree(system: PolynomialSystem, seed: int) -> StartSolutions:
    # the tracker's linear solve recurses without end on some exactly singular Jacobians
    # (algebraic/path.py::_solve, a known fault reported to its author); another random
    # start system avoids them, and the result does not depend on which one is used
    for attempt in range(4):
        try:
            return StartSolutions.by_total_degree(system, seed=seed + attempt)
        except RecursionError:
            continue
    return StartSolutions.by_total_degree(system, seed=seed + 4)
