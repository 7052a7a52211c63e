"""``screwkit limits`` on mechanism graphs driven by body freedoms (``[[drives]]``,
kinematics/graph/limits_driven.py), checked two ways:

* against a dense-sampling brute force: the outputs (joint freedoms and named outputs) solved
  at 400 points per segment between the input rows; every change of direction of a sampled
  output inside a segment is one reported limit (and no other is reported), the reported input
  lies within one dense step of it, and the reported value is at least as extreme as every
  dense sample of that segment (to round-off) and within the sampling error y''·h²/8 of the
  most extreme one;
* by a physical fact: a four-bar's rocker swings between the same two extremes whatever drives
  it. Driven by the travel of a coupler point, the rocker's limit is the crank-driven
  mechanism's (graph/limits.py, itself checked against the collinearity of crank and coupler)
  to 1e-9, and the coupler point there is where the crank-driven motion puts it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.limits import graph_limit_positions
from screwkit.kinematics.graph.limits_driven import driven_outputs

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
DENSE = 400
runner = CliRunner()


def _point_driven_fourbar(tmp_path: Path) -> Path:
    """The four-bar driven by its coupler point P's x travel, 1 to 17.5 mm below the drawing:
    the crank turns back from near 0° to about −168° (P's x falls monotonically there), past the
    rocker's limit at −141.7°."""
    text = (EXAMPLES / "fourbar_graph.toml").read_text(encoding="utf-8")
    text = text.replace("input = true\n", "")
    text = text.replace("[motion]\nstart = 0\nstop = 360\nstep = 1",
                        '[[drives]]\npoint = "P"\nfreedom = "x"\n\n'
                        "[motion]\nstart = -17.5\nstop = -1\nstep = 0.5")
    path = tmp_path / "fourbar_point_driven.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _limits(path: Path, *args: str) -> dict:
    r = runner.invoke(app, ["limits", str(path), "--json", *args])
    assert r.exit_code == 0, r.output
    return json.loads(r.output)


def _dense(mech: sk.Mechanism, X: np.ndarray) -> object:
    """The drawn mode at DENSE + 1 points of every segment between the rows (one solve)."""
    t = np.arange(DENSE + 1) / DENSE
    D = np.diff(X, axis=0)
    rows = (X[:-1, None, :] + t[None, :, None] * D[:, None, :]).reshape(-1, X.shape[1])
    md = solve_mechanism(mech, rows, rates=1.0, accelerations=0.0).modes[0]
    assert md.assembles.all()
    return md


def _check_against_brute(mech: sk.Mechanism, X: np.ndarray, doc: dict, along_rows: bool
                         ) -> int:
    """Every output's reported limits equal the brute force's (module docstring)."""
    D = np.diff(X, axis=0)
    md = _dense(mech, X)
    checked = 0
    for name in doc["outputs"]:
        y = md.outputs[name] if name in md.outputs else md.variables[name]  # type: ignore
        Y = y.reshape(len(D), DENSE + 1)
        got = [x for x in doc["limits"] if x["output"] == name]
        want = []
        for k, y in enumerate(Y):
            d = np.diff(y)
            for i in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0] + 1:
                want.append((k, i, y))
        assert len(got) == len(want), (name, len(got), len(want))
        for (k, i, y), lim in zip(want, got, strict=True):
            s = k + i / DENSE  # position in rows; with one freedom, the freedom's value
            where = lim["input"] if along_rows else (lim["input"] - X[0, 0]) / D[0, 0]
            assert abs(where - s) <= 1.0 / DENSE, (name, where, s)
            upper = y[i] > y[i - 1]  # a maximum
            span = np.abs(y).max() + np.abs(Y).max()
            v = lim["value"]
            assert (v >= y.max() - 1e-12 * span) if upper else (v <= y.min() + 1e-12 * span)
            d2 = lim["second_derivative"] * (1.0 if along_rows else D[0, 0] ** 2)  # per row
            assert abs(v - (y.max() if upper else y.min())) <= abs(d2) / DENSE**2 / 8 \
                + 1e-12 * span
            assert abs(lim["derivatives"][0]) <= 1e-9 * abs(lim["derivatives"][1]), name
            assert lim["dwell_order"] == 1 and np.sign(lim["second_derivative"]) == \
                (-1 if upper else 1)
            checked += 1
    return checked


def test_point_driven_fourbar_rocker_limit_is_the_crank_driven_one(tmp_path: Path) -> None:
    path = _point_driven_fourbar(tmp_path)
    doc = _limits(path, "--var", "D.theta")
    assert doc["input_name"] == "coupler.x" and doc["input_kind"] == "length"
    (lim,) = doc["limits"]
    crank = sk.load_spec(EXAMPLES / "fourbar_graph.toml")
    ref = [x for x in graph_limit_positions(solve_mechanism(crank.mechanism, crank.inputs),
                                            "D.theta").limits if x.input > np.pi]
    assert len(ref) == 1
    assert abs(lim["value"] - ref[0].value) <= 1e-9 * abs(ref[0].value)
    at = solve_mechanism(crank.mechanism, [[ref[0].input - 2 * np.pi]]).modes[0]
    px0 = crank.mechanism.points[0].at[0]
    assert abs(at.points["P"][0, 0] - px0 - lim["input"]) <= 1e-9 * 0.04
    # every output against the brute force, the rocker's limit among them
    spec = sk.load_spec(path)
    full = _limits(path)
    assert set(full["outputs"]) == set(driven_outputs(spec.mechanism))
    assert _check_against_brute(spec.mechanism, spec.inputs, full, along_rows=False) >= 1


