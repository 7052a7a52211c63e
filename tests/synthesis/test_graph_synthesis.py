"""Synthesis on graph specs (docs/synthesis.md, "Graphs"): each result checked independently —
a design whose exact answer is known (targets generated from it) is recovered from a perturbed
start; the four-bar drawn as a graph reaches the loop route's optimum on the same problem; the
finite-difference Jacobian agrees with a five-point stencil; the written spec, analysed anew,
generates what the synthesis reported."""

from __future__ import annotations

import copy
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.errors import SpecError
from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.io.spec import load_spec
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.registry import family
from screwkit.model import geometry
from screwkit.synthesis.graph_route import (
    graph_jacobian,
    graph_residuals,
    synthesize_graph,
    synthesize_graph_multistart,
)
from screwkit.synthesis.loop_route import LoopResidualModel, LoopSynthesisProblem
from screwkit.synthesis.loop_solve import synthesize_loop
from screwkit.synthesis.solve import SynthesisError
from screwkit.synthesis.targets import ScrewTarget, library_function

ROOT = Path(__file__).resolve().parents[2]
MECH = ROOT / "examples" / "mechanisms"
runner = CliRunner()
IN = 0.0254


def _fourbar(c: list[float], d: list[float]) -> dict:
    data = tomllib.loads((MECH / "fourbar_graph.toml").read_text(encoding="utf-8"))
    data["joints"][2]["at"] = [*c, 0.0]
    data["joints"][3]["at"] = [*d, 0.0]
    return data


def _path_rows(data: dict, inputs_deg: np.ndarray) -> list[list[float]]:
    """The coupler point P's x, y (mm) at the inputs (deg), of the design ``data``."""
    spec = graph_spec_from_data(data, "true.toml")
    md = solve_mechanism(spec.mechanism, np.radians(inputs_deg)[:, None]).modes[0]
    assert md.assembles.all()
    return [[float(a), float(p[0] * 1e3), float(p[1] * 1e3)]
            for a, p in zip(inputs_deg, md.points["P"], strict=True)]


UNKNOWNS = ["joints.C.at.x", "joints.C.at.y", "joints.D.at[0]", "joints.D.at.y"]


def test_a_known_four_bar_is_recovered_from_its_coupler_path():
    true_c, true_d = [33.0, 27.0], [42.0, 2.0]
    rows = _path_rows(_fourbar(true_c, true_d), np.arange(0.0, 360.0, 40.0))
    data = _fourbar([35.0, 25.0], [40.0, 0.0])  # the drawing: every unknown 2 mm off
    data["synthesis"] = {"unknowns": UNKNOWNS,
                         "targets": [{"point": "P", "coordinates": ["x", "y"], "rows": rows}]}
    problem = graph_spec_from_data(data, "start.toml").synthesis
    assert problem is not None
    result = synthesize_graph(problem)
    truth = np.array([*true_c, *true_d]) * 1e-3
    assert result.status == "converged" and result.range_ok
    assert np.max(np.abs(result.x - truth)) < 1e-8 * 1e-3  # 1e-8 mm
    assert result.objective < 1e-20 and not result.at_bounds


def test_a_known_suspension_is_recovered_from_its_camber_and_toe_curves():
    """Spatial: targets from the double wishbone with the tie rod's inner ball and the upper
    ball moved; the drawing's values are the start."""
    base = tomllib.loads((MECH / "double_wishbone.toml").read_text(encoding="utf-8"))
    true = copy.deepcopy(base)
    names = [j["name"] for j in true["joints"]]
    true["joints"][names.index("TI")]["at"] = [-140.0, 362.0, 201.0]
    true["joints"][names.index("UB")]["at"] = [-5.0, 690.0, 478.0]
    spec = graph_spec_from_data(true, "true.toml")
    th = np.arange(-10.0, 10.1, 2.5)
    md = solve_mechanism(spec.mechanism, np.radians(th)[:, None]).modes[0]
    targets = [{"output": o, "rows": [[float(a), float(np.degrees(v))]
                                      for a, v in zip(th, md.outputs[o], strict=True)]}
               for o in ("camber", "toe")]
    base["synthesis"] = {"unknowns": ["joints.TI.at.y", "joints.TI.at.z", "joints.UB.at.z"],
                         "targets": targets}
    problem = graph_spec_from_data(base, "start.toml").synthesis
    assert problem is not None
    result = synthesize_graph(problem)
    assert result.status == "converged"
    np.testing.assert_allclose(result.x, np.array([362.0, 201.0, 478.0]) * 1e-3, rtol=0,
                               atol=1e-11)


