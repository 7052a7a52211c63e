"""6-6 Stewart–Gough forward kinematics in Study coordinates: 40 complex poses.

The platform pose is the Study point (x; y) ∈ P⁷ (x the rotation quaternion, y the dual part;
Husty 1996, "An algorithm for solving the direct kinematics of general Stewart–Gough platforms",
Mech. Mach. Theory 31(4); Wampler 1996, "Forward displacement analysis of general
six-in-parallel SPS (Stewart) platform manipulators using soma coordinates", Mech. Mach. Theory
31(3)). With Δ = x·x, R = R'(x)/Δ (R' the quadratic rotation matrix of the quaternion) and
t = 2 vec(y x̄)/Δ, the pose is real and rigid on the Study quadric x·y = 0, and the squared leg
length ‖R b_i + t − a_i‖² = L_i² times Δ is the quadric

    Δ(‖a_i‖² + ‖b_i‖² − L_i²) + 4 y·y + 4 b_i·vec(x̄ y) − 4 a_i·vec(y x̄) − 2 a_iᵀ R'(x) b_i = 0

(y·y = ‖y x̄‖²/Δ and (R b)·t = b·Rᵀt with Rᵀt = 2 vec(x̄ y)/Δ). The unknowns are the eight
Study coordinates on the affine patch r·x = 1 (r fixed random real): the patch is on x only,
which keeps out the exceptional set x = 0, y·y = 0 that satisfies every leg equation. Equations:
the Study quadric, the six legs, the patch (8 in 8). Parameters: the base points a_i (world),
the platform points b_i (platform frame) and the squared lengths L_i² (42, all free: any complex
values are an instance). The generic count is 40 (Husty 1996; Wampler 1996; Raghavan 1993).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.algebraic.solve import StartSolutions
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.modes.starts import start_solutions
from screwkit.model.mechanism import GROUND, Mechanism, MechanismJoint

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

#: the generic number of complex solutions (Husty 1996; Wampler 1996)
STEWART_GENERIC_COUNT = 40
#: the affine patch r·x = 1: fixed, so that one compiled system serves every instance, and real,
#: so that a real pose has real Study coordinates (the solver's real and certified-real tests
#: then apply to poses directly)
PATCH = np.random.default_rng(20260627).normal(size=4)
STUDY_NAMES = ("x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3")


def quaternion_product(a: list, b: list) -> list:
    """Hamilton product of quaternions given as [w, x, y, z] (Polys or numbers)."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return [a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0]


def _conjugate(q: list) -> list:
    return [q[0], -1 * q[1], -1 * q[2], -1 * q[3]]


def rotation_numerator(x: list) -> list[list]:
    """R'(x) = (x·x) R: the rotation matrix of the quaternion x = [w, x, y, z], times its norm²."""
    w, a, b, c = x
    return [[w * w + a * a - b * b - c * c, 2 * (a * b - w * c), 2 * (a * c + w * b)],
            [2 * (a * b + w * c), w * w - a * a + b * b - c * c, 2 * (b * c - w * a)],
            [2 * (a * c - w * b), 2 * (b * c + w * a), w * w - a * a - b * b + c * c]]


@lru_cache(maxsize=1)
def stewart_system() -> PolynomialSystem:
    """The compiled forward-kinematics system (module docstring): unknowns x0..x3, y0..y3;
    parameters a{i}_{xyz}, b{i}_{xyz} (i = 0..5) then L2_{i}."""
    sym = [Poly.variable(k) for k in range(8 + 42)]
    x, y = sym[0:4], sym[4:8]
    a = [sym[8 + 3 * i: 11 + 3 * i] for i in range(6)]
    b = [sym[26 + 3 * i: 29 + 3 * i] for i in range(6)]
    L2 = sym[44:50]
    delta = sum((xi * xi for xi in x), Poly())
    yy = sum((yi * yi for yi in y), Poly())
    xby = quaternion_product(_conjugate(x), y)[1:]  # vec(x̄ y)
    yxb = quaternion_product(y, _conjugate(x))[1:]  # vec(y x̄)
    Rn = rotation_numerator(x)
    eqs = [sum((x[k] * y[k] for k in range(4)), Poly())]
    for i in range(6):
        aa = sum((c * c for c in a[i]), Poly())
        bb = sum((c * c for c in b[i]), Poly())
        leg = delta * (aa + bb - L2[i]) + 4 * yy
        for r in range(3):
            leg = leg + 4 * b[i][r] * xby[r] - 4 * a[i][r] * yxb[r]
            for s in range(3):
                leg = leg - 2 * a[i][r] * Rn[r][s] * b[i][s]
        eqs.append(leg)
    eqs.append(sum((complex(PATCH[k]) * x[k] for k in range(4)), Poly()) - 1.0)
    params = ([f"a{i}_{c}" for i in range(6) for c in "xyz"]
              + [f"b{i}_{c}" for i in range(6) for c in "xyz"] + [f"L2_{i}" for i in range(6)])
    return compile_system(eqs, STUDY_NAMES, params)


