"""Every mode of a Stewart–Gough graph spec: platform poses decoded into joint variables.

The forward kinematics (modes/stewart.py) gives platform poses (R, t) as Study coordinates.
The graph tracker needs every joint's variable, measured from the drawing. Each leg i (base
centre a_i, platform centre b_i, slide axis u_i, slide s_i = the input) is rebuilt from the pose:

- the leg vector in the world is d_i = R b_i + t − a_i; drawn in the lower body it is
  w_i = b_i − a_i + s_i u_i (‖w_i‖ = ‖d_i‖ is the leg equation the homotopy solved);
- the lower body turns about a_i by R_c with R_c w_i = d_i. For a U joint R_c = Rot(e₁, α)
  Rot(e₂, β) (e₁ the axis fixed in the joint's first body, Rot the Rodrigues rotation; the
  axes swap and the angles change sign when the joint is drawn ground-last). Dotting
  Rot(e₂, β) w = Rot(e₁, −α) d with e₁ leaves one equation in β,
  e₁·w∥ + cos β e₁·w⊥ + sin β e₁·(e₂ × w) = e₁·d (w∥, w⊥ along and across e₂), with two
  roots β = φ ± acos(C/ρ); the one nearer the drawing (the smaller |β|) is taken, and α turns
  Rot(e₂, β) w onto d about e₁. For an S joint R_c is the least rotation from w_i to d_i (the
  leg's spin is idle);
- the upper body is the lower one slid by s_i u_i; the platform carries (R, t).

Every joint's variable then follows from the two poses it joins, M_j = T_a⁻¹ T_b
(graph/closure.py: T_b = T_a M_j(q)): a U joint's angles from M_j's rotation (θ₁ turns e₂ to
M e₂ about e₁, θ₂ is Rot(e₁, −θ₁) M about e₂), a P joint's slide u·p, an S joint's rotation.
The other root of each U (the leg spun half a turn about itself, through the U's own
singularity) is the same platform pose: it is not counted as another mode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import Solutions, StartSolutions
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph.closure import GraphLayout, axis_rotation, graph_layout
from screwkit.kinematics.modes.rod_loops import least_rotation
from screwkit.kinematics.modes.stewart import (
    StewartMechanism,
    pose_from_study,
    stewart_from_mechanism,
    stewart_start,
    stewart_system,
)
from screwkit.kinematics.modes.stewart_solve import solve_stewart
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]
Pose = tuple[Array, Array]


def _angle_about(e: Array, a: Array, b: Array) -> Array:
    """The angles (N,) that turn a (N, 3) onto b (N, 3) about the unit axis e, both taken
    across e."""
    a = a - np.multiply.outer(a @ e, e)
    b = b - np.multiply.outer(b @ e, e)
    return np.asarray(np.arctan2(np.cross(a, b) @ e, np.sum(a * b, axis=-1)))


def u_rotation(e1: Array, e2: Array, w: Array, d: Array) -> Array:
    """Rotations R (N, 3, 3) = Rot(e1, α) Rot(e2, β) with R w = d (w, d (N, 3) of equal
    length), β the root nearer 0 (module docstring); where no real root exists (d out of the
    joint's reach) the nearest pose, which then does not close."""
    par = np.multiply.outer(w @ e2, e2)
    perp = w - par
    A, B = perp @ e1, np.cross(e2, w) @ e1
    C = d @ e1 - par @ e1
    rho = np.maximum(np.hypot(A, B), 1e-300)
    phi = np.arctan2(B, A)
    off = np.arccos(np.clip(C / rho, -1.0, 1.0))
    roots = np.stack([phi + off, phi - off])
    roots = np.angle(np.exp(1j * roots))  # wrapped to (−π, π]
    beta = roots[np.argmin(np.abs(roots), axis=0), np.arange(len(w))]
    Rb = axis_rotation(e2, beta)
    v = np.einsum("nij,nj->ni", Rb, w)
    alpha = _angle_about(e1, v, d)
    return np.asarray(axis_rotation(e1, alpha) @ Rb)


def joint_values(mech: Mechanism, lay: GraphLayout, poses: dict[str, Pose]) -> Configuration:
    """The configuration (N) whose joints join the world body poses ``poses`` (name → R
    (N, 3, 3), p (N, 3); the ground may be left out): M_j = T_a⁻¹ T_b per joint (module
    docstring). R, C, P, U and S joints."""
    N = next(iter(poses.values()))[0].shape[0]
    full = dict(poses)
    full.setdefault(GROUND, (np.broadcast_to(np.eye(3), (N, 3, 3)), np.zeros((N, 3))))
    scalars = np.zeros((N, lay.n_scalar))
    spherical = np.broadcast_to(np.eye(3), (N, lay.n_spherical, 3, 3)).copy()
    for i, j in enumerate(mech.joints):
        (Ra, pa), (Rb, pb) = full[j.bodies[0]], full[j.bodies[1]]
        RaT = np.swapaxes(Ra, -1, -2)
        MR = RaT @ Rb
        Mp = np.einsum("nij,nj->ni", RaT, pb - pa)
        f0 = lay.first_freedom[i]
        if j.kind == "S":
            spherical[:, lay.spherical_of_joint[i]] = MR
        elif j.kind == "P":
            scalars[:, lay.scalar_col[f0]] = Mp @ j.axis
        elif j.kind in ("R", "C"):
            e = j.axis
            if j.kind == "C":  # its slide along the axis (the turn's part is square to it)
                scalars[:, lay.scalar_col[f0 + 1]] = Mp @ e
            ref = np.cross(e, [1.0, 0.0, 0.0] if abs(e[0]) < 0.9 else [0.0, 1.0, 0.0])
            scalars[:, lay.scalar_col[f0]] = _angle_about(
                e, np.broadcast_to(ref, (N, 3)), MR @ ref)
        elif j.kind == "U":
            assert j.axis2 is not None
            e1, e2 = j.axis, j.axis2
            th1 = _angle_about(e1, np.broadcast_to(e2, (N, 3)), MR @ e2)
            Q = axis_rotation(e1, -th1) @ MR
            ref = np.cross(e2, [1.0, 0.0, 0.0] if abs(e2[0]) < 0.9 else [0.0, 1.0, 0.0])
            scalars[:, lay.scalar_col[f0]] = th1
            scalars[:, lay.scalar_col[f0 + 1]] = _angle_about(
                e2, np.broadcast_to(ref, (N, 3)), Q @ ref)
        else:
            raise CapabilityError(f"{mech.name}: joint {j.name!r} is a {j.kind} joint; joint "
                                  "values are decoded from body poses for R, C, P, U and S "
                                  "joints only")
    return Configuration(scalars, spherical)


class StudyPlatformSystem:
    """The 40-solution Study-coordinate system of a 6-6 platform (modes/stewart.py) and its
    start solutions, for the formulations that solve a platform with it: the Stewart–Gough
    platform here and the Delta robot (modes/delta.py)."""

    @property
    def system(self) -> PolynomialSystem:
        return stewart_system()

    def start(self) -> StartSolutions:
        return stewart_start()


@dataclass(frozen=True)
class StewartFormulation(StudyPlatformSystem):
    """A Stewart–Gough graph spec as a formulation of modes/every_mode.py: the 40-solution
    Study system (modes/stewart.py), its parameters from the leg slides, and the decoding of
    each real pose into the graph's joint variables (module docstring)."""

    mechanism: Mechanism
    stewart: StewartMechanism
    #: measured homotopy time per anchor and generic solution (docs/kinematics.md: ~1.4 s per
    #: instance in a batch, 40 paths), for the time budget of modes/along.py
    seconds_per_root: float = 0.035

    def parameters(self, input_values: ArrayLike) -> Array:
        return self.stewart.parameters(input_values)

    def solve(self, p: ArrayLike) -> Solutions:
        """Every pose at the parameter rows p: the elimination template, the homotopy where it
        falls short (modes/stewart_solve.py)."""
        return solve_stewart(p)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """Configurations (N) of the real Study solutions (N, 8) at one input row."""
        R, t = pose_from_study(np.real(np.asarray(solutions)).astype(complex))
        return decode_poses(self.stewart, R.real, t.real, input_values), \
            graph_layout(self.mechanism)


def decode_poses(sm: StewartMechanism, R: Array, t: Array, input_values: ArrayLike
                 ) -> Configuration:
    """The graph configurations (N) of platform poses R (N, 3, 3), t (N, 3) at one row of
    input values (the leg slides are read from it; module docstring)."""
    mech = sm.mechanism
    lay = graph_layout(mech)
    x = np.asarray(input_values, dtype=float).reshape(-1)
    N = R.shape[0]
    poses: dict[str, Pose] = {sm.platform: (R, t)}
    for leg, col in enumerate(sm.input_columns):
        a, b, u = sm.base[leg], sm.top[leg], sm.slide_axes[leg]
        slide = mech.joints[sm.slide_joints[leg]]
        lower, upper = slide.bodies
        w = np.broadcast_to(b - a + x[col] * u, (N, 3))
        d = np.einsum("nij,j->ni", R, b) + t - a
        base = mech.joints[sm.base_joints[leg]]
        if base.kind == "U":
            assert base.axis2 is not None
            if base.bodies[0] == GROUND:
                Rc = u_rotation(base.axis, base.axis2, w, d)
            else:  # drawn ground-last: R_c⁻¹ = Rot(e₁, θ₁) Rot(e₂, θ₂)
                Rc = u_rotation(base.axis2, base.axis, w, d)
        else:
            Rc = least_rotation(w[0], d)
        pc = a - Rc @ a
        poses[lower] = (Rc, pc)
        poses[upper] = (Rc, pc + Rc @ (x[col] * u))
    return joint_values(mech, lay, poses)


def stewart_formulation(mech: Mechanism) -> StewartFormulation:
    """The Stewart formulation of ``mech``, or a CapabilityError (stewart_from_mechanism)."""
    return StewartFormulation(mech, stewart_from_mechanism(mech))
