"""The ``[synthesis]`` table of a graph spec (docs/synthesis.md, "Graphs"): validated once at load
and turned into a :class:`~screwkit.synthesis.graph_route.GraphSynthesisProblem` (SI).

The start is the drawing itself. ``unknowns`` name the drawing's hardpoints and axes by the keys
of a graph spec (docs/sweeps.md, "Graph specs"): ``joints.<joint>.at[k]`` (or ``at.x``, ``.y``,
``.z``), ``joints.<joint>.axis[k]``, ``axis2[k]``, ``points.<point>.at[k]``; only these change the
motion (masses and the motion's keys do not). ``bounds`` are in the spec's units. Each
``[[synthesis.targets]]`` names one of ``point`` (with ``coordinates``, default x, y, z),
``output`` (``[[outputs]]``) or ``variable`` (a joint variable such as ``C.theta``), and gives
``rows = [[input(s)..., value(s)...], ...]`` or ``expression`` in ``theta`` (the input) with
``design_points``. Target inputs must lie inside the spec's motion.
"""

from __future__ import annotations

import math
import re
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StrictInt, StrictStr, ValidationError

from screwkit.io.errors import SpecError
from screwkit.io.validation import validation_lines
from screwkit.messages import listing
from screwkit.synthesis.expressions import parse_expression
from screwkit.synthesis.graph_route import GraphSynthesisProblem, GraphTarget, GraphVariable

if TYPE_CHECKING:
    from screwkit.io.mechanism_spec import GraphSpec

__all__ = ["GraphSynthesisError", "graph_synthesis_problem"]

Value = float | int | str
_XYZ = {"x": 0, "y": 1, "z": 2}
_KEY = re.compile(r"^(joints|points)\.([^.\[\]]+)\.(at|axis2|axis)(?:\[(\d+)\]|\.([xyz]))$")
#: single-loop keys that have no meaning on a graph, with the reason
_LOOP_ONLY = {
    "solver": "a graph has one route (least squares on its drawn mode)",
    "method": "the overlay is for the RSRC; a graph uses least squares",
    "start": "the start of a graph is its drawing: edit the hardpoints in [[joints]]/[[points]]",
    "rotation": "give [[synthesis.targets]] with output/variable/point instead",
    "translation": "give [[synthesis.targets]] with output/variable/point instead",
    "inversion": "the drawn mode is followed (the drawing fixes it)",
    "mode": "the drawn mode is followed (the drawing fixes it)",
    "constraints": "parameters of constraint are the RSRC's closed route",
    "input_direction": "inputs are measured from the drawing",
    "output_direction": "targets are compared as the outputs are defined",
}