def test_the_jacobian_agrees_with_a_five_point_stencil():
    """Central differences (the solver's) against the five-point stencil at another step, on
    coordinates of joints and points and an axis component of the double wishbone."""
    data = tomllib.loads((MECH / "double_wishbone.toml").read_text(encoding="utf-8"))
    data["synthesis"] = {
        "unknowns": ["joints.TI.at.z", "joints.UB.at.y", "joints.U.axis[2]",
                     "points.contact_patch.at.y"],
        "targets": [{"output": "camber", "expression": "0.1 * theta",
                     "design_points": {"start": -10, "stop": 10, "step": 5}},
                    {"point": "contact_patch", "rows": [[5, 0, 780, 30], [-5, 0, 770, -30]]}]}
    problem = graph_spec_from_data(data, "dw.toml").synthesis
    assert problem is not None
    x = problem.start_vector()
    j3 = graph_jacobian(problem, x)
    j5 = graph_jacobian(problem, x, step=3e-4, stencil=5)
    assert np.abs(j3).max() > 0
    np.testing.assert_allclose(j3, j5, rtol=0, atol=1e-7 * np.abs(j5).max())
    assert np.abs(j3[:, 3]).max() > 0  # the contact patch's coordinate moves its own target


def _loop_problem(start: dict[str, float]) -> LoopSynthesisProblem:
    fam = family("4R")
    dims = tuple(fam.dimensions)
    th = np.radians(np.arange(10.0, 91.0, 10.0))
    target = ScrewTarget(library_function("power", amplitude=math.radians(60),
                                          span=math.radians(90), power=2), th)
    return LoopSynthesisProblem(
        "4R", lambda v: fam.linkage(**{k: v[k] for k in dims}),
        lambda v: geometry.fourbar_geometry(**{k: v[k] for k in dims}), dict(fam.dimensions),
        target, start, ("d1", "d2", "d3", "theta01"), rotation_output="phi0", mode=0,
        length_scale=IN, max_iterations=300, time_limit=60.0)


def _fourbar_graph(b: np.ndarray, c: np.ndarray, a: float) -> dict:
    """A 4R drawn as a graph (inches): A at the origin, B, C as given, D at (a, 0); the rocker's
    rotation about z as an output; the target is the loop problem's. The loop's unknowns d1,
    θ01 are the crank's point B, d2, d3 the joint C."""
    th = np.arange(10.0, 91.0, 10.0)
    psi = 60.0 * (th / 90.0) ** 2
    return {
        "mechanism": {"name": "4R as a graph"}, "units": {"length": "in", "angle": "deg"},
        "bodies": [{"name": n} for n in ("crank", "coupler", "rocker")],
        "joints": [
            {"name": "A", "kind": "R", "between": ["ground", "crank"], "at": [0, 0, 0],
             "axis": [0, 0, 1], "input": True},
            {"name": "B", "kind": "R", "between": ["crank", "coupler"],
             "at": [float(b[0]), float(b[1]), 0.0], "axis": [0, 0, 1]},
            {"name": "C", "kind": "R", "between": ["coupler", "rocker"],
             "at": [float(c[0]), float(c[1]), 0.0], "axis": [0, 0, 1]},
            {"name": "D", "kind": "R", "between": ["rocker", "ground"], "at": [a, 0, 0],
             "axis": [0, 0, 1]}],
        "outputs": [{"name": "psi", "body": "rocker", "vector": [float(c[0]) - a,
                                                                  float(c[1]), 0],
                     "about": [0, 0, 1]}],
        "motion": {"start": 0, "stop": 90, "step": 1},
        "synthesis": {"unknowns": ["joints.B.at.x", "joints.B.at.y", "joints.C.at.x",
                                   "joints.C.at.y"],
                      "targets": [{"output": "psi", "rows": [[float(t), float(p)] for t, p
                                                             in zip(th, psi, strict=True)]}]}}


