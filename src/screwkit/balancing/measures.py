"""Load measures of one motion cycle as quadratic forms in the inertial parameters
(Rahman 1996, eqs 4.1/4.2, with the corrections of the reference SPEC §8.4).

Each measure is a non-dimensional mean square over the N **distinct** samples of a periodic
cycle (the seed counted 0° and 360° twice; spec files drop the repeated sample):

* ``F``  — shaking force:   mean |F_sh|² / F₀²
* ``T``  — shaking moment:  mean |M_sh|² / (F₀ ℓ)²
* ``R``  — bearing forces:  mean Σ_joints |f_j|² / F₀²
* ``M``  — bearing moments: mean Σ_joints |m_j|² / (F₀ b)², moments about the joint centres,
  the driven component (the input torque itself) removed
* ``T0`` — input effort:    mean Σ_inputs τ² / (F₀ ℓ)² (a driven slide: / F₀²)

with the seed's constants F₀ = m₁ ℓ ω² (m₁ the input link's mass, ℓ its length, ω the input
speed) and b the bearing length (SPEC §4.1: C1 = L·m₁²a₁²ω⁴, C2 = C1·a₁², C3 = C1·b²). Every
load is linear in π (the regressor), so every measure is ‖Y·π + y‖²·s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.balancing.errors import BalancingError
from screwkit.dynamics import Regressor
from screwkit.dynamics.graph_regressor import GraphRegressor
from screwkit.kinematics.motion import ModeMotion
from screwkit.messages import given
from screwkit.model.linkage import Linkage
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

#: the five measures, in the seed's order W1…W5 of the program (SPEC §4.1)
MEASURES = ("F", "T", "R", "M", "T0")
MEASURE_TITLES = {
    "F": "shaking force",
    "T": "shaking moment",
    "R": "bearing forces",
    "M": "bearing moments",
    "T0": "input torque",
}


@dataclass(frozen=True)
class Normalisation:
    """The seed's normalising constants: force F₀ = mass·length·speed², moment arm ``length``
    (shaking moment, input torque) and ``bearing_length`` (bearing moments)."""

    mass: float
    length: float
    speed: float
    bearing_length: float

    @property
    def force(self) -> float:
        return self.mass * self.length * self.speed**2

    def as_dict(self) -> dict[str, float]:
        return {"mass": self.mass, "length": self.length, "speed": self.speed,
                "bearing_length": self.bearing_length, "force": self.force}


def default_normalisation(
    linkage: Linkage | Mechanism,
    mode: ModeMotion,
    speed: float,
    *,
    mass: float | None = None,
    length: float | None = None,
    bearing_length: float | None = None,
) -> Normalisation:
    """Seed defaults: the first moving link's mass and length (distance between its two joint
    centres, e.g. the crank a₁), the input speed ω; bearing length defaults to that length.
    On a mechanism graph, the body the first input drives and the distance from the input
    joint's centre to the centre of that body's next joint (the crank of a six-bar)."""
    if isinstance(linkage, Mechanism):
        mass, length = _graph_defaults(linkage, mode, mass, length)
    if mass is None:
        assert isinstance(linkage, Linkage)
        first = linkage.links[0].mass
        if first is None:
            raise BalancingError(f"link {linkage.links[0].name!r} has no mass properties")
        mass = first.mass
    if length is None:
        assert isinstance(linkage, Linkage)
        d = np.linalg.norm(mode.joint_centres[:, 1] - mode.joint_centres[:, 0], axis=-1)
        length = float(np.nanmean(d))
        if not np.isfinite(length) or length <= 0.0:
            length = linkage.length_scale
    if bearing_length is None:
        bearing_length = length
    if not (np.isfinite(speed) and speed != 0.0):
        raise BalancingError(
            "the input speed is zero: the seed's normalisation F₀ = m₁·a₁·ω² needs ω ≠ 0; "
            "set [motion] speed or [balancing.normalisation] speed"
        )
    for key, val in (("mass", mass), ("length", length), ("bearing_length", bearing_length)):
        if not (np.isfinite(val) and val > 0):
            raise BalancingError(f"[balancing.normalisation] {key} must be > 0; got {given(val)}")
    return Normalisation(float(mass), float(length), abs(float(speed)), float(bearing_length))


def _graph_defaults(mech: Mechanism, mode: ModeMotion, mass: float | None,
                    length: float | None) -> tuple[float, float]:
    """Mass and length of the body the first input drives (see default_normalisation)."""
    names = [j.name for j in mech.joints]
    j0 = names.index(mech.inputs[0].rsplit(".", 1)[0])
    a, b = mech.joints[j0].bodies
    body = b if b != GROUND else a
    if mass is None:
        props = next(x.mass for x in mech.bodies if x.name == body)
        if props is None:
            raise BalancingError(f"body {body!r} has no mass properties (give mass, com and "
                                 "inertia in its [[bodies]] entry)")
        mass = props.mass
    if length is None:
        other = [k for k, j in enumerate(mech.joints) if k != j0 and body in j.bodies]
        length = float("nan")
        if other:
            d = mode.joint_centres[:, other[0]] - mode.joint_centres[:, j0]
            length = float(np.nanmean(np.linalg.norm(d, axis=-1)))
        if not np.isfinite(length) or length <= 0.0:
            length = mech.length_scale
    return float(mass), float(length)


@dataclass(frozen=True)
class LoadRows:
    """For each measure k: ``rows[k]`` (N, r_k, P) and ``offset[k]`` (N, r_k) so that the loads
    of the measure at sample n are rows[k][n] @ π + offset[k][n], already divided by the
    measure's scale; measure_k(π) = mean_n |rows·π + offset|²."""

    rows: dict[str, Array]
    offset: dict[str, Array]
    normalisation: Normalisation

    @property
    def samples(self) -> int:
        return int(self.rows["F"].shape[0])

    def per_sample(self, pi: Array) -> dict[str, Array]:
        """(N,) squared normalised load of each measure at each sample."""
        return {k: np.sum((self.rows[k] @ pi + self.offset[k]) ** 2, axis=-1) for k in MEASURES}

    def values(self, pi: Array) -> dict[str, float]:
        return {k: float(np.mean(v)) for k, v in self.per_sample(pi).items()}


