"""Tolerance analysis of a spec (docs/sweeps.md, "Tolerance analysis"): the first-order
sensitivity of every output variable over the cycle to every toleranced value, exact from the
loop's screw Jacobian (:mod:`screwkit.kinematics.analysis.sensitivity`), and the stack-ups

    worst case  Δy_wc  = Σ_k |∂y/∂x_k| t_k
    statistical Δy_rss = √(Σ_k (∂y/∂x_k t_k)²)

with ±t_k read as ±3σ of a normal scatter (so Δy_rss is the output's 3σ). The Monte Carlo
check (:mod:`screwkit.sweep.monte_carlo`) draws designs with those scatters on the sweep
engine and compares.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.quantity import QuantitySyntaxError, parse_quantity
from screwkit.io.spec import Spec, spec_from_data
from screwkit.kinematics.analysis.sensitivity import (
    SensitivityError,
    constants_derivative,
    joint_sensitivities,
    seed_aliases,
)
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.loop import Array
from screwkit.messages import listing
from screwkit.model.linkage import Linkage
from screwkit.pipeline import Pipeline
from screwkit.sweep.keys import SpecKey, SpecKeyError, spec_key, unit_of, with_values

_PLUS_MINUS = re.compile(r"^\s*(?:±|\+-|\+/-)\s*")


class ToleranceError(InputError):
    """A ``--tol`` that cannot be used; the message shows the right form."""


@dataclass(frozen=True)
class Tolerance:
    """One toleranced value: its key (with the unit its numbers are in), nominal value and
    tolerance ±t in that unit."""

    key: SpecKey
    nominal: float
    tolerance: float

    @property
    def sigma(self) -> float:
        """The standard deviation of the scatter: ±t is ±3σ."""
        return self.tolerance / 3.0


def parse_tolerance(text: str) -> tuple[str, float, str | None]:
    """``KEY=±T[unit]`` (also ``+-`` or ``+/-``) → (key, t, unit)."""
    key, sep, rest = text.partition("=")
    m = _PLUS_MINUS.match(rest)
    if not sep or not key.strip() or m is None:
        raise ToleranceError(f"--tol {text!r}: write KEY=±T with a unit or in the spec's units, "
                             "e.g. d2=±0.05mm or links.coupler.com[0]=+-0.1mm")
    value = rest[m.end():].strip()
    try:
        q = parse_quantity(value)
    except QuantitySyntaxError as exc:
        raise ToleranceError(f"--tol {text!r}: cannot read {value!r}: {exc}") from None
    if not q.magnitude > 0:
        raise ToleranceError(f"--tol {text!r}: a tolerance is a positive amount (±T)")
    return key.strip(), q.magnitude, unit_of(value)


def _nominal_number(data: dict[str, Any], spec: Spec, key: SpecKey) -> float:
    """The spec's value at ``key`` in the key's unit."""
    from screwkit.io.units import to_si
    from screwkit.sweep.keys import get_value

    raw = get_value(data, key.path)
    if raw is None:
        raise ToleranceError(f"--tol {key.text}: the spec does not give this value; write it "
                             "in the spec first")
    if key.kind is None or key.kind == "integer":
        raise ToleranceError(f"--tol {key.text}: only dimensions and other physical values "
                             "(lengths, angles …) can have a tolerance")
    if isinstance(raw, int | float) and not isinstance(raw, bool) and not key.written_unit:
        return float(raw)  # a bare number is in the key's unit already
    if isinstance(raw, str) and unit_of(raw) == key.unit:
        return parse_quantity(raw).magnitude
    si = to_si(raw, key.kind, spec.units.get(key.kind))
    return si / to_si(1.0, key.kind, key.unit)


def tolerance_texts(data: dict[str, Any], given: list[str] | None) -> list[str]:
    """The ``--tol`` options, or without any the spec's ``[tolerances]`` table (``KEY =
    "±T"`` per line) as the same ``KEY=±T`` texts."""
    if given:
        return list(given)
    table = data.get("tolerances") or {}
    return [f"{key}={value}" for key, value in table.items()]


def make_tolerances(data: dict[str, Any], spec: Spec, texts: list[str]) -> list[Tolerance]:
    """The ``--tol`` options as :class:`Tolerance` values (units checked, keys resolved)."""
    if not texts:
        raise ToleranceError("give at least one --tol KEY=±T (e.g. --tol d2=±0.05mm), or a "
                             "[tolerances] table in the spec")
    out = []
    expanded: list[tuple[str, float, str | None, str]] = []
    for text in texts:
        name, t, unit = parse_tolerance(text)
        if getattr(spec, "family", None) == "graph":  # joints.*.at: every hardpoint coordinate
            from screwkit.sweep.graph_tolerance import expand_keys

            expanded.extend((k, t, unit, text) for k in expand_keys(data, name))
        else:
            expanded.append((name, t, unit, text))
    for name, t, unit, text in expanded:
        try:
            key = spec_key(data, spec, name, None)
        except SpecKeyError as exc:
            raise ToleranceError(f"--tol {exc}") from None
        if unit is not None and key.kind is not None:
            from screwkit.io.units import UnitError, to_si

            try:  # the tolerance in the key's unit
                t = to_si(f"{t!r} {unit}", key.kind) / to_si(1.0, key.kind, key.unit)
            except UnitError as exc:
                raise ToleranceError(f"--tol {text!r}: {exc}") from None
        out.append(Tolerance(key, _nominal_number(data, spec, key), t))
    names = [tol.key.text for tol in out]
    if len(set(names)) != len(names):
        raise ToleranceError(f"--tol names a key more than once: {listing(names)}")
    return out


def rebuilt_linkage(data: dict[str, Any], path: str, key: SpecKey, value: float) -> Linkage:
    """The linkage of the spec with ``key`` set to ``value`` (in the key's unit)."""
    return spec_from_data(with_values(data, [(key.path, key.toml_value(value))]), path).linkage


@dataclass(frozen=True)
class FirstOrder:
    """Sensitivities and stack-ups of every output over the cycle: ``sensitivity[out][key]``
    (N,) in SI per unit of the key; ``worst_case[out]`` and ``rss[out]`` (N,) in SI."""

    inputs: Array
    outputs: list[str]
    nominal: dict[str, Array]
    sensitivity: dict[str, dict[str, Array]]
    worst_case: dict[str, Array]
    rss: dict[str, Array]
    freedom_of: dict[str, tuple[str, float]]  # output → (joint freedom, sign)
    kinds: dict[str, str] | None = None  # output → "angle"/"length" (a graph's named outputs)

    def kind(self, output: str) -> str:
        """``"angle"`` or ``"length"``: the output's kind."""
        if self.kinds is not None:
            return self.kinds[output]
        return "length" if self.freedom_of[output][0].endswith(".s") else "angle"


def output_names(linkage: Linkage, mode: ModeMotion, sens: dict[str, Array]) -> dict[str, tuple[str, float]]:
    """Outputs: every seed name that is ± a joint freedom, then every other scalar joint
    freedom; the inputs left out."""
    aliases = {n: a for n, a in seed_aliases(mode).items() if a[0] not in linkage.inputs}
    used = {a[0] for a in aliases.values()}
    out = dict(aliases)
    out.update({n: (n, 1.0) for n in sens if n not in used and n not in linkage.inputs})
    return out


def first_order(data: dict[str, Any], spec: Spec, path: str, tolerances: list[Tolerance],
                pipe: Pipeline) -> FirstOrder:
    """Sensitivities and stack-ups of the spec's ``[motion] mode`` (module docstring)."""
    mode = pipe.mode()
    lk = spec.linkage
    per_key: dict[str, dict[str, Array]] = {}
    for tol in tolerances:
        step = max(1e-3 * abs(tol.nominal), tol.tolerance)
        def rebuild(value: float, key: SpecKey = tol.key) -> Linkage:
            return rebuilt_linkage(data, path, key, value)

        try:
            d = constants_derivative(rebuild, tol.nominal, step)
        except (SensitivityError, ValueError) as exc:
            raise ToleranceError(f"--tol {tol.key.text}: cannot differentiate the mechanism "
                                 f"near {tol.nominal:g} ± {step:g} {tol.key.unit or ''}: {exc}"
                                 ) from None
        if not np.any(d.vector()):
            raise ToleranceError(f"--tol {tol.key.text}: this value does not change the loop's "
                                 "geometry, so the motion does not depend on it (tolerance "
                                 "analysis covers [dimensions] and [[joints]])")
        per_key[tol.key.text] = joint_sensitivities(lk, mode, d)
    first = next(iter(per_key.values()))
    outs = output_names(lk, mode, first)
    sens = {o: {k: sign * v[f] for k, v in per_key.items()} for o, (f, sign) in outs.items()}
    tol_of = {t.key.text: t.tolerance for t in tolerances}
    worst = {o: np.sum([np.abs(s[k]) * tol_of[k] for k in s], axis=0) for o, s in sens.items()}
    rss = {o: np.sqrt(np.sum([(s[k] * tol_of[k]) ** 2 for k in s], axis=0))
           for o, s in sens.items()}
    x = np.asarray(pipe.motion.input_values, dtype=float)
    nominal = {o: np.asarray(mode.variables[o], dtype=float) for o in outs}
    return FirstOrder(x, list(outs), nominal, sens, worst, rss, outs)


def summary_rows(fo: FirstOrder, tolerances: list[Tolerance]) -> list[dict[str, Any]]:
    """Per output: the largest worst-case and RSS deviation over the cycle, where, and the
    key contributing most there."""
    rows = []
    for o in fo.outputs:
        wc = fo.worst_case[o]
        if not np.isfinite(wc).any():
            continue
        i = int(np.nanargmax(wc))
        contrib = {t.key.text: abs(float(fo.sensitivity[o][t.key.text][i])) * t.tolerance
                   for t in tolerances}
        rows.append({"output": o, "max_worst_case": float(wc[i]),
                     "max_rss": float(np.nanmax(fo.rss[o])), "at_input": float(fo.inputs[i]),
                     "dominant": max(contrib, key=lambda k: contrib[k]),
                     "contributions": contrib})
    return rows


def tolerance_document(spec_path: Path, spec: Spec, tolerances: list[Tolerance],
                       fo: FirstOrder, monte_carlo: dict[str, Any] | None) -> dict[str, Any]:
    """The JSON document of ``screwkit tolerance`` (SI units; docs/sweeps.md)."""
    return {
        "spec": str(spec_path), "mechanism": spec.name, "mode": spec.mode,
        "units": {"outputs": "rad or m", "sensitivity": "output SI unit per unit of the key",
                  "tolerances": "the key's unit"},
        "convention": "±t is ±3σ; rss is the output's 3σ; worst_case adds every |∂y/∂x|·t",
        "tolerances": [{"key": t.key.text, "unit": t.key.unit, "nominal": t.nominal,
                        "tolerance": t.tolerance} for t in tolerances],
        "input": fo.inputs,
        "outputs": {o: {"joint_freedom": fo.freedom_of[o][0], "kind": fo.kind(o),
                        "nominal": fo.nominal[o],
                        "sensitivity": fo.sensitivity[o], "worst_case": fo.worst_case[o],
                        "rss": fo.rss[o]} for o in fo.outputs},
        "summary": summary_rows(fo, tolerances),
        "monte_carlo": monte_carlo,
    }