def test_the_four_bar_as_a_graph_reaches_the_loop_routes_optimum():
    """Bagci-style function generation ψ = 60° (θ/90°)² by a 4R with d1, d2, d3, θ01 free: the
    loop route and the graph (B and C free) from the same start (near the loop route's optimum
    found from its own start: the problem has other local optima) reach the same four-bar."""
    first = synthesize_loop(_loop_problem(dict(a=3 * IN, d1=IN, d2=3 * IN, d3=2.5 * IN,
                                               theta01=math.radians(60))))
    d = first.dimensions
    start = dict(a=3 * IN, d1=1.04 * d["d1"], d2=0.97 * d["d2"], d3=1.05 * d["d3"],
                 theta01=d["theta01"] + 0.03)
    loop = _loop_problem(start)
    r_loop = LoopResidualModel(loop, 0).evaluate(loop.start_vector()).residuals
    # the drawing of the start: C where the coupler meets the rocker, both assemblies; the one
    # generating the loop's rotation is the loop's mode
    b = start["d1"] / IN * np.array([math.cos(start["theta01"]), math.sin(start["theta01"])])
    dd = np.array([3.0, 0.0])
    dist = float(np.linalg.norm(dd - b))
    r2, r3 = start["d2"] / IN, start["d3"] / IN
    along = (dist**2 + r2**2 - r3**2) / (2 * dist)
    u = (dd - b) / dist
    n = np.array([-u[1], u[0]])
    same = []
    for sign in (1, -1):
        c = b + along * u + sign * math.sqrt(r2**2 - along**2) * n
        problem = graph_spec_from_data(_fourbar_graph(b, c, 3.0), "4r.toml").synthesis
        assert problem is not None
        r = graph_residuals(problem, problem.start_vector())
        same.append((float(np.max(np.abs(r - r_loop))), problem))
    gap, problem = min(same, key=lambda s: s[0])
    assert gap < 1e-10  # the graph generates the loop's rotation on the same branch
    ours = synthesize_graph(problem)
    ref = synthesize_loop(loop)
    assert ours.status == ref.status == "converged"
    assert ours.objective == pytest.approx(ref.objective, rel=1e-9)
    assert ref.relative_gradient < 1e-8 and ours.range_ok and ref.range_check.ok
    bx, by, cx, cy = ours.x  # the graph's hardpoints as the loop's dimensions
    dims = ref.dimensions
    # the optimum lies in a flat valley: two graph solves whose residuals differ only in
    # round-off (~5e-15 against 4.5e-4; the dyads' route and the loop engine's) end 1.3e-7
    # apart with objectives equal to 1.3e-12, so the dimensions are fixed to ~1e-6, not better
    assert math.hypot(bx, by) == pytest.approx(dims["d1"], rel=1e-6)
    assert math.atan2(by, bx) % (2 * math.pi) == pytest.approx(dims["theta01"], rel=1e-6)
    assert math.hypot(cx - bx, cy - by) == pytest.approx(dims["d2"], rel=1e-6)
    assert math.hypot(cx - 3 * IN, cy) == pytest.approx(dims["d3"], rel=1e-6)


def test_a_design_whose_drawn_mode_does_not_assemble_is_infeasible_not_switched():
    """Rocker pivot D at (45, 30) mm: the drawn mode reaches 60° of crank rotation, not 90°."""
    data = _fourbar([35.0, 25.0], [40.0, 0.0])
    data["synthesis"] = {"unknowns": UNKNOWNS, "targets": [
        {"point": "P", "coordinates": ["x"], "rows": [[90, 10]]}]}
    problem = graph_spec_from_data(data, "x.toml").synthesis
    assert problem is not None
    far = problem.start_vector() + np.array([0.0, 0.0, 5e-3, 30e-3])
    with pytest.raises(SynthesisError, match="does not assemble|stops assembling"):
        graph_residuals(problem, far)
    # a drawing that cannot reach a target input on its drawn mode is refused, not re-assembled
    data["joints"][3]["at"] = [45.0, 30.0, 0.0]
    p2 = graph_spec_from_data(data, "y.toml").synthesis
    assert p2 is not None
    with pytest.raises(SynthesisError, match="cannot start from the drawing"):
        synthesize_graph(p2)


