"""Rigid-body mass properties and equivalent point-mass models.

``MassProperties`` holds one rigid link: its mass, the centre of mass (CoM) in the link frame and
the inertia tensor about the CoM in link-frame axes. Everything is SI (kg, m, kg·m²); unit
conversion (for example Rahman's lbf·s²/in) happens at the boundary, never here.

``PointMassModel`` is a set of point masses fixed in a link. ``equivalent_point_masses`` builds
Rahman's seven-point model (Rahman 1996, §2.2, eqs 2.31–2.41; reference SPEC §2): three "active"
pairs of half masses m1/2, m2/2, m3/2 at ±X, ±Y, ±Z on the principal axes through the CoM and one
mass m4 at the CoM. With the half weights the model has the rigid body's mass, CoM and inertia
tensor exactly, so it is dynamically equivalent for every rigid motion. (Rahman's FORTRAN program
gives each point of a pair the full mass m_k; SPEC §3.2. That error is not reproduced here.)

Inertial-parameter vector (order used throughout screwkit)::

    π = (m, m·c_x, m·c_y, m·c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz)

with c the CoM and I the inertia tensor about the **link-frame origin** (not the CoM). The
products I_xy, I_xz, I_yz are the tensor entries I[0, 1], I[0, 2], I[1, 2], i.e. I_xy = −∫x·y dm.
Every load of a rigid link is linear in π.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.constants import STANDARD_GRAVITY
from screwkit.errors import InputError, InputTypeError
from screwkit.messages import given, shown_values

Array = NDArray[np.float64]

#: relative tolerance for symmetry, definiteness and triangle checks (round-off of frame changes)
CONSISTENCY_RTOL = 1e-9

#: number of entries of the inertial-parameter vector π
N_INERTIAL_PARAMETERS = 10


class PhysicalConsistencyError(InputError):
    """Mass properties that no real body can have (negative mass, non-PSD inertia, …)."""


class PointMassSplitError(InputError):
    """A split of a link mass into Rahman's point masses that cannot reproduce its inertia."""


def _point_inertia(mass: float, r: Array) -> Array:
    """Inertia tensor of a point mass at ``r`` about the origin: m(|r|²·1 − r rᵀ)."""
    return mass * (float(r @ r) * np.eye(3) - np.outer(r, r))


def _clip_second_moment(inertia: Array) -> Array:
    """Nearest tensor whose second moment Σ = ½tr(I)·1 − I is PSD (clips round-off negatives;
    I = tr(Σ)·1 − Σ)."""
    sym = 0.5 * (inertia + inertia.T)
    second = 0.5 * np.trace(sym) * np.eye(3) - sym
    values, vectors = np.linalg.eigh(second)
    if np.all(values >= 0.0):
        return sym
    second = vectors @ np.diag(np.clip(values, 0.0, None)) @ vectors.T
    return np.asarray(np.trace(second) * np.eye(3) - second)