def stewart_parameters(base: ArrayLike, platform: ArrayLike, lengths: ArrayLike) -> Complex:
    """The parameter vector(s) (…, 42) of base points (…, 6, 3), platform points in the platform
    frame (…, 6, 3) and leg lengths (…, 6) (not squared)."""
    A = np.asarray(base, dtype=complex)
    B = np.asarray(platform, dtype=complex)
    L = np.asarray(lengths, dtype=complex)
    if A.shape[-2:] != (6, 3) or B.shape[-2:] != (6, 3) or L.shape[-1:] != (6,):
        raise InputError("a 6-6 Stewart platform needs 6 base points, 6 platform points "
                         f"(6 × 3 each) and 6 leg lengths; got shapes {A.shape}, {B.shape}, "
                         f"{L.shape}")
    lead = A.shape[:-2]
    return np.concatenate([A.reshape(*lead, 18), B.reshape(*lead, 18), L**2], axis=-1)


def study_from_pose(R: ArrayLike, t: ArrayLike) -> Complex:
    """Study coordinates (…, 8) of poses (R (…, 3, 3), t (…, 3)) on the patch r·x = 1:
    x the quaternion of R (Shepperd's method, from the largest diagonal term), y = t x / 2."""
    R = np.asarray(R, dtype=complex)
    t = np.asarray(t, dtype=complex)
    tr = np.trace(R, axis1=-2, axis2=-1)
    # the four candidates 4w², 4x², 4y², 4z² and the quaternion from each (Shepperd 1978)
    cands = np.stack([1 + tr, 1 + 2 * R[..., 0, 0] - tr, 1 + 2 * R[..., 1, 1] - tr,
                      1 + 2 * R[..., 2, 2] - tr], -1)
    k = np.argmax(np.abs(cands), axis=-1)
    w = np.stack([cands[..., 0], R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], -1)
    a = np.stack([R[..., 2, 1] - R[..., 1, 2], cands[..., 1], R[..., 0, 1] + R[..., 1, 0],
                  R[..., 0, 2] + R[..., 2, 0]], -1)
    b = np.stack([R[..., 0, 2] - R[..., 2, 0], R[..., 0, 1] + R[..., 1, 0], cands[..., 2],
                  R[..., 1, 2] + R[..., 2, 1]], -1)
    c = np.stack([R[..., 1, 0] - R[..., 0, 1], R[..., 0, 2] + R[..., 2, 0],
                  R[..., 1, 2] + R[..., 2, 1], cands[..., 3]], -1)
    x = np.choose(k[..., None], [w, a, b, c])
    tq = np.concatenate([np.zeros(t.shape[:-1] + (1,)), t], -1)
    y = np.stack(quaternion_product(list(np.moveaxis(tq, -1, 0)),
                                    list(np.moveaxis(x, -1, 0))), -1) / 2
    z = np.concatenate([x, y], -1)
    return np.asarray(z / (z[..., :4] @ PATCH)[..., None], dtype=complex)


def pose_from_study(z: ArrayLike) -> tuple[Complex, Complex]:
    """Poses (R (…, 3, 3), t (…, 3)) of Study coordinates (…, 8): R = R'(x)/Δ,
    t = 2 vec(y x̄)/Δ (module docstring)."""
    z = np.asarray(z, dtype=complex)
    x = list(np.moveaxis(z[..., :4], -1, 0))
    y = list(np.moveaxis(z[..., 4:], -1, 0))
    delta = sum(xi * xi for xi in x)
    R = np.moveaxis(np.array(rotation_numerator(x)), (0, 1), (-2, -1)) / delta[..., None, None]
    t = 2 * np.stack(quaternion_product(y, _conjugate(x))[1:], -1) / delta[..., None]
    return R, t


def leg_lengths(R: ArrayLike, t: ArrayLike, base: ArrayLike, platform: ArrayLike) -> Complex:
    """The leg lengths ‖R b_i + t − a_i‖ (…, 6) of poses (R, t): the independent check of a
    solution, from the pose and not from the polynomial system."""
    R, t = np.asarray(R), np.asarray(t)
    ends = np.einsum("...ij,...kj->...ki", R, np.asarray(platform)) + t[..., None, :]
    d = ends - np.asarray(base)
    return np.sqrt(np.sum(d * d, axis=-1))


