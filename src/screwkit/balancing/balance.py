"""``balance``: from a linkage, one assembly mode and design variables to a
:class:`BalanceResult` (regressor → load rows → quadratic objective → QP → report)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import (
    MEASURES,
    LoadRows,
    Normalisation,
    default_normalisation,
    load_rows,
)
from screwkit.balancing.problem import (
    QuadraticObjective,
    check_weights,
    consistency_constraints,
    quadratic_objective,
    solve_balancing,
)
from screwkit.balancing.result import BalanceResult
from screwkit.balancing.variables import DesignVariables, VariableBlock, assemble
from screwkit.dynamics import Dynamics, Regressor, regressor
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage
from screwkit.model.mass import N_INERTIAL_PARAMETERS, MassProperties


@dataclass(frozen=True, eq=False)
class BalancingSetup:
    """Everything that does not depend on the weights (reused by a Pareto sweep)."""

    linkage: Linkage
    mode: ModeMotion
    regressor: Regressor
    rows: LoadRows
    variables: DesignVariables
    extra_constraints: list  # type: ignore[type-arg]
    inputs: np.ndarray


def prepare(
    linkage: Linkage,
    mode: ModeMotion,
    blocks: Sequence[VariableBlock],
    *,
    speed: float,
    gravity: ArrayLike | None = None,
    normalisation: Normalisation | None = None,
    inputs: ArrayLike | None = None,
) -> BalancingSetup:
    """Regressor, load rows and design variables of one mode (see :func:`balance`)."""
    variables = assemble(linkage, blocks)
    reg = regressor(linkage, mode, gravity=gravity, inputs=inputs)
    norm = normalisation or default_normalisation(linkage, mode, speed)
    rows = load_rows(linkage, mode, reg, norm)
    extra = consistency_constraints(reg, variables)
    x_in = (np.asarray(inputs, dtype=float).reshape(mode.assembles.shape[0], -1)[:, 0]
            if inputs is not None else mode.variables[linkage.inputs[0]])
    return BalancingSetup(linkage, mode, reg, rows, variables, extra, np.asarray(x_in))


def _check_free_counterweights(variables: DesignVariables, weights: Mapping[str, float]) -> None:
    free = [b for b in variables.blocks if b.kind == "free_counterweight"]
    others = {k: w for k, w in weights.items() if k != "F" and w > 0}
    if free and others:
        raise BalancingError(
            f"free-position counterweight(s) {[b.names[0].rsplit('.', 1)[0] for b in free]} "
            f"enter the measures {sorted(others)} through their second moments μ·p·pᵀ, which are "
            "not linear in the variables (μ, μ·p): give them a fixed position ('at') or weight "
            "only the shaking force F"
        )


def _link_masses(linkage: Linkage, pi: np.ndarray) -> dict[str, float]:
    return {lk.name: float(pi[N_INERTIAL_PARAMETERS * k]) for k, lk in enumerate(linkage.links)}


def _mass_properties(linkage: Linkage, pi: np.ndarray) -> dict[str, MassProperties]:
    return {lk.name: MassProperties.from_inertial_parameters(
        pi[N_INERTIAL_PARAMETERS * k: N_INERTIAL_PARAMETERS * (k + 1)])
        for k, lk in enumerate(linkage.links)}


def _sample_loads(setup: BalancingSetup, dyn: Dynamics, pi: np.ndarray,
                  weights: Mapping[str, float]) -> dict[str, np.ndarray]:
    sq = setup.rows.per_sample(pi)
    norm = setup.rows.normalisation
    F0 = norm.force
    efforts = list(dyn.efforts.values())
    return {
        "G": sum((weights[k] * sq[k] for k in MEASURES), start=np.zeros(setup.rows.samples)),
        "shaking_force": np.linalg.norm(dyn.shaking_force, axis=-1),
        "shaking_moment": np.linalg.norm(dyn.shaking_moment, axis=-1),
        "bearing_force": np.sqrt(sq["R"]) * F0,
        "bearing_moment": np.sqrt(sq["M"]) * F0 * norm.bearing_length,
        "input_torque": efforts[0] if efforts else np.zeros(setup.rows.samples),
    }


def solve_setup(setup: BalancingSetup, weights: Mapping[str, float]) -> BalanceResult:
    """Solve the balancing QP for one set of weights W1…W5 (by measure name)."""
    w = check_weights(weights)
    v = setup.variables
    _check_free_counterweights(v, w)
    objective: QuadraticObjective = quadratic_objective(setup.rows, v, w)
    opt = solve_balancing(objective, v, setup.extra_constraints)
    pi0, pi1 = v.physical_parameters(v.original), v.physical_parameters(opt.x)
    dyn0, dyn1 = setup.regressor.apply(pi0), setup.regressor.apply(pi1)
    notes = []
    if not opt.unique:
        notes.append(
            "the optimum is not unique: the Hessian is singular and the loads do not change "
            f"along {len(opt.directions)} direction(s) of the variables; the member nearest to "
            "the original design (least relative change) is returned")
    if setup.extra_constraints:
        notes.append(f"{len(setup.extra_constraints)} equality(ies) keep S-S links axisymmetric "
                     "(the idle spin of a rod between two ball joints carries no load)")
    return BalanceResult(
        variables=v, before=v.original.copy(), after=opt.x, objective=objective,
        measures_before=objective.measures(v.original), measures_after=objective.measures(opt.x),
        per_sample_before=_sample_loads(setup, dyn0, pi0, w),
        per_sample_after=_sample_loads(setup, dyn1, pi1, w),
        inputs=setup.inputs,
        link_mass_before=_link_masses(setup.linkage, pi0),
        link_mass_after=_link_masses(setup.linkage, pi1),
        mass_properties_before=_mass_properties(setup.linkage, pi0),
        mass_properties_after=_mass_properties(setup.linkage, pi1),
        unique=opt.unique, directions=opt.directions, active_constraints=opt.active,
        multipliers={c.name: float(m) for c, m in zip(opt.constraints, opt.multipliers,
                                                       strict=True) if m != 0.0},
        normalisation=setup.rows.normalisation, dynamics_before=dyn0, dynamics_after=dyn1,
        notes=notes,
    )


def balance(
    linkage: Linkage,
    mode: ModeMotion,
    blocks: Sequence[VariableBlock],
    weights: Mapping[str, float],
    *,
    speed: float,
    gravity: ArrayLike | None = None,
    normalisation: Normalisation | None = None,
    inputs: ArrayLike | None = None,
) -> BalanceResult:
    """Optimum balancing of one assembly mode (Rahman 1996 ch. 4, corrected; docs/balancing.md).

    ``blocks`` — design variables (:func:`~screwkit.balancing.variables.point_mass_variables`,
    :func:`~screwkit.balancing.variables.counterweight_variables`); ``weights`` — W by measure
    name (``F``, ``T``, ``R``, ``M``, ``T0``); ``speed`` — the input speed ω for the seed's
    normalisation (or give ``normalisation``).
    """
    setup = prepare(linkage, mode, blocks, speed=speed, gravity=gravity,
                    normalisation=normalisation, inputs=inputs)
    return solve_setup(setup, weights)
