"""Inverse dynamics of any mechanism graph: :func:`graph_inverse_dynamics` → :class:`GraphDynamics`.

Three steps, as for a single loop (dynamics/inverse.py): the applied inertia + weight wrench of
every moving body (dynamics/inertia.py: Newton–Euler in the world frame; a body's mass properties
are given in the drawing, whose frame is the body frame), the unit screws of every freedom (from
the graph kinematics), and the joint wrenches and input efforts from the bodies' balances and the
joints' "no work along a passive freedom" conditions (dynamics/graph_statics.py). The regressor
runs the same solve with one load column per inertial parameter (loads = Y·π).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dynamics.checks import DynamicsInputError, MissingMassError, check_vector3
from screwkit.dynamics.graph_statics import GraphStatics, solve_graph_statics
from screwkit.dynamics.inertia import inertia_wrench_regressor, inertia_wrenches
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class GraphDynamics:
    """Loads of one mode of a mechanism over its samples (SI, world frame).

    ``efforts`` (N, n_e): the effort (torque of an R, force of a P) of each freedom in
    ``input_names`` — the joint inputs, then the actuated freedoms of a body-driven mechanism —
    what the driving body exerts on the driven one along the freedom; ``reaction_force``/``reaction_moment``
    (N, J, 3): the wrench each joint's first body exerts on its second, moment about the joint
    centre; ``shaking_force``/``shaking_moment`` (N, 3): what the moving bodies exert on the
    ground, moment about the world origin; ``ok`` where the mode assembles and is regular;
    ``indeterminate``: statically indeterminate components (least-norm choice, docs), carried by
    ``indeterminate_joints``; ``residual`` (N,) of the equations relative to the loads."""

    input_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    efforts: Array
    reaction_force: Array
    reaction_moment: Array
    shaking_force: Array
    shaking_moment: Array
    ok: NDArray[np.bool_]
    indeterminate: int
    indeterminate_joints: list[str]
    residual: Array
    gravity: Array

    @property
    def gravity_on(self) -> bool:
        """Whether the loads include gravity (a non-zero ``gravity`` vector)."""
        return bool(np.any(self.gravity != 0))

    @property
    def relative_residual(self) -> Array:
        """``residual`` (already relative to the loads), as single loops name it."""
        return self.residual

    def as_dict(self) -> dict[str, Any]:
        return {"inputs": list(self.input_names),
                "efforts": {n: self.efforts[:, k] for k, n in enumerate(self.input_names)},
                "reactions": {n: {"force": self.reaction_force[:, j],
                                  "moment": self.reaction_moment[:, j]}
                              for j, n in enumerate(self.joint_names)},
                "shaking_force": self.shaking_force, "shaking_moment": self.shaking_moment,
                "assembles_and_regular": self.ok, "gravity": self.gravity,
                "indeterminate": {"count": self.indeterminate,
                                  "joints": self.indeterminate_joints,
                                  "choice": "least-norm reactions, moments about the joint "
                                            "centres divided by the length scale"},
                "residual": self.residual,
                "units": {"force": "N", "moment": "N*m", "length": "m"}}


def body_masses(motion: MechanismMotion) -> list[MassProperties]:
    """Every moving body's mass properties; a clear error naming the bodies without."""
    mech = motion.mechanism
    missing = [b.name for b in mech.bodies if b.mass is None]
    if missing:
        raise MissingMassError(
            f"{mech.name}: loads need the mass properties of every moving body; "
            f"{', '.join(missing)} {'has' if len(missing) == 1 else 'have'} none (give mass, "
            "com and inertia in its [[bodies]] entry)")
    return [b.mass for b in mech.bodies if b.mass is not None]


