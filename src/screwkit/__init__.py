"""screwkit — analysis, synthesis and dynamic balancing of spatial linkages with dual-number
screw calculus.

The front door (``import screwkit as sk``), Pinocchio-style verbs on read-only models::

    spec = sk.load_spec("examples/rsrc_fig7_dynamics.toml")      # a Spec (SI units)
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)   # a Motion
    dyn = sk.inverse_dynamics(motion, 0, gravity=[0, 0, -9.80665])         # a Dynamics
    sk.mobility(spec.linkage), sk.limit_positions(motion), sk.transmission(motion)
    sk.balance(motion, 0, [sk.point_mass_variables(spec.linkage, "coupler")], {"F": 1})
    sk.synthesize(sk.load_spec("examples/bagci_example1_synthesis.toml").synthesis)
    sk.Pipeline(spec).balance()       # every job of a spec on one solved motion

Mechanisms: ``sk.rsrc``, ``sk.cssp``, ``sk.fourbar``, ``sk.rssr``, ``sk.rccc`` (the seeds'
parameter names, SI units and radians), ``sk.Linkage.from_hartenberg_denavit`` for any loop,
``sk.family(name)`` for what each family offers. Layers (imports go down only):
:mod:`screwkit.dual` → :mod:`screwkit.model` → :mod:`screwkit.kinematics` →
:mod:`screwkit.dynamics`, :mod:`screwkit.mobility` → :mod:`screwkit.balancing`,
:mod:`screwkit.synthesis` → :mod:`screwkit.io`, :mod:`screwkit.pipeline`, :mod:`screwkit.cli`
(docs/architecture.md). Names are imported on first use, so ``import screwkit`` is quick.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: public name -> module that defines it
_EXPORTS: dict[str, str] = {
    # errors
    "ScrewkitError": "screwkit.errors",
    # spec files
    "load_spec": "screwkit.io.spec",
    "Spec": "screwkit.io.spec",
    "SpecError": "screwkit.io.errors",
    # the model
    "Linkage": "screwkit.model.linkage",
    "Link": "screwkit.model.linkage",
    "Joint": "screwkit.model.joints",
    "MassProperties": "screwkit.model.mass",
    "rsrc": "screwkit.model.families",
    "cssp": "screwkit.model.families",
    "fourbar": "screwkit.model.families",
    "rssr": "screwkit.model.families",
    "rccc": "screwkit.model.families",
    "Mechanism": "screwkit.model.mechanism",
    "Body": "screwkit.model.mechanism",
    "MechanismJoint": "screwkit.model.mechanism",
    "BodyPoint": "screwkit.model.mechanism",
    "solve_mechanism": "screwkit.kinematics.graph.motion",
    "MechanismMotion": "screwkit.kinematics.graph.motion",
    "mechanism_topology": "screwkit.kinematics.graph.topology",
    "delta_forward": "screwkit.kinematics.modes.delta",
    "delta_inverse": "screwkit.kinematics.modes.delta",
    "family": "screwkit.kinematics.registry",
    # kinematics
    "solve_motion": "screwkit.kinematics.solve_motion",
    "solve_joints": "screwkit.kinematics.tracker.joint_motion",
    "JointMotion": "screwkit.kinematics.tracker.joint_motion",
    "Motion": "screwkit.kinematics.motion",
    "ModeMotion": "screwkit.kinematics.motion",
    "AssemblyError": "screwkit.kinematics.motion",
    "limit_positions": "screwkit.kinematics.analysis.limit_positions",
    "coupler_point_path": "screwkit.kinematics.analysis.coupler_curves",
    "transmission": "screwkit.kinematics.analysis.transmission",
    "mobility": "screwkit.mobility",   # the package, callable: screwkit.mobility(linkage)
    # dynamics
    "inverse_dynamics": "screwkit.dynamics.inverse",
    "regressor": "screwkit.dynamics.inverse",
    "Dynamics": "screwkit.dynamics.result",
    "ExternalLoad": "screwkit.dynamics.checks",
    # balancing
    "balance": "screwkit.balancing.balance",
    "point_mass_variables": "screwkit.balancing.variables",
    "counterweight_variables": "screwkit.balancing.variables",
    "BalanceResult": "screwkit.balancing.result",
    "BalancingConfig": "screwkit.balancing.config",
    # synthesis
    "synthesize": "screwkit.synthesis.config",
    "SynthesisConfig": "screwkit.synthesis.config",
    # one spec, every job
    "Pipeline": "screwkit.pipeline",
}
_ALIASES = {"synthesize": "run_synthesis"}

__all__ = [
    "ScrewkitError",
    "AssemblyError",
    "BalanceResult",
    "Body",
    "BodyPoint",
    "BalancingConfig",
    "Dynamics",
    "ExternalLoad",
    "Joint",
    "Link",
    "JointMotion",
    "Linkage",
    "MassProperties",
    "Mechanism",
    "MechanismJoint",
    "MechanismMotion",
    "ModeMotion",
    "Motion",
    "Pipeline",
    "Spec",
    "SpecError",
    "SynthesisConfig",
    "balance",
    "counterweight_variables",
    "coupler_point_path",
    "cssp",
    "delta_forward",
    "delta_inverse",
    "family",
    "fourbar",
    "inverse_dynamics",
    "limit_positions",
    "load_spec",
    "mechanism_topology",
    "mobility",
    "point_mass_variables",
    "rccc",
    "regressor",
    "rsrc",
    "rssr",
    "solve_joints",
    "solve_mechanism",
    "solve_motion",
    "synthesize",
    "transmission",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'screwkit' has no attribute {name!r}")
    imported = importlib.import_module(module)
    value = imported if module == f"screwkit.{name}" else getattr(imported, _ALIASES.get(name, name))
    globals()[name] = value
    return value


_SUBPACKAGES = ["balancing", "dual", "dynamics", "io", "kinematics", "mobility", "model",
                "pipeline", "synthesis"]


def __dir__() -> list[str]:
    """What tab completion offers: the front door, the layers and the version."""
    return sorted({*__all__, *_SUBPACKAGES, "__version__"})


if TYPE_CHECKING:
    from screwkit.balancing.balance import balance
    from screwkit.balancing.config import BalancingConfig
    from screwkit.balancing.result import BalanceResult
    from screwkit.balancing.variables import counterweight_variables, point_mass_variables
    from screwkit.dynamics.checks import ExternalLoad
    from screwkit.dynamics.inverse import inverse_dynamics, regressor
    from screwkit.dynamics.result import Dynamics
    from screwkit.errors import ScrewkitError
    from screwkit.io.errors import SpecError
    from screwkit.io.spec import Spec, load_spec
    from screwkit.kinematics.analysis.coupler_curves import coupler_point_path
    from screwkit.kinematics.analysis.limit_positions import limit_positions
    from screwkit.kinematics.analysis.loop_mobility import mobility
    from screwkit.kinematics.analysis.transmission import transmission
    from screwkit.kinematics.graph.motion import MechanismMotion, solve_mechanism
    from screwkit.kinematics.graph.topology import mechanism_topology
    from screwkit.kinematics.modes.delta import delta_forward, delta_inverse
    from screwkit.kinematics.motion import AssemblyError, ModeMotion, Motion
    from screwkit.kinematics.registry import family
    from screwkit.kinematics.solve_motion import solve_motion
    from screwkit.kinematics.tracker.joint_motion import JointMotion, solve_joints
    from screwkit.model.families import cssp, fourbar, rccc, rsrc, rssr
    from screwkit.model.joints import Joint
    from screwkit.model.linkage import Link, Linkage
    from screwkit.model.mass import MassProperties
    from screwkit.model.mechanism import Body, BodyPoint, Mechanism, MechanismJoint
    from screwkit.pipeline import Pipeline
    from screwkit.synthesis.config import SynthesisConfig
    from screwkit.synthesis.config import run_synthesis as synthesize
