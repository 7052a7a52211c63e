"""The design a studio edits: the spec file it was started with, the values of that spec a page
may change (every dimension of a family, every length, twist, offset and pitch of a joint
list, and ``[motion] mode``; a graph spec's hardpoints and masses, :mod:`screwkit.studio.
graph`), and the spec with new values, loaded exactly as ``screwkit analyze`` loads a file
(:func:`~screwkit.io.spec.spec_from_data`, or :func:`~screwkit.io.mechanism_spec.
graph_spec_from_data` for a graph), so every number the studio shows is the number the CLI
prints for a spec holding those values (docs/studio.md).

Values are held in the unit the spec writes them in (the unit written with the value, else the
``[units]`` default of its kind, else SI): a page shows and sends those numbers. Saving
replaces only the changed values in the file's own TOML document (tomlkit), so its comments,
order and layout stay as they were.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from screwkit.errors import InputError
from screwkit.io.spec import Spec, spec_from_data
from screwkit.io.toml_file import read_toml
from screwkit.kinematics.registry import family
from screwkit.sweep.keys import SpecKey, get_value, spec_key, with_values

#: the fields of a ``[[joints]]`` entry a studio offers as dimensions (docs/spec-format.md)
JOINT_FIELDS = ("length", "twist", "offset", "pitch")
#: the half-width of an angle's slider range, degrees
ANGLE_HALF_RANGE_DEG = 90.0


class StudioError(InputError):
    """A value a page sent that the design cannot take (the message says which and why)."""


@dataclass(frozen=True)
class Dimension:
    """One value of the spec a page may change: its key (``dimensions.d2``,
    ``joints[1].twist``), its kind, the unit its numbers are in, its value in the file and the
    default range of its slider (same unit)."""

    key: SpecKey
    value: float
    low: float
    high: float

    @property
    def name(self) -> str:
        return self.key.text

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "kind": self.key.kind, "unit": self.key.unit or "",
                "value": self.value, "low": self.low, "high": self.high,
                "step": (self.high - self.low) / 1000.0}


def _number(data: dict[str, Any], spec: Spec, key: SpecKey) -> float:
    """The value of ``key`` in the spec's tables in the key's unit (the unit its numbers are
    in); 0 for a value the file leaves to its default."""
    from screwkit.io.units import to_si

    raw = get_value(data, key.path)
    if raw is None:
        return 0.0
    if key.kind is None:
        return float(raw)
    value = spec.quantity(raw, key.kind, key.text) / to_si(1.0, key.kind, key.unit)
    return float(f"{value:.12g}")  # "3.0 in" reads back as 3.0, not 2.9999999999999996


def _ranges(spec: Spec, keys: list[SpecKey], values: list[float]) -> list[tuple[float, float]]:
    """The default slider range of each value: an angle ± 90°, a length ± the larger of its own
    size and a quarter of the spec's largest length (so a zero offset can still move)."""
    from screwkit.io.units import to_si

    lengths = [abs(v) * to_si(1.0, "length", k.unit) for k, v in zip(keys, values, strict=True)
               if k.kind == "length"]
    scale = max(lengths, default=1.0) or 1.0
    out = []
    for k, v in zip(keys, values, strict=True):
        unit_si = to_si(1.0, k.kind, k.unit) if k.kind else 1.0
        if k.kind == "angle":
            half = math.radians(ANGLE_HALF_RANGE_DEG) / unit_si
        else:
            half = max(abs(v), 0.25 * scale / unit_si)
        out.append((v - half, v + half))
    return out


def editable_keys(data: dict[str, Any], spec: Spec) -> list[SpecKey]:
    """The spec's values a page may change: every dimension the file gives (a family), or
    every length, twist, offset and pitch of every joint the file gives (a joint list)."""
    keys: list[SpecKey] = []
    if family(spec.family).build is not None:
        for name in family(spec.family).dimensions:
            if name in spec.raw.dimensions:
                keys.append(spec_key(data, spec, f"dimensions.{name}", None))
        return keys
    for k, joint in enumerate(data.get("joints", [])):
        for field in JOINT_FIELDS:
            if field in joint:
                keys.append(spec_key(data, spec, f"joints[{k}].{field}", None))
    return keys


