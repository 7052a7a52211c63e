"""Sweeps and tolerance analysis of graph specs (docs/sweeps.md, "Graph specs"): a sweep row
equals ``screwkit analyze`` on the design written as its own file; the Dask engine gives the
same table; hardpoints made off the drawing re-assemble (a rigid shift of every chassis point
moves the suspension rigidly); the first-order sensitivities equal central differences of
re-solved motions; the worst case equals the brute-force corner enumeration; the Monte Carlo
agrees with the RSS within its sampling error; a zero tolerance gives zero spread."""

from __future__ import annotations

import itertools
import json
from dataclasses import replace

import numpy as np
import pytest
from sweep_helpers import EXAMPLES, command_json, runner, toml_text

from screwkit.cli.main import app
from screwkit.io.toml_file import read_toml
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.sweep import EngineConfig, JobOptions, define_sweep, run_sweep
from screwkit.sweep.engine import start_engine
from screwkit.sweep.graph_tolerance import (
    graph_first_order,
    graph_monte_carlo_batch,
    hardpoints,
    made_off,
    output_values,
    run_graph_monte_carlo,
)
from screwkit.sweep.keys import with_values
from screwkit.sweep.monte_carlo import compare
from screwkit.sweep.run import read_spec_tables
from screwkit.sweep.table import read_table
from screwkit.sweep.tolerance import Tolerance, make_tolerances

WISHBONE = EXAMPLES / "mechanisms" / "double_wishbone.toml"
FOURBAR = EXAMPLES / "mechanisms" / "fourbar_graph.toml"


def _small_wishbone(tmp_path, step="2.5"):
    """The suspension over ±10° in fewer samples (fast)."""
    data = read_toml(WISHBONE)
    data["motion"]["step"] = float(step)
    path = tmp_path / "wishbone.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    return path


def test_sweep_rows_equal_the_analyze_command_on_each_design(tmp_path):
    spec = _small_wishbone(tmp_path)
    d = define_sweep(spec, ["joints.UB.at.z=465:475:2", "points.contact_patch.at[1]=770:780:2"],
                     "analyze")
    assert [k.text for k in d.designs.keys] == ["joints.UB.at[2]", "points.contact_patch.at[1]"]
    out = tmp_path / "t.csv"
    run_sweep(d, out, EngineConfig(workers=0))
    rows = read_table(out)
    assert [r["joints.UB.at[2] [mm]"] for r in rows] == [465.0, 465.0, 475.0, 475.0]
    data = read_toml(spec)
    for row in rows:
        i = row["design"]
        design = with_values(data, [(k.path, v) for k, v in zip(
            d.designs.keys, [v for _, v in d.designs.overrides(i)], strict=True)])
        f = tmp_path / f"design{i}.toml"
        f.write_text(toml_text(design), encoding="utf-8")
        doc = command_json("analyze", str(f))
        assert row["status"] == "ok" and row["assembles"] and row["where"] == "everywhere"
        for name, o in doc["modes"][0]["outputs"].items():
            v = np.asarray(o["value"], dtype=float)
            assert row[f"mode0.{name}.min"] == pytest.approx(v.min(), abs=1e-15)
            assert row[f"mode0.{name}.max"] == pytest.approx(v.max(), abs=1e-15)
            assert row[f"mode0.{name}.mean"] == pytest.approx(v.mean(), rel=1e-12, abs=1e-15)
            assert row[f"mode0.{name}.range"] == pytest.approx(v.max() - v.min(), abs=1e-15)
    # the override reached the model: the upper ball's height changes the camber curve
    assert rows[0]["mode0.camber.range"] != rows[2]["mode0.camber.range"]


def test_graph_sweep_on_the_embedded_cluster_gives_the_same_table(tmp_path):
    vary = ["joints.C.at[0]=34:36:3", "joints.B.at.y=-1:1:2"]
    tables = []
    for workers, name in ((0, "a.csv"), (2, "b.csv")):
        r = runner.invoke(app, ["sweep", str(FOURBAR), *sum((["--vary", v] for v in vary), []),
                                "--job", "analyze", "-o", str(tmp_path / name),
                                "--workers", str(workers)])
        assert r.exit_code == 0, r.output
        tables.append((tmp_path / name).read_bytes())
    assert tables[0] == tables[1]
    rows = read_table(tmp_path / "a.csv")
    assert len(rows) == 6 and all(r["status"] == "ok" for r in rows)