def test_multistart_keeps_the_best_and_reports_bounds():
    data = _fourbar([35.0, 25.0], [40.0, 0.0])
    rows = _path_rows(_fourbar([33.0, 27.0], [42.0, 2.0]), np.arange(0.0, 360.0, 60.0))
    data["synthesis"] = {"unknowns": UNKNOWNS, "bounds": {"joints.D.at.x": [38, 41]},
                         "multistart": {"starts": 3, "seed": 1, "keep": 2},
                         "targets": [{"point": "P", "coordinates": ["x", "y"], "rows": rows}]}
    problem = graph_spec_from_data(data, "x.toml").synthesis
    assert problem is not None
    results = synthesize_graph_multistart(problem)
    best = results[0]
    assert best.at_bounds["joints.D.at[0]"] == ("upper", pytest.approx(0.041))
    assert "ended on its upper bound" in best.message
    assert all(best.objective <= r.objective for r in results)
    # the Python front door takes the graph's problem too: the same results
    import screwkit as sk

    again = sk.synthesize(problem)
    assert [r.objective for r in again] == [r.objective for r in results]
    with pytest.raises(sk.ScrewkitError, match="synthesize: starts"):
        sk.synthesize(problem, starts=0)


@pytest.mark.parametrize(("change", "words"), [
    ({"unknowns": ["joints.Q.at.x"]}, ["no joint 'Q'", "A, B, C, D"]),
    ({"unknowns": ["bodies.coupler.mass"]}, ["not a hardpoint or axis", "joints.A.at[0..2]"]),
    ({"bounds": {"joints.C.at.x": [40, 30]}}, ["bounds.joints.C.at.x", "swap"]),
    ({"bounds": {"joints.C.at.x": [36, 40]}}, ["outside its bounds"]),
    ({"targets": [{"point": "P", "rows": [[400, 1, 2, 3]]}]}, ["outside the spec's motion",
                                                              "400 deg"]),
    ({"targets": [{"point": "Z", "rows": [[10, 1, 2, 3]]}]}, ["no point 'Z'"]),
    ({"targets": [{"output": "camber", "rows": [[10, 1]]}]}, ["no output 'camber'"]),
    ({"targets": [{"variable": "C.theta", "rows": [[10, 1, 2]]}]}, ["rows.0", "1 target"]),
    ({"mode": 1}, ["mode", "drawn mode is followed"]),
    ({"solver": "generic"}, ["solver"]),
    ({"unknown_key": 1}, ["unknown_key"]),
])
def test_bad_synthesis_tables_are_refused_with_the_key(change, words):
    data = _fourbar([35.0, 25.0], [40.0, 0.0])
    data["synthesis"] = {"unknowns": ["joints.C.at.x"],
                         "targets": [{"variable": "C.theta", "rows": [[10, 5]]}]}
    data["synthesis"].update(change)
    with pytest.raises(SpecError) as err:
        graph_spec_from_data(data, "bad.toml")
    for w in words:
        assert w in str(err.value)


def test_cli_synthesizes_the_suspension_and_writes_a_spec_that_reproduces_it(tmp_path):
    out = tmp_path / "tuned.toml"
    r = runner.invoke(app, ["synthesize", str(MECH / "double_wishbone_synthesis.toml"),
                            "--json", "--spec-out", str(out)])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["status"] == "converged" and doc["range_check"]["ok"]
    assert doc["synthesised_spec"] == str(out)
    text = out.read_text(encoding="utf-8")
    assert "# Camber and bump steer tuned" in text and "# lower arm hinge" in text  # comments
    spec = load_spec(out)
    by_name = {v["name"]: v for v in doc["variables"]}
    for k, name in ((1, "U"), (2, "U"), (2, "UB"), (1, "TI"), (2, "TI")):
        j = [jt for jt in spec.mechanism.joints if jt.name == name][0]
        assert j.at[k] * 1e3 == pytest.approx(by_name[f"joints.{name}.at[{k}]"]["after"],
                                              rel=1e-12)
    assert any(v["on_bound"] for v in doc["variables"]) == bool(doc["at_bounds"])
    # the written spec, analysed anew, generates the reported camber and toe
    rows = [row for row in doc["rows"] if row["target"].startswith("output")]
    x = np.array([row["input"] for row in rows])
    md = solve_mechanism(spec.mechanism, x).modes[0]
    for i, row in enumerate(rows):
        name = row["target"].split()[-1]
        assert md.outputs[name][i] == pytest.approx(row["generated"][0], abs=1e-12)
        assert abs(row["error"][0]) < math.radians(0.01)
    # its report plots the targets against what the synthesised drawing generates
    from screwkit.report.graph_scene import graph_spec_scene

    plots = {p["title"]: p for p in graph_spec_scene(spec)["plots"] if p["group"] == "synthesis"}
    for name in ("camber", "toe"):
        series = {s["name"]: s for s in plots[f"output {name}: desired vs generated"]["series"]}
        mine = sorted((r["input"][0], r["generated"][0]) for r in rows
                      if r["target"] == f"output {name}")
        np.testing.assert_allclose(series["generated"]["x"], [m[0] for m in mine], atol=1e-15)
        np.testing.assert_allclose(series["generated"]["y"], [m[1] for m in mine], atol=1e-12)


