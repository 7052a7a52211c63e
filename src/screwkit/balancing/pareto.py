"""Trade-off between the load measures: sweep the weights over a simplex grid, solve each QP
(the regressor and the variables are built once), and keep the non-dominated points."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.balance import BalancingSetup, solve_setup
from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import MEASURES
from screwkit.messages import listing

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ParetoFront:
    """``weights`` (K, m) and ``measures`` (K, m) for the swept measures ``names``;
    ``designs`` (K, n); ``efficient`` (K,) marks the non-dominated points."""

    names: tuple[str, ...]
    weights: Array
    measures: Array
    designs: Array
    efficient: NDArray[np.bool_]


def simplex_grid(m: int, divisions: int) -> Array:
    """All weight vectors with m entries k/divisions summing to 1."""
    pts = [c for c in itertools.product(range(divisions + 1), repeat=m) if sum(c) == divisions]
    return np.array(pts, dtype=float) / divisions


def non_dominated(values: Array, rtol: float = 1e-9) -> NDArray[np.bool_]:
    """Rows no other row beats in every column (and strictly in one)."""
    K = values.shape[0]
    tol = rtol * np.max(np.abs(values), axis=0)
    out = np.ones(K, dtype=bool)
    for i in range(K):
        better = np.all(values <= values[i] + tol, axis=1) & np.any(values < values[i] - tol,
                                                                    axis=1)
        out[i] = not better.any()
    return out


def pareto_front(setup: BalancingSetup, measures: Sequence[str] = ("F", "T", "T0"),
                 divisions: int = 4,
                 progress: Callable[[int, int], None] | None = None) -> ParetoFront:
    """Solve the balancing QP for every weight vector of a simplex grid over ``measures``;
    ``progress(done, total)`` is called after each weighting."""
    bad = [k for k in measures if k not in MEASURES]
    if bad or len(measures) < 2:
        raise BalancingError(f"pareto measures must be at least two of {listing(MEASURES)}; "
                             f"got {listing(measures)}")
    if divisions < 1:
        raise BalancingError(f"divisions must be >= 1; got {divisions}")
    grid = simplex_grid(len(measures), divisions)
    vals, designs = [], []
    for i, w in enumerate(grid):
        res = solve_setup(setup, dict(zip(measures, w, strict=True)))
        vals.append([res.measures_after[k] for k in measures])
        designs.append(res.after)
        if progress is not None:
            progress(i + 1, len(grid))
    values = np.array(vals)
    return ParetoFront(tuple(measures), grid, values, np.array(designs), non_dominated(values))
