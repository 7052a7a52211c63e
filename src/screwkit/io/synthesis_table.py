"""The ``[synthesis]`` table of a spec file: validated with pydantic and turned, once, into a typed
:class:`~screwkit.synthesis.config.SynthesisConfig` (the problem of its route, SI units).

Keys are documented in docs/synthesis.md.  Numbers take the spec's ``[units]`` (angles usually
in degrees, lengths in the spec's length unit); strings with units ("1 in", "80 deg") work too.
The start of the unknowns is the spec's ``[dimensions]`` table, overridden by
``[synthesis.start]`` (which also holds theta01 and the starts of free q1, q2).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    ValidationError,
    model_validator,
)

from screwkit.errors import InputError
from screwkit.io.errors import SpecError
from screwkit.io.units import UnitError, to_si
from screwkit.kinematics.registry import family_of, require
from screwkit.messages import listing
from screwkit.synthesis.config import Multistart, Problem, SynthesisConfig
from screwkit.synthesis.loop_route import LoopSynthesisProblem
from screwkit.synthesis.overlay import OverlayDwell
from screwkit.synthesis.overlay_synthesis import OverlayProblem
from screwkit.synthesis.problem import (
    ANGLE_NAMES,
    DIMENSION_NAMES,
    ConstraintConstruction,
    ConstraintPoint,
    RSRCSynthesisProblem,
)
from screwkit.synthesis.targets import (
    LIBRARY,
    DesiredFunction,
    ScrewTarget,
    data_function,
    expression_function,
    library_function,
)

if TYPE_CHECKING:
    from screwkit.io.spec import MechanismSpec

__all__ = ["MultistartTable", "OverlayTable", "SynthesisConfigError", "SynthesisTable",
           "overlay_problem_from_spec", "problem_from_spec", "synthesis_config",
           "synthesis_from_spec"]

Value = float | int | str


class SynthesisConfigError(SpecError):
    """A ``[synthesis]`` table that cannot be used; the message names the key."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class RangeTable(_Strict):
    start: Value
    stop: Value
    step: Value


class DataTable(_Strict):
    theta: list[Value]
    value: list[Value]


class ComponentTable(_Strict):
    """One component of the desired screw: a library function, an expression, or data."""

    function: str | None = None
    parameters: dict[str, Value] = Field(default_factory=dict)
    expression: str | None = None
    data: DataTable | None = None
    design_points: list[Value] | RangeTable | None = None

    @model_validator(mode="after")
    def _one_source(self) -> ComponentTable:
        given = [k for k in ("function", "expression", "data") if getattr(self, k) is not None]
        if len(given) != 1:
            raise InputError("give exactly one of function, expression or data "
                             f"(got {listing(given)})")
        if self.function is not None and self.function not in LIBRARY:
            raise InputError(f"unknown function {self.function!r}; choose one of "
                             f"{listing(sorted(LIBRARY), 'or')}")
        if self.design_points is None and self.data is None:
            raise InputError("design_points are needed (a list, or {start, stop, step})")
        return self


class PointTable(_Strict):
    theta: Value
    q: Value = "dwell"
    other_tangency: StrictBool = False


class ConstraintsTable(_Strict):
    method: Literal["parameters"] = "parameters"
    points: list[PointTable]
    rotation_between: Value | None = None

    @model_validator(mode="after")
    def _two(self) -> ConstraintsTable:
        if len(self.points) != 2:
            raise InputError(f"parameters of constraint need exactly 2 points, got "
                             f"{len(self.points)}")
        return self


class MultistartTable(_Strict):
    starts: int = Field(20, ge=1, le=10000)
    seed: int = 0
    keep: int = Field(3, ge=1, le=100)
    spread: float = Field(0.5, gt=0.0, le=3.0)


class DwellTable(_Strict):
    theta: Value
    tangency: Literal["interior", "exterior"] = "interior"


