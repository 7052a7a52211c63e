"""Unit handling at the boundary. Inside the library everything is SI and radians.

A value is read by the quantity grammar of :mod:`screwkit.io.quantity` (a number and unit
names with small powers); pint only looks up each unit *name* and converts. After conversion a
value must be finite and inside the engineering range of its kind (:data:`MAGNITUDE_LIMITS`,
docs/reliability.md): a mass of 1e300 kg is a typing mistake, and letting it through turns into
overflow deep inside the solvers.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING, Any

from screwkit.errors import InputError, UnknownNameError, did_you_mean
from screwkit.io.quantity import (
    MAX_QUANTITY_CHARS,
    QuantitySyntaxError,
    excerpt,
    parse_quantity,
    parse_unit,
)

if TYPE_CHECKING:
    import pint


class UnitError(InputError):
    """A quantity that cannot be read or has the wrong kind of unit."""


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry[Any]:
    """pint's registry, built on first use (0.2 s): the common units of :data:`COMMON_UNITS`
    never need it."""
    import pint

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
    "torque": "N*m",
    "time": "s",
    "rotational_damping": "N*m*s/rad",
    "translational_damping": "N*s/m",
    "moment": "N*m",
    "mass_moment": "kg*m",
    "dimensionless": "",
}

#: powers of (m, kg, s) of each kind; an angle is dimensionless, as in pint
KIND_DIMENSIONS: dict[str, tuple[int, int, int]] = {
    "length": (1, 0, 0), "angle": (0, 0, 0), "angular_velocity": (0, 0, -1),
    "angular_acceleration": (0, 0, -2), "velocity": (1, 0, -1), "acceleration": (1, 0, -2),
    "mass": (0, 1, 0), "force": (1, 1, -2), "inertia": (2, 1, 0), "moment": (2, 1, -2),
    "torque": (2, 1, -2), "mass_moment": (1, 1, 0), "time": (0, 0, 1),
    "rotational_damping": (2, 1, -1), "translational_damping": (0, 1, -1),
    "dimensionless": (0, 0, 0),
}

_INCH = 0.0254
_POUND = 0.4535923700000001  # pint's double for 0.45359237 kg (from 7000 grains): the same bits
_G0 = 9.80665
_TURN = 2.0 * math.pi
_LENGTH, _MASS, _TIME, _NONE = (1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 0)

#: the unit names most spec files use, read without building pint's registry (start-up time):
#: name -> (SI value of one unit, powers of m, kg, s). The same definitions as pint's (tested
#: against pint name by name); any other name goes to pint.
COMMON_UNITS: dict[str, tuple[float, tuple[int, int, int]]] = {
    **dict.fromkeys(("m", "meter", "metre", "meters", "metres"), (1.0, _LENGTH)),
    **dict.fromkeys(("mm", "millimeter", "millimetre", "millimeters"), (1e-3, _LENGTH)),
    **dict.fromkeys(("cm", "centimeter", "centimetre"), (1e-2, _LENGTH)),
    **dict.fromkeys(("km", "kilometer", "kilometre"), (1e3, _LENGTH)),
    **dict.fromkeys(("um", "µm", "μm", "micrometer"), (1e-6, _LENGTH)),
    **dict.fromkeys(("in", "inch", "inches"), (_INCH, _LENGTH)),
    **dict.fromkeys(("ft", "foot", "feet"), (12 * _INCH, _LENGTH)),
    **dict.fromkeys(("rad", "radian", "radians"), (1.0, _NONE)),
    **dict.fromkeys(("deg", "degree", "degrees"), (math.pi / 180.0, _NONE)),
    **dict.fromkeys(("rev", "revs", "revolution", "revolutions", "turn"), (_TURN, _NONE)),
    **dict.fromkeys(("s", "sec", "second", "seconds"), (1.0, _TIME)),
    **dict.fromkeys(("ms", "millisecond"), (1e-3, _TIME)),
    **dict.fromkeys(("min", "minute", "minutes"), (60.0, _TIME)),
    **dict.fromkeys(("h", "hr", "hour", "hours"), (3600.0, _TIME)),
    "rpm": (_TURN / 60.0, (0, 0, -1)),
    **dict.fromkeys(("kg", "kilogram", "kilograms"), (1.0, _MASS)),
    **dict.fromkeys(("g", "gram", "grams"), (1e-3, _MASS)),
    **dict.fromkeys(("lb", "pound", "pounds"), (_POUND, _MASS)),
    **dict.fromkeys(("N", "newton", "newtons"), (1.0, (1, 1, -2))),
    "kN": (1e3, (1, 1, -2)),
    "lbf": (_POUND * _G0, (1, 1, -2)),
    "kgf": (_G0, (1, 1, -2)),
}


def common_unit_factor(names: tuple[tuple[str, int], ...], kind: str) -> float | None:
    """SI value of one of the unit ``names`` if every name is in :data:`COMMON_UNITS` and the
    powers make a unit of ``kind``; ``None`` otherwise (pint then decides, and words the
    error)."""
    factor = 1.0
    dims = [0, 0, 0]
    for name, power in names:
        entry = COMMON_UNITS.get(name)
        if entry is None:
            return None
        factor *= entry[0] ** power
        for k in range(3):
            dims[k] += entry[1][k] * power
    return factor if tuple(dims) == KIND_DIMENSIONS.get(kind) else None


#: SI unit of each kind as printed in messages
SI_SYMBOL = {"length": "m", "angle": "rad", "angular_velocity": "rad/s",
             "angular_acceleration": "rad/s^2", "velocity": "m/s", "acceleration": "m/s^2",
             "mass": "kg", "force": "N", "inertia": "kg*m^2", "torque": "N*m", "time": "s",
             "rotational_damping": "N*m*s/rad", "translational_damping": "N*s/m",
             "moment": "N*m", "mass_moment": "kg*m",
             "dimensionless": ""}

#: (largest |value|, smallest non-zero |value|) accepted per kind, in SI. Zero is always
#: accepted here (a zero offset, a massless link, a resting input); rules that need a positive
#: value (a step, gravity) are checked where the value is used. The ranges cover every machine
#: from a MEMS linkage to a crane; docs/reliability.md says how to widen them.
MAGNITUDE_LIMITS: dict[str, tuple[float, float]] = {
    "length": (1e6, 1e-9),                  # 1000 km … 1 nm
    "angle": (1e5, 1e-12),                  # ~16 000 turns … 1e-12 rad
    "angular_velocity": (1e6, 1e-12),       # ~9.5 million rpm
    "angular_acceleration": (1e12, 1e-12),
    "velocity": (1e6, 1e-12),               # 1000 km/s
    "acceleration": (1e9, 1e-12),           # 1e8 g
    "mass": (1e9, 1e-12),                   # a million tonnes … 1 ng
    "force": (1e12, 1e-12),
    "inertia": (1e15, 1e-27),               # kg·m²
    "torque": (1e12, 1e-12),                # N·m
    "time": (1e7, 1e-12),                   # ~4 months … 1 ps
    "rotational_damping": (1e12, 1e-15),    # N·m·s/rad
    "translational_damping": (1e12, 1e-15),  # N·s/m
    "moment": (1e15, 1e-15),
    "mass_moment": (1e12, 1e-15),
    "dimensionless": (1e12, 1e-300),
}

#: names pint does not define that spec files use, and what they mean
ALIASES = {"rev": "revolution", "revs": "revolution"}

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
    "torque": '"5 N*m" or "40 lbf*in"',
    "time": '"2 s" or "150 ms"',
    "rotational_damping": '"0.01 N*m*s/rad"',
    "translational_damping": '"5 N*s/m"',
    "moment": '"N*m" or "lbf*in"',
    "mass_moment": '"kg*m" or "kg*mm"',
    "dimensionless": "a plain number",
}


def _words(kind: str) -> str:
    return kind.replace("_", " ")


def _a(kind: str) -> str:
    """The kind with its article: "a length", "an angle"."""
    w = _words(kind)
    return f"an {w}" if w[0] in "aeiou" else f"a {w}"


@lru_cache(maxsize=512)
def _unit(names: tuple[tuple[str, int], ...]) -> Any:
    """The pint unit of parsed (name, power) pairs: each name is looked up on its own (a
    single identifier, which pint resolves as a name, with prefixes and plurals)."""
    ureg = registry()
    unit = ureg.Unit("")
    for name, power in names:
        try:
            one = ureg.Unit(ALIASES.get(name, name))
        except Exception as exc:  # UndefinedUnitError and friends
            raise UnitError(f"unknown unit {excerpt(name)}") from exc
        unit = unit * one**power
    return unit


@lru_cache(maxsize=512)
def _factor(names: tuple[tuple[str, int], ...], kind: str) -> float:
    """SI value of one of the unit; raises :class:`UnitError` for the wrong kind."""
    import pint

    unit = _unit(names)
    target = KIND_UNITS[kind]
    try:
        q = registry().Quantity(1.0, unit)
        factor = float(q.to(target).magnitude) if target else float(q.to("").magnitude)
    except pint.DimensionalityError as exc:
        raise UnitError(f"its unit is {unit}") from exc
    except Exception as exc:  # offset units (degC) cannot be multiplied
        raise UnitError(f"the unit {unit} cannot be used here ({type(exc).__name__})") from exc
    return factor


def _has_hertz(names: tuple[tuple[str, int], ...]) -> bool:
    """Whether a unit names hertz (1/s with no angle: ambiguous for an angular speed)."""
    hertz = registry().Unit("hertz")
    return any(_unit(((n, 1),)) == hertz for n, _ in names)


def check_kind(kind: object) -> str:
    """``kind`` if it is a quantity kind of :data:`KIND_UNITS`; otherwise an
    :class:`~screwkit.errors.UnknownNameError` listing the kinds and the closest one."""
    if isinstance(kind, str) and kind in KIND_UNITS:
        return kind
    raise UnknownNameError(f"unknown quantity kind {kind!r}; {did_you_mean(kind, KIND_UNITS)}"
                           f"the kinds are {', '.join(KIND_UNITS)}")


def check_unit(unit: str, kind: str) -> None:
    """Raise :class:`UnitError` unless ``unit`` is a unit expression of the right kind."""
    check_kind(kind)
    if not isinstance(unit, str):
        raise UnitError(f"a unit is a string such as \"in\" or \"deg\"; got {unit!r}")
    try:
        names = parse_unit(unit) if len(unit) <= MAX_QUANTITY_CHARS else None
    except QuantitySyntaxError as exc:
        raise UnitError(f"cannot read the unit {excerpt(unit)}: {exc}; write e.g. "
                        f"{EXAMPLES[kind]}") from exc
    if names is None:
        raise UnitError(f"the unit {excerpt(unit)} is longer than {MAX_QUANTITY_CHARS} characters")
    if common_unit_factor(names, kind) is not None:
        return
    try:
        _unit(names)
    except UnitError as exc:
        raise UnitError(f"unknown unit {excerpt(unit)} for {_words(kind)}; write e.g. "
                        f"{EXAMPLES[kind]}") from exc
    try:
        _factor(names, kind)
    except UnitError as exc:
        raise UnitError(f"{excerpt(unit)} is not a unit of {_words(kind)}; write e.g. "
                        f"{EXAMPLES[kind]}") from exc


def check_magnitude(value_si: float, kind: str, shown: str) -> float:
    """``value_si`` if it is finite and inside :data:`MAGNITUDE_LIMITS` for ``kind``; otherwise
    a :class:`UnitError` that shows the value as ``shown``."""
    unit = SI_SYMBOL[kind]
    if not math.isfinite(value_si):
        raise UnitError(f"{shown} is not a finite {_words(kind)} (it overflows in SI)")
    high, low = MAGNITUDE_LIMITS[kind]
    size = abs(value_si)
    if size > high or 0.0 < size < low:
        raise UnitError(
            f"{shown} is {value_si:.3g} {unit} in SI, outside the range accepted for "
            f"{_a(kind)} (0, or {low:g} to {high:g} {unit} in magnitude); check the "
            "number and its unit (the limits and how to change them: docs/reliability.md)")
    return value_si


def to_si(value: Any, kind: str, default_unit: str | None = None) -> float:
    """Convert ``value`` (a number, or a string such as ``"2 in"``) to the SI unit of ``kind``.

    A bare number (or a string holding only a number) takes ``default_unit`` (from the spec's
    ``[units]`` table), or SI if none. A unit written in the value wins over the default.
    """
    check_kind(kind)
    if default_unit is not None:
        check_unit(default_unit, kind)
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        shown_value = repr(value)
        if len(shown_value) > 40:
            shown_value = shown_value[:40] + "…"
        raise UnitError(f"expected {_a(kind)}, e.g. {EXAMPLES[kind]}; got {shown_value} "
                        f"({type(value).__name__})")
    shown = excerpt(str(value)) if isinstance(value, str) else repr(value)
    if isinstance(value, str):
        try:
            parsed = parse_quantity(value)
        except QuantitySyntaxError as exc:
            raise UnitError(f"cannot read {shown} as {_a(kind)}: {exc}; write e.g. "
                            f"{EXAMPLES[kind]}") from None
        magnitude, names = parsed.magnitude, parsed.units
    else:
        try:
            magnitude = float(value)
        except OverflowError:
            raise UnitError(f"{excerpt(repr(value))} is too large for {_a(kind)}") from None
        names = ()
        if not math.isfinite(magnitude):
            raise UnitError(f"{shown} is not a finite number")
    if not names and kind != "dimensionless" and default_unit is not None:
        names = parse_unit(default_unit)
    if not names:
        return check_magnitude(magnitude, kind, shown)
    common = common_unit_factor(names, kind)
    if common is not None:
        return check_magnitude(magnitude * common, kind, shown)
    try:
        factor = _factor(names, kind)
    except UnitError as exc:
        if str(exc).startswith("unknown unit"):
            raise UnitError(f"{exc} in {shown}; write e.g. {EXAMPLES[kind]}") from None
        raise UnitError(f"{shown} is not {_a(kind)} ({exc}); write e.g. "
                        f"{EXAMPLES[kind]}") from None
    if kind == "angular_velocity" and _has_hertz(names):
        raise UnitError(
            f"{shown} is ambiguous for an angular speed (Hz is 1/s, with no angle): write "
            f"revolutions as \"50 rev/s\" or \"3000 rpm\", or radians as \"314.16 rad/s\"")
    return check_magnitude(magnitude * factor, kind, shown)


def unit_factor(unit: str, kind: str) -> float:
    """The SI value of one ``unit`` of ``kind`` (``unit_factor("deg", "angle")`` is π/180);
    a :class:`UnitError` for a unit that cannot be read or is of another kind. Remembered per
    (unit, kind): a spec's units are read again with every studio change."""
    if isinstance(unit, str) and isinstance(kind, str):
        return _unit_factor(unit, kind)
    return _unit_factor.__wrapped__(unit, kind)


@lru_cache(maxsize=1024)
def _unit_factor(unit: str, kind: str) -> float:
    check_unit(unit, kind)
    names = parse_unit(unit)
    common = common_unit_factor(names, kind)
    return common if common is not None else _factor(names, kind)
