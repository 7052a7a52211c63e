"""Spec values named by a dotted key path into the spec file's TOML tables, e.g.
``dimensions.d2``, ``links.coupler.mass``, ``links.crank.com[0]``, ``motion.speed``,
``joints[2].length`` or ``balancing.links.rod.max_decrease`` (docs/sweeps.md, "Keys").

A bare dimension name (``d2``) means ``dimensions.d2``. A sweep reads a value's *kind*
(length, angle, mass …) from where the key sits in the spec format, and the *unit* its numbers
are in from the spec: the unit written in the spec's value (``d2 = "4.5 in"``), else the
``[units]`` default for the kind, else SI. Replacing a value never changes the file: the
overrides are applied to a copy of the parsed TOML tables, which is then validated exactly as
:func:`~screwkit.io.spec.load_spec` validates a file (:func:`~screwkit.io.spec.spec_from_data`).
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass
from typing import Any

from screwkit.errors import InputError
from screwkit.io.quantity import QuantitySyntaxError, parse_quantity
from screwkit.io.spec import Spec
from screwkit.io.units import SI_SYMBOL, UnitError, check_unit
from screwkit.kinematics.registry import family

Segment = str | int

_SEGMENT = re.compile(r"([A-Za-z_][A-Za-z0-9_\-]*)((?:\[\d+\])*)")
_INDEX = re.compile(r"\[(\d+)\]")


class SpecKeyError(InputError):
    """A key path that does not name a value of the spec (the message says which part)."""


def parse_key(text: str) -> tuple[Segment, ...]:
    """``"links.crank.com[0]"`` → ``("links", "crank", "com", 0)``; numeric segments
    (``com.0``) are list indices too."""
    if not text or len(text) > 200:
        raise SpecKeyError(f"a key is a dotted path such as dimensions.d2 or links.coupler.mass; "
                        f"got {text!r}")
    out: list[Segment] = []
    for part in text.split("."):
        if part.isdigit():
            out.append(int(part))
            continue
        m = _SEGMENT.fullmatch(part)
        if m is None:
            raise SpecKeyError(f"cannot read the key {text!r} at {part!r}: a key is names joined "
                            "by dots, with [k] for the k-th item of a list (joints[2].length)")
        out.append(m.group(1))
        out.extend(int(i) for i in _INDEX.findall(m.group(2)))
    return tuple(out)


def key_text(path: tuple[Segment, ...]) -> str:
    """The canonical text of a key path: ``joints[2].length``, ``links.crank.com[0]``."""
    text = ""
    for seg in path:
        text += f"[{seg}]" if isinstance(seg, int) else (f".{seg}" if text else seg)
    return text


def resolve_key(data: dict[str, Any], spec: Spec, text: str) -> tuple[Segment, ...]:
    """The key path of ``text`` in the spec: a bare dimension name means ``dimensions.<name>``;
    the path must lead through existing tables and lists to a value the spec has or may have."""
    path = parse_key(text)
    fam = family(spec.family)
    if len(path) == 1 and isinstance(path[0], str) and path[0] not in data and (
            path[0] in fam.dimensions or path[0] in spec.raw.dimensions):
        path = ("dimensions", path[0])
    node: Any = data
    for depth, seg in enumerate(path[:-1]):
        where = key_text(path[:depth + 1])
        if isinstance(seg, int):
            if not isinstance(node, list) or seg >= len(node):
                size = len(node) if isinstance(node, list) else 0
                raise SpecKeyError(f"{key_text(path)}: {key_text(path[:depth])} has no item "
                                f"[{seg}] (it has {size})")
            node = node[seg]
        else:
            if not isinstance(node, dict) or seg not in node:
                raise SpecKeyError(f"{key_text(path)}: the spec has no table [{where}]; a "
                                "sweep replaces values of the spec, so give that table in the "
                                "spec first")
            node = node[seg]
    last = path[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise SpecKeyError(f"{key_text(path)}: {key_text(path[:-1])} is not a list with an "
                            f"item [{last}]")
    elif not isinstance(node, dict):
        raise SpecKeyError(f"{key_text(path)}: {key_text(path[:-1])} is not a table")
    elif last not in node and not _may_add(path, spec):
        raise SpecKeyError(f"{key_text(path)}: the spec has no value there; give it in the "
                        "spec first (a sweep varies values the spec has, or optional "
                        "dimensions and [motion] values)")
    return path


def _may_add(path: tuple[Segment, ...], spec: Spec) -> bool:
    """Keys a sweep may set although the spec file leaves them out (they have defaults)."""
    if path[0] == "dimensions" and len(path) == 2:
        return str(path[1]) in family(spec.family).dimensions
    if path[0] == "motion" and len(path) == 2:
        return path[1] in ("start", "stop", "step", "speed", "acceleration", "mode")
    return path == ("gravity",)


def get_value(data: dict[str, Any], path: tuple[Segment, ...]) -> Any:
    """The value at ``path`` (``None`` where the spec leaves it to its default)."""
    node: Any = data
    for seg in path:
        try:
            node = node[seg]
        except (KeyError, IndexError, TypeError):
            return None
    return node


def with_values(data: dict[str, Any], values: list[tuple[tuple[Segment, ...], Any]]
                ) -> dict[str, Any]:
    """A deep copy of the TOML tables with each path set to its value."""
    out = copy.deepcopy(data)
    for path, value in values:
        node: Any = out
        for seg in path[:-1]:
            node = node[seg]
        node[path[-1]] = value
    return out


def key_kind(spec: Spec, path: tuple[Segment, ...]) -> str | None:
    """The quantity kind of the value at ``path`` (docs/spec-format.md), ``"integer"`` for a
    count or index, or ``None`` where the spec format does not fix one (e.g. keys of
    ``[balancing]`` and ``[synthesis]``, whose own tables read them)."""
    head = path[0]
    rate = spec.input_is_angle
    if head == "dimensions" and len(path) == 2:
        return family(spec.family).dimensions.get(str(path[1]))
    if head == "motion" and len(path) == 2:
        return {"start": "angle" if rate else "length", "stop": "angle" if rate else "length",
                "step": "angle" if rate else "length",
                "speed": "angular_velocity" if rate else "velocity",
                "acceleration": "angular_acceleration" if rate else "acceleration",
                "mode": "integer"}.get(str(path[1]))
    if head == "links" and len(path) >= 3:
        return {"mass": "mass", "weight": "force", "com": "length",
                "inertia": "inertia"}.get(str(path[2]))
    if head == "coupler_point" and len(path) == 2:
        return "length"
    if head == "gravity" and len(path) == 1:
        return "acceleration"
    if head == "joints" and len(path) == 3 and isinstance(path[1], int):
        if path[2] in ("length", "pitch"):
            return "length"
        if path[2] == "twist":
            return "angle"
        if path[2] == "offset":
            kind = spec.raw.joints[path[1]].kind if path[1] < len(spec.raw.joints) else "R"
            return "angle" if kind == "P" else "length"
    return None


def unit_of(value: Any) -> str | None:
    """The unit written in a spec value (``"4.5 in"`` → ``"in"``), ``None`` for a bare number."""
    if not isinstance(value, str):
        return None
    try:
        parsed = parse_quantity(value)
    except QuantitySyntaxError:
        return None
    if not parsed.units:
        return None
    return "*".join(name if p == 1 else f"{name}^{p}" for name, p in parsed.units)


@dataclass(frozen=True)
class SpecKey:
    """One value of a spec a sweep or a tolerance replaces: its path, its kind and the unit
    its numbers are given in (``None``: plain numbers, for a value without a kind)."""

    path: tuple[Segment, ...]
    kind: str | None
    unit: str | None
    written_unit: bool  # the value is written with its unit ("4.6 in"), not as a bare number
    label: str | None = None  # the name by names of a graph spec's key (joints.LB.at[0])

    @property
    def text(self) -> str:
        return self.label if self.label is not None else key_text(self.path)

    @property
    def column(self) -> str:
        """The column of a result table holding this key's values: ``dimensions.d2 [in]``."""
        return f"{self.text} [{self.unit}]" if self.unit else self.text

    def toml_value(self, number: float) -> Any:
        """The value to put into the TOML tables for ``number`` (in :attr:`unit`)."""
        if self.kind == "integer":
            return int(number)
        if self.written_unit:
            return f"{float(number)!r} {self.unit}"
        return float(number)


