"""A balancing run described as data: design variables, weights, normalisation, the optional SDP
bound and Pareto sweep — what a spec file's ``[balancing]`` table says, validated and in SI units
(:mod:`screwkit.io.balancing_table` builds it), and :func:`balance_with_config`, which runs it on
one assembly mode (docs/balancing.md, "Spec file")."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike

from screwkit.balancing.balance import BalancingSetup, prepare, solve_setup
from screwkit.balancing.measures import default_normalisation
from screwkit.balancing.result import BalanceResult
from screwkit.balancing.variables import VariableBlock
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage


@dataclass(frozen=True)
class NormalisationConfig:
    """The seed's normalisation constants, SI; ``None`` takes the default from the mechanism
    (:func:`~screwkit.balancing.measures.default_normalisation`)."""

    mass: float | None = None
    length: float | None = None
    speed: float | None = None
    bearing_length: float | None = None


@dataclass(frozen=True)
class BalancingConfig:
    """One balancing run (Rahman 1996 ch. 4, corrected; docs/balancing.md).

    ``blocks``: the design variables; ``weights``: W by measure name (``F``, ``T``, ``R``,
    ``M``, ``T0``); ``gravity``: include the links' weights in the loads; ``bound``: per link an
    ellipsoid (centre, semi-axes; link frame, m) for the bound over every physically consistent
    redistribution (SDP); ``pareto``: the measures of a weight sweep and its grid divisions.
    """

    blocks: tuple[VariableBlock, ...]
    weights: Mapping[str, float]
    gravity: bool = False
    normalisation: NormalisationConfig = field(default_factory=NormalisationConfig)
    bound: Mapping[str, tuple[Sequence[float], Sequence[float]]] | None = None
    pareto: tuple[tuple[str, ...], int] | None = None


def balance_with_config(linkage: Linkage, mode: ModeMotion, config: BalancingConfig, *,
                        speed: float, gravity: ArrayLike | None = None,
                        inputs: ArrayLike | None = None,
                        progress: Callable[[int, int], None] | None = None) -> BalanceResult:
    """Run ``config`` on one assembly mode: the QP for its weights, then the SDP bound and the
    Pareto sweep when asked for (``progress(done, total)`` after each of its weightings). ``speed`` is the input speed ω of the motion (the default for
    the normalisation); ``gravity`` the gravitational acceleration vector (used when
    ``config.gravity``)."""
    nt = config.normalisation
    norm = default_normalisation(linkage, mode, speed if nt.speed is None else nt.speed,
                                 mass=nt.mass, length=nt.length,
                                 bearing_length=nt.bearing_length)
    g = gravity if config.gravity else None
    setup = prepare(linkage, mode, list(config.blocks), speed=speed, gravity=g,
                    normalisation=norm, inputs=inputs)
    return run_config(setup, config, progress)


def run_config(setup: BalancingSetup, config: BalancingConfig,
               progress: Callable[[int, int], None] | None = None) -> BalanceResult:
    """The QP of ``config``'s weights on a prepared setup (a loop's or a graph's), then the SDP
    bound and the Pareto sweep when asked for."""
    result = solve_setup(setup, config.weights)
    if config.bound is not None:
        from screwkit.balancing.sdp import redistribution_bound

        bound = redistribution_bound(setup, config.weights,
                                     {k: (np.asarray(c), np.asarray(a))
                                      for k, (c, a) in config.bound.items()})
        result = replace(result, redistribution_bound=bound)
    if config.pareto is not None:
        from screwkit.balancing.pareto import pareto_front

        result = replace(result, pareto=pareto_front(setup, *config.pareto, progress=progress))
    return result