def test_cli_bad_input_exits_2_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (MECH / "double_wishbone_synthesis.toml").read_text(encoding="utf-8")
    bad.write_text(text.replace('"joints.TI.at.z" = [150, 230]', '"joints.TI.at.z" = [230, 150]'),
                   encoding="utf-8")
    out = tmp_path / "out.toml"
    r = runner.invoke(app, ["synthesize", str(bad), "--spec-out", str(out)])
    assert r.exit_code == 2 and "swap" in r.output and not out.exists()
    r = runner.invoke(app, ["synthesize", str(MECH / "double_wishbone_synthesis.toml"),
                            "--plot", str(tmp_path / "x.txt"), "--csv", str(tmp_path / "x.csv")])
    assert r.exit_code == 2 and "--plot" in r.output and ".png" in r.output
    assert not (tmp_path / "x.txt").exists() and not (tmp_path / "x.csv").exists()
    r = runner.invoke(app, ["synthesize", str(MECH / "double_wishbone_synthesis.toml"),
                            "--workers", "2"])
    assert r.exit_code == 2 and "--workers" in r.output


def test_cli_csv_and_plot_of_a_graph_synthesis(tmp_path):
    import csv

    from screwkit.report.graph_synthesis_plots import _dense_curve

    spec_path = MECH / "double_wishbone_synthesis.toml"
    table, png = tmp_path / "rows.csv", tmp_path / "fit.png"
    r = runner.invoke(app, ["synthesize", str(spec_path), "--json", "--csv", str(table),
                            "--plot", str(png)])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    # the CSV (the spec's units: mm, deg) read back equals the JSON rows (SI) to round-off
    with table.open(encoding="utf-8", newline="") as fh:
        lines = list(csv.DictReader(fh))
    expected = [(row, c) for row in doc["rows"] for c in range(len(row["desired"]))]
    assert len(lines) == len(expected) == 17  # 9 camber rows, 8 toe rows
    for line, (row, c) in zip(lines, expected, strict=True):
        assert (line["target"], line["kind"], line["component"]) == (row["target"], row["kind"], "")
        assert float(line["input_L.theta [deg]"]) == pytest.approx(
            math.degrees(row["input"][0]), rel=1e-14, abs=1e-13)
        scale, unit = (math.degrees(1.0), "deg") if row["kind"] == "angle" else (1e3, "mm")
        other = "length [mm]" if row["kind"] == "angle" else "angle [deg]"
        for q in ("desired", "generated", "error"):
            assert float(line[f"{q}_{row['kind']} [{unit}]"]) == pytest.approx(
                row[q][c] * scale, rel=1e-13, abs=1e-15)
            assert line[f"{q}_{other}"] == ""
    # the plot is a PNG; its curve (the design solved anew on 121 inputs) passes through the
    # generated values of the document at the target inputs (-10, -7.5, ..., 10 deg: grid
    # points, the grid's step being 1/6 deg)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    problem = load_spec(spec_path).synthesis
    x = np.array([doc["x"][v.label] for v in problem.variables])
    for k, t in enumerate(problem.targets):
        grid, vals = _dense_curve(problem, x, k)
        gen = [row["generated"][0] for row in doc["rows"] if row["target"] == t.label]
        at = np.rint((t.inputs[:, 0] - grid[0]) / (grid[1] - grid[0])).astype(int)
        np.testing.assert_allclose(grid[at], t.inputs[:, 0], atol=1e-15)
        np.testing.assert_allclose(vals[at, 0], gen, atol=1e-10)