def test_graph_sweep_dynamics_rows(tmp_path):
    spec = _small_wishbone(tmp_path, "5")
    d = define_sweep(spec, ["bodies.upright.mass=400g:600g:2"], "dynamics",
                     options=JobOptions(gravity=True))
    out = tmp_path / "d.parquet"
    run_sweep(d, out, EngineConfig(workers=0))
    rows = read_table(out)
    assert all(r["status"] == "ok" for r in rows)
    # the effort of holding the upright against gravity grows with its mass
    assert rows[1]["effort.L.theta.rms"] > rows[0]["effort.L.theta.rms"] > 0


def test_a_rigid_shift_of_every_chassis_point_moves_the_suspension_rigidly():
    _, spec = read_spec_tables(WISHBONE)
    mech = spec.mechanism
    nominal = solve_mechanism(mech, spec.inputs).modes[0]
    shift = np.array([1e-3, 2e-3, -1.5e-3])
    ground = [replace(j, at=j.at + shift, seat_offset=shift) if j.bodies[0] == "ground" else j
              for j in mech.joints]
    moved = solve_mechanism(replace(mech, joints=tuple(ground)), spec.inputs).modes[0]
    assert moved.assembles.all() and np.nanmax(moved.closure_residual) < 1e-12
    for name in ("camber", "toe"):
        assert np.max(np.abs(moved.outputs[name] - nominal.outputs[name])) < 1e-12
    for p in ("wheel_centre", "contact_patch"):
        assert np.max(np.abs(moved.points[p] - nominal.points[p] - shift)) < 1e-12


def _wishbone_tolerances(texts, path=WISHBONE):
    data, spec = read_spec_tables(path)
    tolerances = make_tolerances(data, spec, texts)
    mode = solve_mechanism(spec.mechanism, spec.inputs).modes[0]
    return spec, tolerances, mode


def test_sensitivities_equal_central_differences_of_re_assembled_motions():
    spec, tols, mode = _wishbone_tolerances(["joints.*.at=±0.5mm", "points.*.at=±0.5mm"])
    assert len(tols) == 24
    fo = graph_first_order(spec, tols, mode)
    mech, pts = spec.mechanism, hardpoints(tols)
    h = 1e-3  # mm
    for i in (0, 5, 10, 13, 17, 20, 23):
        e = np.zeros(len(tols))
        e[i] = h
        plus, minus = (solve_mechanism(made_off(mech, pts, s * e), spec.inputs).modes[0]
                       for s in (1, -1))
        lay = graph_layout(mech)
        yp = output_values(made_off(mech, pts, e), lay, plus.conf, mech)
        ym = output_values(made_off(mech, pts, -e), lay, minus.conf, mech)
        for o in fo.outputs:
            fd = (yp[o] - ym[o]) / (2 * h)
            s = fo.sensitivity[o][tols[i].key.text]
            scale = max(np.max(np.abs(fd)), 1e-9)
            # re-assembled and tracked motions closed to 1e-13 carry ~1e-13/h of noise
            assert np.max(np.abs(s - fd)) < 1e-6 * scale + 1e-9, (o, tols[i].key.text)
    # RSS and worst case are the sums of those sensitivities
    t = np.array([x.tolerance for x in tols])
    for o in fo.outputs:
        S = np.stack([fo.sensitivity[o][x.key.text] for x in tols])
        assert np.allclose(fo.rss[o], np.sqrt(((S * t[:, None]) ** 2).sum(0)), rtol=1e-14)
        assert np.allclose(fo.worst_case[o], (np.abs(S) * t[:, None]).sum(0), rtol=1e-14)


