"""Units for people: terminal tables, CSV/Parquet/NPZ tables and plots show every kind of
quantity in the spec's ``[units]`` (or in SI, or with per-kind overrides); JSON documents stay in
SI with their ``units`` block, so machines get one convention and people another
(docs/cli.md, "Units").

A kind without a unit of its own follows its base kinds: rates follow the angle and length
units (``deg/s`` and ``deg/s^2`` when angles are in degrees, ``mm/s`` when lengths are in mm),
moments are force·length when the force unit is set (``lbf*in``), else N·m, and the first mass
moments of the balancing variables are mass·length. A kind named in ``[units]`` or by
``--unit kind=unit`` keeps that unit.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.errors import did_you_mean
from screwkit.io.units import KIND_UNITS, UnitError, unit_factor
from screwkit.tables import SI_LABELS

#: kinds a table can show in a unit of the user's choice
DISPLAY_KINDS = ("length", "angle", "time", "mass", "force", "moment", "inertia", "velocity",
                 "acceleration", "angular_velocity", "angular_acceleration", "mass_moment")
SYSTEMS = ("spec", "si")


@dataclass(frozen=True)
class DisplayUnits:
    """The unit (``labels[kind]``) and the SI value of one such unit (``factors[kind]``) of
    every kind in :data:`DISPLAY_KINDS`; other kinds (ratios, percentages, flags) are shown as
    they are."""

    labels: Mapping[str, str]
    factors: Mapping[str, float]

    def unit_of(self, kind: str) -> tuple[str, float]:
        """(label, SI value of one unit) of ``kind``; what :class:`screwkit.tables.ResultTable`
        asks for."""
        if kind in self.labels:
            return self.labels[kind], self.factors[kind]
        return SI_LABELS.get(kind, ""), 1.0

    def label(self, kind: str) -> str:
        """The unit as text (ASCII, as in CSV headers): ``deg/s^2``, ``N*m``."""
        return self.unit_of(kind)[0]

    def pretty(self, kind: str) -> str:
        """The unit for plots and terminals: ``deg/s²``, ``N·m``."""
        return pretty_unit(self.label(kind))

    def show(self, kind: str, si: Any) -> Any:
        """SI value(s) of ``kind`` (a number or an array) in the display unit."""
        factor = self.unit_of(kind)[1]
        if isinstance(si, np.ndarray):
            return si / factor
        return float(si) / factor

    def as_dict(self) -> dict[str, str]:
        return dict(self.labels)

    def describe(self) -> str:
        """One line: ``angles in deg (deg/s, deg/s^2), lengths in mm (mm/s, mm/s^2), …``."""
        lb = self.labels
        return (f"angles in {lb['angle']} ({lb['angular_velocity']}, "
                f"{lb['angular_acceleration']}), lengths in {lb['length']} ({lb['velocity']}, "
                f"{lb['acceleration']}), forces in {lb['force']}, moments in {lb['moment']}, "
                f"masses in {lb['mass']}")

    @property
    def is_si(self) -> bool:
        return all(math.isclose(f, 1.0, rel_tol=1e-15) for f in self.factors.values())


def pretty_unit(text: str) -> str:
    """``kg*m^2`` → ``kg·m²``: powers as superscripts, products with a middle dot."""
    for power, sup in (("^-1", "⁻¹"), ("^-2", "⁻²"), ("**2", "²"), ("**3", "³"), ("^2", "²"),
                       ("^3", "³"), ("^4", "⁴")):
        text = text.replace(power, sup)
    return text.replace("*", "·")


def parse_unit_overrides(items: Iterable[str]) -> dict[str, str]:
    """``["length=mm", "angle=deg"]`` → ``{"length": "mm", "angle": "deg"}``, each unit checked
    against its kind; a :class:`UnitError` naming the item otherwise."""
    out: dict[str, str] = {}
    for item in items:
        kind, sep, unit = item.partition("=")
        kind, unit = kind.strip(), unit.strip()
        if not sep or not kind or not unit:
            raise UnitError(f"--unit {item!r}: write kind=unit, e.g. --unit length=mm or "
                            f"--unit angle=deg; the kinds are {', '.join(DISPLAY_KINDS)}")
        if kind == "torque":  # the [units] name of a moment (e.g. the drive's torques)
            kind = "moment"
        if kind not in DISPLAY_KINDS:
            raise UnitError(f"--unit {item!r}: unknown kind {kind!r}; "
                            f"{did_you_mean(kind, DISPLAY_KINDS)}the kinds are "
                            f"{', '.join(DISPLAY_KINDS)}")
        try:
            unit_factor(unit, kind)
        except UnitError as exc:
            raise UnitError(f"--unit {item!r}: {exc}") from None
        out[kind] = unit
    return out


def display_units(spec_units: Mapping[str, str] | None = None, *, system: str = "spec",
                  overrides: Mapping[str, str] | None = None) -> DisplayUnits:
    """The units tables and plots use (module docstring): ``system="spec"`` starts from the
    spec's ``[units]`` table (``spec_units``), ``"si"`` from SI; ``overrides`` (kind → unit, from
    ``--unit``) win over both."""
    if system not in SYSTEMS:
        raise UnitError(f"--units {system!r}: choose spec (the spec's [units], the default) "
                        "or si")
    base = {k: v for k, v in (spec_units or {}).items()
            if system == "spec" and k in KIND_UNITS and k != "dimensionless"}
    if "torque" in base and "moment" not in base:  # [units] torque (the drive's) is a moment
        base["moment"] = base["torque"]
    for kind in overrides or {}:
        if kind not in DISPLAY_KINDS:
            raise UnitError(f"unknown kind {kind!r} in the unit overrides; "
                            f"{did_you_mean(kind, DISPLAY_KINDS)}the kinds are "
                            f"{', '.join(DISPLAY_KINDS)}")
    base.update(overrides or {})
    length = base.get("length", "m")
    angle = base.get("angle", "rad")
    mass = base.get("mass", "kg")
    force = base.get("force", "N")
    derived = {
        "length": length, "angle": angle, "time": base.get("time", "s"), "mass": mass,
        "force": force,
        "moment": f"{force}*{length}" if "force" in base else "N*m",
        "inertia": "kg*m^2",
        "velocity": f"{length}/s", "acceleration": f"{length}/s^2",
        "angular_velocity": f"{angle}/s", "angular_acceleration": f"{angle}/s^2",
        "mass_moment": f"{mass}*{length}",
    }
    labels = {k: base.get(k, derived[k]) for k in DISPLAY_KINDS}
    return DisplayUnits(labels, {k: unit_factor(v, k) for k, v in labels.items()})


SI = display_units(system="si")
