"""Optimum balancing of spatial linkages (Rahman 1996 ch. 4, corrected; docs/balancing.md).

Load measures over one cycle (shaking force F, shaking moment T, bearing forces R, bearing
moments M, input torque T0) are quadratic in the links' inertial parameters; the design variables
(point masses of each link's equivalent model, counterweights) enter those linearly, so the
weighted objective is a convex QP, solved with Clarabel. A singular Hessian (a non-unique
optimum) is detected and reported.
"""

from screwkit.balancing.balance import BalancingSetup, balance, prepare, solve_setup
from screwkit.balancing.errors import (
    BalancingError,
    InfeasibleConstraintsError,
    MissingSolverError,
    SolverError,
)
from screwkit.balancing.measures import MEASURES, Normalisation, default_normalisation
from screwkit.balancing.result import BalanceResult
from screwkit.balancing.variables import (
    DesignVariables,
    LinearConstraint,
    VariableBlock,
    counterweight_variables,
    point_mass_variables,
)

__all__ = [
    "MEASURES",
    "BalanceResult",
    "BalancingError",
    "BalancingSetup",
    "DesignVariables",
    "InfeasibleConstraintsError",
    "LinearConstraint",
    "MissingSolverError",
    "Normalisation",
    "SolverError",
    "VariableBlock",
    "balance",
    "counterweight_variables",
    "default_normalisation",
    "point_mass_variables",
    "prepare",
    "solve_setup",
]
