"""A Delta robot (Clavel 1988): every plate position, every leg branch and every assembly mode.

A Delta-type :class:`Mechanism` is read from its graph, not its names: three driven R joints
from the ground to three arms; each arm carries two rods, each rod a body with exactly two S
joints (one on the arm, one on a common plate); the plate has no other joints. Each arm's two
rods, as drawn, form a parallelogram: equal and parallel rod vectors E − P (E the elbow ball
on the arm, P the ball on the plate). With the plate's frame the world's at the drawing, the
plate pose is (R, t) and rod k closes when ‖R P_k + t − E_k(θ)‖ = L_k (six equations).

**Translating modes** (R = I, the parallelograms kept). The two rods of arm i give one sphere,
‖t − c_i‖ = L_i with c_i = E_i(θ_i) − P_i: the plate translation is the intersection of three
spheres (:func:`plate_positions`). Subtracting sphere 1 from spheres 2 and 3 leaves two planes,
2 (c_j − c_1)·t = ‖c_j‖² − ‖c_1‖² − L_j² + L_1²; with n = (c_2 − c_1) × (c_3 − c_1) and t₀ the
point of both planes in the plane of the centres (n·(t₀ − c_1) = 0), t = t₀ ± λ n with
λ² ‖n‖² = L_1² − ‖t₀ − c_1‖² (Tsai 1999, "Robot Analysis", §3.6; Williams, "The Delta parallel
robot: kinematics solutions"). Two real positions where that is positive; they meet where it is
zero (the plate in the plane of the three sphere centres: every rod parallel to that plane, an
output or platform singularity, Gosselin & Angeles 1990 type II).

**Leg branches** (inverse kinematics, :func:`arm_angles`). With the arm angle θ about the unit
axis a through the pivot O and the drawn elbow r = E − O = r∥ + r⊥ (along and across a),
E(θ) − O = r∥ + cos θ r⊥ + sin θ (a × r⊥); with q = P + t − O the rod equation is
A cos θ + B sin θ = C, A = 2 q·r⊥, B = 2 q·(a × r⊥), C = ‖q‖² + ‖r‖² − 2 q·r∥ − L², so
θ = atan2(B, A) ± acos(C/ρ), ρ = √(A² + B²): two branches per arm (elbow out and in), which meet
where |C| = ρ (the arm and its rods in one plane across the axis: an input singularity).

**Every assembly mode** (:class:`DeltaFormulation`). The six rod equations are those of a 6-6
Stewart–Gough platform whose base points are the elbow balls (placed by the inputs): the
Study-coordinate system of modes/stewart.py (generic count 40) solves them with every plate
rotation, not only R = I. A Delta with ball-jointed rods has real modes with the plate turned
(the parallelograms twisted into skew quadrilaterals with equal opposite sides): 14 besides the
two translating ones at the bundled example's first input rows, some of them born or dying at
folds along its motion. Each real pose is decoded into the graph's
joint variables: each arm turned by its input, the plate at (R, t), each rod turned from its
drawn direction onto its closed one by the least rotation (its spin about its own axis is idle,
as in graph/legs.py), every joint's variable from the two poses it joins (modes/stewart_decode.py
``joint_values``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import GraphLayout, axis_rotation, graph_layout
from screwkit.kinematics.modes.rod_loops import least_rotation
from screwkit.kinematics.modes.stewart import (
    pose_from_study,
    stewart_parameters,
)
from screwkit.kinematics.modes.stewart_decode import StudyPlatformSystem, joint_values
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism

Array = NDArray[np.float64]

#: a parallelogram's two rod vectors agree to this, relative to the rod length
PARALLELOGRAM_TOLERANCE = 1e-9
#: the two plate positions (or an arm's two branches) meet where the discriminant is within
#: this of the squared rod length (relative)
MEET_TOLERANCE = 1e-9


@dataclass(frozen=True)
class DeltaArm:
    """One arm: its driven R joint (index, input column, pivot O, world axis a, +1 where drawn
    ground-first), its body, and its two rods (rod body, elbow ball E and plate ball P as
    drawn, rod length L)."""

    joint: int
    column: int
    body: str
    pivot: Array
    axis: Array
    sign: float
    rods: tuple[str, str]
    elbows: Array  # (2, 3)
    feet: Array  # (2, 3)
    length: float


@dataclass(frozen=True)
class DeltaMechanism:
    """A Delta robot read from a :class:`Mechanism` (module docstring)."""

    mechanism: Mechanism
    plate: str
    arms: tuple[DeltaArm, DeltaArm, DeltaArm]

    def elbows(self, input_values: ArrayLike) -> Array:
        """World elbow balls (N, 6, 3) at rows of input values (N, 3), arm by arm."""
        X = _rows(input_values)
        out = np.empty((X.shape[0], 6, 3))
        for i, arm in enumerate(self.arms):
            R = axis_rotation(arm.axis, arm.sign * X[:, arm.column])
            out[:, 2 * i: 2 * i + 2] = arm.pivot + np.einsum(
                "nij,kj->nki", R, arm.elbows - arm.pivot)
        return out

    @property
    def feet(self) -> Array:
        """The plate balls (6, 3) as drawn, arm by arm."""
        return np.concatenate([arm.feet for arm in self.arms])

    @property
    def lengths(self) -> Array:
        return np.repeat([arm.length for arm in self.arms], 2)


def _rows(input_values: ArrayLike) -> Array:
    X = np.atleast_2d(np.asarray(input_values, dtype=float))
    if X.ndim != 2 or X.shape[1] != 3 or not np.all(np.isfinite(X)):
        raise InputError(f"a Delta robot takes rows of three finite arm angles (N, 3), in "
                         f"radians from the drawing; got shape {np.shape(input_values)}")
    return X


def _not_delta(mech: Mechanism, why: str) -> CapabilityError:
    return CapabilityError(
        f"{mech.name}: not a Delta robot ({why}); a Delta is three driven R joints from the "
        "ground to three arms, each arm holding two S–S rods that form a parallelogram down "
        "to one plate")


def delta_from_mechanism(mech: Mechanism) -> DeltaMechanism:
    """Recognise a Delta robot in ``mech`` (module docstring), or a CapabilityError saying
    which part of the structure is missing."""
    if mech.drives or len(mech.inputs) != 3:
        raise _not_delta(mech, f"{len(mech.inputs)} joint inputs and {len(mech.drives)} "
                         "driven body freedoms, not three joint inputs")
    joints_of: dict[str, list[int]] = {}
    for k, j in enumerate(mech.joints):
        for b in j.bodies:
            joints_of.setdefault(b, []).append(k)
    arms, plates = [], set()
    for col, name in enumerate(mech.inputs):
        k = next(i for i, j in enumerate(mech.joints) if j.name == name.split(".")[0])
        shoulder = mech.joints[k]
        if shoulder.kind != "R" or GROUND not in shoulder.bodies:
            raise _not_delta(mech, f"input {name!r} is not an R joint on the ground")
        body = shoulder.bodies[1] if shoulder.bodies[0] == GROUND else shoulder.bodies[0]
        elbows = [i for i in joints_of[body] if i != k]
        if len(elbows) != 2 or any(mech.joints[i].kind != "S" for i in elbows):
            raise _not_delta(mech, f"arm {body!r} does not hold exactly two rods by S joints")
        rods, E, P = [], [], []
        for i in elbows:
            rod = next(b for b in mech.joints[i].bodies if b != body)
            own = [m for m in joints_of[rod] if m != i]
            if rod == GROUND or len(own) != 1 or mech.joints[own[0]].kind != "S":
                raise _not_delta(mech, f"body {rod!r} on arm {body!r} is not a rod with one "
                                 "more S joint")
            rods.append(rod)
            E.append(mech.joints[i].at)
            P.append(mech.joints[own[0]].at)
            plates.add(next(b for b in mech.joints[own[0]].bodies if b != rod))
        E_, P_ = np.array(E), np.array(P)
        d = E_ - P_
        L = float(np.linalg.norm(d[0]))
        if np.abs(d[0] - d[1]).max() > PARALLELOGRAM_TOLERANCE * L:
            raise _not_delta(mech, f"the rods of arm {body!r} are not drawn as a parallelogram "
                             "(equal and parallel)")
        arms.append(DeltaArm(k, col, body, shoulder.at, shoulder.axis,
                             1.0 if shoulder.bodies[0] == GROUND else -1.0,
                             (rods[0], rods[1]), E_, P_, L))
    plate = plates.pop() if len(plates) == 1 else None
    if plate is None or plate == GROUND or len(joints_of[plate]) != 6 or \
            len(mech.bodies) != 10 or len(mech.joints) != 15:
        raise _not_delta(mech, "the six rods do not all end on one plate with no other joints")
    if len({a.body for a in arms}) != 3:
        raise _not_delta(mech, "two inputs turn the same arm")
    return DeltaMechanism(mech, plate, (arms[0], arms[1], arms[2]))


@dataclass(frozen=True)
class PlatePositions:
    """The translating modes at N input rows: ``t`` (N, 2, 3) the plate translations from the
    drawing (λ > 0 first: along n = (c₂ − c₁) × (c₃ − c₁)), ``real`` (N,) where they exist,
    ``singular`` (N,) where the two meet, ``discriminant`` (N,) (L₁² − ‖t₀ − c₁‖²)/L₁²."""

    t: Array
    real: NDArray[np.bool_]
    singular: NDArray[np.bool_]
    discriminant: Array


def plate_positions(dm: DeltaMechanism, input_values: ArrayLike) -> PlatePositions:
    """Every real plate translation at each row of arm angles (N, 3), the intersection of
    three spheres (module docstring), vectorised over rows."""
    X = _rows(input_values)
    E = dm.elbows(X)[:, ::2]  # the first rod of each arm stands for both
    c = E - np.array([arm.feet[0] for arm in dm.arms])  # (N, 3, 3)
    L2 = np.array([arm.length for arm in dm.arms]) ** 2
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    M = np.stack([2 * (c[:, 1] - c[:, 0]), 2 * (c[:, 2] - c[:, 0]), n], axis=1)
    cc = np.sum(c * c, axis=2)
    rhs = np.stack([cc[:, 1] - cc[:, 0] - L2[1] + L2[0], cc[:, 2] - cc[:, 0] - L2[2] + L2[0],
                    np.sum(n * c[:, 0], axis=1)], axis=1)
    nn = np.sum(n * n, axis=1)
    flat = nn <= 1e-24 * L2[0] ** 2  # three centres on a line: no finite pair of positions
    M[flat] = np.eye(3)
    t0 = np.linalg.solve(M, rhs[..., None])[..., 0]
    disc = (L2[0] - np.sum((t0 - c[:, 0]) ** 2, axis=1)) / L2[0]
    disc[flat] = np.nan
    lam = np.sqrt(np.maximum(disc, 0.0) * L2[0] / np.where(flat, 1.0, nn))
    t = t0[:, None, :] + np.array([1.0, -1.0])[None, :, None] * (lam[:, None] * n)[:, None, :]
    real = ~flat & (disc >= -MEET_TOLERANCE)
    t[~real] = np.nan
    return PlatePositions(t, real, real & (np.abs(disc) <= MEET_TOLERANCE), disc)


@dataclass(frozen=True)
class ArmBranches:
    """The leg branches at M plate translations: ``angles`` (M, 3, 2) each arm's two input
    angles (the first is atan2(B, A) + acos(C/ρ)), ``real`` (M, 3), ``singular`` (M, 3)
    where an arm's two branches meet (module docstring)."""

    angles: Array
    real: NDArray[np.bool_]
    singular: NDArray[np.bool_]


