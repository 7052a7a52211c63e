"""Every load of a mechanism graph as a linear function of its bodies' inertial parameters:
:func:`graph_load_regressor` → :class:`GraphRegressor` (load = Y·π), what balancing builds on.

The joint wrenches of dynamics/graph_statics.py are the least-norm solution of a linear system
whose right-hand side is the bodies' applied inertia + weight wrenches, and those are linear in
each body's ten inertial parameters (dynamics/inertia.py, Atkeson, An & Hollerbach 1986). One
solve with one right-hand side per parameter therefore gives every load's regressor exactly:
efforts, the reaction force and moment of every joint (about its centre), the shaking force and
moment (about the world origin), and the equations' residual — non-zero only along idle freedoms
(a rod spinning between two ball joints), whose consistency the balancing keeps as equalities.
The fields and :meth:`GraphRegressor.apply` mirror the single loop's
:class:`~screwkit.dynamics.inverse.Regressor`, link read as body.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.dynamics.checks import DynamicsInputError, check_vector3
from screwkit.dynamics.graph_inverse import GraphDynamics, effort_names, statics_of_mode
from screwkit.dynamics.inertia import inertia_wrench_regressor
from screwkit.dynamics.inverse import INERTIAL_PARAMETER_NAMES
from screwkit.dynamics.result import Indeterminacy
from screwkit.kinematics.graph.motion import MechanismMotion
from screwkit.model.mass import N_INERTIAL_PARAMETERS
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class GraphRegressor:
    """Loads of one mode of a mechanism, linear in π (P = 10·B, the bodies' parameters in
    ``mechanism.bodies`` order, each about the body-frame origin = the drawing's origin).

    Arrays carry P last: ``shaking_force``/``shaking_moment`` (N, 3, P), ``reactions`` {joint:
    {"force", "moment"}: (N, 3, P)} (by the joint's first body on its second, moment about the
    joint centre), ``efforts`` {input: (N, P)}, ``residual`` (N, R, P) the statics equations'
    residual (scaled as solved). ``constant`` is the π-independent part, zero (no external loads
    on graphs). Only regular samples of a mode that is regular everywhere are taken."""

    parameter_names: tuple[str, ...]
    shaking_force: Array
    shaking_moment: Array
    reactions: Mapping[str, Mapping[str, Array]]
    efforts: Mapping[str, Array]
    residual: Array
    constant: Mapping[str, Any]
    indeterminacy: Indeterminacy
    mechanism: Mechanism
    _rhs: Array  # (N, R, P): the scaled right-hand side, for the relative residual
    _gravity: Array
    _ok: NDArray[np.bool_]
    _indeterminate_joints: tuple[str, ...]

    def apply(self, parameters: ArrayLike) -> GraphDynamics:
        """The loads for inertial parameters π (P,): a :class:`GraphDynamics` equal to
        :func:`~screwkit.dynamics.graph_inverse.graph_inverse_dynamics` of bodies with them."""
        pi = np.asarray(parameters, dtype=float)
        P = len(self.parameter_names)
        if pi.shape != (P,) or not np.all(np.isfinite(pi)):
            raise DynamicsInputError(
                f"parameters must be a finite vector of length {P} (10 per moving body, "
                f"order {self.parameter_names[:10]}…); got shape {pi.shape}")
        mech = self.mechanism
        force = np.stack([self.reactions[j.name]["force"] @ pi for j in mech.joints], 1)
        moment = np.stack([self.reactions[j.name]["moment"] @ pi for j in mech.joints], 1)
        efforts = np.stack([self.efforts[n] @ pi for n in effort_names(mech)], 1)
        res = np.linalg.norm(self.residual @ pi, axis=1)
        residual = res / (np.linalg.norm(self._rhs @ pi, axis=1) + 1e-300)
        return GraphDynamics(effort_names(mech), tuple(j.name for j in mech.joints), efforts, force,
                             moment, self.shaking_force @ pi, self.shaking_moment @ pi, self._ok,
                             self.indeterminacy.count, list(self._indeterminate_joints),
                             residual, self._gravity)


def graph_load_regressor(motion: MechanismMotion, mode: int = 0,
                         gravity: ArrayLike | None = None) -> GraphRegressor:
    """The regressor of every load of ``mode`` (module docstring). The mode must assemble and be
    regular at every sample (balancing takes a full cycle); mass properties are not needed."""
    mech = motion.mechanism
    g = check_vector3(gravity, "gravity")
    md = motion.mode(mode)
    ok = np.asarray(md.assembles & ~md.singular)
    if not ok.all():
        raise DynamicsInputError(
            f"{mech.name}: mode {mode} does not assemble (or is singular) at "
            f"{int((~ok).sum())} of {ok.size} samples; the load regressor needs every sample")
    Y = np.nan_to_num(inertia_wrench_regressor(md, g, np.zeros(3)))  # (N, B, 6, 10)
    N, B = Y.shape[:2]
    P = N_INERTIAL_PARAMETERS * B
    loads = np.zeros((N, B, 6, P))
    for b in range(B):
        loads[:, b, :, N_INERTIAL_PARAMETERS * b:N_INERTIAL_PARAMETERS * (b + 1)] = Y[:, b]
    st, (_, fr) = statics_of_mode(motion, mode, loads)
    W = st.wrenches  # (N, J, 6, P), moment about the origin
    c = fr.centres  # (N, J, 3)
    force = W[:, :, :3]
    moment = W[:, :, 3:] - np.cross(c[:, :, None, :], force.swapaxes(2, 3)).swapaxes(2, 3)
    shaking = np.zeros((N, 6, P))
    for j, joint in enumerate(mech.joints):
        first, second = joint.bodies
        if second == GROUND:
            shaking += W[:, j]
        elif first == GROUND:
            shaking -= W[:, j]
    length = float(mech.length_scale)  # graph_layout's: the statics' moment scale
    rows = np.ones(6)
    rows[3:] = 1.0 / length
    rhs = np.zeros_like(st.equation_residual)
    rhs[:, :6 * B] = -(loads * rows[None, None, :, None]).reshape(N, 6 * B, P)
    idle = rhs.shape[1] - st.rank
    zero3 = np.zeros((N, 3, 1))
    constant = {"shaking_force": zero3, "shaking_moment": zero3,
                "reaction_force": np.zeros((N, len(mech.joints), 3, 1)),
                "reaction_moment": np.zeros((N, len(mech.joints), 3, 1)),
                "efforts": {n: np.zeros((N, 1)) for n in effort_names(mech)},
                "residual": np.zeros((N, rhs.shape[1], 1))}
    names = tuple(f"{b.name}.{p}" for b in mech.bodies for p in INERTIAL_PARAMETER_NAMES)
    return GraphRegressor(
        names, shaking[:, :3], shaking[:, 3:],
        {j.name: {"force": force[:, k], "moment": moment[:, k]}
         for k, j in enumerate(mech.joints)},
        {n: st.efforts[:, k] for k, n in enumerate(effort_names(mech))},
        st.equation_residual, constant,
        Indeterminacy(st.indeterminate, np.zeros((0, 6)), idle),
        mech, rhs, g, ok, tuple(st.indeterminate_joints))