def random_stewart(rng: np.random.Generator, count: int, complex_values: bool = False
                   ) -> tuple[Complex, Complex]:
    """``count`` random instances with one known solution: parameters (count, 42) and the
    Study coordinates (count, 8) of a random pose that they assemble in (the leg lengths are
    computed from the pose). Complex instances are the generic start of a parameter homotopy."""
    def draw(*shape: int) -> Complex:
        v = rng.normal(size=shape).astype(complex)
        return v + 1j * rng.normal(size=shape) if complex_values else v

    A, B = draw(count, 6, 3), draw(count, 6, 3) * 0.6
    q = draw(count, 4)
    q = q / np.sqrt(np.sum(q * q, -1))[:, None]
    R = np.moveaxis(np.array(rotation_numerator(list(q.T))), (0, 1), (-2, -1))
    t = draw(count, 3) * 0.3 + np.array([0.0, 0.0, 1.5])
    z = study_from_pose(R, t)
    return stewart_parameters(A, B, leg_lengths(R, t, A, B)), z


def stewart_start() -> StartSolutions:
    """The 40 start solutions at a random complex instance (monodromy; cached per process)."""
    return start_solutions(stewart_system(), lambda rng: random_stewart(rng, 1, True),
                           STEWART_GENERIC_COUNT)


@dataclass(frozen=True)
class StewartMechanism:
    """A 6-6 platform drawn as a :class:`Mechanism`: six legs from the ground to one platform
    body, each a driven P joint between two bodies, the lower one jointed to the ground at a
    (U or S) centre a_i, the upper one to the platform at an S centre b_i. The platform's
    frame is the world's in the drawing, so b_i are the platform points as drawn; a leg's
    length at slide s is ‖b_i − a_i + s u_i‖ (u_i the slide axis, in the lower body)."""

    mechanism: Mechanism
    platform: str
    base: Array
    top: Array
    slide_axes: Array
    input_columns: tuple[int, ...]
    #: per leg: the index of its P joint and of its joint to the ground (U or S)
    slide_joints: tuple[int, ...] = ()
    base_joints: tuple[int, ...] = ()

    def parameters(self, input_values: ArrayLike) -> Array:
        """Parameters (N, 42) at rows of input values (N, n_inputs) (metres from the drawing)."""
        X = np.atleast_2d(np.asarray(input_values, dtype=float))
        d = (self.top - self.base)[None] + X[:, self.input_columns, None] * self.slide_axes[None]
        N = X.shape[0]
        return stewart_parameters(np.broadcast_to(self.base, (N, 6, 3)),
                                  np.broadcast_to(self.top, (N, 6, 3)),
                                  np.linalg.norm(d, axis=2)).real


def _beyond(mech: Mechanism, joint: MechanismJoint, body: str, kinds: str
            ) -> tuple[str, Array, int] | None:
    """The body across ``body``'s only other joint (of one of ``kinds``), that joint's
    centre and its index, or None."""
    near = [k for k, j in enumerate(mech.joints) if body in j.bodies and j is not joint]
    if len(near) != 1 or mech.joints[near[0]].kind not in kinds:
        return None
    j = mech.joints[near[0]]
    return (j.bodies[1] if j.bodies[0] == body else j.bodies[0], j.at, near[0])


def stewart_from_mechanism(mech: Mechanism) -> StewartMechanism:
    """Recognise the six legs of a Stewart–Gough platform in ``mech`` (class docstring)."""
    legs = []
    for col, name in enumerate(mech.inputs):
        k = next(i for i, j in enumerate(mech.joints) if j.name == name.split(".")[0])
        joint = mech.joints[k]
        if joint.kind != "P":
            continue
        lower, upper = joint.bodies
        down, up = _beyond(mech, joint, lower, "US"), _beyond(mech, joint, upper, "S")
        if down is None or up is None or down[0] != GROUND:
            continue
        legs.append((col, up[0], down[1], up[1], joint.axis, k, down[2]))
    platforms = {leg[1] for leg in legs}
    if len(legs) != 6 or len(platforms) != 1 or len(mech.bodies) != 13 or \
            len(mech.inputs) != 6:
        raise CapabilityError(f"{mech.name}: not a 6-6 Stewart–Gough platform (six legs, each "
                              "a driven P joint between a body jointed to the ground by a U or "
                              "S joint and one jointed to the platform by an S joint)")
    return StewartMechanism(mech, platforms.pop(), np.array([leg[2] for leg in legs]),
                            np.array([leg[3] for leg in legs]), np.array([leg[4] for leg in legs]),
                            tuple(leg[0] for leg in legs), tuple(leg[5] for leg in legs),
                            tuple(leg[6] for leg in legs))
