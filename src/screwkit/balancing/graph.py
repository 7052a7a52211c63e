"""Optimum balancing of any mechanism graph (docs/balancing.md, "Mechanism graphs"): the same
problem as a single loop's (Rahman 1996 ch. 4, corrected), built from the graph's load regressor
(:func:`~screwkit.dynamics.graph_regressor.graph_load_regressor`, loads = Y·π over the bodies'
inertial parameters). Design variables name bodies where a loop's name links: a body's
seven-point model, counterweights at a point of the body (drawing coordinates, the body frame),
the SDP redistribution bound; measures F, T, R, M, T0 over every joint and every input.

:func:`prepare_graph` builds the :class:`~screwkit.balancing.balance.BalancingSetup` (then
:func:`~screwkit.balancing.balance.solve_setup`, the Pareto sweep and the SDP work unchanged);
:func:`balance_mechanism` runs one set of weights or a whole
:class:`~screwkit.balancing.config.BalancingConfig`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from screwkit.balancing.balance import BalancingSetup, check_idle_spin, solve_setup
from screwkit.balancing.config import BalancingConfig, run_config
from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import Normalisation, default_normalisation, load_rows
from screwkit.balancing.problem import consistency_constraints
from screwkit.balancing.result import BalanceResult
from screwkit.balancing.variables import VariableBlock, assemble
from screwkit.dynamics.graph_regressor import graph_load_regressor
from screwkit.errors import expect_instance
from screwkit.kinematics.graph.motion import MechanismMotion


def _mode(motion: MechanismMotion, mode: int) -> None:
    """A clear error unless ``mode`` assembles regularly at every sample."""
    md = motion.mode(mode)
    ok = np.asarray(md.assembles & ~md.singular)
    if not ok.all():
        x = np.asarray(motion.inputs)[~ok, 0]
        listed = ", ".join(f"{v:.6g}" for v in x[:8]) + (" …" if x.size > 8 else "")
        raise BalancingError(
            f"{motion.mechanism.name}: mode {mode} does not assemble (or is singular) at "
            f"{int(x.size)} of {ok.size} samples (first input {listed}, SI); balancing needs "
            "loads over the whole sweep: change the [motion] range to one where it assembles")


def graph_speed(motion: MechanismMotion) -> float:
    """The first input's speed (the normalisation's ω); an error if it varies."""
    rates = np.asarray(motion.input_rates)[:, 0]
    if not np.all(rates == rates[0]):
        raise BalancingError("the input speed varies over the motion: give speed= (the ω of "
                             "the normalisation) or a normalisation")
    return float(rates[0])


def prepare_graph(motion: MechanismMotion, mode: int, blocks: Sequence[VariableBlock], *,
                  speed: float | None = None, gravity: ArrayLike | None = None,
                  normalisation: Normalisation | None = None) -> BalancingSetup:
    """Regressor, load rows and design variables of one mode of a mechanism graph."""
    expect_instance(motion, MechanismMotion, "balance: motion",
                    "a solved mechanism (sk.solve_mechanism(...))")
    mech = motion.mechanism
    variables = assemble(mech, blocks)
    _mode(motion, mode)
    md = motion.mode(mode)
    reg = graph_load_regressor(motion, mode, gravity)
    w = graph_speed(motion) if speed is None else speed
    norm = normalisation or default_normalisation(mech, md, w)
    rows = load_rows(mech, md, reg, norm)
    check_idle_spin(mech, md, reg, variables)
    extra = consistency_constraints(reg, variables)
    x_in = np.asarray(motion.inputs, dtype=float)[:, 0]
    return BalancingSetup(mech, md, reg, rows, variables, extra, x_in)


def balance_mechanism(
    motion: MechanismMotion,
    mode: int,
    blocks: Sequence[VariableBlock] | BalancingConfig,
    weights: Mapping[str, float] | None = None,
    *,
    speed: float | None = None,
    gravity: ArrayLike | None = None,
    normalisation: Normalisation | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> BalanceResult:
    """Optimum balancing of mode ``mode`` of a solved mechanism graph (module docstring).

    ``blocks``: design variables (:func:`~screwkit.balancing.variables.point_mass_variables`,
    :func:`~screwkit.balancing.variables.counterweight_variables` with the mechanism and a body
    name) or a whole :class:`BalancingConfig` (its weights, gravity, normalisation, SDP bound and
    Pareto sweep; ``gravity`` is then the vector used when the config asks for it); ``speed``:
    the ω of the normalisation (default the first input's rate, which must be constant)."""
    expect_instance(motion, MechanismMotion, "balance: motion",
                    "a solved mechanism (sk.solve_mechanism(...))")
    mech = motion.mechanism
    if isinstance(blocks, BalancingConfig):
        nt = blocks.normalisation
        _mode(motion, mode)
        w = graph_speed(motion) if speed is None else speed
        norm = default_normalisation(mech, motion.mode(mode), w if nt.speed is None else nt.speed,
                                     mass=nt.mass, length=nt.length,
                                     bearing_length=nt.bearing_length)
        setup = prepare_graph(motion, mode, list(blocks.blocks), speed=w,
                              gravity=gravity if blocks.gravity else None, normalisation=norm)
        return run_config(setup, blocks, progress)
    if weights is None:
        raise BalancingError("give the weights by measure name, e.g. {'F': 1.0, 'T0': 0.5}")
    setup = prepare_graph(motion, mode, blocks, speed=speed, gravity=gravity,
                          normalisation=normalisation)
    return solve_setup(setup, weights)
