"""Desired screw displacements psi_d(theta) = psi_d0(theta) + eps S_d(theta) (Bagci 1969, §5.1).

theta is the input rotation measured from theta01 (theta0 = theta01 + theta, or theta01 - theta
for a clockwise input); both components are zero at theta = 0 by construction (eq. 5.1: the
generated screw is measured from its value at theta01).  Rotation in radians, translation in
metres.  Each component is optional and has its own design points (Example 2 uses 3 rotation and
17 translation points).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError
from screwkit.messages import listing
from screwkit.synthesis.expressions import parse_expression

__all__ = ["LIBRARY", "DesiredFunction", "ScrewTarget", "data_function", "library_function"]

FloatArray = NDArray[np.float64]
DesiredFunction = Callable[[FloatArray], FloatArray]


def _power(amplitude: float, span: float, power: float = 2.0) -> DesiredFunction:
    """amplitude (theta/span)^power: Bagci Ex. 2-4 rotation (power 2), Ex. 4/8 translation (1)."""
    if float(power).is_integer():
        return lambda t: amplitude * (t / span) ** int(power)
    return lambda t: amplitude * np.abs(t / span) ** power


def _parabola_dip(amplitude: float, span: float) -> DesiredFunction:
    """amplitude [(1 - 2 theta/span)^2 - 1]: Bagci Ex. 1 translation (Program B DSIRED IV=1)."""
    return lambda t: amplitude * ((1.0 - 2.0 * t / span) ** 2 - 1.0)


def _parabola_rise(amplitude: float, span: float) -> DesiredFunction:
    """amplitude [1 - (1 - theta/span)^2]: Bagci Ex. 2 translation."""
    return lambda t: amplitude * (1.0 - (1.0 - t / span) ** 2)


def _cubic_inflection(amplitude: float, span: float) -> DesiredFunction:
    """amplitude/2 [1 + (2 theta/span - 1)^3]: y = x^3/4 of Bagci Ex. 6 and 9, scaled to the
    ranges (an inflection with zero slope at theta = span/2: a second-order dwell)."""
    return lambda t: 0.5 * amplitude * (1.0 + (2.0 * t / span - 1.0) ** 3)


def _zero() -> DesiredFunction:
    return lambda t: np.zeros_like(t)


#: Named desired functions of the seed, with their parameters (SI: rad, m).
LIBRARY: dict[str, Callable[..., DesiredFunction]] = {
    "zero": _zero,
    "power": _power,
    "parabola_dip": _parabola_dip,
    "parabola_rise": _parabola_rise,
    "cubic_inflection": _cubic_inflection,
}


def library_function(name: str, **parameters: float) -> DesiredFunction:
    """A function of `LIBRARY` by name; a wrong name or parameter raises ValueError."""
    factory = LIBRARY.get(name)
    if factory is None:
        raise InputError(f"unknown desired function {name!r}; choose one of {listing(sorted(LIBRARY))}, or "
                         "give an expression")
    for pname, value in parameters.items():
        if not np.isfinite(float(value)):
            raise InputError(f"desired function {name!r}: parameter {pname} must be finite, got "
                             f"{float(value)}")
    if "span" in parameters and not float(parameters["span"]) > 0.0:
        raise InputError(f"desired function {name!r}: span must be > 0 (the input rotation over "
                         f"which the function runs), got {float(parameters['span'])}")
    try:
        return factory(**{k: float(v) for k, v in parameters.items()})
    except TypeError as exc:
        raise InputError(f"desired function {name!r}: {exc}") from None


def data_function(theta: ArrayLike, values: ArrayLike) -> DesiredFunction:
    """A desired function given as data (Bagci Ex. 5, 6, 7): piecewise-linear between points."""
    t = np.asarray(theta, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if t.ndim != 1 or t.shape != v.shape or t.size < 1:
        raise InputError(f"data: theta and values must be 1-D of equal length, got {t.shape}, "
                         f"{v.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
        raise InputError("data: theta and values must be finite")
    order = np.argsort(t)
    if np.any(np.diff(t[order]) == 0.0):
        raise InputError("data: theta values must be distinct")
    ts, vs = t[order], v[order]

    def interpolate(x: FloatArray) -> FloatArray:
        x = np.asarray(x, dtype=np.float64)
        outside = (x < ts[0]) | (x > ts[-1])
        if np.any(outside):
            shown = ", ".join(f"{math.degrees(float(v)):.6g}" for v in np.unique(x[outside])[:8])
            raise InputError(
                f"data: design point(s) theta = {shown} deg lie outside the data's range "
                f"[{math.degrees(float(ts[0])):.6g}, {math.degrees(float(ts[-1])):.6g}] deg; the "
                "data would be held constant there. Extend the data or move the design points")
        return np.interp(x, ts, vs)

    interpolate.theta_range = (float(ts[0]), float(ts[-1]))  # type: ignore[attr-defined]
    return interpolate


def expression_function(text: str, *, angle_unit: float, value_unit: float,
                        parameters: Mapping[str, float] | None = None) -> DesiredFunction:
    """A safe user expression in the spec's units: theta [angle_unit] -> value [value_unit]."""
    expr = parse_expression(text, parameters)
    return lambda t: expr(np.asarray(t) / angle_unit) * value_unit


