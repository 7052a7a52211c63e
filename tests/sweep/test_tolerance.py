"""Tolerance analysis: the Jacobian sensitivities against re-solving the loop at perturbed
dimensions (every joint kind whose constants a dimension moves), the first-order stack-ups
against a Monte Carlo run on the sweep engine (RSRC and RSSR: agreement inside the Monte Carlo's
confidence interval; and disagreement when the tolerances are too large for first order), the
worst case against the solved corner design, and the command line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from sweep_helpers import EXAMPLES, runner

from screwkit.cli.main import app
from screwkit.kinematics.analysis.sensitivity import constants_derivative, joint_sensitivities
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.loop import layout
from screwkit.kinematics.tracker.solve import newton
from screwkit.model import families
from screwkit.model.joints import Joint
from screwkit.model.linkage import Linkage
from screwkit.pipeline import Pipeline
from screwkit.sweep.engine import EngineConfig, start_engine
from screwkit.sweep.monte_carlo import compare, run_monte_carlo
from screwkit.sweep.run import read_spec_tables
from screwkit.sweep.tolerance import ToleranceError, first_order, make_tolerances

X = np.radians(np.arange(0.0, 360.0, 20.0))


def _loop(o1: float, po: float, pitch: float) -> Linkage:
    joints = [Joint("i", "R", o1), Joint("c2", "C"), Joint("p", "P", po),
              Joint("h", "H", 0.1, pitch), Joint("c5", "C")]
    return Linkage.from_hartenberg_denavit("RCPHC", joints, [0.6, 2.63, 3.34, 1.91, 1.0],
                                           [0.4, -0.4, 0.55, 0.15, 0.3], ["i.theta"])


CASES = [
    (families.rsrc, dict(d1=2.0, d2=4.5, d3=3.0, a=3.0, b=3.0, e=1.0, delta0=np.radians(18),
                         lambda0=np.radians(60))),
    (families.rssr, dict(d1=25.0, d2=100.0, d3=75.0, a=75.0, b=50.0, lambda0=np.radians(50),
                         output_offset=12.5)),
    (families.cssp, dict(a1=2.0, a2=8.0, a4=1.0, alpha4=np.radians(250), s1=0.4)),
    (_loop, dict(o1=0.2, po=0.3, pitch=0.05)),  # offsets of R and P joints, an H pitch
]


@pytest.mark.parametrize(("build", "dims"), CASES, ids=["RSRC", "RSSR", "CSSP", "RCPHC"])
def test_jacobian_sensitivities_equal_re_solving_the_loop(build, dims):
    lk = build(**dims)
    mode = solve_motion(lk, X).modes[0]
    lay = layout(lk)
    ok = mode.assembles & ~mode.singular
    assert ok.sum() >= 3
    for key, value in dims.items():
        def rebuild(v, key=key):
            return build(**{**dims, key: v})

        sens = joint_sensitivities(lk, mode, constants_derivative(rebuild, value,
                                                                  1e-3 * max(abs(value), 1)))
        h = 1e-6 * max(abs(value), 1.0)
        plus, minus = (newton(rebuild(value + s * h), mode.conf, max_iter=50, tol=1e-14)
                       for s in (1, -1))
        for name, s in sens.items():
            col = lay.scalar_col[lay.names.index(name)]
            fd = (plus.conf.scalars[:, col] - minus.conf.scalars[:, col]) / (2 * h)
            # central differences of a re-solve (closed to 1e-14, step h) carry ~1e-14/h of
            # noise and O(h²) truncation; the Jacobian result is exact
            assert np.max(np.abs(s[ok] - fd[ok])) < 1e-6 * np.max(np.abs(fd[ok])) + 3e-8, \
                (key, name)


def _analysis(spec: str, tols: list[str], n: int, seed: int = 0, workers: int = 0):
    path = EXAMPLES / spec
    data, s = read_spec_tables(path)
    tolerances = make_tolerances(data, s, tols)
    pipe = Pipeline(s)
    fo = first_order(data, s, str(path), tolerances, pipe)
    with start_engine(EngineConfig(workers=workers)) as engine:
        dev = run_monte_carlo(engine, data, str(path), tolerances, pipe.mode(), fo, n, seed)
    return fo, tolerances, dev, compare(fo, tolerances, dev, seed)


@pytest.mark.parametrize(("spec", "tols"), [
    ("bagci_fig7_rsrc.toml", ["d2=±0.01in", "delta0=±0.1deg", "e=±0.1mm"]),
    ("rssr_spatial.toml", ["d2=±0.05mm", "lambda0=±0.05deg", "b=±0.05mm"]),
], ids=["RSRC", "RSSR"])
def test_first_order_agrees_with_monte_carlo(spec, tols):
    fo, tolerances, dev, mc = _analysis(spec, tols, 600)
    assert mc["failed_designs"] == 0 and mc["points_compared"] >= 18
    # every compared point: first-order σ inside the MC's (Bonferroni-corrected) interval
    assert mc["inside_bonferroni_interval"] == mc["points_compared"]
    assert mc["max_prediction_error_over_sigma"] < 0.05  # second order is small here
    assert mc["agree"]
    lo, hi = mc["std_ratio_range"]
    assert 0.85 < lo <= hi < 1.15
    for o in fo.outputs:  # worst case ≥ RSS, both ≥ 0
        assert np.all(fo.worst_case[o][np.isfinite(fo.worst_case[o])] >= fo.rss[o][np.isfinite(fo.rss[o])] - 1e-15)


def test_monte_carlo_detects_tolerances_too_large_for_first_order():
    _, _, _, mc = _analysis("bagci_fig7_rsrc.toml", ["d2=±0.8in", "delta0=±10deg"], 400)
    assert not mc["agree"]
    assert mc["max_prediction_error_over_sigma"] > 0.1


def test_worst_case_is_the_solved_corner_to_second_order():
    path = EXAMPLES / "bagci_fig7_rsrc.toml"
    data, s = read_spec_tables(path)
    tolerances = make_tolerances(data, s, ["d2=±0.002in", "delta0=±0.02deg", "a=±0.002in"])
    pipe = Pipeline(s)
    fo = first_order(data, s, str(path), tolerances, pipe)
    mode = pipe.mode()
    i = 4  # one input sample
    signs = np.sign([fo.sensitivity["phi0"][t.key.text][i] for t in tolerances])
    from screwkit.io.spec import spec_from_data
    from screwkit.sweep.keys import with_values
    from screwkit.sweep.tolerance import rebuilt_linkage

    corner = [(t.key.path, t.key.toml_value(t.nominal + sg * t.tolerance))
              for t, sg in zip(tolerances, signs, strict=True)]
    lk = spec_from_data(with_values(data, corner), str(path)).linkage
    solved = newton(lk, mode.conf.take(np.array([i])), tol=1e-14)
    lay = layout(lk)
    col = lay.scalar_col[lay.names.index("output_C.theta")]
    moved = -(solved.conf.scalars[0, col] - mode.conf.scalars[i, col])  # φ0 = −output_C.theta
    assert moved == pytest.approx(fo.worst_case["phi0"][i], rel=1e-3)
    assert rebuilt_linkage  # the helper the first-order path uses


@pytest.mark.parametrize(("tol", "message"), [
    ("d2=0.05mm", "KEY=±T"), ("d2=±-1mm", "positive"), ("d2=±x", "cannot read"), ("d2=±0.05kg", "length"),
    ("links.crank.mass=±0.01kg", "does not change the loop"), ("d9=±1mm", "d9"),
])
def test_bad_tolerances_are_clear_errors(tol, message):
    path = EXAMPLES / "rsrc_fig7_dynamics.toml"
    data, s = read_spec_tables(path)
    with pytest.raises(ToleranceError, match=message):
        tols = make_tolerances(data, s, [tol])
        first_order(data, s, str(path), tols, Pipeline(s))


def test_tolerance_command_on_the_embedded_cluster(tmp_path):
    out, png = tmp_path / "tol.json", tmp_path / "tol.png"
    r = runner.invoke(app, ["tolerance", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--tol",
                            "d2=±0.01in", "--tol", "lambda0=+-0.05deg", "--monte-carlo", "300",
                            "--workers", "2", "-o", str(out), "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert png.exists() and "wrote" in r.stdout  # -o: one line (docs/cli.md)
    doc = json.loads(out.read_text())
    assert doc["monte_carlo"]["agree"] and doc["monte_carlo"]["samples"] == 300
    assert set(doc["outputs"]) == {"phi0", "chi0", "S"}
    assert doc["tolerances"][0] == {"key": "dimensions.d2", "unit": "in", "nominal": 4.5,
                                    "tolerance": 0.01}
    # the same draw in this process gives the same numbers (the engine does not matter)
    r2 = runner.invoke(app, ["tolerance", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--tol",
                             "d2=±0.01in", "--tol", "lambda0=+-0.05deg", "--monte-carlo", "300",
                             "--workers", "0", "--json"])
    assert json.loads(r2.stdout)["monte_carlo"] == doc["monte_carlo"]
    assert Path(out).read_text().count("NaN") == 0


def test_tolerance_tables_are_in_the_spec_units():
    """An inch spec gives its stack-ups in inches (and deg); the JSON stays SI."""
    spec = str(EXAMPLES / "bagci_fig7_rsrc.toml")
    args = ["tolerance", spec, "--tol", "d2=±0.01in", "--monte-carlo", "0"]
    doc = json.loads(runner.invoke(app, [*args, "--json"]).stdout)
    r = runner.invoke(app, args, env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    assert "lengths in in" in r.output
    s_row = next(row for row in doc["summary"] if row["output"] == "S")
    shown = next(line for line in r.output.splitlines() if line.strip("│ ").startswith("S "))
    value = float(shown.split("│")[2])
    assert value == pytest.approx(s_row["max_worst_case"] / 0.0254, rel=1e-4)
