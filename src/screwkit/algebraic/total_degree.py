"""The total-degree homotopy: every isolated solution of a small system with no known solution.

The start system G_i(x) = x_i^(d_i) − 1 (d_i the total degree of equation i) has the
Π d_i (Bézout number) solutions x_i = exp(2πi·j_i/d_i). The homotopy
H_i(x, s) = (1 − s)·γ_i·G_i(x) + s·F_i(x; p), with random complex γ_i (the "gamma trick"),
has smooth paths for s ∈ [0, 1) with probability one, and every isolated solution of
F(x; p) = 0 is the end of one of them; the other paths go to infinity or to positive-dimensional
components (Sommese & Wampler, *The Numerical Solution of Systems of Polynomials*, 2005, §8.4,
Theorem 8.4.1). It is run as a parameter homotopy of the system extended with the parameters
a_i, b_i: b_i·F_i(x; p) + a_i·G_i(x), from (p, a = γ, b = 0) to (p, a = 0, b = 1).

The number of paths is the Bézout number, which grows fast: this is for the first solve of a
small system; afterwards a parameter homotopy from the stored generic solutions
(:mod:`.solve`) tracks only as many paths as there are solutions.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.track import TrackResult, track_parameter_homotopy
from screwkit.errors import InputError
from screwkit.messages import shown_values

#: the largest Bézout number :func:`solve_total_degree` tracks
MAX_PATHS = 5000


def bezout_number(system: PolynomialSystem) -> int:
    """Π d_i: the total-degree bound on the number of isolated solutions."""
    return math.prod(system.degrees)


def with_start_system(system: PolynomialSystem) -> PolynomialSystem:
    """The extended system b_i·F_i(x; p) + a_i·(x_i^(d_i) − 1) with parameters (p, a, b)."""
    n, k = system.n, system.k
    T, width = system.sym.shape
    a = n + k + np.arange(n)
    b = a + n
    sym = np.zeros((T + 2 * n, width + 1), dtype=np.intp)
    pw = np.zeros_like(sym)
    sym[:T, :width], pw[:T, :width] = system.sym, system.pw
    sym[:T, width], pw[:T, width] = b[system.eq], 1
    eq = np.concatenate([system.eq, np.repeat(np.arange(n), 2)])
    lead = T + 2 * np.arange(n)
    sym[lead, 0], pw[lead, 0] = np.arange(n), system.degrees  # x_i^(d_i)·a_i
    sym[lead, 1], pw[lead, 1] = a, 1
    sym[lead + 1, 0], pw[lead + 1, 0] = a, 1  # −a_i
    coef = np.concatenate([system.coef, np.tile([1.0, -1.0], n)]).astype(complex)
    order = np.argsort(eq, kind="stable")
    eq = eq[order]
    starts = np.minimum(np.searchsorted(eq, np.arange(n)), len(eq) - 1).astype(np.intp)
    names = tuple(f"start_a{i}" for i in range(n)) + tuple(f"start_b{i}" for i in range(n))
    return PolynomialSystem(system.variables, system.parameters + names, eq, coef[order],
                            sym[order], pw[order], starts, system.degrees)


def start_solutions(degrees: tuple[int, ...]) -> Complex:
    """The Π d_i solutions of x_i^(d_i) = 1, (Π d_i, n)."""
    roots = [np.exp(2j * np.pi * np.arange(d) / d) for d in degrees]
    return np.array(list(itertools.product(*roots)), dtype=complex).reshape(-1, len(degrees))


def solve_total_degree(system: PolynomialSystem, p: Complex,
                       options: TrackOptions | None = None, seed: int = 0) -> TrackResult:
    """Track the Bézout number of paths from x_i^(d_i) = 1 to F(x; p) = 0, for one parameter
    vector p (k,) or a batch (B, k). Returns the :class:`TrackResult` of every path
    (instance b's paths are rows b·D .. (b+1)·D − 1, D the Bézout number); its regular ends
    are the nonsingular isolated solutions."""
    if any(d < 1 for d in system.degrees):
        raise InputError("every equation must involve the unknowns (total degree ≥ 1); "
                         f"the degrees are {shown_values(system.degrees)}")
    count = bezout_number(system)
    if count > MAX_PATHS:
        raise InputError(f"the total-degree homotopy would track {count} paths (the Bézout "
                         f"number Π d_i with d = {shown_values(system.degrees)}), more than {MAX_PATHS}; "
                         "use monodromy_solve from one known solution instead")
    p = np.asarray(p, dtype=complex)
    if p.shape[-1:] != (system.k,) or p.ndim not in (1, 2):
        raise InputError(f"p must have shape ({system.k},) or (B, {system.k}); got {p.shape}")
    batch = p.reshape(1, system.k) if p.ndim == 1 else p
    B, n = len(batch), system.n
    rng = np.random.default_rng(seed)
    gamma = np.exp(2j * np.pi * rng.random(n))
    extended = with_start_system(system)
    p_start = np.concatenate([batch, np.tile(gamma, (B, 1)), np.zeros((B, n))], axis=1)
    p_target = np.concatenate([batch, np.zeros((B, n)), np.ones((B, n))], axis=1)
    x0 = start_solutions(system.degrees)
    return track_parameter_homotopy(extended, np.repeat(p_start, count, axis=0),
                                    np.repeat(p_target, count, axis=0), np.tile(x0, (B, 1)),
                                    options)
