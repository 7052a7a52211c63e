"""``balance``: from a linkage, one assembly mode and design variables to a
:class:`BalanceResult` (regressor → load rows → quadratic objective → QP → report)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

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
from screwkit.balancing.variables import (
    DesignVariables,
    Subject,
    VariableBlock,
    assemble,
    moving_parts,
)
from screwkit.dynamics import Dynamics, Regressor, regressor
from screwkit.dynamics.graph_inverse import GraphDynamics
from screwkit.dynamics.graph_regressor import GraphRegressor
from screwkit.errors import expect_instance, expect_number
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.messages import listing, shown
from screwkit.model.linkage import Linkage
from screwkit.model.mass import N_INERTIAL_PARAMETERS, MassProperties
from screwkit.model.mechanism import Mechanism

if TYPE_CHECKING:
    from screwkit.balancing.config import BalancingConfig
    from screwkit.kinematics.graph.motion import MechanismMotion


@dataclass(frozen=True, eq=False)
class BalancingSetup:
    """Everything that does not depend on the weights (reused by a Pareto sweep); ``linkage``
    is a single loop's Linkage or a graph's Mechanism (balancing/graph.py builds that setup)."""

    linkage: Subject
    mode: ModeMotion
    regressor: Regressor | GraphRegressor
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
    check_idle_spin(linkage, mode, reg, variables)
    extra = consistency_constraints(reg, variables)
    x_in = (np.asarray(inputs, dtype=float).reshape(mode.assembles.shape[0], -1)[:, 0]
            if inputs is not None else mode.variables[linkage.inputs[0]])
    return BalancingSetup(linkage, mode, reg, rows, variables, extra, np.asarray(x_in))


#: relative idle-spin residual (docs/dynamics.md) above which the original design is refused
IDLE_RESIDUAL_RTOL = 1e-8


def _ss_links(linkage: Linkage) -> list[int]:
    """Indices of the moving links between two spherical joints (link k joins joints k, k+1)."""
    kinds = [j.kind for j in linkage.joints]
    return [k for k in range(len(linkage.links))
            if kinds[k] == "S" and kinds[(k + 1) % len(kinds)] == "S"]


def _rod_description(linkage: Linkage, mode: ModeMotion, k: int) -> str:
    """Transverse principal moments and CoM offset of S–S link k about the line of its ball
    centres (at the first assembled sample), for the error message."""
    mp = linkage.links[k].mass
    assert mp is not None  # only links with mass properties are described
    i = int(np.flatnonzero(mode.assembles & ~mode.singular)[0])
    R, o = mode.link_rotation[i, k], mode.link_origin[i, k]
    c0, c1 = mode.joint_centres[i, k], mode.joint_centres[i, (k + 1) % len(linkage.joints)]
    u = R.T @ (c1 - c0)
    u /= np.linalg.norm(u)
    p0 = R.T @ (c0 - o)
    e = np.linalg.svd(u[None, :])[2][1:]  # two unit vectors normal to the axis (link frame)
    transverse = np.linalg.eigvalsh(e @ np.asarray(mp.inertia) @ e.T)
    r = np.asarray(mp.com) - p0
    offset = float(np.linalg.norm(r - (r @ u) * u))
    return (f"link {linkage.links[k].name!r} (transverse moments of inertia about its CoM "
            f"{shown(transverse[0], 'inertia')} and {shown(transverse[1], 'inertia')}, CoM "
            f"{shown(offset, 'length', digits=3)} off the line "
            "of its ball centres)")


def check_idle_spin(linkage: Subject, mode: ModeMotion, reg: Regressor | GraphRegressor,
                     variables: DesignVariables) -> None:
    """The original design must already balance the idle spin of every S–S rod (docs/dynamics.md:
    an S–S rod must be axisymmetric about the line of its ball centres, CoM on that line, for
    its idle spin to carry no load). Otherwise the consistency equalities cannot hold and the
    QP would only report "infeasible constraints"."""
    if reg.residual.size == 0 or reg.indeterminacy.idle_freedoms == 0:
        return
    dyn = reg.apply(variables.physical_parameters(variables.original))
    worst = float(np.max(dyn.relative_residual, initial=0.0))
    if worst <= IDLE_RESIDUAL_RTOL:
        return
    rods = ([] if isinstance(linkage, Mechanism) else
            [_rod_description(linkage, mode, k) for k in _ss_links(linkage)
             if linkage.links[k].mass is not None])
    raise BalancingError(
        f"{'; '.join(rods) or 'an S-S link'}: the original design loads the idle spin of the "
        f"rod about the line of its ball centres (residual up to {worst:.3g} of the largest "
        "joint load). Two ball joints cannot carry that moment: an S-S rod must be axisymmetric "
        "about the line of its ball centres, with its CoM on it (equal transverse moments; "
        "docs/dynamics.md, 'idle passive freedoms'). Make the rod's two transverse moments "
        "equal (e.g. inertia = [Ia, I, I] with x along the rod) before balancing")


def check_free_counterweights(blocks: Sequence[VariableBlock], weights: Mapping[str, float]
                              ) -> None:
    """Free-position counterweights enter every measure but F non-linearly: refuse them with
    another measure weighted (also checked at load, so `validate` reports it)."""
    free = [b for b in blocks if b.kind == "free_counterweight"]
    others = {k: w for k, w in weights.items() if k != "F" and w > 0}
    if free and others:
        raise BalancingError(
            f"free-position counterweight(s) {listing(b.names[0].rsplit('.', 1)[0] for b in free)} "
            f"enter the measures {listing(sorted(others))} through their second moments μ·p·pᵀ, which are "
            "not linear in the variables (μ, μ·p): give them a fixed position ('at') or weight "
            "only the shaking force F"
        )


def _link_masses(linkage: Subject, pi: np.ndarray) -> dict[str, float]:
    return {lk.name: float(pi[N_INERTIAL_PARAMETERS * k])
            for k, lk in enumerate(moving_parts(linkage))}


def _mass_properties(linkage: Subject, pi: np.ndarray) -> dict[str, MassProperties]:
    return {lk.name: MassProperties.from_inertial_parameters(
        pi[N_INERTIAL_PARAMETERS * k: N_INERTIAL_PARAMETERS * (k + 1)])
        for k, lk in enumerate(moving_parts(linkage))}


def _sample_loads(setup: BalancingSetup, dyn: Dynamics | GraphDynamics, pi: np.ndarray,
                  weights: Mapping[str, float]) -> dict[str, np.ndarray]:
    sq = setup.rows.per_sample(pi)
    norm = setup.rows.normalisation
    F0 = norm.force
    efforts = (list(dyn.efforts.T) if isinstance(dyn, GraphDynamics)
               else list(dyn.efforts.values()))
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
    check_free_counterweights(v.blocks, w)
    objective: QuadraticObjective = quadratic_objective(setup.rows, v, w)
    opt = solve_balancing(objective, v, setup.extra_constraints)
    pi0, pi1 = v.physical_parameters(v.original), v.physical_parameters(opt.x)
    dyn0, dyn1 = setup.regressor.apply(pi0), setup.regressor.apply(pi1)
    notes = []
    if opt.unique is False:
        notes.append(
            "the optimum is not unique: the Hessian is singular and the loads do not change "
            f"along {len(opt.directions)} direction(s) of the variables; the member nearest to "
            "the original design (least relative change) is returned")
    elif opt.unique is None:
        notes.append(
            "could not determine whether the optimum is unique: a linear program for the extent "
            "of the optimal set failed (the optimum itself is checked by its KKT conditions); "
            f"directions concerned: {len(opt.directions)}")
    indeterminate = setup.regressor.indeterminacy.count
    if indeterminate and (w["R"] > 0 or w["M"] > 0):
        notes.append(
            f"{indeterminate} reaction component(s) are statically indeterminate (overconstrained "
            "loop, e.g. a planar 4R solved as a spatial one): the bearing measures R and M use the "
            "minimum-norm reactions (docs/dynamics.md), one choice among many, so their optimum "
            "depends on that choice; real bearing loads depend on clearances and compliance. "
            "Weight only F, T and T0 for results independent of it")
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


def _check_arguments(linkage: object, mode: object, blocks: object, weights: object,
                     config_type: type, speed: object) -> None:
    """A BalancingError naming the argument of :func:`balance` that has the wrong type."""
    expect_instance(linkage, Linkage | Motion, "balance: linkage",
                    "a solved Motion (sk.solve_motion(...)) or a Linkage")
    if isinstance(linkage, Motion) and (isinstance(mode, bool)
                                        or not isinstance(mode, int | np.integer)):
        raise BalancingError(f"balance: with a Motion, give the assembly mode as an index "
                             f"0…{len(linkage.modes) - 1}; got {mode!r}")
    if not isinstance(blocks, config_type) and (
            isinstance(blocks, str) or not isinstance(blocks, Sequence)
            or not all(isinstance(b, VariableBlock) for b in blocks)):
        raise BalancingError("balance: blocks must be a list of design variables "
                             "([sk.point_mass_variables(linkage, 'coupler'), …]) or a "
                             f"BalancingConfig; got {type(blocks).__name__}")
    if speed is not None:
        expect_number(speed, "balance: speed")
    if weights is not None and not isinstance(weights, Mapping):
        raise BalancingError(f"balance: weights must be a mapping by measure name, e.g. "
                             f"{{'F': 1.0, 'T0': 0.5}}; got {type(weights).__name__}")


def balance(
    linkage: Linkage | Motion | MechanismMotion,
    mode: ModeMotion | int,
    blocks: Sequence[VariableBlock] | BalancingConfig,
    weights: Mapping[str, float] | None = None,
    *,
    speed: float | None = None,
    gravity: ArrayLike | None = None,
    normalisation: Normalisation | None = None,
    inputs: ArrayLike | None = None,
) -> BalanceResult:
    """Optimum balancing of one assembly mode (Rahman 1996 ch. 4, corrected; docs/balancing.md):
    the design variables that minimise the weighted mean squares of the shaking force and
    moment, bearing forces and moments and input torque over the cycle (a convex QP).

    ``balance(motion, k, blocks, weights)`` balances mode ``k`` of a solved
    :class:`~screwkit.kinematics.motion.Motion` (speed ω from its input rates), or of a solved
    mechanism graph (``sk.solve_mechanism``; :func:`screwkit.balancing.graph.balance_mechanism`,
    blocks naming bodies);
    ``balance(linkage, mode_motion, blocks, weights, speed=ω)`` one mode's
    :class:`~screwkit.kinematics.motion.ModeMotion` of ``linkage``.

    ``blocks`` — design variables (:func:`~screwkit.balancing.variables.point_mass_variables`,
    :func:`~screwkit.balancing.variables.counterweight_variables`), or a whole
    :class:`~screwkit.balancing.config.BalancingConfig` (then ``weights`` come from it);
    ``weights`` — W by measure name (``F``, ``T``, ``R``, ``M``, ``T0``); ``speed`` — the input
    speed ω (rad/s) of the seed's normalisation (or give ``normalisation``); ``gravity`` — the
    gravitational acceleration vector (m/s²), or none.
    """
    from screwkit.balancing.config import BalancingConfig, balance_with_config
    from screwkit.kinematics.graph.motion import MechanismMotion

    if isinstance(linkage, MechanismMotion):  # a mechanism graph (balancing/graph.py)
        from screwkit.balancing.graph import balance_mechanism

        if isinstance(mode, bool) or not isinstance(mode, int | np.integer):
            raise BalancingError(f"balance: with a solved mechanism, give the mode as an index "
                                 f"(0, the drawn mode); got {mode!r}")
        return balance_mechanism(linkage, int(mode), blocks, weights, speed=speed,
                                 gravity=gravity, normalisation=normalisation)
    _check_arguments(linkage, mode, blocks, weights, BalancingConfig, speed)
    if isinstance(linkage, Motion):
        motion = linkage
        linkage, mode = motion.linkage, motion.mode(int(mode))  # type: ignore[arg-type]
        inputs = motion.inputs if inputs is None else inputs
        if speed is None:
            rates = motion.input_rates[:, 0]
            if not np.all(rates == rates[0]) and normalisation is None:
                raise BalancingError("the input speed varies over the motion: give speed= (the "
                                     "ω of the normalisation) or a normalisation")
            speed = float(rates[0])
    if not isinstance(mode, ModeMotion):
        raise BalancingError("with a linkage, give one mode's ModeMotion (motion.mode(k)); or "
                             "pass the Motion itself: balance(motion, k, ...)")
    if speed is None:
        raise BalancingError("give speed= (the input speed ω, rad/s, of the normalisation)")
    if isinstance(blocks, BalancingConfig):
        return balance_with_config(linkage, mode, blocks, speed=speed, gravity=gravity,
                                   inputs=inputs)
    if weights is None:
        raise BalancingError("give the weights by measure name, e.g. {'F': 1.0, 'T0': 0.5}")
    setup = prepare(linkage, mode, blocks, speed=speed, gravity=gravity,
                    normalisation=normalisation, inputs=inputs)
    return solve_setup(setup, weights)
