"""The designs of a sweep: which spec values vary and the value of each in every design
(docs/sweeps.md, "Designs").

``--vary KEY=START:STOP:COUNT`` gives COUNT equally spaced values from START to STOP (both
included), ``--vary KEY=V1,V2,…`` a list (one value fixes the key); a grid takes every combination (the first ``--vary``
varies slowest, the last fastest). ``--sample lhs:N`` draws N designs by Latin hypercube
sampling over the ``KEY=START:STOP`` box (McKay, Beckman & Conover 1979; scipy.stats.qmc) with a
reproducible seed. Numbers carry the unit written with them (``d2=4in:5in:11``) or the spec's
unit for the key (:mod:`screwkit.sweep.keys`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.quantity import QuantitySyntaxError, parse_quantity
from screwkit.io.spec import Spec
from screwkit.messages import listing
from screwkit.sweep.keys import SpecKey, SpecKeyError, spec_key, unit_of

#: the most designs one sweep may have (a typing mistake in COUNT should not fill the disk)
MAX_DESIGNS = 10_000_000


class DesignError(InputError):
    """A ``--vary`` or ``--sample`` that cannot be read; the message shows the right form."""


@dataclass(frozen=True)
class VaryText:
    """One ``--vary`` as read: the key, then START/STOP/COUNT or a list, and the unit."""

    key: str
    start: float | None = None
    stop: float | None = None
    count: int | None = None
    values: tuple[float, ...] | None = None
    unit: str | None = None


def _numbers(items: list[str], where: str) -> tuple[list[float], str | None]:
    numbers, units = [], set()
    for item in items:
        try:
            q = parse_quantity(item.strip())
        except QuantitySyntaxError as exc:
            raise DesignError(f"{where}: cannot read {item.strip()!r}: {exc}") from None
        numbers.append(q.magnitude)
        unit = unit_of(item.strip())
        if unit is not None:
            units.add(unit)
    if len(units) > 1:
        raise DesignError(f"{where}: give every value in one unit (got {listing(sorted(units))})")
    return numbers, (units.pop() if units else None)


def parse_vary(text: str) -> VaryText:
    """Read ``KEY=START:STOP:COUNT``, ``KEY=START:STOP`` (Latin hypercube) or
    ``KEY=V1,V2,…``."""
    where = f"--vary {text!r}"
    key, sep, rest = text.partition("=")
    if not sep or not key.strip() or not rest.strip():
        raise DesignError(f"{where}: write KEY=START:STOP:COUNT (e.g. dimensions.d2=4in:5in:11), "
                          "KEY=START:STOP with --sample lhs:N, or KEY=V1,V2,V3")
    key = key.strip()
    if "," in rest or ":" not in rest:
        values, unit = _numbers(rest.split(","), where)
        return VaryText(key, values=tuple(values), unit=unit)
    parts = rest.split(":")
    if len(parts) not in (2, 3):
        raise DesignError(f"{where}: give START:STOP:COUNT (a grid), START:STOP (with --sample "
                          "lhs:N) or a list V1,V2,V3")
    (start, stop), unit = _numbers(parts[:2], where)
    count = None
    if len(parts) == 3:
        c = parts[2].strip()
        if not c.isdigit() or not 1 <= int(c) <= MAX_DESIGNS:
            raise DesignError(f"{where}: COUNT must be a whole number from 1 to {MAX_DESIGNS}; "
                              f"got {c!r}")
        count = int(c)
    return VaryText(key, start, stop, count, None, unit)


@dataclass(frozen=True)
class DesignSet:
    """The designs of a sweep: ``values[i, k]`` is key ``keys[k]`` of design ``i`` in that
    key's unit (:attr:`SpecKey.unit`); ``sampling`` says how they were drawn."""

    keys: tuple[SpecKey, ...]
    values: np.ndarray
    sampling: str

    def __len__(self) -> int:
        return int(self.values.shape[0])

    @property
    def columns(self) -> list[str]:
        return [k.column for k in self.keys]

    def overrides(self, index: int) -> list[tuple[tuple[str | int, ...], Any]]:
        """(path, TOML value) of every key in design ``index``."""
        return [(k.path, k.toml_value(v)) for k, v in zip(self.keys, self.values[index],
                                                            strict=True)]

    def fingerprint(self) -> str:
        """A hash of the keys, units and every value (part of a sweep's checkpoint key)."""
        h = hashlib.sha256(json.dumps([[k.text, k.unit, k.written_unit] for k in self.keys])
                           .encode())
        h.update(np.ascontiguousarray(self.values, dtype="<f8").tobytes())
        h.update(self.sampling.encode())
        return h.hexdigest()