class OverlayTable(_Strict):
    """``[synthesis.overlay]``: options of the overlay technique (§5.4)."""

    dwells: list[DwellTable] = Field(default_factory=list)
    keep: int = Field(3, ge=1, le=100)
    starts: int = Field(12, ge=1, le=1000)
    d3_range: list[Value] | None = None

    @model_validator(mode="after")
    def _check(self) -> OverlayTable:
        if len(self.dwells) > 2:
            raise InputError(f"at most two dwells can be placed on the overlay, got "
                             f"{len(self.dwells)} (two fix the output circle already)")
        if self.d3_range is not None and len(self.d3_range) != 2:
            raise InputError("d3_range must be [lower, upper]")
        return self


OVERLAY_UNKNOWNS = ({"d3", "a", "b"}, {"d2", "d3", "a", "b"})


class SynthesisTable(_Strict):
    method: Literal["least_squares", "overlay"] = "least_squares"
    solver: Literal["auto", "closed", "generic"] = "auto"
    unknowns: list[str] | None = None
    inversion: int | Literal["all"] = "all"
    mode: int | Literal["all"] = "all"
    input_direction: Literal["ccw", "cw"] = "ccw"
    output_direction: Literal["ccw", "cw", "both"] = "ccw"
    length_scale: Value | None = None
    max_iterations: int = Field(1000, ge=1, le=1_000_000)
    time_limit: float = Field(10.0, gt=0.0, le=3600.0)
    start: dict[str, Value] = Field(default_factory=dict)
    bounds: dict[str, list[Value]] = Field(default_factory=dict)
    rotation: ComponentTable | None = None
    translation: ComponentTable | None = None
    constraints: ConstraintsTable | None = None
    multistart: MultistartTable | None = None
    overlay: OverlayTable | None = None

    @model_validator(mode="after")
    def _check(self) -> SynthesisTable:
        if isinstance(self.inversion, int) and self.inversion not in (1, 2, 3, 4):
            raise InputError("inversion must be 1, 2, 3, 4 or \"all\"")
        if isinstance(self.mode, int) and not 0 <= self.mode <= 10_000:
            raise InputError("mode must be an assembly mode index (0, 1, …) or \"all\"")
        if self.rotation is None and self.translation is None:
            raise InputError("give a rotation and/or a translation to generate")
        if self.method == "overlay":
            return self._check_overlay()
        if self.unknowns is None:
            raise InputError("unknowns: give the names to solve for (method = \"least_squares\")")
        if self.overlay is not None:
            raise InputError("[synthesis.overlay] belongs to method = \"overlay\"; set method "
                             "or remove the table")
        if self.output_direction == "both":
            raise InputError("output_direction = \"both\" is for method = \"overlay\"; the "
                             "least-squares route solves one sense (\"ccw\" or \"cw\")")
        for name, pair in self.bounds.items():
            if len(pair) != 2:
                raise InputError(f"bounds.{name} must be [lower, upper]")
        return self

    def _check_overlay(self) -> SynthesisTable:
        if self.rotation is None:
            raise InputError("the overlay technique fits the output rotation: give "
                             "[synthesis.rotation] (the translation is only evaluated)")
        unused = [k for k in ("constraints", "multistart") if getattr(self, k) is not None]
        unused += ["bounds"] if self.bounds else []
        unused += ["inversion"] if self.inversion != "all" else []
        if unused:
            raise InputError(f"{listing(unused)} not used by method = \"overlay\" (it finds the output "
                             "circle and the assembly mode from the overlay; dwells go in "
                             "[synthesis.overlay] dwells)")
        if self.unknowns is not None and set(self.unknowns) not in OVERLAY_UNKNOWNS:
            raise InputError(f"unknowns of the overlay are [\"d3\", \"a\", \"b\"] or, to refine "
                             f"the coupler too, [\"d2\", \"d3\", \"a\", \"b\"]; got {listing(self.unknowns)}")
        return self


def key_error(path: str, key: str, message: str) -> SynthesisConfigError:
    return SynthesisConfigError(f"{path}: [synthesis.{key}] {message}")


def _kind(name: str) -> str:
    return "angle" if name in ANGLE_NAMES else "length"