def test_wheel_travel_suspension_against_brute_force() -> None:
    """Camber, toe, track change and every joint angle over ±50 mm of wheel travel."""
    path = EXAMPLES / "double_wishbone_travel.toml"
    doc = _limits(path)
    spec = sk.load_spec(path)
    assert set(doc["outputs"]) == set(driven_outputs(spec.mechanism))
    assert {"camber", "toe", "track_change", "L.theta", "U.theta"} <= set(doc["outputs"])
    _check_against_brute(spec.mechanism, spec.inputs, doc, along_rows=False)


def test_pose_driven_platform_along_its_rows_against_brute_force() -> None:
    """Six driven pose freedoms given as rows: the limits along the straight path through
    them, the position counted in rows, every driven freedom's value there."""
    path = EXAMPLES / "stewart_platform_pose.toml"
    doc = _limits(path)
    assert doc["input_name"] == "row" and doc["input_kind"] == "ratio"
    spec = sk.load_spec(path)
    X = np.asarray(spec.inputs, dtype=float)
    n = _check_against_brute(spec.mechanism, X, doc, along_rows=True)
    assert n >= 2
    for lim in doc["limits"]:
        k = int(lim["input"])
        t = lim["input"] - k
        want = X[k] + t * (X[k + 1] - X[k])
        got = [lim["variables"][d] for d in spec.mechanism.driven_names]
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_unknown_output_and_other_modes_are_refused(tmp_path: Path) -> None:
    r = runner.invoke(app, ["limits", str(EXAMPLES / "double_wishbone_travel.toml"),
                            "--var", "caster"])
    assert r.exit_code == 2
    assert "no output 'caster'; the outputs are camber, toe," in " ".join(r.output.split())
    spec = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml")
    motion = solve_mechanism(spec.mechanism, spec.inputs[:3])
    with pytest.raises(sk.ScrewkitError, match="drawn mode"):
        graph_limit_positions(motion, mode=1)


def test_named_outputs_of_a_joint_driven_suspension_against_brute_force(tmp_path: Path) -> None:
    """``--var camber`` (a named output) on the arm-driven double wishbone, over a wider arm
    swing than the example's, against the brute force; the arm-driven and travel-driven
    suspensions' camber limits are the same configuration."""
    text = (EXAMPLES / "double_wishbone.toml").read_text(encoding="utf-8")
    text = text.replace("start = -10\nstop = 10\nstep = 0.5", "start = -25\nstop = 25\nstep = 1")
    path = tmp_path / "wishbone_wide.toml"
    path.write_text(text, encoding="utf-8")
    spec = sk.load_spec(path)
    assert spec.inputs.max() > np.radians(24)
    n = 0
    for name in ("camber", "toe", "track_change"):
        doc = _limits(path, "--var", name)
        assert doc["outputs"] == [name] and doc["input_name"] == "L.theta"
        n += _check_against_brute(spec.mechanism, spec.inputs, doc, along_rows=False)
    assert n >= 1


def test_the_studio_lists_the_limits_of_a_pose_driven_platform() -> None:
    """The studio's numbers (screwkit.studio.graph) give the same limits, at rows of the path."""
    from screwkit.studio.graph import GraphRun, graph_numbers

    path = EXAMPLES / "stewart_platform_pose.toml"
    doc = _limits(path)
    rows = {r[0]: r[1] for r in graph_numbers(GraphRun(sk.load_spec(path), 0))}
    assert doc["limits"]
    for lim in doc["limits"]:
        text = rows[f"limit of {lim['output']}, mode 0"]
        assert f"at row {lim['input']:.6g} of the input path (dwell order 1)" in text


def test_the_way_to_a_segment_through_every_row_gives_the_same_limit(tmp_path: Path,
                                                                      monkeypatch) -> None:
    """A segment is reached straight from the drawing only when that lands where the motion
    is; otherwise through every row before it: both routes give the same limit here, and a
    start the motion is not at is told apart."""
    import dataclasses

    from screwkit.kinematics.graph import limits_driven

    spec = sk.load_spec(_point_driven_fourbar(tmp_path))
    motion = solve_mechanism(spec.mechanism, spec.inputs)
    md = motion.modes[0]
    X = np.asarray(spec.inputs, dtype=float)
    assert limits_driven._way_to(spec.mechanism, X, 5, md).shape == (1, 1)
    moved = dataclasses.replace(md, link_origin=md.link_origin + 1e-6)
    assert limits_driven._way_to(spec.mechanism, X, 5, moved).shape == (6, 1)
    straight = graph_limit_positions(motion, "D.theta").limits
    monkeypatch.setattr(limits_driven, "_way_to", lambda mech, X, k, m: X[:k + 1])
    (lim,) = graph_limit_positions(motion, "D.theta").limits
    assert abs(lim.input - straight[0].input) <= 1e-12
    assert abs(lim.value - straight[0].value) <= 1e-12
