"""Unit handling at the boundary (pint). Inside the library everything is SI and radians."""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import pint


class UnitError(ValueError):
    """A quantity that cannot be read or has the wrong kind of unit."""


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry[Any]:
    ureg: pint.UnitRegistry[Any] = pint.UnitRegistry()
    return ureg


KIND_UNITS = {
    "length": "m",
    "angle": "rad",
    "angular_velocity": "rad/s",
    "angular_acceleration": "rad/s**2",
    "velocity": "m/s",
    "acceleration": "m/s**2",
    "mass": "kg",
    "force": "N",
    "inertia": "kg*m**2",
    "dimensionless": "",
}

EXAMPLES = {
    "length": '"2.0 in" or "50 mm"',
    "angle": '"250 deg" or "1.2 rad"',
    "angular_velocity": '"3000 rpm" or "314.16 rad/s"',
    "angular_acceleration": '"0 rad/s^2"',
    "velocity": '"1 m/s"',
    "acceleration": '"386.4 in/s^2" or "9.80665 m/s^2"',
    "mass": '"0.86 kg"',
    "force": '"1.9 lbf"',
    "inertia": '"2.05e-4 lbf*s^2*in" or "1e-3 kg*m^2"',
    "dimensionless": "a plain number",
}


def to_si(value: Any, kind: str, default_unit: str | None = None) -> float:
    """Convert ``value`` (a number, or a string such as ``"2 in"``) to the SI unit of ``kind``.

    A bare number takes ``default_unit`` (from the spec's ``[units]`` table), or SI if none.
    """
    ureg = registry()
    target = KIND_UNITS[kind]
    if default_unit is not None:
        check_unit(default_unit, kind)
    if isinstance(value, bool):
        raise UnitError(f"expected a {kind.replace('_', ' ')}, e.g. {EXAMPLES[kind]}; got {value!r}")
    if isinstance(value, int | float):
        if default_unit is None or kind == "dimensionless":
            return _finite(float(value), value, kind)
        q = ureg.Quantity(float(value), default_unit)
    elif isinstance(value, str):
        try:
            q = ureg.Quantity(value)
        except Exception as exc:  # pint raises several types for unreadable text
            raise UnitError(
                f"cannot read {value!r} as a {kind.replace('_', ' ')}; write e.g. {EXAMPLES[kind]}"
            ) from exc
        if not isinstance(q, pint.Quantity):
            q = ureg.Quantity(float(q), default_unit or target or "")
        elif q.unitless and default_unit and kind != "dimensionless":
            # a number written as text ("2"): the default unit applies. A unit the user wrote
            # ("1.2 rad" under angle = "deg") is kept, even if pint calls it dimensionless.
            q = ureg.Quantity(float(q.magnitude), default_unit)
        if kind == "angular_velocity" and "hertz" in str(q.units):
            raise UnitError(
                f"{value!r} is ambiguous for an angular speed (Hz is 1/s, with no angle): write "
                f"revolutions as \"50 rev/s\" or \"3000 rpm\", or radians as \"314.16 rad/s\""
            )
    else:
        raise UnitError(f"expected a {kind.replace('_', ' ')}, e.g. {EXAMPLES[kind]}; got {value!r}")
    try:
        out = float(q.to(target).magnitude) if target else float(q.to("").magnitude)
    except pint.DimensionalityError as exc:
        raise UnitError(
            f"{value!r} is not a {kind.replace('_', ' ')} (its unit is {q.units}); "
            f"write e.g. {EXAMPLES[kind]}"
        ) from exc
    return _finite(out, value, kind)


def _finite(out: float, value: Any, kind: str) -> float:
    if out != out or out in (float("inf"), float("-inf")):
        raise UnitError(f"{value!r} is not a finite {kind.replace('_', ' ')}")
    return out


def check_unit(unit: str, kind: str) -> None:
    """Raise :class:`UnitError` unless ``unit`` is a unit pint knows and of the right kind."""
    ureg = registry()
    try:
        q = ureg.Quantity(1.0, unit)
    except Exception as exc:  # UndefinedUnitError and friends
        raise UnitError(f"unknown unit {unit!r} for {kind.replace('_', ' ')}; write e.g. "
                        f"{EXAMPLES[kind]}") from exc
    target = KIND_UNITS[kind]
    try:
        q.to(target) if target else q.to("")
    except pint.DimensionalityError as exc:
        raise UnitError(f"{unit!r} is not a unit of {kind.replace('_', ' ')}; write e.g. "
                        f"{EXAMPLES[kind]}") from exc
