"""The ``[balancing]`` table of a spec file: validated with pydantic and turned, once, into a typed
:class:`~screwkit.balancing.config.BalancingConfig` in SI units (docs/balancing.md, "Spec file").

Lengths and masses take the spec's units (``[units]``) or explicit unit strings. Every error
names the file and the key (:class:`BalancingConfigError`, a SpecError and a BalancingError)."""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictBool, ValidationError

from screwkit.balancing.balance import check_free_counterweights
from screwkit.balancing.config import BalancingConfig, NormalisationConfig
from screwkit.balancing.errors import BalancingError
from screwkit.balancing.measures import MEASURES
from screwkit.balancing.problem import check_weights
from screwkit.balancing.sdp import ellipsoid_row
from screwkit.balancing.variables import (
    POINT_MASS_NAMES,
    VariableBlock,
    counterweight_variables,
    moving_parts,
    part_word,
    point_mass_variables,
)
from screwkit.io.errors import SpecError
from screwkit.io.validation import Name
from screwkit.messages import listing

Value = float | int | str


#: most weightings a Pareto sweep may solve (each is one QP)
MAX_PARETO_WEIGHTINGS = 10_000


class BalancingConfigError(SpecError, BalancingError):
    """A ``[balancing]`` table that cannot be used; the message names the file and the key."""
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
    name: Name
    link: Name
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
    """The validated ``[balancing]`` table of a spec (messages name the file and the key)."""
    raw = spec.raw.balancing
    if raw is None:
        raise BalancingConfigError(f"{spec.path}: no [balancing] table; see docs/balancing.md")
    try:
        return BalancingTable.model_validate(raw)
    except ValidationError as exc:
        lines = [f"{spec.path}: the [balancing] table is not valid:"]
        for err in exc.errors():
            loc = ".".join(str(p) for p in err["loc"])
            msg = ("unknown key (see docs/balancing.md)" if err["type"] == "extra_forbidden"
                   else str(err["msg"]).removeprefix("Value error, "))
            lines.append(f"  [balancing{'.' + loc if loc else ''}] {msg}")
        raise BalancingConfigError("\n".join(lines)) from exc


def _subject(spec: Any) -> Any:
    """What the table's names refer to: a loop's Linkage (links) or a graph's Mechanism
    (bodies; ``[balancing.links.<body>]`` and a counterweight's ``link`` name a body)."""
    return spec.mechanism if getattr(spec, "family", None) == "graph" else spec.linkage


def _si(spec: Any, value: Any, kind: str, key: str) -> float:
    return float(spec.quantity(value, kind, f"balancing.{key}"))


def _link_blocks(spec: Any, table: BalancingTable) -> list[VariableBlock]:
    lk = _subject(spec)
    names = [link.name for link in moving_parts(lk)]
    blocks: list[VariableBlock] = []
    for link, t in table.links.items():
        if link not in names:
            word = part_word(lk)
            raise BalancingConfigError(f"{spec.path}: [balancing.links.{link}] no moving {word} "
                                       f"named {link!r}; the "
                                       f"{'bodies' if word == 'body' else 'links'} are {listing(names)}")
        if not t.variables:
            raise BalancingConfigError(f"{spec.path}: [balancing.links.{link}] has no variables; "
                                       f"list some of {listing(POINT_MASS_NAMES)} or remove the table")
        try:
            blocks.append(point_mass_variables(
                lk, link, split=t.split, max_decrease=t.max_decrease,
                max_increase=t.max_increase, pair_sum=t.pair_sum, link_mass=t.link_mass,
                variables=t.variables))
        except BalancingError as exc:
            raise BalancingConfigError(f"{spec.path}: [balancing.links.{link}] {exc}") from exc
    return blocks


def _counterweight_blocks(spec: Any, table: BalancingTable) -> list[VariableBlock]:
    lk = _subject(spec)
    blocks: list[VariableBlock] = []
    for k, cw in enumerate(table.counterweights):
        key = f"counterweights[{k}]"
        if (cw.at is None) == (cw.box_min is None or cw.box_max is None):
            raise BalancingConfigError(f"{spec.path}: [balancing.{key}] give either at = [x, y, z] "
                                       "or both box_min and box_max")
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
            raise BalancingConfigError(f"{spec.path}: [balancing.{key}] {exc}") from exc
    return blocks


def blocks_from_table(spec: Any, table: BalancingTable) -> list[VariableBlock]:
    """The design variables of a ``[balancing]`` table (point masses, then counterweights)."""
    blocks = _link_blocks(spec, table) + _counterweight_blocks(spec, table)
    if not blocks:
        raise BalancingConfigError(f"{spec.path}: [balancing] has no design variables; add "
                                   "[balancing.links.<link>] or [[balancing.counterweights]]")
    return blocks