def _floats(value: ArrayLike, name: str) -> Array:
    """``value`` as floats, or an InputTypeError naming ``name``."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputTypeError(f"{name} must be numbers (SI units); got {value!r:.60}") from None


def _vector3(value: ArrayLike, name: str) -> Array:
    arr = _floats(value, name)
    if arr.shape != (3,):
        raise InputError(f"{name} must have shape (3,), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be finite, got {arr}")
    return arr.copy()


def _matrix33(value: ArrayLike, name: str) -> Array:
    arr = _floats(value, name)
    if arr.shape != (3, 3):
        raise InputError(f"{name} must have shape (3, 3), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be finite, got\n{arr}")
    return arr.copy()


def physical_consistency_violations(
    mass: float, inertia: ArrayLike, *, rtol: float = CONSISTENCY_RTOL, atol: float = 0.0
) -> list[str]:
    """Every way in which (mass, inertia about the CoM) fails to describe a real body.

    Conditions (each reported with the amount by which it fails):

    * mass > 0;
    * inertia symmetric: max |I − Iᵀ| ≤ rtol·max|I|;
    * inertia positive semidefinite: every principal moment λ_k ≥ −rtol·max|λ|;
    * triangle inequalities λ_i ≤ λ_j + λ_k for the principal moments (equivalently the second
      moment ½tr(I)·1 − I is positive semidefinite). They imply semidefiniteness and hold in any
      axes, so they also cover I_xx ≤ I_yy + I_zz etc. for the diagonal entries.

    Each tolerance is max(rtol·scale, atol), ``atol`` in kg·m² (for round-off inherited from a
    larger quantity, e.g. the inertia about a distant origin). An empty list means the body is
    physically consistent. See ``check_physical_consistency``.
    """
    problems: list[str] = []
    inertia_arr = np.asarray(inertia, dtype=float)
    if inertia_arr.shape != (3, 3) or not np.all(np.isfinite(inertia_arr)):
        raise InputError(f"inertia must be a finite (3, 3) array, got shape {inertia_arr.shape}")
    if not np.isfinite(mass) or mass <= 0.0:
        problems.append(f"mass must be > 0, got {given(mass)} kg")
    scale = float(np.max(np.abs(inertia_arr)))
    asym = float(np.max(np.abs(inertia_arr - inertia_arr.T)))
    if asym > max(rtol * scale, atol):
        problems.append(
            f"inertia tensor is not symmetric: max |I - I^T| = {asym:.3e} kg m^2 "
            f"(allowed {rtol:.0e} x max|I| = {rtol * scale:.3e})"
        )
        return problems
    moments = np.linalg.eigvalsh(0.5 * (inertia_arr + inertia_arr.T))
    tol = max(rtol * float(np.max(np.abs(moments))), atol)
    names = ("λ1", "λ2", "λ3")
    for k in range(3):
        if moments[k] < -tol:
            problems.append(
                f"inertia tensor is not positive semidefinite: principal moment {names[k]} = "
                f"{moments[k]:.6e} kg m^2 < 0 (principal moments {np.array2string(moments)})"
            )
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        slack = moments[j] + moments[k] - moments[i]
        if slack < -tol:
            problems.append(
                f"triangle inequality {names[i]} <= {names[j]} + {names[k]} fails by "
                f"{-slack:.6e} kg m^2 (principal moments {np.array2string(moments)}); "
                "no mass distribution has these moments"
            )
    return problems


def check_physical_consistency(
    mass: float, inertia: ArrayLike, *, rtol: float = CONSISTENCY_RTOL, where: str = "body"
) -> None:
    """Raise ``PhysicalConsistencyError`` listing every violated condition (see
    ``physical_consistency_violations``); ``where`` names the body in the message."""
    problems = physical_consistency_violations(mass, inertia, rtol=rtol)
    if problems:
        raise PhysicalConsistencyError(
            f"{where}: mass properties are not physically consistent:\n  - "
            + "\n  - ".join(problems)
        )


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass, centre of mass and central inertia tensor of one rigid link (SI units).

    Attributes
    ----------
    mass:
        kg, > 0.
    com:
        (3,) centre of mass in the link frame, m.
    inertia:
        (3, 3) inertia tensor about the CoM, link-frame axes, kg·m². Stored symmetrised.

    The constructor rejects physically inconsistent data (``PhysicalConsistencyError``); use
    ``physical_consistency_violations`` to inspect a candidate without constructing it.
    """

    mass: float
    com: Array
    inertia: Array

    def __init__(self, mass: float, com: ArrayLike, inertia: ArrayLike) -> None:
        mass = float(_floats(mass, "mass"))
        com = _vector3(com, "com")
        inertia = _matrix33(inertia, "inertia")
        check_physical_consistency(mass, inertia)
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", 0.5 * (inertia + inertia.T))
        for arr in (self.com, self.inertia):
            arr.setflags(write=False)

    # --- constructors ----------------------------------------------------------------------
    @classmethod
    def from_principal(
        cls,
        mass: float,
        com: ArrayLike,
        principal_moments: ArrayLike,
        principal_axes: ArrayLike | None = None,
        *,
        axes_as: Literal["columns", "rows"] = "columns",
    ) -> MassProperties:
        """Body from its principal central moments and principal axes.

        ``principal_axes`` is the direction-cosine matrix L between the principal (CoM) frame and
        the link frame (identity if omitted). With ``axes_as="columns"`` column k of L is
        principal axis k in link coordinates, so I = L·diag(λ)·Lᵀ (Rahman 1996 text, §2.2).
        With ``axes_as="rows"`` row k is axis k, I = Lᵀ·diag(λ)·L — the reading of Rahman's
        FORTRAN program (L1(1,j), L1(2,j), …; SPEC §2). Both agree when L = I.
        """
        moments = _vector3(principal_moments, "principal_moments")
        axes = np.eye(3) if principal_axes is None else _matrix33(principal_axes, "principal_axes")
        if axes_as == "rows":
            axes = axes.T
        elif axes_as != "columns":
            raise InputError(f"axes_as must be 'columns' or 'rows', got {axes_as!r}")
        orth_err = float(np.max(np.abs(axes.T @ axes - np.eye(3))))
        if orth_err > 1e-5 or np.linalg.det(axes) <= 0:
            raise InputError(
                f"principal_axes must be orthonormal and right-handed (a direction-cosine matrix); "
                f"max |L^T L - 1| = {orth_err:.3e}, det = {np.linalg.det(axes):.6g}. Check its "
                "entries (printed direction cosines to 5-6 decimals are accepted)."
            )
        if orth_err > 0.0:
            # direction cosines typed to a few decimals: the nearest rotation (polar factor)
            u, _, vt = np.linalg.svd(axes)
            axes = u @ vt
        return cls(mass, _vector3(com, "com"), axes @ np.diag(moments) @ axes.T)

    @classmethod
    def from_weight(
        cls,
        weight: float,
        com: ArrayLike,
        *,
        inertia: ArrayLike | None = None,
        radii_of_gyration: ArrayLike | None = None,
        gravity: float = STANDARD_GRAVITY,
    ) -> MassProperties:
        """Body of the given weight (N): mass = weight / gravity (m/s²).

        Give either the central ``inertia`` tensor (kg·m²) or the central principal
        ``radii_of_gyration`` k (m) along the link axes, I = m·diag(k²). This mirrors Rahman's
        program (M1 = 1.9/G, I1X = M1·K1XCG², SPEC §5); convert lbf and in/s² to N and m/s²
        before calling.
        """
        if not np.isfinite(gravity) or gravity <= 0.0:
            raise InputError(f"gravity must be a positive acceleration in m/s^2, got {given(gravity)}")
        if not np.isfinite(weight) or weight <= 0.0:
            raise InputError(f"weight must be a positive force in N, got {given(weight)}")
        mass = float(weight) / float(gravity)
        if (inertia is None) == (radii_of_gyration is None):
            raise InputError("give exactly one of inertia= or radii_of_gyration=")
        if radii_of_gyration is not None:
            k = _vector3(radii_of_gyration, "radii_of_gyration")
            if np.any(k < 0.0):
                raise InputError(f"radii_of_gyration must be >= 0, got {k}")
            return cls(mass, _vector3(com, "com"), mass * np.diag(k**2))
        assert inertia is not None
        return cls(mass, _vector3(com, "com"), _matrix33(inertia, "inertia"))

    @classmethod
    def from_inertial_parameters(cls, parameters: ArrayLike) -> MassProperties:
        """Body from π = (m, m c_x, m c_y, m c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz), the inertia
        taken about the link-frame **origin** (module docstring). Inverse of
        ``inertial_parameters``."""
        pi = np.asarray(parameters, dtype=float)
        if pi.shape != (N_INERTIAL_PARAMETERS,):
            raise InputError(
                f"inertial parameters must have shape ({N_INERTIAL_PARAMETERS},) "
                f"(m, m cx, m cy, m cz, Ixx, Iyy, Izz, Ixy, Ixz, Iyz), got {pi.shape}"
            )
        if not np.all(np.isfinite(pi)):
            raise InputError(f"inertial parameters must be finite, got {pi}")
        mass = float(pi[0])
        if mass <= 0.0:
            raise PhysicalConsistencyError(
                f"inertial parameters: mass must be > 0, got {given(mass)} kg"
            )
        com = pi[1:4] / mass
        ixx, iyy, izz, ixy, ixz, iyz = pi[4:]
        inertia_origin = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        inertia = inertia_origin - _point_inertia(mass, com)
        # Shifting to the CoM cancels m|c|²: its round-off is relative to the origin inertia.
        roundoff = 64 * np.finfo(float).eps * float(np.max(np.abs(inertia_origin)))
        problems = physical_consistency_violations(mass, inertia, atol=roundoff)
        if problems:
            raise PhysicalConsistencyError(
                "inertial parameters are not physically consistent (central inertia after the "
                "parallel-axis shift):\n  - " + "\n  - ".join(problems)
            )
        return cls(mass, com, _clip_second_moment(inertia))

    # --- derived quantities ----------------------------------------------------------------
    def inertial_parameters(self) -> Array:
        """π = (m, m c_x, m c_y, m c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz) about the link
        origin (order: module docstring)."""
        i_o = self.inertia_about(np.zeros(3))
        return np.array(
            [
                self.mass,
                *(self.mass * self.com),
                i_o[0, 0],
                i_o[1, 1],
                i_o[2, 2],
                i_o[0, 1],
                i_o[0, 2],
                i_o[1, 2],
            ]
        )

    def inertia_about(self, point: ArrayLike) -> Array:
        """Inertia tensor about ``point`` (link frame, link axes) by the parallel-axis theorem,
        I_P = I_c + m(|r|²·1 − r rᵀ) with r = c − P."""
        p = _vector3(point, "point")
        return self.inertia + _point_inertia(self.mass, self.com - p)

    def principal(self) -> tuple[Array, Array]:
        """Principal central moments (ascending) and axes (columns, right-handed, link frame),
        so that ``inertia = axes @ diag(moments) @ axes.T``."""
        moments, axes = np.linalg.eigh(self.inertia)
        if np.linalg.det(axes) < 0.0:
            axes[:, 2] = -axes[:, 2]
        return moments, axes

    def radii_of_gyration(self) -> Array:
        """Central principal radii of gyration sqrt(λ_k / m), ascending (as ``principal``)."""
        return np.sqrt(np.clip(self.principal()[0], 0.0, None) / self.mass)

    def pseudo_inertia(self) -> Array:
        """4×4 pseudo-inertia matrix about the link origin,
        J = [[Σ, m c], [m cᵀ, m]] with Σ = ∫ r rᵀ dm = ½tr(I_O)·1 − I_O.

        J is positive semidefinite exactly when the parameters are realisable by a non-negative
        mass density (Wensing, Kim & Slotine 2017); it is linear in π."""
        i_o = self.inertia_about(np.zeros(3))
        second_moment = 0.5 * np.trace(i_o) * np.eye(3) - i_o
        h = self.mass * self.com
        out = np.empty((4, 4))
        out[:3, :3] = second_moment
        out[:3, 3] = h
        out[3, :3] = h
        out[3, 3] = self.mass
        return out