def arm_angles(dm: DeltaMechanism, t: ArrayLike) -> ArmBranches:
    """Every real arm angle for plate translations ``t`` (M, 3) from the drawing (inverse
    kinematics, module docstring), vectorised over positions."""
    T = np.atleast_2d(np.asarray(t, dtype=float))
    if T.ndim != 2 or T.shape[1] != 3 or not np.all(np.isfinite(T)):
        raise InputError(f"plate translations are rows of three finite numbers (M, 3) in "
                         f"metres from the drawing; got shape {np.shape(t)}")
    angles = np.full((T.shape[0], 3, 2), np.nan)
    real = np.zeros((T.shape[0], 3), dtype=bool)
    singular = np.zeros_like(real)
    for i, arm in enumerate(dm.arms):  # three arms: the rows are vectorised
        a = arm.axis
        r = arm.elbows[0] - arm.pivot
        r_par = (r @ a) * a
        r_perp = r - r_par
        q = arm.feet[0] + T - arm.pivot
        A, B = 2 * q @ r_perp, 2 * q @ np.cross(a, r_perp)
        C = np.sum(q * q, axis=1) + r @ r - 2 * q @ r_par - arm.length ** 2
        rho = np.hypot(A, B)
        ratio = C / np.maximum(rho, 1e-300)
        ok = np.abs(ratio) <= 1.0 + MEET_TOLERANCE
        off = np.arccos(np.clip(ratio, -1.0, 1.0))
        th = np.arctan2(B, A)[:, None] + np.stack([off, -off], axis=1)
        th = np.angle(np.exp(1j * th)) * arm.sign  # the input is measured ground-first
        angles[ok, i] = th[ok]
        real[:, i] = ok
        singular[:, i] = ok & (np.abs(np.abs(ratio) - 1.0) <= MEET_TOLERANCE)
    return ArmBranches(angles, real, singular)