class GraphSynthesisError(SpecError):
    """A ``[synthesis]`` table of a graph spec that cannot be used (the message names the key)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class _Points(_Strict):
    start: Value
    stop: Value
    step: Value


class _Target(_Strict):
    point: StrictStr | None = None
    output: StrictStr | None = None
    variable: StrictStr | None = None
    coordinates: list[StrictStr] | None = None
    rows: list[list[Value]] | None = Field(None, max_length=10_000)
    expression: StrictStr | None = None
    parameters: dict[str, float] = Field(default_factory=dict)
    design_points: list[Value] | _Points | None = None


class _Multistart(_Strict):
    starts: StrictInt = Field(1, ge=1, le=10_000)
    seed: StrictInt = 0
    keep: StrictInt = Field(3, ge=1, le=100)
    spread: float = Field(0.1, gt=0.0, le=10.0)


class _Table(_Strict):
    unknowns: list[StrictStr] = Field(min_length=1, max_length=200)
    targets: list[_Target] = Field(min_length=1, max_length=100)
    bounds: dict[str, list[Value]] = Field(default_factory=dict)
    length_scale: Value | None = None
    max_iterations: StrictInt = Field(200, ge=1, le=100_000)
    time_limit: float = Field(30.0, gt=0.0)
    multistart: _Multistart | None = None


def _fail(spec: GraphSpec, key: str, message: str) -> GraphSynthesisError:
    return GraphSynthesisError(f"{spec.path}: [synthesis.{key}] {message}")


def _variable(spec: GraphSpec, text: str) -> GraphVariable:
    valid = ([f"joints.{j.name}.at[0..2]" for j in spec.raw.joints]
             + [f"joints.{j.name}.axis[0..2]" for j in spec.raw.joints if j.axis is not None]
             + [f"joints.{j.name}.axis2[0..2]" for j in spec.raw.joints if j.axis2 is not None]
             + [f"points.{p.name}.at[0..2]" for p in spec.raw.points])
    listed = ", ".join(valid[:30]) + (f" … ({len(valid)} in all)" if len(valid) > 30 else "")
    m = _KEY.match(text)
    if m is None:
        raise _fail(spec, "unknowns", f"{text!r} is not a hardpoint or axis of the drawing; the "
                                      f"design variables of this spec are {listed}")
    table, name, fld, idx, letter = m.groups()
    comp = int(idx) if idx is not None else _XYZ[letter]
    items = spec.raw.joints if table == "joints" else spec.raw.points
    names = [it.name for it in items]
    if name not in names:
        raise _fail(spec, "unknowns", f"{text!r}: the spec has no {table[:-1]} {name!r} (its "
                                      f"{table}: {', '.join(names) or 'none'})")
    k = names.index(name)
    if comp > 2 or (fld != "at" and getattr(items[k], fld) is None):
        raise _fail(spec, "unknowns", f"{text!r}: {table[:-1]} {name!r} has no {fld}[{comp}]; "
                                      f"the design variables of this spec are {listed}")
    return GraphVariable(f"{table}.{name}.{fld}[{comp}]", table, k, fld, comp,
                         "length" if fld == "at" else "number")


def _design_inputs(spec: GraphSpec, t: _Target, key: str, in_kind: str) -> np.ndarray:
    dp = t.design_points
    if dp is None:
        raise _fail(spec, key, "an expression needs design_points (a list, or {start, stop, "
                               "step}) in the input's unit")
    if isinstance(dp, list):
        vals = [spec.coordinate(v, in_kind, f"synthesis.{key}.design_points") for v in dp]
    else:
        a = spec.coordinate(dp.start, in_kind, f"synthesis.{key}.design_points.start")
        b = spec.quantity(dp.stop, in_kind, f"synthesis.{key}.design_points.stop")
        s = spec.quantity(dp.step, in_kind, f"synthesis.{key}.design_points.step")
        if not s > 0 or b < a or (b - a) / s > 10_000:
            raise _fail(spec, f"{key}.design_points", "give start ≤ stop and a positive step "
                                                      "(at most 10000 points)")
        vals = list(a + s * np.arange(int(math.floor((b - a) / s + 1e-9)) + 1))
    if not vals:
        raise _fail(spec, f"{key}.design_points", "give at least one design point")
    return np.array(vals, dtype=float)[:, None]


def _target(spec: GraphSpec, t: _Target, k: int) -> GraphTarget:
    key = f"targets.{k}"
    mech = spec.mechanism
    given = [w for w in ("point", "output", "variable") if getattr(t, w) is not None]
    if len(given) != 1:
        raise _fail(spec, key, "give exactly one of point, output or variable (the quantity "
                               f"to fit); got {', '.join(given) or 'none'}")
    what = given[0]
    name = str(getattr(t, what))
    comps: tuple[int, ...] = (0,)
    if what == "point":
        names = [p.name for p in mech.points]
        if name not in names:
            raise _fail(spec, f"{key}.point", f"no point {name!r}; the points are "
                                              f"{', '.join(names) or 'none (add [[points]])'}")
        coords = t.coordinates or ["x", "y", "z"]
        if any(c not in _XYZ for c in coords) or len(set(coords)) != len(coords):
            raise _fail(spec, f"{key}.coordinates", f"{listing(coords)}: give distinct names among "
                                                    "'x', 'y', 'z'")
        comps, kind = tuple(_XYZ[c] for c in coords), "length"
    elif what == "output":
        outs = {o.name: o for o in mech.outputs}
        if name not in outs:
            raise _fail(spec, f"{key}.output", f"no output {name!r}; the outputs are "
                                               f"{', '.join(outs) or 'none (add [[outputs]])'}")
        kind = "length" if hasattr(outs[name], "point") else "angle"
    else:
        from screwkit.kinematics.graph.closure import graph_layout

        lay = graph_layout(mech)
        names = list(lay.names)
        if name not in names:
            raise _fail(spec, f"{key}.variable", f"no joint variable {name!r}; the variables "
                                                 f"are {', '.join(names)}")
        kind = "length" if lay.is_translation[names.index(name)] else "angle"
    if t.coordinates is not None and what != "point":
        raise _fail(spec, f"{key}.coordinates", "coordinates are for a point target")
    n_in, in_kind = len(mech.driven_names), ("angle" if spec.input_is_angle else "length")
    in_kinds = ["length" if tr else "angle" for tr in mech.driven_is_translation()]
    if (t.rows is None) == (t.expression is None):
        raise _fail(spec, key, "give either rows = [[input..., value...], ...] or expression "
                               "with design_points")
    if t.rows is not None:
        width = n_in + len(comps)
        if not t.rows:
            raise _fail(spec, f"{key}.rows", "give at least one row")
        X, V = [], []
        for r, row in enumerate(t.rows):
            if len(row) != width:
                raise _fail(spec, f"{key}.rows.{r}", f"each row is {n_in} input value(s) then "
                                                     f"{len(comps)} target value(s); got "
                                                     f"{len(row)} numbers")
            X.append([spec.coordinate(v, in_kinds[c], f"synthesis.{key}.rows.{r}")
                      for c, v in enumerate(row[:n_in])])
            V.append([spec.coordinate(v, kind, f"synthesis.{key}.rows.{r}")
                      for v in row[n_in:]])
        inputs, values = np.array(X, dtype=float), np.array(V, dtype=float)
    else:
        if n_in != 1 or len(comps) != 1:
            raise _fail(spec, f"{key}.expression", "an expression is for one input and one "
                                                   "value; give rows instead")
        inputs = _design_inputs(spec, t, key, in_kind)
        fn = parse_expression(str(t.expression), t.parameters)
        shown = spec.display_units()
        theta = shown.show(in_kind, inputs[:, 0])
        try:
            values = np.asarray(fn(theta), dtype=float)[:, None] * shown.unit_of(kind)[1]
        except ValueError as exc:
            raise _fail(spec, f"{key}.expression", str(exc)) from None
    lo, hi = spec.inputs.min(axis=0), spec.inputs.max(axis=0)
    slack = 1e-9 * np.maximum(1.0, np.abs(spec.inputs).max(axis=0))
    outside = np.flatnonzero(np.any((inputs < lo - slack) | (inputs > hi + slack), axis=1))
    if outside.size:
        du = spec.display_units()
        shown_row = [f"{du.show(in_kinds[c], v):.6g} {du.label(in_kinds[c])}"
                     for c, v in enumerate(inputs[outside[0]])]
        span = [f"[{du.show(in_kinds[c], a):.6g}, {du.show(in_kinds[c], b):.6g}] "
                f"{du.label(in_kinds[c])}" for c, (a, b) in enumerate(zip(lo, hi, strict=True))]
        raise _fail(spec, key, f"target input {', '.join(shown_row)} lies outside the spec's motion "
                               f"({'; '.join(span)}); move it inside or widen [motion]")
    label = f"{what} {name}" + (f" ({', '.join('xyz'[c] for c in comps)})"
                                if what == "point" else "")
    return GraphTarget(label, what, name, comps, inputs, values, kind)


def graph_synthesis_problem(spec: GraphSpec, data: dict[str, Any]) -> GraphSynthesisProblem:
    """The problem of a graph spec's ``[synthesis]`` table ``data`` (module docstring)."""
    for key, why in _LOOP_ONLY.items():
        if key in data:
            raise _fail(spec, key, f"not a key of a graph's synthesis: {why}")
    try:
        table = _Table.model_validate(data)
    except ValidationError as exc:
        raise GraphSynthesisError("\n".join([f"{spec.path}: [synthesis] is not valid:",
                                             *validation_lines(exc)])) from None
    variables = tuple(_variable(spec, u) for u in table.unknowns)
    labels = [v.label for v in variables]
    if len(set(labels)) != len(labels):
        raise _fail(spec, "unknowns", f"each unknown once; got {listing(table.unknowns)}")
    lower = np.full(len(variables), -np.inf)
    upper = np.full(len(variables), np.inf)
    for text, pair in table.bounds.items():
        v = _variable(spec, text)
        if v.label not in labels:
            raise _fail(spec, f"bounds.{text}", "bounds for a variable that is not in unknowns")
        if len(pair) != 2:
            raise _fail(spec, f"bounds.{text}", f"give [lower, upper]; got {pair!r}")
        j = labels.index(v.label)
        if v.kind == "length":
            lo, hi = (spec.coordinate(b, "length", f"synthesis.bounds.{text}") for b in pair)
        elif all(isinstance(b, int | float) and not isinstance(b, bool) and math.isfinite(b)
                 for b in pair):
            lo, hi = float(pair[0]), float(pair[1])
        else:
            raise _fail(spec, f"bounds.{text}", f"an axis component is a plain finite number; "
                                                f"give [lower, upper] without units, got "
                                                f"{pair!r}")
        if not lo < hi:
            raise _fail(spec, f"bounds.{text}", f"lower {pair[0]!r} must be below upper "
                                                f"{pair[1]!r}; swap them")
        lower[j], upper[j] = lo, hi
    targets = tuple(_target(spec, t, k) for k, t in enumerate(table.targets))
    L = 1.0 * spec.display_units().unit_of("length")[1]
    if table.length_scale is not None:
        L = spec.quantity(table.length_scale, "length", "synthesis.length_scale")
        if not L > 0:
            raise _fail(spec, "length_scale", f"must be a positive length; got "
                                              f"{table.length_scale!r}")
    axes = {k: (None if j.axis is None else np.array([float(a) for a in j.axis]),
                None if j.axis2 is None else np.array([float(a) for a in j.axis2]))
            for k, j in enumerate(spec.raw.joints)}  # plain numbers (checked at load)
    ms = table.multistart or _Multistart.model_validate({})
    start = GraphSynthesisProblem(spec.mechanism, axes, variables, targets, lower, upper,
                                  spec.inputs).start_vector()
    out = np.flatnonzero((start < lower) | (start > upper))
    if out.size:
        v = variables[int(out[0])]
        raise _fail(spec, f"bounds.{v.label}", f"the drawing's {v.label} lies outside its "
                                               "bounds; widen them or move the drawing")
    return GraphSynthesisProblem(spec.mechanism, axes, variables, targets, lower, upper,
                                 spec.inputs, length_scale=L,
                                 max_iterations=table.max_iterations,
                                 time_limit=table.time_limit, starts=ms.starts, seed=ms.seed,
                                 keep=ms.keep, spread=ms.spread, rates=spec.speed)