@dataclass(frozen=True)
class ParsedSynthesis:
    """The parts of a ``[synthesis]`` table that both routes share (SI units)."""

    table: SynthesisTable
    si: Callable[[Any, str, str], float]
    start: dict[str, float]
    target: ScrewTarget
    length_scale: float
    show: Callable[[float, str], str]


def synthesis_from_spec(spec: MechanismSpec) -> tuple[Problem, SynthesisTable]:
    """The problem of the ``[synthesis]`` table's route: Bagci's closed form (least squares or
    the overlay) for the RSRC and the 4R, the generic route for any loop (``solver``)."""
    if synthesis_route(spec) == "generic":
        from screwkit.io.loop_synthesis_table import loop_problem_from_spec

        return loop_problem_from_spec(spec)
    if isinstance(spec.raw.synthesis, dict) and spec.raw.synthesis.get("method") == "overlay":
        return overlay_problem_from_spec(spec)
    return problem_from_spec(spec)


def validated_table(spec: MechanismSpec) -> SynthesisTable:
    """``[synthesis]`` validated by pydantic (a SynthesisConfigError lists every bad key)."""
    path = spec.path
    try:
        require(spec.linkage, "synthesize")
    except ValueError as exc:
        raise SynthesisConfigError(f"{path}: [synthesis] {exc}") from None
    raw: dict[str, Any] | None = spec.raw.synthesis
    if raw is None:
        raise SynthesisConfigError(f"{path}: no [synthesis] table; see docs/synthesis.md")
    try:
        return SynthesisTable.model_validate(raw)
    except ValidationError as exc:
        lines = [f"{path}: the [synthesis] table is not valid:"]
        for err in exc.errors():
            loc = ".".join(str(p) for p in err["loc"])
            msg = ("unknown key (see docs/synthesis.md)" if err["type"] == "extra_forbidden"
                   else str(err["msg"]).removeprefix("Value error, "))
            lines.append(f"  [synthesis{'.' + loc if loc else ''}] {msg}")
        raise SynthesisConfigError("\n".join(lines)) from None


def synthesis_route(spec: MechanismSpec) -> str:
    """``"closed"`` (Bagci's closed form: the RSRC and its plane case the 4R) or ``"generic"``
    (any loop), as ``solver`` asks; what the family cannot have is refused first, with why."""
    raw = spec.raw.synthesis if isinstance(spec.raw.synthesis, dict) else {}
    solver, method = raw.get("solver", "auto"), raw.get("method", "least_squares")
    fam = family_of(spec.linkage)
    closed = "closed_synthesis" in fam.capabilities
    for key, capability, asked in (("solver", "closed_synthesis", solver == "closed"),
                                   ("method", "overlay", method == "overlay")):
        if asked:
            try:
                require(spec.linkage, capability)
            except ValueError as exc:
                raise key_error(spec.path, key, str(exc)) from None
    route = "closed" if solver == "closed" or (solver != "generic" and closed) else "generic"
    if route == "generic" and method == "overlay":
        raise key_error(spec.path, "method", "the overlay technique (Bagci §5.4) belongs to the "
                        "closed route; use method = \"least_squares\" with solver = \"generic\"")
    validated_table(spec)
    return route


def _closed_names(spec: MechanismSpec) -> dict[str, str]:
    """The start/unknown names of the closed route and their kinds: the RSRC's, or the 4R's own
    (its other RSRC dimensions are held by the registry's ``closed_synthesis``)."""
    fam = family_of(spec.linkage)
    held = fam.closed_synthesis or {}
    return {n: _kind(n) for n in (*DIMENSION_NAMES, "q1", "q2") if n not in held}