def delta_configuration(dm: DeltaMechanism, input_values: ArrayLike, R: ArrayLike,
                        t: ArrayLike) -> Configuration:
    """The graph configurations (N) of plate poses R (N, 3, 3), t (N, 3) at input rows (N, 3)
    (or one row for all): arms turned by the inputs, each rod by the least rotation from its
    drawn direction onto the closed one (module docstring)."""
    R_ = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    t_ = np.asarray(t, dtype=float).reshape(-1, 3)
    N = R_.shape[0]
    X = np.broadcast_to(_rows(input_values), (N, 3))
    E = dm.elbows(X)
    poses: dict[str, tuple[Array, Array]] = {dm.plate: (R_, t_)}
    for i, arm in enumerate(dm.arms):
        Ra = axis_rotation(arm.axis, arm.sign * X[:, arm.column])
        poses[arm.body] = (Ra, arm.pivot - Ra @ arm.pivot)
        for k, rod in enumerate(arm.rods):
            e = E[:, 2 * i + k]
            d = np.einsum("nij,j->ni", R_, arm.feet[k]) + t_ - e
            Rr = least_rotation(arm.feet[k] - arm.elbows[k], d)
            poses[rod] = (Rr, e - Rr @ arm.elbows[k])
    return joint_values(dm.mechanism, graph_layout(dm.mechanism), poses)