def _keys(data: dict[str, Any], spec: Spec, varies: list[VaryText]) -> list[SpecKey]:
    keys = []
    for v in varies:
        try:
            keys.append(spec_key(data, spec, v.key, v.unit))
        except SpecKeyError as exc:
            raise DesignError(f"--vary {exc}") from None
    texts = [k.text for k in keys]
    repeated = sorted({t for t in texts if texts.count(t) > 1})
    if repeated:
        raise DesignError(f"--vary names {listing(repeated)} more than once; give each key once")
    return keys


def _grid_values(v: VaryText, key: SpecKey) -> np.ndarray:
    if v.values is not None:
        values = np.array(v.values, dtype=float)
    elif v.count is None:
        raise DesignError(f"--vary {v.key}: a grid needs COUNT (START:STOP:COUNT), or use "
                          "--sample lhs:N for START:STOP ranges")
    else:
        assert v.start is not None and v.stop is not None
        values = np.linspace(v.start, v.stop, v.count)
    if key.kind == "integer" and not np.all(values == np.round(values)):
        raise DesignError(f"--vary {v.key}: {key.text} takes whole numbers; give values that "
                          "are (e.g. 0,1)")
    return values


def grid_designs(data: dict[str, Any], spec: Spec, varies: list[VaryText]) -> DesignSet:
    """Every combination of the ``--vary`` values (first key slowest)."""
    keys = _keys(data, spec, varies)
    axes = [_grid_values(v, k) for v, k in zip(varies, keys, strict=True)]
    total = int(np.prod([a.size for a in axes], dtype=float))
    if total > MAX_DESIGNS:
        raise DesignError(f"the grid has {total} designs; at most {MAX_DESIGNS} (use fewer "
                          "values or --sample lhs:N)")
    mesh = np.meshgrid(*axes, indexing="ij")
    values = np.stack([m.reshape(-1) for m in mesh], axis=1)
    return DesignSet(tuple(keys), values, "grid")


def lhs_designs(data: dict[str, Any], spec: Spec, varies: list[VaryText], n: int,
                seed: int) -> DesignSet:
    """``n`` designs by Latin hypercube sampling of the ``KEY=START:STOP`` box (scipy's
    ``qmc.LatinHypercube`` with ``seed``: the same seed gives the same designs)."""
    from scipy.stats import qmc

    if not 1 <= n <= MAX_DESIGNS:
        raise DesignError(f"--sample lhs:N: N must be from 1 to {MAX_DESIGNS}; got {n}")
    keys = _keys(data, spec, varies)
    for v, k in zip(varies, keys, strict=True):
        if v.values is not None or v.count is not None or v.start is None:
            raise DesignError(f"--vary {v.key}: with --sample lhs:N give a range START:STOP "
                              "(no COUNT, no list)")
        if k.kind == "integer":
            raise DesignError(f"--vary {v.key}: {k.text} is a whole number; Latin hypercube "
                              "sampling draws real values: vary it on a grid instead")
    lo = np.array([v.start for v in varies], dtype=float)
    hi = np.array([v.stop for v in varies], dtype=float)
    unit = qmc.LatinHypercube(d=len(varies), seed=np.random.default_rng(seed)).random(n)
    return DesignSet(tuple(keys), lo + unit * (hi - lo), f"lhs:{n} seed {seed}")


def parse_sample(text: str | None) -> int | None:
    """``--sample``: ``None``/``grid`` → None (a grid), ``lhs:N`` → N."""
    if text is None or text.strip() == "grid":
        return None
    kind, _, n = text.partition(":")
    if kind.strip() != "lhs" or not n.strip().isdigit():
        raise DesignError(f"--sample {text!r}: give grid or lhs:N (N designs by Latin hypercube "
                          "sampling, e.g. lhs:200)")
    return int(n)


def make_designs(data: dict[str, Any], spec: Spec, vary: list[str], sample: str | None,
                 seed: int) -> DesignSet:
    """The designs of ``--vary`` options and ``--sample`` (docs/sweeps.md)."""
    if not vary:
        raise DesignError("give at least one --vary KEY=START:STOP:COUNT (e.g. "
                          "--vary dimensions.d2=4in:5in:11)")
    varies = [parse_vary(v) for v in vary]
    n = parse_sample(sample)
    if n is None:
        return grid_designs(data, spec, varies)
    return lhs_designs(data, spec, varies, n, seed)