def _check_finite(name: str, fn: DesiredFunction, theta: FloatArray) -> None:
    """The desired ``name`` must be finite at theta = 0 (the reference, eq. 5.1) and at every
    design point; numpy's warnings are silenced, the error names the points."""
    pts = np.concatenate([[0.0], theta])
    with np.errstate(all="ignore"):
        values = np.asarray(fn(pts), dtype=np.float64).reshape(-1)
    if values.shape != pts.shape:
        raise InputError(f"the desired {name} must give one value per design point")
    bad = ~np.isfinite(values)
    if bad.any():
        shown = ", ".join(f"{math.degrees(float(t)):.6g}" for t in np.unique(pts[bad])[:8])
        raise InputError(f"the desired {name} is not finite at theta = {shown} deg (theta = 0 is "
                         "the reference the target is measured from): change the function, its "
                         "parameters or the design points")


@dataclass(frozen=True)
class ScrewTarget:
    """Desired rotation psi_d0(theta) [rad] and translation S_d(theta) [m] with design points.

    Attributes
    ----------
    rotation, translation : callables of theta (radians, shape (N,)), or None when the
        component is not prescribed (its error is not counted: Bagci Ex. 4-7 "accepted as
        generated").
    theta_rotation, theta_translation : design points theta_i (radians, from theta01).
    """

    rotation: DesiredFunction | None
    theta_rotation: FloatArray = field(default_factory=lambda: np.zeros(0))
    translation: DesiredFunction | None = None
    theta_translation: FloatArray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        for name in ("theta_rotation", "theta_translation"):
            arr = np.asarray(getattr(self, name), dtype=np.float64).reshape(-1)
            if not np.all(np.isfinite(arr)):
                raise InputError(f"ScrewTarget.{name} must be finite")
            object.__setattr__(self, name, arr)
        if self.rotation is None:
            object.__setattr__(self, "theta_rotation", np.zeros(0))
        if self.translation is None:
            object.__setattr__(self, "theta_translation", np.zeros(0))
        if self.theta_rotation.size + self.theta_translation.size == 0:
            raise InputError("the target prescribes nothing: give a rotation or a translation "
                             "with at least one design point")
        if self.rotation is not None and self.theta_rotation.size == 0:
            raise InputError("a rotation is prescribed but it has no design points")
        if self.translation is not None and self.theta_translation.size == 0:
            raise InputError("a translation is prescribed but it has no design points")
        for name, fn, pts in (("rotation", self.rotation, self.theta_rotation),
                              ("translation", self.translation, self.theta_translation)):
            if fn is not None:
                _check_finite(name, fn, pts)

    @property
    def theta_all(self) -> FloatArray:
        """Sorted distinct design points with theta = 0 (the reference, eq. 5.1) first."""
        pts = np.unique(np.concatenate([[0.0], self.theta_rotation, self.theta_translation]))
        return np.concatenate([[0.0], pts[pts != 0.0]])

    def desired_rotation(self, theta: ArrayLike) -> FloatArray:
        t = np.asarray(theta, dtype=np.float64)
        if self.rotation is None:
            return np.full(t.shape, np.nan)
        return np.asarray(self.rotation(t), dtype=np.float64) - float(self.rotation(np.zeros(1))[0])

    def desired_translation(self, theta: ArrayLike) -> FloatArray:
        t = np.asarray(theta, dtype=np.float64)
        if self.translation is None:
            return np.full(t.shape, np.nan)
        return (np.asarray(self.translation(t), dtype=np.float64)
                - float(self.translation(np.zeros(1))[0]))