@dataclass(frozen=True)
class DeltaFormulation(StudyPlatformSystem):
    """A Delta robot as a formulation of modes/every_mode.py: the Study-coordinate system of a
    6-6 platform whose base points are the elbow balls (every plate pose, rotated ones too),
    its parameters from the arm angles, and the decoding of each real pose (module
    docstring)."""

    mechanism: Mechanism
    delta: DeltaMechanism
    #: homotopy time per anchor and generic solution: measured ~2.4 s per row of the bundled
    #: example (40 paths, a third of them ending at infinity through the endgame)
    seconds_per_root: float = 0.06

    def parameters(self, input_values: ArrayLike) -> Array:
        X = _rows(input_values)
        N = X.shape[0]
        dm = self.delta
        return np.asarray(stewart_parameters(
            dm.elbows(X), np.broadcast_to(dm.feet, (N, 6, 3)),
            np.broadcast_to(dm.lengths, (N, 6))).real)

    def configuration(self, solutions: ArrayLike, input_values: ArrayLike
                      ) -> tuple[Configuration, GraphLayout]:
        """Configurations (N) of the real Study solutions (N, 8) at one input row."""
        R, t = pose_from_study(np.real(np.asarray(solutions)).astype(complex))
        return (delta_configuration(self.delta, input_values, R.real, t.real),
                graph_layout(self.mechanism))


def delta_formulation(mech: Mechanism) -> DeltaFormulation:
    """The Delta formulation of ``mech``, or a CapabilityError (delta_from_mechanism)."""
    return DeltaFormulation(mech, delta_from_mechanism(mech))


def delta_forward(mech: Mechanism, input_values: ArrayLike) -> PlatePositions:
    """Forward kinematics of a Delta robot drawn as ``mech``: every real plate translation
    (metres from the drawing, the plate level) at each row of arm angles (N, 3), radians from
    the drawing: the intersection of three spheres (Tsai 1999 §3.6; docs/kinematics.md,
    "Every mode of a mechanism"), flagged singular where the two meet. Every assembly mode,
    the plate's turned ones too, comes from ``solve_mechanism(mech, inputs, every_mode=True)``
    or ``every_mode(mech, inputs)`` (modes/every_mode.py)."""
    return plate_positions(delta_from_mechanism(mech), input_values)


def delta_inverse(mech: Mechanism, plate_translations: ArrayLike) -> ArmBranches:
    """Inverse kinematics of a Delta robot drawn as ``mech``: each arm's two angles (rad from
    the drawing, both leg branches, flagged singular where they meet) for level plate
    translations (M, 3), metres from the drawing (:func:`arm_angles`; docs/kinematics.md)."""
    return arm_angles(delta_from_mechanism(mech), plate_translations)