def test_worst_case_is_the_largest_of_the_corners_enumerated():
    spec, tols, mode = _wishbone_tolerances(["joints.UB.at=±0.02mm"])
    fo = graph_first_order(spec, tols, mode)
    mech, pts = spec.mechanism, hardpoints(tols)
    lay = graph_layout(mech)
    nominal = output_values(mech, lay, mode.conf, mech)
    worst = {o: np.zeros(mode.assembles.size) for o in fo.outputs}
    for signs in itertools.product((-1.0, 1.0), repeat=3):
        d = np.array(signs) * 0.02
        design = made_off(mech, pts, d)
        corner = solve_mechanism(design, spec.inputs).modes[0]
        y = output_values(design, lay, corner.conf, mech)
        for o in fo.outputs:
            worst[o] = np.maximum(worst[o], np.abs(y[o] - nominal[o]))
    for o in fo.outputs:  # equal up to the second-order terms, (0.02 mm / 0.5 m)-relative
        assert np.allclose(worst[o], fo.worst_case[o], rtol=2e-3, atol=1e-12), o


def test_monte_carlo_agrees_with_rss_within_its_sampling_error(tmp_path):
    spec, tols, mode = _wishbone_tolerances(["joints.*.at=±0.5mm"], _small_wishbone(tmp_path))
    fo = graph_first_order(spec, tols, mode)
    n = 300
    with start_engine(EngineConfig(workers=0)) as engine:
        dev = run_graph_monte_carlo(engine, spec, tols, mode, fo, n, 0)
    mc = compare(fo, tols, dev, 0)
    assert mc["failed_designs"] == 0 and mc["points_compared"] == 3 * 9
    assert mc["agree"] and mc["inside_bonferroni_interval"] == mc["points_compared"]
    # σ's relative standard error is 1/√(2(n−1)) ≈ 4.1 %: every ratio within 4 of those
    lo, hi = mc["std_ratio_range"]
    bound = 4 / np.sqrt(2 * (n - 1))
    assert 1 - bound < lo <= hi < 1 + bound
    # the mean deviation is zero to first order: within 4 standard errors σ/√n
    assert mc["max_mean_shift_over_sigma"] < 4 / np.sqrt(n)
    # each design's Newton solve from the nominal mode equals re-assembling and tracking it
    pts = hardpoints(tols)
    rng = np.random.default_rng(1)
    d = rng.normal(0.0, 0.5 / 3, (2, len(tols)))
    values = np.array([t.nominal for t in tols]) + d
    idx, got = graph_monte_carlo_batch(_task(spec, tols, mode, fo), np.arange(2), values)
    lay = graph_layout(spec.mechanism)
    for r in range(2):
        design = made_off(spec.mechanism, pts, d[r])
        solved = solve_mechanism(design, spec.inputs).modes[0]
        y = output_values(design, lay, solved.conf, spec.mechanism)
        for c, o in enumerate(fo.outputs):
            assert np.max(np.abs(got[r, c] - (y[o] - fo.nominal[o]))) < 1e-12


def _task(spec, tols, mode, fo):
    from screwkit.sweep.graph_tolerance import GraphMonteCarloTask

    idx = np.arange(mode.assembles.size)
    return GraphMonteCarloTask(spec.mechanism, tuple(hardpoints(tols)),
                               np.array([t.nominal for t in tols]), mode.conf.scalars,
                               mode.conf.spherical, spec.inputs, idx, idx.size,
                               tuple(fo.outputs), np.stack([fo.nominal[o] for o in fo.outputs]))


def test_a_zero_tolerance_gives_zero_spread():
    spec, tols, mode = _wishbone_tolerances(["joints.LB.at=±0.5mm"])
    zero = [Tolerance(t.key, t.nominal, 0.0) for t in tols]
    fo = graph_first_order(spec, zero, mode)
    for o in fo.outputs:
        assert np.all(fo.worst_case[o] == 0.0) and np.all(fo.rss[o] == 0.0)
    with start_engine(EngineConfig(workers=0)) as engine:
        dev = run_graph_monte_carlo(engine, spec, zero, mode, fo, 5, 0)
    assert np.all(dev == 0.0)