def load_rows(
    linkage: Linkage | Mechanism, mode: ModeMotion, reg: Regressor | GraphRegressor,
    norm: Normalisation
) -> LoadRows:
    """The five measures' load rows from a regressor (see module docstring); a graph's
    (:class:`~screwkit.dynamics.graph_regressor.GraphRegressor`) has the same fields, joints
    and inputs by name."""
    F0 = norm.force
    ell = norm.length
    const = reg.constant
    rows: dict[str, Array] = {}
    off: dict[str, Array] = {}
    rows["F"] = reg.shaking_force / F0
    off["F"] = const["shaking_force"][..., 0] / F0
    rows["T"] = reg.shaking_moment / (F0 * ell)
    off["T"] = const["shaking_moment"][..., 0] / (F0 * ell)
    names = [j.name for j in linkage.joints]
    forces = np.concatenate([reg.reactions[j]["force"] for j in names], axis=1)
    rows["R"] = forces / F0
    off["R"] = const["reaction_force"][..., 0].reshape(forces.shape[0], -1) / F0
    moments = np.stack([reg.reactions[j]["moment"] for j in names], axis=1)  # (N, n, 3, P)
    moments_c = const["reaction_moment"][..., 0]  # (N, n, 3)
    driven_rot = np.zeros(len(names), dtype=bool)
    for name in linkage.inputs:
        joint, freedom = name.rsplit(".", 1)
        if freedom == "theta":  # R, C, H: a rotation about the joint axis
            driven_rot[names.index(joint)] = True
    if driven_rot.any():
        # remove the driven component: the input torque is measured by T0, not as a bearing load
        axes = mode.joint_axes  # (N, n, 3)
        proj = np.einsum("nji,nji...->nj...", axes, moments)
        moments = moments - np.where(driven_rot[None, :, None, None],
                                     axes[..., None] * proj[:, :, None, :], 0.0)
        proj_c = np.einsum("nji,nji->nj", axes, moments_c)
        moments_c = moments_c - np.where(driven_rot[None, :, None], axes * proj_c[..., None], 0.0)
    b = norm.bearing_length
    N = moments.shape[0]
    rows["M"] = moments.reshape(N, -1, moments.shape[-1]) / (F0 * b)
    off["M"] = moments_c.reshape(N, -1) / (F0 * b)
    eff, eff_c = [], []
    for name in linkage.inputs:
        scale = F0 if name.rsplit(".", 1)[1] == "s" else F0 * ell
        eff.append(reg.efforts[name] / scale)
        eff_c.append(const["efforts"][name][..., 0] / scale)
    rows["T0"] = np.stack(eff, axis=1)
    off["T0"] = np.stack(eff_c, axis=1)
    if not all(np.all(np.isfinite(r)) for r in rows.values()):
        raise BalancingError("the regressor has non-finite entries (samples that do not "
                             "assemble?); balancing needs a full valid cycle")
    return LoadRows(rows, off, norm)