def _bound(spec: Any, table: BalancingTable) -> dict[str, tuple[list[float], list[float]]] | None:
    if table.bound is None:
        return None
    ell = {}
    for link, e in table.bound.ellipsoids.items():
        key = f"bound.ellipsoids.{link}"
        if len(e.centre) != 3 or len(e.semi_axes) != 3:
            raise BalancingConfigError(f"{spec.path}: [balancing.{key}] centre and semi_axes "
                                       "need 3 values each")
        ell[link] = ([_si(spec, v, "length", key) for v in e.centre],
                     [_si(spec, v, "length", key) for v in e.semi_axes])
        _check_ellipsoid(spec, key, link, *ell[link])
    return ell


def _check_ellipsoid(spec: Any, key: str, link: str, centre: list[float],
                     semi_axes: list[float]) -> None:
    """The bound keeps the link inside its ellipsoid, so the link as it is must be inside it
    (checked at load: `validate` reports it)."""
    subject = _subject(spec)
    links = {lk.name: lk for lk in moving_parts(subject)}
    if link not in links:
        word = part_word(subject)
        raise BalancingConfigError(f"{spec.path}: [balancing.{key}] no {word} {link!r}; the "
                                   f"{'bodies' if word == 'body' else 'links'} are {listing(links)}")
    mass = links[link].mass
    if mass is None:
        return  # named by the dynamics' own check
    try:
        row = ellipsoid_row(centre, semi_axes)
    except BalancingError as exc:
        raise BalancingConfigError(f"{spec.path}: [balancing.{key}] {exc}") from None
    pi = mass.inertial_parameters()
    if row @ pi < -1e-9 * pi[0]:
        word = part_word(subject)
        frame = "the drawing's axes" if word == "body" else "the link's body frame"
        raise BalancingConfigError(
            f"{spec.path}: [balancing.{key}] the {word} {link!r} as it is does not lie inside "
            f"this ellipsoid (centre and semi-axes in {frame}, in the spec's length unit); "
            f"enlarge it or move its centre to the {word}'s centre of mass")


def balancing_config(spec: Any) -> BalancingConfig:
    """The ``[balancing]`` table of a loaded spec as a typed, SI :class:`BalancingConfig`."""
    table = balancing_table(spec)
    try:
        check_weights(table.weights)  # a bad weight is named at load, before any dynamics
    except BalancingError as exc:
        raise BalancingConfigError(f"{spec.path}: [balancing.weights] {exc}") from None
    nt = table.normalisation

    def optional(value: Any, kind: str, key: str) -> float | None:
        return None if value is None else _si(spec, value, kind, f"normalisation.{key}")

    norm = NormalisationConfig(
        mass=optional(nt.mass, "mass", "mass"), length=optional(nt.length, "length", "length"),
        speed=optional(nt.speed, "angular_velocity", "speed"),
        bearing_length=optional(nt.bearing_length, "length", "bearing_length"))
    pareto = None
    if table.pareto is not None:
        measures, divisions = table.pareto.measures, table.pareto.divisions
        if any(k not in MEASURES for k in measures) or len(measures) < 2:
            raise BalancingConfigError(f"{spec.path}: [balancing.pareto.measures] must be at "
                                       f"least two of {listing(MEASURES)}; got {listing(measures)}")
        if divisions < 1:
            raise BalancingConfigError(f"{spec.path}: [balancing.pareto.divisions] must be >= 1; "
                                       f"got {divisions}")
        points = math.comb(divisions + len(measures) - 1, len(measures) - 1)
        if points > MAX_PARETO_WEIGHTINGS:
            raise BalancingConfigError(
                f"{spec.path}: [balancing.pareto.divisions] = {divisions} over "
                f"{len(measures)} measures makes {points:,} weightings (one QP each), over the "
                f"limit of {MAX_PARETO_WEIGHTINGS:,}; use fewer divisions (e.g. 10 gives "
                f"{math.comb(10 + len(measures) - 1, len(measures) - 1)})")
        pareto = (tuple(table.pareto.measures), table.pareto.divisions)
    blocks = blocks_from_table(spec, table)
    weightings = [dict(table.weights)]
    if pareto is not None:
        weightings.append({k: 1.0 for k in pareto[0]})
    for w in weightings:
        try:
            check_free_counterweights(blocks, w)
        except BalancingError as exc:
            raise BalancingConfigError(f"{spec.path}: [balancing] {exc}") from None
    return BalancingConfig(blocks=tuple(blocks),
                           weights=dict(table.weights), gravity=table.gravity,
                           normalisation=norm, bound=_bound(spec, table), pareto=pareto)