def effort_names(mech: Mechanism) -> tuple[str, ...]:
    """The freedoms whose efforts hold the mechanism: its joint inputs, then the actuated
    freedoms of a mechanism driven by body freedoms (one per drive; model/mechanism_drives.py)."""
    if mech.drives and len(mech.actuated) != len(mech.drives):
        raise DynamicsInputError(
            f"{mech.name}: loads of a mechanism driven by {len(mech.drives)} body freedom(s) "
            f"({', '.join(d.name for d in mech.drives)}) need as many actuated joint freedoms, "
            "the motors whose efforts hold it on that path; mark actuated = true on them (e.g. "
            "a Stewart platform's six leg slides)")
    return (*mech.inputs, *mech.actuated)


def statics_of_mode(motion: MechanismMotion, mode: int, loads: Array
                    ) -> tuple[GraphStatics, Any]:
    """The joint wrenches and efforts for body loads ``loads`` (N, B, 6, K) at the regular
    samples of ``mode``, with (the regular-sample mask, the graph frames there)."""
    mech = motion.mechanism
    md = motion.mode(mode)
    ok = np.asarray(md.assembles & ~md.singular)
    if not ok.any():
        raise DynamicsInputError(f"{mech.name}: mode {mode} assembles (regularly) at no sample")
    lay = graph_layout(mech)
    driven = [lay.names.index(n) for n in effort_names(mech)]
    passive = [f for f in range(lay.m) if f not in driven]
    fr = graph_forward(mech, lay, md.conf.take(np.nonzero(ok)[0]))
    st = solve_graph_statics(mech, fr.screws, fr.centres, loads[ok], passive, driven,
                             lay.joint_of, lay.length)
    return st, (ok, fr)


def graph_inverse_dynamics(motion: MechanismMotion, mode: int = 0,
                           gravity: ArrayLike | None = None) -> GraphDynamics:
    """Efforts, joint reactions and shaking loads of ``mode`` (module docstring)."""
    mech = motion.mechanism
    g = check_vector3(gravity, "gravity")
    masses = body_masses(motion)
    md = motion.mode(mode)
    loads = np.nan_to_num(inertia_wrenches(masses, md, g, np.zeros(3)))[..., None]
    st, (ok, fr) = statics_of_mode(motion, mode, loads)
    N, J = md.samples, len(mech.joints)
    W = np.full((N, J, 6), np.nan)
    W[ok] = st.wrenches[..., 0]
    centres = np.full((N, J, 3), np.nan)
    centres[ok] = fr.centres
    force = W[:, :, :3]
    moment = W[:, :, 3:] - np.cross(centres, force)
    shaking = np.zeros((N, 6))
    for j, joint in enumerate(mech.joints):
        a, b = joint.bodies
        if b == GROUND:
            shaking += W[:, j]
        elif a == GROUND:
            shaking -= W[:, j]
    efforts = np.full((N, len(effort_names(mech))), np.nan)
    efforts[ok] = st.efforts[..., 0]
    residual = np.full(N, np.nan)
    residual[ok] = st.residual[:, 0]
    return GraphDynamics(effort_names(mech), tuple(j.name for j in mech.joints), efforts, force,
                         moment, shaking[:, :3], shaking[:, 3:], ok, st.indeterminate,
                         st.indeterminate_joints, residual, g)


def graph_regressor(motion: MechanismMotion, mode: int = 0, gravity: ArrayLike | None = None
                    ) -> Array:
    """The efforts' regressor (N, n_e, 10·B): efforts = Y·π with π the bodies' inertial
    parameters (``MassProperties.inertial_parameters``, about the body-frame origin, which is the
    world origin of the drawing) stacked body by body; NaN where the mode is not regular."""
    mech = motion.mechanism
    g = check_vector3(gravity, "gravity")
    md = motion.mode(mode)
    Y = np.nan_to_num(inertia_wrench_regressor(md, g, np.zeros(3)))  # (N, B, 6, 10)
    N, B = Y.shape[:2]
    loads = np.zeros((N, B, 6, 10 * B))
    for b in range(B):
        loads[:, b, :, 10 * b:10 * b + 10] = Y[:, b]
    st, (ok, _) = statics_of_mode(motion, mode, loads)
    out = np.full((N, len(effort_names(mech)), 10 * B), np.nan)
    out[ok] = st.efforts
    return out