def test_tolerance_command_on_a_graph_spec(tmp_path):
    spec = _small_wishbone(tmp_path, "5")
    out = tmp_path / "tol.json"
    r = runner.invoke(app, ["tolerance", str(spec), "--tol", "joints.*.at=±0.5mm",
                            "--tol", "points.wheel_centre.at=±0.5mm", "--monte-carlo", "120",
                            "--workers", "0", "-o", str(out), "--plot",
                            str(tmp_path / "tol.png")])
    assert r.exit_code == 0, r.output
    doc = json.loads(out.read_text())
    assert set(doc["outputs"]) == {"camber", "toe", "track_change"}
    assert doc["outputs"]["camber"]["kind"] == "angle"
    assert doc["outputs"]["track_change"]["kind"] == "length"
    assert len(doc["tolerances"]) == 21 and doc["tolerances"][0]["unit"] == "mm"
    assert doc["monte_carlo"]["agree"] and doc["monte_carlo"]["failed_designs"] == 0
    assert (tmp_path / "tol.png").stat().st_size > 1000
    r = runner.invoke(app, ["tolerance", str(spec), "--tol", "joints.UB.at[2]=±0.5mm",
                            "--monte-carlo", "0"], env={"COLUMNS": "80"})
    assert r.exit_code == 0, r.output
    assert "camber" in r.output and "joints.UB.at[2]" in r.output
    # without --tol: the spec's [tolerances] table (every hardpoint ±0.5 mm)
    r = runner.invoke(app, ["tolerance", str(spec), "--monte-carlo", "0", "--json"])
    assert r.exit_code == 0, r.output
    assert len(json.loads(r.stdout)["tolerances"]) == 24


def test_the_headline_numbers_of_docs_sweeps():
    """docs/sweeps.md, "Tolerances on a graph": ±0.5 mm on every hardpoint coordinate."""
    spec, tols, mode = _wishbone_tolerances(["joints.*.at=±0.5mm", "points.*.at=±0.5mm"])
    fo = graph_first_order(spec, tols, mode)
    deg = np.degrees
    got = {o: (np.nanmax(fo.worst_case[o]), np.nanmax(fo.rss[o])) for o in fo.outputs}
    assert deg(got["camber"][0]) == pytest.approx(0.430, abs=5e-4)
    assert deg(got["camber"][1]) == pytest.approx(0.171, abs=5e-4)
    assert deg(got["toe"][0]) == pytest.approx(0.987, abs=5e-4)
    assert deg(got["toe"][1]) == pytest.approx(0.393, abs=5e-4)
    assert got["track_change"][0] * 1e3 == pytest.approx(2.52, abs=5e-3)
    assert got["track_change"][1] * 1e3 == pytest.approx(1.11, abs=5e-3)


def test_graph_monte_carlo_on_the_embedded_cluster_equals_the_in_process_run(tmp_path):
    spec, tols, mode = _wishbone_tolerances(["joints.UB.at=±0.5mm", "points.*.at=±0.5mm"],
                                            _small_wishbone(tmp_path, "5"))
    fo = graph_first_order(spec, tols, mode)
    runs = []
    for workers in (0, 2):
        with start_engine(EngineConfig(workers=workers)) as engine:
            runs.append(run_graph_monte_carlo(engine, spec, tols, mode, fo, 40, 3))
    assert np.isfinite(runs[0]).all()
    assert np.array_equal(runs[0], runs[1])


def test_a_loop_spec_reads_its_tolerances_table_and_tol_replaces_it(tmp_path):
    from screwkit.sweep.tolerance import tolerance_texts

    data = read_toml(EXAMPLES / "bagci_fig7_rsrc.toml")
    data["tolerances"] = {"d2": "±0.01 in", "delta0": "+-0.1 deg"}
    path = tmp_path / "rsrc.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    data, spec = read_spec_tables(path)
    tols = make_tolerances(data, spec, tolerance_texts(data, None))
    assert [(t.key.text, t.tolerance) for t in tols] == [("dimensions.d2", 0.01),
                                                         ("dimensions.delta0", 0.1)]
    tols = make_tolerances(data, spec, tolerance_texts(data, ["e=±0.1mm"]))
    assert [t.key.text for t in tols] == ["dimensions.e"]
