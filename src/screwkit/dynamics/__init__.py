"""Inverse dynamics of single closed loops: inertia wrenches, shaking force and moment, joint
reactions, driven efforts, gravity and external loads, and the regressor (loads = Y·π).

See docs/dynamics.md for conventions and for how statically indeterminate components and idle
passive freedoms are reported.
"""

from screwkit.dynamics.checks import (
    DynamicsInputError,
    ExternalLoad,
    MissingMassError,
    NonAssemblingMotionError,
)
from screwkit.dynamics.cssp_fused_dynamics import cssp_inverse_dynamics
from screwkit.dynamics.inertia import inertia_wrench_regressor, inertia_wrenches
from screwkit.dynamics.inverse import (
    INERTIAL_PARAMETER_NAMES,
    Regressor,
    inverse_dynamics,
    regressor,
)
from screwkit.dynamics.result import Dynamics, Indeterminacy
from screwkit.dynamics.sample_blocks import BLOCK_SAMPLES
from screwkit.dynamics.screws import FreedomScrews, freedom_screws

__all__ = [
    "BLOCK_SAMPLES",
    "INERTIAL_PARAMETER_NAMES",
    "Dynamics",
    "DynamicsInputError",
    "ExternalLoad",
    "FreedomScrews",
    "Indeterminacy",
    "MissingMassError",
    "NonAssemblingMotionError",
    "Regressor",
    "cssp_inverse_dynamics",
    "freedom_screws",
    "inertia_wrench_regressor",
    "inertia_wrenches",
    "inverse_dynamics",
    "regressor",
]
