"""What ``screwkit synthesize`` gives for a graph spec (docs/synthesis.md, "Graphs"): the JSON
document of the results (SI, with the variables also in the spec's units) and the synthesised
spec file — the input's text with the new hardpoints and axes put in place by tomlkit, so its
comments and layout are kept."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.synthesis.graph_route import GraphSynthesisProblem, GraphSynthesisResult

__all__ = ["graph_synthesis_document", "graph_synthesis_table", "synthesised_spec_text",
           "variable_rows"]


def _in_spec_units(spec: Any, kind: str, si: float) -> float:
    return float(spec.display_units().show(kind, si)) if kind == "length" else float(si)


def variable_rows(spec: Any, problem: GraphSynthesisProblem, result: GraphSynthesisResult
                  ) -> list[dict[str, Any]]:
    """Per variable: name, unit (the spec's length unit, or "" for an axis component), value
    before and after in that unit, and the bound it ended on ("lower"/"upper", or None)."""
    unit = spec.display_units().label("length")
    out = []
    for k, v in enumerate(problem.variables):
        side = result.at_bounds.get(v.label)
        out.append({"name": v.label, "unit": unit if v.kind == "length" else "",
                    "before": _in_spec_units(spec, v.kind, result.start[k]),
                    "after": _in_spec_units(spec, v.kind, result.x[k]),
                    "on_bound": side[0] if side else None})
    return out


def _target_rows(problem: GraphSynthesisProblem, result: GraphSynthesisResult
                 ) -> list[dict[str, Any]]:
    rows = []
    for t, g in zip(problem.targets, result.generated, strict=True):
        for i in range(t.inputs.shape[0]):
            d, v = t.values[i], g[i]
            err = d - v
            if t.kind == "angle":
                err = np.remainder(err + math.pi, 2 * math.pi) - math.pi
            rows.append({"target": t.label, "kind": t.kind, "input": t.inputs[i].tolist(),
                         "desired": d.tolist(), "generated": v.tolist(),
                         "error": err.tolist()})
    return rows


def _result_document(spec: Any, problem: GraphSynthesisProblem, r: GraphSynthesisResult
                     ) -> dict[str, Any]:
    return {
        "variables": variable_rows(spec, problem, r),
        "x": {v.label: float(x) for v, x in zip(problem.variables, r.x, strict=True)},
        "objective": r.objective, "rmse": r.rmse, "length_scale": problem.length_scale,
        "gradient_norm": r.gradient_norm, "status": r.status, "message": r.message,
        "at_bounds": {k: {"side": s, "bound": b} for k, (s, b) in r.at_bounds.items()},
        "range_check": {"ok": r.range_ok, "message": r.range_message},
        "iterations": r.iterations, "evaluations": r.evaluations, "time": r.time,
        "rows": _target_rows(problem, r),
    }


def graph_synthesis_document(spec: Any, problem: GraphSynthesisProblem,
                             results: list[GraphSynthesisResult], spec_out: Path | None
                             ) -> dict[str, Any]:
    """The document of ``screwkit synthesize`` on a graph spec: the best result, then
    ``alternatives`` (the other distinct results of a multistart); SI except ``variables``
    (the spec's units)."""
    doc = _result_document(spec, problem, results[0])
    doc["alternatives"] = [_result_document(spec, problem, r) for r in results[1:]]
    doc["method"] = "least_squares"
    doc["route"] = "graph"
    doc["spec"] = str(spec.path)
    doc["synthesised_spec"] = None if spec_out is None else str(spec_out)
    return doc


def _number(old: Any, value: float, unit: str | None) -> Any:
    """``value`` written as ``old`` was: a string with its unit, or a plain number."""
    if isinstance(old, str) and unit:
        return f"{value!r} {unit}"
    return float(value)


def synthesised_spec_text(spec: Any, problem: GraphSynthesisProblem, x: np.ndarray) -> str:
    """The spec file's text with the variables at ``x`` (the spec's units; tomlkit keeps the
    comments and the layout). A coordinate written with a unit ("35 mm") is written in the
    spec's length unit with it."""
    try:
        import tomlkit
    except ImportError:
        raise InputError("--spec-out writes the synthesised spec with tomlkit: pip install "
                         "'screwkit[synthesis]'") from None
    text = Path(spec.path).read_text(encoding="utf-8")
    doc = tomlkit.parse(text)
    unit = spec.display_units().label("length")
    for v, value in zip(problem.variables, x, strict=True):
        item: Any = doc[v.table][v.index]
        vec = item[v.field]
        shown = _in_spec_units(spec, v.kind, float(value))
        vec[v.component] = _number(vec[v.component], shown, unit if v.kind == "length"
                                   else None)
    return tomlkit.dumps(doc)


def graph_synthesis_table(spec: Any, problem: GraphSynthesisProblem, doc: dict[str, Any]) -> Any:
    """The target rows of the best result as a table (``--csv``, ``-o FILE.csv``): one line per
    target row and component — target, kind, component (x/y/z of a point, else empty), every
    input, then desired, generated and error (desired − generated, angles wrapped to (−π, π]) in
    ``*_angle`` or ``*_length`` columns by the target's kind (the other pair empty). SI here;
    written in the display units (the spec's by default), as the document's ``rows``."""
    from screwkit.tables import Column, ResultTable

    names = list(spec.mechanism.driven_names)
    slides = list(spec.mechanism.driven_is_translation())
    comps = {t.label: t.components if t.what == "point" else None for t in problem.targets}
    text: dict[str, list[str]] = {"target": [], "kind": [], "component": []}
    inputs: list[list[float]] = []
    vals: dict[str, list[float]] = {f"{q}_{k}": [] for k in ("angle", "length")
                                    for q in ("desired", "generated", "error")}
    for r in doc["rows"]:
        cs = comps.get(r["target"])
        for c in range(len(r["desired"])):
            text["target"].append(r["target"])
            text["kind"].append(r["kind"])
            text["component"].append("xyz"[cs[c]] if cs is not None else "")
            inputs.append(r["input"])
            for q in ("desired", "generated", "error"):
                for k in ("angle", "length"):
                    vals[f"{q}_{k}"].append(r[q][c] if r["kind"] == k else math.nan)
    x = np.array(inputs, dtype=float).reshape(-1, len(names))
    cols = [Column(k, "text", np.array(v, dtype=str)) for k, v in text.items()]
    cols += [Column(f"input_{n}", "length" if s else "angle", x[:, i])
             for i, (n, s) in enumerate(zip(names, slides, strict=True))]
    cols += [Column(k, k.split("_")[-1], np.array(v, dtype=float)) for k, v in vals.items()]
    return ResultTable(tuple(cols), "graph synthesis: targets against the synthesised design")