class Design:
    """The spec file a studio was started with, its editable values and how to rebuild and
    save the spec with new ones (module docstring)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.data = read_toml(self.path)
        self.text = self.path.read_text(encoding="utf-8")
        from screwkit.io.mechanism_spec import is_graph_spec

        #: a graph spec (studio/graph.py): its hardpoints and masses are its dimensions
        self.graph = is_graph_spec(self.data)
        self.spec = self.load_tables(self.data)
        if self.graph:
            from screwkit.studio.graph import graph_keys, graph_ranges

            keys = graph_keys(self.data, self.spec)
            values = [_number(self.data, self.spec, k) for k in keys]
            ranges = graph_ranges(self.spec, keys, values)
        else:
            keys = editable_keys(self.data, self.spec)
            values = [_number(self.data, self.spec, k) for k in keys]
            ranges = _ranges(self.spec, keys, values)
        self.dimensions = [Dimension(k, v, lo, hi) for k, v, (lo, hi)
                           in zip(keys, values, ranges, strict=True)]
        self.by_name = {d.name: d for d in self.dimensions}

    def load_tables(self, data: dict[str, Any]) -> Any:
        """The spec of these tables, validated as ``load_spec`` validates a file."""
        if self.graph:
            from screwkit.io.mechanism_spec import graph_spec_from_data

            return graph_spec_from_data(data, self.path)
        return spec_from_data(data, self.path)

    @property
    def initial_values(self) -> dict[str, float]:
        return {d.name: d.value for d in self.dimensions}

    @property
    def initial_mode(self) -> int:
        return int(self.spec.mode)

    def check(self, values: dict[str, float], mode: int) -> None:
        """A :class:`StudioError` unless every name is an editable value with a finite number
        and ``mode`` is a mode index (0 … 7)."""
        for name, v in values.items():
            if name not in self.by_name:
                raise StudioError(f"{name!r} is not a value this studio edits; the values are "
                                  f"{', '.join(self.by_name)}")
            if not math.isfinite(v):
                raise StudioError(f"{name}: give a finite number; got {v!r}")
        if not 0 <= mode < 8:
            raise StudioError(f"assembly mode {mode}: give a mode index 0 … 7")

    def changes(self, values: dict[str, float], mode: int) -> list[tuple[tuple[Any, ...], Any]]:
        """(key path, TOML value) of every value that differs from the file's."""
        self.check(values, mode)
        out: list[tuple[tuple[Any, ...], Any]] = []
        for name, v in values.items():
            d = self.by_name[name]
            if v != d.value:
                out.append((d.key.path, d.key.toml_value(v)))
        if mode != self.initial_mode and not self.graph:  # a graph spec has no [motion] mode
            out.append((("motion", "mode"), int(mode)))
        return out

    def spec_with(self, values: dict[str, float], mode: int) -> Any:
        """The spec with these values (in their units) and ``[motion] mode``, validated as
        ``screwkit analyze`` validates a file (a SpecError says what is wrong); a graph spec
        (a :class:`~screwkit.io.mechanism_spec.GraphSpec`) for a graph."""
        data = with_values(self.data, self.changes(values, mode))
        return self.load_tables(data)

    def text_with(self, values: dict[str, float], mode: int) -> str:
        """The spec file's text with these values, its comments and layout kept (tomlkit)."""
        import tomlkit

        doc = tomlkit.parse(self.text)
        for path, value in self.changes(values, mode):
            node: Any = doc
            for seg in path[:-1]:
                if isinstance(seg, str) and seg not in node:
                    node[seg] = tomlkit.table()
                node = node[seg]
            node[path[-1]] = value
        return tomlkit.dumps(doc)