def parse_synthesis(spec: MechanismSpec, names: dict[str, str] | None = None,
           start_values: dict[str, float] | None = None) -> ParsedSynthesis:
    """The shared part of every route. ``names``: the start/unknown names and their kinds
    (default: the closed route's); ``start_values``: the start before ``[synthesis.start]``
    (default: the spec's dimensions, with the dimensions the closed route holds)."""
    path = spec.path
    table = validated_table(spec)
    fam = family_of(spec.linkage)
    closed = names is None
    names = _closed_names(spec) if names is None else names
    held = dict(fam.closed_synthesis or {}) if closed else {}
    units = spec.units

    def si(value: Any, kind: str, key: str) -> float:
        try:
            return to_si(value, kind, units.get(kind))
        except UnitError as exc:
            raise key_error(path, key, str(exc)) from None

    angle_unit = si(1.0, "angle", "units")
    length_unit = si(1.0, "length", "units")
    start: dict[str, float] = (dict(start_values) if start_values is not None
                               else {**dict(fam.optional), **dict(spec.dimensions)})
    for name, value in table.start.items():
        if name not in names:
            why = (f" (the closed route solves a {fam.name} as Bagci's RSRC with "
                   f"{', '.join(sorted(held))} = 0)" if name in held else "")
            raise key_error(path, f"start.{name}", f"unknown name{why}; use "
                        f"{', '.join(n for n in names)}")
        start[name] = si(value, names[name], f"start.{name}")
    start.update(held)
    if "theta01" not in start:
        raise key_error(path, "start.theta01", "give the start (or value) of theta01, the input "
                    "angle at which the desired screw starts")

    def component(tab: ComponentTable, kind: str, key: str) -> tuple[DesiredFunction, np.ndarray]:
        unit = angle_unit if kind == "angle" else length_unit
        pts: np.ndarray | None = None
        if tab.design_points is not None:
            dp = tab.design_points
            if isinstance(dp, RangeTable):
                a, b, h = (si(v, "angle", f"{key}.design_points") for v in (dp.start, dp.stop,
                                                                             dp.step))
                if h <= 0 or b < a:
                    raise key_error(path, f"{key}.design_points", "need step > 0 and stop >= start")
                pts = a + h * np.arange(int(np.floor((b - a) / h + 1e-9)) + 1)
            else:
                pts = np.array([si(v, "angle", f"{key}.design_points") for v in dp])
        try:
            if tab.function is not None:
                params = {}
                for pname, pval in tab.parameters.items():
                    pkind = {"amplitude": kind, "span": "angle"}.get(pname, "dimensionless")
                    params[pname] = si(pval, pkind, f"{key}.parameters.{pname}")
                fn = library_function(tab.function, **params)
            elif tab.expression is not None:
                fn = expression_function(tab.expression, angle_unit=angle_unit, value_unit=unit,
                                         parameters={k: float(si(v, "dimensionless", key))
                                                     for k, v in tab.parameters.items()})
            else:
                assert tab.data is not None
                th = [si(v, "angle", f"{key}.data.theta") for v in tab.data.theta]
                val = [si(v, kind, f"{key}.data.value") for v in tab.data.value]
                fn = data_function(th, val)
                if pts is None:
                    pts = np.array(th)
        except SynthesisConfigError:
            raise  # already names its key
        except ValueError as exc:
            raise key_error(path, key, str(exc)) from None
        assert pts is not None
        return fn, pts

    rot = component(table.rotation, "angle", "rotation") if table.rotation else None
    tra = component(table.translation, "length", "translation") if table.translation else None
    try:
        target = ScrewTarget(rot[0] if rot else None, rot[1] if rot else np.zeros(0),
                             tra[0] if tra else None, tra[1] if tra else np.zeros(0))
    except ValueError as exc:
        raise key_error(path, "rotation", str(exc)) from None
    scale = (length_unit if table.length_scale is None
             else si(table.length_scale, "length", "length_scale"))

    def show(value: float, kind: str) -> str:
        """An SI value in the spec's unit of ``kind`` (and in SI when that differs)."""
        si_unit = "m" if kind == "length" else "rad"
        unit = units.get(kind)
        if unit is None or unit == si_unit:
            return f"{float(value):.6g} {si_unit}"
        return f"{float(value) / si(1.0, kind, 'units'):.6g} {unit} ({float(value):.6g} {si_unit})"

    return ParsedSynthesis(table, si, start, target, scale, show)