@dataclass(frozen=True, eq=False)
class PointMassModel:
    """Point masses fixed in one link: ``positions`` (k, 3) in the link frame (m) and
    ``masses`` (k,) in kg (each ≥ 0, total > 0)."""

    positions: Array
    masses: Array

    def __init__(self, positions: ArrayLike, masses: ArrayLike) -> None:
        positions = np.array(positions, dtype=float)
        masses = np.array(masses, dtype=float)
        if positions.ndim != 2 or positions.shape[1] != 3:
            raise InputError(f"positions must have shape (k, 3), got {positions.shape}")
        if masses.shape != (positions.shape[0],):
            raise InputError(
                f"masses must have shape ({positions.shape[0]},) to match positions, "
                f"got {masses.shape}"
            )
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(masses))):
            raise InputError("positions and masses must be finite")
        if np.any(masses < 0.0):
            bad = np.flatnonzero(masses < 0.0)
            raise PhysicalConsistencyError(
                f"point masses must be >= 0; masses {shown_values(bad)} (counted from 0) are "
                f"{shown_values(masses[bad], 'mass')}"
            )
        if masses.sum() <= 0.0:
            raise PhysicalConsistencyError("the point masses must have a positive total mass")
        positions.setflags(write=False)
        masses.setflags(write=False)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "masses", masses)

    def to_mass_properties(self) -> MassProperties:
        """The rigid body with the same mass, first and second moments:
        m = Σm_i, c = Σm_i p_i / m, I_c = Σ m_i(|r_i|²·1 − r_i r_iᵀ), r_i = p_i − c."""
        mass = float(self.masses.sum())
        com = self.masses @ self.positions / mass
        r = self.positions - com
        r2 = np.einsum("ki,ki->k", r, r)
        inertia = np.einsum("k,ij->ij", self.masses * r2, np.eye(3)) - np.einsum(
            "k,ki,kj->ij", self.masses, r, r
        )
        return MassProperties(mass, com, inertia)

    def with_masses(self, masses: ArrayLike) -> PointMassModel:
        """Same points, new masses (what a point-mass balancing optimisation varies)."""
        return PointMassModel(self.positions, masses)


