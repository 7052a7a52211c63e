"""Validation of what inverse dynamics is given: mass properties, the motion, loads, vectors.

Every failure is a ``ValueError`` subclass whose message says what is wrong, where, and how to
fix it (STYLE: no silent NaN).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError
from screwkit.kinematics.motion import ModeMotion
from screwkit.messages import given, listing
from screwkit.model.linkage import Linkage
from screwkit.model.mass import (
    MassProperties,
    PhysicalConsistencyError,
    physical_consistency_violations,
)

Array = NDArray[np.float64]


class DynamicsInputError(InputError):
    """Inverse dynamics was given something it cannot use (missing masses, bad motion …)."""


class MissingMassError(DynamicsInputError):
    """A moving link has no mass properties."""


class NonAssemblingMotionError(DynamicsInputError):
    """The motion has samples where the loop does not assemble or is singular."""


@dataclass(frozen=True)
class ExternalLoad:
    """A constant load on one moving link: ``force`` (N) and ``moment`` (N·m) fixed in the world
    frame, the force acting at ``point`` (m), a point fixed in the link (link body frame)."""

    force: ArrayLike = field(default_factory=lambda: np.zeros(3))
    moment: ArrayLike = field(default_factory=lambda: np.zeros(3))
    point: ArrayLike = field(default_factory=lambda: np.zeros(3))


def check_vector3(value: ArrayLike | None, name: str) -> Array:
    """A finite (3,) vector (zeros for ``None``)."""
    if value is None:
        return np.zeros(3)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.full(1, np.nan)  # not numbers: the message below names the argument
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise DynamicsInputError(
            f"{name} must be a finite 3-vector in the world frame (SI units); got {given(value)}"
        )
    return arr


def check_link_masses(linkage: Linkage) -> list[MassProperties]:
    """The mass properties of every moving link, re-checked for physical consistency."""
    out: list[MassProperties] = []
    for k, link in enumerate(linkage.links):
        mp = link.mass
        where = f"{linkage.name}: link {link.name!r} (moving link {k + 1} of {len(linkage.links)})"
        if mp is None:
            raise MissingMassError(
                f"{where} has no mass properties; give every moving link one, e.g. "
                f"linkage.with_links([Link({link.name!r}, MassProperties(mass, com, inertia)), …])"
            )
        if not all(hasattr(mp, a) for a in ("mass", "com", "inertia")):
            raise DynamicsInputError(
                f"{where}: mass must be a screwkit.model.mass.MassProperties, got {type(mp)!r}"
            )
        com = np.asarray(mp.com, dtype=float)
        inertia = np.asarray(mp.inertia, dtype=float)
        if com.shape != (3,) or not np.all(np.isfinite(com)):
            raise DynamicsInputError(f"{where}: the centre of mass must be a finite 3-vector")
        if inertia.shape != (3, 3):
            raise DynamicsInputError(f"{where}: the inertia tensor must be 3×3")
        problems = physical_consistency_violations(float(mp.mass), inertia)
        if problems:
            raise PhysicalConsistencyError(
                f"{where}: mass properties are physically impossible:\n  - "
                + "\n  - ".join(problems)
            )
        out.append(mp if isinstance(mp, MassProperties) else MassProperties(mp.mass, com, inertia))
    return out


def check_external_loads(
    linkage: Linkage, loads: Mapping[str, ExternalLoad] | None
) -> dict[int, tuple[Array, Array, Array]]:
    """External loads by moving-link index: (force, moment, point)."""
    if loads is None:
        return {}
    if not isinstance(loads, Mapping):
        raise DynamicsInputError(f"external_loads must be a mapping of link name to "
                                 f"ExternalLoad; got {type(loads).__name__}")
    names = [lk.name for lk in linkage.links]
    out: dict[int, tuple[Array, Array, Array]] = {}
    for name, load in loads.items():
        if name not in names:
            raise DynamicsInputError(
                f"external load on {name!r}: no such moving link in {linkage.name}; "
                f"moving links are {listing(names)}"
            )
        if not isinstance(load, ExternalLoad):
            raise DynamicsInputError(f"external load on {name!r} must be an ExternalLoad(force, "
                                     f"moment, point); got {type(load).__name__}")
        out[names.index(name)] = (
            check_vector3(load.force, f"external force on {name!r}"),
            check_vector3(load.moment, f"external moment on {name!r}"),
            check_vector3(load.point, f"application point on {name!r}"),
        )
    return out


def _finite_rows(arr: Array) -> NDArray[np.bool_]:
    """Which samples (first axis) of ``arr`` are finite throughout. A NaN or an infinity makes
    the sample's sum non-finite, so one matrix–vector product (fast in any memory layout)
    decides for most samples; only those whose sum overflows are checked element by element."""
    flat = arr.reshape(arr.shape[0], -1)
    with np.errstate(over="ignore", invalid="ignore"):
        ok = np.isfinite(flat @ np.ones(flat.shape[1]))
    if not ok.all():
        suspect = np.flatnonzero(~ok)
        ok[suspect] = np.all(np.isfinite(flat[suspect]), axis=1)
    return ok


def finite_samples(mode: ModeMotion) -> NDArray[np.bool_]:
    """Which samples have a finite motion: every array that dynamics reads (the link frames,
    their rates, the joint centres and axes)."""
    finite = np.ones(mode.link_rotation.shape[0], dtype=bool)
    for arr in (
        mode.link_rotation,
        mode.link_origin,
        mode.link_angular_velocity,
        mode.link_origin_velocity,
        mode.link_angular_acceleration,
        mode.link_origin_acceleration,
        mode.joint_centres,
        mode.joint_axes,
    ):
        finite &= _finite_rows(arr)
    return finite


def valid_samples(
    linkage: Linkage,
    mode: ModeMotion,
    inputs: Array,
    allow_partial: bool,
    *,
    check_finite: bool = True,
) -> NDArray[np.bool_]:
    """Samples usable for dynamics: assembled, not singular, finite motion.
    ``check_finite=False`` leaves the finiteness to the caller (the blocked inverse dynamics
    checks each block while it is in the cache, :func:`finite_samples`)."""
    if not isinstance(mode, ModeMotion):
        raise DynamicsInputError(
            f"expected one assembly mode (a ModeMotion, e.g. motion(...).modes[0]); "
            f"got {type(mode).__name__}"
        )
    n_links = len(linkage.links)
    if mode.link_rotation.ndim != 4 or mode.link_rotation.shape[1] != n_links:
        raise DynamicsInputError(
            f"the motion has {mode.link_rotation.shape[1:2]} moving links but {linkage.name} has "
            f"{n_links}: pass the ModeMotion computed for this linkage"
        )
    valid = mode.assembles & ~mode.singular
    if check_finite:
        valid &= finite_samples(mode)
    _check_frames(linkage, mode, valid)
    if not valid.any():
        raise NonAssemblingMotionError(
            f"{linkage.name}: the mode assembles (non-singularly) at none of its "
            f"{valid.size} samples; choose a mode or a sweep where it does"
        )
    if not allow_partial and not valid.all():
        bad = np.nonzero(~valid)[0]
        singular = np.nonzero(mode.singular & mode.assembles)[0]
        from screwkit.kinematics.motion import format_inputs

        shown = "; ".join(f"#{i} ({format_inputs(linkage, inputs[i])})" for i in bad[:8])
        more = f" and {bad.size - 8} more" if bad.size > 8 else ""
        what = "is singular at" if singular.size == bad.size else "does not assemble (or is singular) at"
        raise NonAssemblingMotionError(
            f"{linkage.name}: the mode {what} {bad.size} of {valid.size} samples: {shown}{more}. "
            "Restrict the sweep (the spec's [motion] start/stop/step) to where the mode assembles "
            "or pick another mode; from Python, allow_partial=True gives NaN there (None in "
            "as_dict())."
        )
    return valid


def _check_frames(linkage: Linkage, mode: ModeMotion, valid: NDArray[np.bool_]) -> None:
    """Link rotations must carry each joint axis to the next: z of (R_l · L_l) = axis of joint
    l+1 (a cheap guard against a motion of another linkage or a frame-convention slip)."""
    idx = np.nonzero(valid)[0]
    idx = idx[np.unique(np.linspace(0, idx.size - 1, min(64, idx.size)).astype(int))]
    for l, transform in enumerate(linkage.link_transforms[:-1]):
        z_next = (mode.link_rotation[idx, l] @ transform.real)[:, :, 2]
        err = float(np.max(np.abs(z_next - mode.joint_axes[idx, l + 1]), initial=0.0))
        if err > 1e-6:
            raise DynamicsInputError(
                f"{linkage.name}: the motion's rotation of link {linkage.links[l].name!r} does not "
                f"carry joint {linkage.joints[l].name!r}'s frame to joint "
                f"{linkage.joints[l + 1].name!r}'s axis (error {err:.2e}); pass the ModeMotion "
                "computed for this linkage (link_rotation must be the world rotation, base "
                "included)"
            )