def _check_closed_keys(spec: MechanismSpec, table: SynthesisTable) -> None:
    """What Bagci's closed-form route cannot take from this family, refused with the key."""
    fam = family_of(spec.linkage)
    held = fam.closed_synthesis or {}
    if table.mode != "all":
        raise key_error(spec.path, "mode", "the closed route labels its assembly modes by "
                        "Bagci's root order: use inversion = 1 … 4 (mode is the generic route's)")
    for name in table.unknowns or []:
        if name in held:
            raise key_error(spec.path, "unknowns", f"{name} cannot be solved for: the closed "
                            f"route solves a {fam.name} as Bagci's RSRC with "
                            f"{', '.join(sorted(held))} = 0")
    if table.translation is not None and "S" not in fam.outputs:
        raise key_error(spec.path, "translation", f"the output of {fam.title} is a revolute "
                        "(phi0): it generates no translation; prescribe the rotation only")


def problem_from_spec(spec: MechanismSpec) -> tuple[RSRCSynthesisProblem, SynthesisTable]:
    """Validate ``spec.raw.synthesis`` and build the least-squares problem (SI units inside)."""
    parsed = parse_synthesis(spec)
    table, si, start, target = parsed.table, parsed.si, parsed.start, parsed.target
    path = spec.path
    if table.method != "least_squares":
        raise SynthesisConfigError(f"{path}: [synthesis] method = {table.method!r}: use "
                                   "overlay_problem_from_spec (screwkit synthesize does)")
    assert table.unknowns is not None
    _check_closed_keys(spec, table)
    construction = None
    if table.constraints is not None:
        pts_c = []
        for i, pt in enumerate(table.constraints.points, start=1):
            theta = si(pt.theta, "angle", f"constraints.points[{i}].theta")
            if isinstance(pt.q, str) and pt.q in ("dwell", "free"):
                kind_q = pt.q
                value = start.get(f"q{i}", 0.0)
                if kind_q == "free" and f"q{i}" not in start:
                    raise key_error(path, f"start.q{i}", f"q{i} is free: give its start value")
            else:
                kind_q = "fixed"
                value = si(pt.q, "angle", f"constraints.points[{i}].q")
            pts_c.append(ConstraintPoint(theta, kind_q, value, pt.other_tangency))  # type: ignore[arg-type]
        between = (None if table.constraints.rotation_between is None
                   else si(table.constraints.rotation_between, "angle",
                           "constraints.rotation_between"))
        try:
            construction = ConstraintConstruction(pts_c[0], pts_c[1], between)
        except ValueError as exc:
            raise key_error(path, "constraints", str(exc)) from None
    bounds = {}
    for name, (lo, hi) in table.bounds.items():
        bounds[name] = (si(lo, _kind(name), f"bounds.{name}"), si(hi, _kind(name), f"bounds.{name}"))
    for name, (lo, hi) in bounds.items():
        value = start.get(name, lo)
        if lo < hi and not lo <= value <= hi:
            k = _kind(name)
            raise key_error(path, f"bounds.{name}", f"the start of {name}, {parsed.show(value, k)}, is "
                        f"outside its bounds [{parsed.show(lo, k)}, {parsed.show(hi, k)}]: move "
                        "the start ([dimensions] or [synthesis.start]) inside them or widen the "
                        "bounds")
    scale = parsed.length_scale
    try:
        problem = RSRCSynthesisProblem(
            target=target, start=start, unknowns=tuple(table.unknowns), bounds=bounds,
            inversion=None if table.inversion == "all" else int(table.inversion),
            input_direction=1 if table.input_direction == "ccw" else -1,
            output_direction=1 if table.output_direction == "ccw" else -1,
            length_scale=scale, construction=construction,
            max_iterations=table.max_iterations, time_limit=table.time_limit)
    except ValueError as exc:
        raise SynthesisConfigError(f"{path}: [synthesis] {exc}") from None
    return problem, table