# order of the seven points of ``equivalent_point_masses``
EQUIVALENT_POINT_LABELS: tuple[str, ...] = ("+X", "-X", "+Y", "-Y", "+Z", "-Z", "CoM")


def _is_diagonal(matrix: Array) -> bool:
    off = matrix - np.diag(np.diag(matrix))
    return bool(np.max(np.abs(off)) <= 1e-12 * max(float(np.max(np.abs(matrix))), 1e-300))


def point_mass_distances(principal_moments: ArrayLike, pair_masses: ArrayLike) -> Array:
    """Distances (X, Y, Z) of Rahman's three ± pairs from the CoM (Rahman 1996, eqs 2.37/2.39/2.41
    with the ½ of SPEC §2): m1 X² = ½(−λ1 + λ2 + λ3), m2 Y² = ½(λ1 − λ2 + λ3),
    m3 Z² = ½(λ1 + λ2 − λ3), where λ are the principal central moments and (m1, m2, m3) the
    total masses of the pairs (each point carries half).

    Raises ``PointMassSplitError`` when a right-hand side is negative (the moments violate a
    triangle inequality: no real pair exists) or when a pair of zero mass would have to carry
    inertia. A zero-mass pair that carries none gets distance 0.
    """
    moments = _vector3(principal_moments, "principal_moments")
    masses = _vector3(pair_masses, "pair_masses")
    if np.any(masses < 0.0):
        raise PointMassSplitError(f"pair masses must be >= 0, got {shown_values(masses, 'mass')}")
    lam1, lam2, lam3 = moments
    needs = 0.5 * np.array([-lam1 + lam2 + lam3, lam1 - lam2 + lam3, lam1 + lam2 - lam3])
    tol = CONSISTENCY_RTOL * float(np.max(np.abs(moments)))
    distances = np.zeros(3)
    for k, label in enumerate("XYZ"):
        need = needs[k]
        if need < -tol:
            raise PointMassSplitError(
                f"m{k + 1}·{label}² = {need:.6e} kg m^2 < 0: the principal moments "
                f"{shown_values(moments, 'inertia')} violate a triangle inequality, so no real {label}-pair exists"
            )
        need = max(need, 0.0)
        if masses[k] == 0.0:
            if need > tol:
                raise PointMassSplitError(
                    f"m{k + 1} = 0 but the {label}-pair must supply m{k + 1}·{label}² = "
                    f"{need:.6e} kg m^2; give pair {k + 1} a positive mass"
                )
            continue
        distances[k] = np.sqrt(need / masses[k])
    return distances