def spec_key(data: dict[str, Any], spec: Spec, text: str, given_unit: str | None) -> SpecKey:
    """The :class:`SpecKey` of ``text``; ``given_unit`` is the unit the user wrote with the
    numbers (checked against the key's kind), else the spec's unit for the key is used."""
    label = None
    if getattr(spec, "family", None) == "graph":  # io.mechanism_spec.GraphSpec
        from screwkit.sweep.graph_keys import graph_key

        path, kind, label = graph_key(data, spec.input_is_angle, text)
    else:
        path = resolve_key(data, spec, text)
        kind = key_kind(spec, path)
    name = label or key_text(path)
    if kind == "integer":
        if given_unit:
            raise SpecKeyError(f"{name} is a whole number (an index); give it without a unit")
        return SpecKey(path, kind, None, False, label)
    if given_unit is not None:
        if kind is not None:
            try:
                check_unit(given_unit, kind)
            except UnitError as exc:
                raise SpecKeyError(f"{name}: {exc}") from None
        return SpecKey(path, kind, given_unit, True, label)
    written = unit_of(get_value(data, path))
    if written is not None:
        return SpecKey(path, kind, written, True, label)
    if kind is None:
        return SpecKey(path, None, None, False, label)
    default = spec.units.get(kind)
    return SpecKey(path, kind, default or SI_SYMBOL[kind] or None, False, label)