def overlay_problem_from_spec(spec: MechanismSpec) -> tuple[OverlayProblem, SynthesisTable]:
    """Validate a ``[synthesis]`` table with ``method = "overlay"`` and build the overlay problem
    (Bagci 1969, §5.4).  d1, d2, lambda0, delta0 (must be 0) and e come from ``[dimensions]`` /
    ``[synthesis.start]``, theta01 from ``[synthesis.start]``; d3, a, b are found."""
    parsed = parse_synthesis(spec)
    table, si, start = parsed.table, parsed.si, parsed.start
    path = spec.path
    if table.mode != "all":
        raise key_error(path, "mode", "the overlay finds the assembly mode itself; remove mode")
    if table.method != "overlay":
        raise SynthesisConfigError(f"{path}: [synthesis] method is {table.method!r}, not "
                                   "\"overlay\"")
    if abs(math.sin(start.get("delta0", 0.0))) > 1e-12:
        raise key_error(path, "start.delta0", "the overlay technique needs delta0 = 0 (the coupler "
                    "ellipse is then a circle of radius d2, Bagci §5.4); use method = "
                    "\"least_squares\" for delta0 != 0")
    for name in ("d1", "d2", "lambda0"):
        if name not in start:
            raise key_error(path, f"start.{name}", f"the overlay needs {name} (in [dimensions] or "
                        "[synthesis.start])")
    ov = table.overlay if table.overlay is not None else OverlayTable.model_validate({})
    dwells = tuple(OverlayDwell(si(d.theta, "angle", f"overlay.dwells[{i}].theta"), d.tangency)
                   for i, d in enumerate(ov.dwells, start=1))
    d3_range = None
    if ov.d3_range is not None:
        lo, hi = (si(v, "length", "overlay.d3_range") for v in ov.d3_range)
        if not 0 < lo < hi:
            raise key_error(path, "overlay.d3_range", "need 0 < lower < upper, got "
                        f"[{parsed.show(lo, 'length')}, {parsed.show(hi, 'length')}]")
        d3_range = (lo, hi)
    senses = {"ccw": (1,), "cw": (-1,), "both": (1, -1)}[table.output_direction]
    try:
        problem = OverlayProblem(
            target=parsed.target, d1=start["d1"], d2=start["d2"], lambda0=start["lambda0"],
            theta01=start["theta01"], e=start.get("e", 0.0),
            input_direction=1 if table.input_direction == "ccw" else -1,
            output_directions=senses, dwells=dwells,
            refine_d2=table.unknowns is not None and "d2" in table.unknowns, keep=ov.keep,
            n_starts=ov.starts, d3_range=d3_range, length_scale=parsed.length_scale,
            max_iterations=table.max_iterations, time_limit=table.time_limit)
    except ValueError as exc:
        raise SynthesisConfigError(f"{path}: [synthesis] {exc}") from None
    return problem, table


def synthesis_config(spec: MechanismSpec) -> SynthesisConfig:
    """The ``[synthesis]`` table of a loaded spec as a typed :class:`SynthesisConfig`."""
    problem, table = synthesis_from_spec(spec)
    ms = table.multistart
    multistart = None if ms is None else Multistart(ms.starts, ms.seed, ms.keep, ms.spread)
    unit = spec.units.get("length", "m")
    length_unit = f"1 {unit}" if table.length_scale is None else str(table.length_scale)
    fam = family_of(spec.linkage)
    if isinstance(problem, LoopSynthesisProblem):
        return SynthesisConfig(
            problem, multistart, length_unit, (*problem.kinds, "theta01"),
            frozenset({n for n, k in problem.kinds.items() if k == "angle"} | {"theta01"}),
            (problem.rotation_output, problem.translation_output))
    names = _closed_names(spec)
    reported = None if not fam.closed_synthesis else tuple(names)
    angles = frozenset(n for n, k in names.items() if k == "angle")
    return SynthesisConfig(problem, multistart, length_unit, reported, angles,
                           ("phi0", "S" if "S" in fam.outputs else None))
