"""The ``[balancing]`` table of a spec file (validated with pydantic) and
:func:`balance_from_spec` (docs/balancing.md, "Spec file").

Lengths and masses take the spec's units (``[units]``) or explicit unit strings."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StrictBool, ValidationError

from screwkit.balancing.balance import prepare, solve_setup
from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import MEASURES, default_normalisation
from screwkit.balancing.problem import check_weights
from screwkit.balancing.result import BalanceResult
from screwkit.balancing.variables import (
    POINT_MASS_NAMES,
    VariableBlock,
    counterweight_variables,
    point_mass_variables,
)

Value = float | int | str
SumRule = Literal["equal", "at_most", "free"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class LinkVariablesTable(_Strict):
    variables: list[str] = Field(default_factory=lambda: list(POINT_MASS_NAMES))
    split: list[float] | None = None
    max_decrease: float = 0.05
    max_increase: float | None = None
    pair_sum: SumRule = "equal"
    link_mass: SumRule = "free"


class CounterweightTable(_Strict):
    name: str
    link: str
    mass_max: Value
    mass_min: Value = 0.0
    at: list[Value] | None = None
    box_min: list[Value] | None = None
    box_max: list[Value] | None = None


class NormalisationTable(_Strict):
    mass: Value | None = None
    length: Value | None = None
    speed: Value | None = None
    bearing_length: Value | None = None


class EllipsoidTable(_Strict):
    centre: list[Value]
    semi_axes: list[Value]


class BoundTable(_Strict):
    ellipsoids: dict[str, EllipsoidTable]


class ParetoTable(_Strict):
    measures: list[str] = Field(default_factory=lambda: ["F", "T", "T0"])
    divisions: int = 4


class BalancingTable(_Strict):
    weights: dict[str, float] = Field(default_factory=lambda: {k: 1.0 for k in MEASURES})
    gravity: StrictBool = False
    links: dict[str, LinkVariablesTable] = Field(default_factory=dict)
    counterweights: list[CounterweightTable] = Field(default_factory=list)
    normalisation: NormalisationTable = Field(default_factory=NormalisationTable)  # type: ignore[arg-type]
    bound: BoundTable | None = None
    pareto: ParetoTable | None = None


def balancing_table(spec: Any) -> BalancingTable:
    """The validated ``[balancing]`` table of a loaded spec (``SpecError``-style messages)."""
    raw = spec.raw.balancing
    if raw is None:
        raise BalancingError(f"{spec.path}: no [balancing] table; see docs/balancing.md")
    try:
        return BalancingTable.model_validate(raw)
    except ValidationError as exc:
        lines = [f"{spec.path}: the [balancing] table is not valid:"]
        for err in exc.errors():
            loc = ".".join(str(p) for p in err["loc"])
            msg = ("unknown key (see docs/balancing.md)" if err["type"] == "extra_forbidden"
                   else str(err["msg"]).removeprefix("Value error, "))
            lines.append(f"  [balancing{'.' + loc if loc else ''}] {msg}")
        raise BalancingError("\n".join(lines)) from exc


def _si(spec: Any, value: Any, kind: str, key: str) -> float:
    return float(spec._si(value, kind, f"balancing.{key}"))


def blocks_from_table(spec: Any, table: BalancingTable) -> list[VariableBlock]:
    lk = spec.linkage
    names = [link.name for link in lk.links]
    blocks: list[VariableBlock] = []
    for link, t in table.links.items():
        if link not in names:
            raise BalancingError(f"{spec.path}: [balancing.links.{link}] no moving link named "
                                 f"{link!r}; the links are {names}")
        if not t.variables:
            raise BalancingError(f"{spec.path}: [balancing.links.{link}] has no variables; list "
                                 f"some of {list(POINT_MASS_NAMES)} or remove the table")
        try:
            blocks.append(point_mass_variables(
                lk, link, split=t.split, max_decrease=t.max_decrease,
                max_increase=t.max_increase, pair_sum=t.pair_sum, link_mass=t.link_mass,
                variables=t.variables))
        except BalancingError as exc:
            raise BalancingError(f"{spec.path}: [balancing.links.{link}] {exc}") from exc
    for k, cw in enumerate(table.counterweights):
        key = f"counterweights[{k}]"
        if (cw.at is None) == (cw.box_min is None or cw.box_max is None):
            raise BalancingError(f"{spec.path}: [balancing.{key}] give either at = [x, y, z] or "
                                 "both box_min and box_max")
        m_max = _si(spec, cw.mass_max, "mass", key + ".mass_max")
        m_min = _si(spec, cw.mass_min, "mass", key + ".mass_min")
        try:
            if cw.at is not None:
                at = [_si(spec, v, "length", key + ".at") for v in cw.at]
                blocks.append(counterweight_variables(lk, cw.link, cw.name, mass_max=m_max,
                                                      mass_min=m_min, at=at))
            else:
                lo = [_si(spec, v, "length", key + ".box_min") for v in cw.box_min or []]
                hi = [_si(spec, v, "length", key + ".box_max") for v in cw.box_max or []]
                blocks.append(counterweight_variables(lk, cw.link, cw.name, mass_max=m_max,
                                                      mass_min=m_min, box=(lo, hi)))
        except BalancingError as exc:
            raise BalancingError(f"{spec.path}: [balancing.{key}] {exc}") from exc
    if not blocks:
        raise BalancingError(f"{spec.path}: [balancing] has no design variables; add "
                             "[balancing.links.<link>] or [[balancing.counterweights]]")
    return blocks


def _check_assembles(spec: Any, mode_motion: Any) -> None:
    """Balancing needs the whole cycle: name, in the spec's units, the inputs where the mode
    does not assemble and say which [motion] keys to change."""
    ok = np.asarray(mode_motion.assembles) & ~np.asarray(mode_motion.singular)
    if ok.all():
        return
    x = np.asarray(spec.inputs, dtype=float).reshape(len(ok), -1)[:, 0]
    bad = np.degrees(x[~ok]) if spec.input_is_angle else x[~ok]
    unit = "deg" if spec.input_is_angle else "m"
    shown = ", ".join(f"{v:.6g}" for v in bad[:8]) + (" …" if bad.size > 8 else "")
    raise BalancingError(
        f"{spec.path}: [motion] mode {spec.mode} does not assemble (or is singular) at "
        f"{int(bad.size)} of {ok.size} inputs ({shown} {unit}); balancing needs loads over the "
        "whole sweep. Change [motion] start/stop/step to a range where the mode assembles, choose "
        "another [motion] mode, or change the dimensions so that the linkage turns fully")


def balance_from_spec(spec: Any, *, mode_motion: Any | None = None) -> BalanceResult:
    """Run the balancing described by a loaded spec's ``[balancing]`` table (kinematics of
    ``[motion]``, assembly mode ``[motion].mode``). ``mode_motion`` skips the kinematics."""
    from screwkit.kinematics.analysis import mode_motion as spec_mode_motion

    table = balancing_table(spec)
    try:
        check_weights(table.weights)  # before any dynamics: a bad weight is named at once
    except BalancingError as exc:
        raise BalancingError(f"{spec.path}: [balancing.weights] {exc}") from None
    blocks = blocks_from_table(spec, table)
    lk = spec.linkage
    if mode_motion is None:
        try:
            mode_motion = spec_mode_motion(lk, spec.inputs, spec.speed, spec.acceleration, spec.mode)
        except ValueError as exc:
            raise BalancingError(f"{spec.path}: [motion.mode]: {exc}") from exc
    _check_assembles(spec, mode_motion)
    nt = table.normalisation
    speed = spec.speed if nt.speed is None else _si(spec, nt.speed, "angular_velocity",
                                                    "normalisation.speed")
    norm = default_normalisation(
        lk, mode_motion, speed,
        mass=None if nt.mass is None else _si(spec, nt.mass, "mass", "normalisation.mass"),
        length=None if nt.length is None else _si(spec, nt.length, "length",
                                                  "normalisation.length"),
        bearing_length=None if nt.bearing_length is None else _si(
            spec, nt.bearing_length, "length", "normalisation.bearing_length"))
    gravity = None
    if table.gravity:
        gravity = (spec.gravity_magnitude or 9.80665) * np.asarray(spec.gravity_direction,
                                                                   dtype=float)
    setup = prepare(lk, mode_motion, blocks, speed=speed, gravity=gravity, normalisation=norm,
                    inputs=spec.inputs)
    result = solve_setup(setup, table.weights)
    if table.bound is not None:
        from screwkit.balancing.sdp import redistribution_bound

        ell = {}
        for link, e in table.bound.ellipsoids.items():
            key = f"bound.ellipsoids.{link}"
            if len(e.centre) != 3 or len(e.semi_axes) != 3:
                raise BalancingError(f"{spec.path}: [balancing.{key}] centre and semi_axes need "
                                     "3 values each")
            ell[link] = ([_si(spec, v, "length", key) for v in e.centre],
                         [_si(spec, v, "length", key) for v in e.semi_axes])
        b = redistribution_bound(setup, table.weights, ell)
        result.extras["redistribution_bound"] = {
            "measures_before": b.measures_before, "measures_after": b.measures_after,
            "mass_properties": {k: {"mass": v.mass, "com": v.com.tolist(),
                                    "inertia": v.inertia.tolist()}
                                for k, v in b.mass_properties_after.items()}}
    if table.pareto is not None:
        from screwkit.balancing.pareto import pareto_front

        front = pareto_front(setup, table.pareto.measures, table.pareto.divisions)
        result.extras["pareto"] = {"measures": list(front.names),
                                   "weights": front.weights.tolist(),
                                   "values": front.measures.tolist(),
                                   "efficient": front.efficient.tolist()}
        result.extras["_pareto_front"] = front
    return result