def equivalent_point_masses(
    props: MassProperties,
    split: Sequence[float] | ArrayLike | None = None,
    *,
    axes: ArrayLike | None = None,
) -> PointMassModel:
    """Rahman's seven-point equivalent of a rigid link (Rahman 1996, §2.2, eqs 2.31–2.41).

    ``split = (m1, m2, m3, m4)`` in kg must sum to ``props.mass``; default m/4 each (the seed
    program's choice). The points, in the order of ``EQUIVALENT_POINT_LABELS``, are
    c ± X e1 (each m1/2), c ± Y e2 (each m2/2), c ± Z e3 (each m3/2) and c (m4), where e_k are
    the principal axes and, with principal central moments λ1, λ2, λ3,

        m1 X² = ½(−λ1 + λ2 + λ3),  m2 Y² = ½(λ1 − λ2 + λ3),  m3 Z² = ½(λ1 + λ2 − λ3).

    Principal axes: ``axes`` (columns, link frame) if given — it must diagonalise the inertia;
    else the link axes when the inertia is already diagonal there (keeps e1 = x for a link whose
    y and z moments are equal); else those of ``MassProperties.principal``.

    Raises ``PointMassSplitError`` when the split is impossible: a negative or non-summing split,
    or a zero pair mass where the pair must carry inertia (X² would be infinite).
    """
    m = props.mass
    if split is None:
        split_arr = np.full(4, m / 4.0)
    else:
        split_arr = np.asarray(split, dtype=float)
        if split_arr.shape != (4,) or not np.all(np.isfinite(split_arr)):
            raise PointMassSplitError(
                f"split must be four finite masses (m1, m2, m3, m4) in kg, got {given(split_arr)}"
            )
        if np.any(split_arr < 0.0):
            raise PointMassSplitError(f"split masses must be >= 0, got {split_arr} kg")
        if abs(split_arr.sum() - m) > 1e-12 * m:
            raise PointMassSplitError(
                f"split masses must sum to the link mass {m!r} kg; they sum to "
                f"{split_arr.sum()!r} kg (difference {split_arr.sum() - m:.3e} kg)"
            )

    if axes is not None:
        axes_arr = _matrix33(axes, "axes")
        if float(np.max(np.abs(axes_arr.T @ axes_arr - np.eye(3)))) > 1e-9:
            raise InputError("axes must be orthonormal (principal axes as columns)")
        in_axes = axes_arr.T @ props.inertia @ axes_arr
        off_diagonal = in_axes - np.diag(np.diag(in_axes))
        if np.max(np.abs(off_diagonal)) > 1e-9 * np.max(np.abs(in_axes)):
            raise InputError(
                "axes do not diagonalise the inertia tensor; pass principal axes "
                "(MassProperties.principal()[1]) or omit axes"
            )
        moments = np.diag(in_axes).copy()
    elif _is_diagonal(props.inertia):
        axes_arr = np.eye(3)
        moments = np.diag(props.inertia).copy()
    else:
        moments, axes_arr = props.principal()

    distances = point_mass_distances(moments, split_arr[:3])

    offsets = np.concatenate(
        [sign * distances[k] * axes_arr[:, k][None, :] for k in range(3) for sign in (1.0, -1.0)]
        + [np.zeros((1, 3))]
    )
    masses = np.array(
        [split_arr[0] / 2] * 2 + [split_arr[1] / 2] * 2 + [split_arr[2] / 2] * 2 + [split_arr[3]]
    )
    return PointMassModel(props.com[None, :] + offsets, masses)


def mass_properties_from_point_masses(positions: ArrayLike, masses: ArrayLike) -> MassProperties:
    """Rigid body equivalent to point ``masses`` (k,) at ``positions`` (k, 3)."""
    return PointMassModel(positions, masses).to_mass_properties()


__all__ = [
    "CONSISTENCY_RTOL",
    "EQUIVALENT_POINT_LABELS",
    "N_INERTIAL_PARAMETERS",
    "STANDARD_GRAVITY",
    "MassProperties",
    "PhysicalConsistencyError",
    "PointMassModel",
    "PointMassSplitError",
    "check_physical_consistency",
    "equivalent_point_masses",
    "mass_properties_from_point_masses",
    "physical_consistency_violations",
    "point_mass_distances",
]
