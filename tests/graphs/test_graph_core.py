"""The graph model's own checks (issue 26): topology and redundancy, limit positions against
geometry, where a mode stops assembling, the analyze document, several inputs by rows."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.limits import graph_limit_positions
from screwkit.kinematics.graph.topology import mechanism_topology
from screwkit.model.mechanism import Body, BodyPoint, Mechanism, MechanismJoint

FOURBAR = Path(__file__).parents[2] / "examples" / "mechanisms" / "fourbar_graph.toml"
Z = np.array([0.0, 0.0, 1.0])


def joint(name: str, kind: str, a: str, b: str, at: list[float], axis: np.ndarray = Z,
          **kw: object) -> MechanismJoint:
    return MechanismJoint(name, kind, (a, b), np.array(at, float), np.array(axis, float),
                          **kw)  # type: ignore[arg-type]


def rssr() -> Mechanism:
    x = np.array([1.0, 0.0, 0.0])
    return Mechanism("rssr", (Body("crank"), Body("rod"), Body("rocker")),
                     (joint("A", "R", "ground", "crank", [0, 0, 0]),
                      joint("B", "S", "crank", "rod", [1, 0, 0]),
                      joint("C", "S", "rod", "rocker", [3, 2, 1]),
                      joint("D", "R", "rocker", "ground", [3, 0, 1], x)), ("A.theta",),
                     (BodyPoint("mid", "rod", np.array([2.0, 1.0, 0.5])),))


def test_planar_loop_in_3d_has_three_redundant_constraints_named() -> None:
    spec = sk.load_spec(FOURBAR)
    t = spec.topology
    assert (t.mobility, t.rank, t.grubler, t.redundant_count) == (1, 3, -2, 3)
    assert t.loops == [["A", "B", "C", "D"]]
    assert sorted(r.split(": ")[1] for r in t.redundant) == [
        "rotation about x", "rotation about y", "translation along z"]
    assert not t.idle and not t.free


def test_rod_spin_is_an_idle_freedom() -> None:
    t = mechanism_topology(rssr())
    assert (t.mobility, t.redundant_count, len(t.idle)) == (2, 0, 1)
    assert "drive the mechanism: mobility 1 + 1 idle, 1 input(s)" in t.verdict
    assert t.idle == ["rod spin (about the line B–C)"]


def test_rocker_limits_are_where_crank_and_coupler_line_up() -> None:
    spec = sk.load_spec(FOURBAR)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed)
    lims = graph_limit_positions(motion, "D.theta").limits
    assert len(lims) == 2
    A, B0, C0 = (np.array(spec.mechanism.joint(n).at) for n in "ABC")
    d1, d2 = np.linalg.norm(B0 - A), np.linalg.norm(C0 - B0)
    reach = []
    for lim in lims:
        assert abs(lim.derivatives[0]) < 1e-12
        g = solve_mechanism(spec.mechanism, [lim.input]).modes[0]
        reach.append(np.linalg.norm(g.joint_centres[0, 2] - A))
    # the rocker turns back where A, B, C are collinear: |AC| = d2 ± d1
    np.testing.assert_allclose(sorted(reach), [d2 - d1, d2 + d1], rtol=1e-10)


def test_a_mode_that_stops_assembling_says_where() -> None:
    m = solve_mechanism(rssr(), np.radians(np.arange(0.0, 361.0, 2.0))).modes[0]
    assert not m.assembles.all()
    last = int(np.nonzero(m.assembles)[0][-1])
    assert m.events[0].startswith(f"stops assembling after input A.theta = {2 * last:.6g} deg")
    assert np.isnan(m.variables["D.theta"][last + 1:]).all()
    # the rod stays rigid while it assembles
    c = m.joint_centres[: last + 1]
    np.testing.assert_allclose(np.linalg.norm(c[:, 1] - c[:, 2], axis=1), np.sqrt(9.0),
                               rtol=1e-12)


def test_several_inputs_by_rows_and_bad_rows() -> None:
    five = Mechanism("5R", (Body("a"), Body("b"), Body("c"), Body("d")),
                     (joint("A", "R", "ground", "a", [0, 0, 0]),
                      joint("B", "R", "a", "b", [1, 0, 0]),
                      joint("C", "R", "b", "c", [2, 2, 0]),
                      joint("D", "R", "c", "d", [3, 0, 0]),
                      joint("E", "R", "d", "ground", [4, 0, 0])), ("A.theta", "E.theta"))
    rows = np.radians([[0, 0], [5, -3], [10, -6], [15, -9]])
    m = solve_mechanism(five, rows, rates=[1.0, -0.5]).modes[0]
    assert m.assembles.all() and np.nanmax(m.closure_residual) < 1e-12
    np.testing.assert_allclose(m.variables["E.theta"], rows[:, 1])
    with pytest.raises(sk.ScrewkitError, match="rows of 2 value"):
        solve_mechanism(five, np.zeros((3, 3)))
    with pytest.raises(sk.ScrewkitError, match="finite"):
        solve_mechanism(five, [[0.0, np.nan]])


def test_analyze_document_reports_points_by_name() -> None:
    r = CliRunner().invoke(app, ["analyze", str(FOURBAR), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["family"] == "graph" and doc["loops"] == [["A", "B", "C", "D"]]
    p = doc["modes"][0]["coupler_points"]["P"]
    spec = sk.load_spec(FOURBAR)
    m = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed).modes[0]
    np.testing.assert_allclose(p["x"], m.points["P"][:, 0], rtol=0, atol=1e-15)
    assert doc["topology"]["redundant_constraints"]
    # the coupler point stays rigid on the coupler: distances to B and C keep their drawn values
    B, C = m.joint_centres[:, 1], m.joint_centres[:, 2]
    P = m.points["P"]
    for J in (B, C):
        d = np.linalg.norm(P - J, axis=1)
        np.testing.assert_allclose(d, d[0], rtol=1e-12)


def test_limits_and_mobility_commands_on_a_graph() -> None:
    r = CliRunner().invoke(app, ["limits", str(FOURBAR), "--var", "D.theta", "--json"])
    assert r.exit_code == 0, r.output
    assert len(json.loads(r.output)["limits"]) == 2
    r = CliRunner().invoke(app, ["mobility", str(FOURBAR), "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["mobility"] == 1


def test_a_change_point_is_flagged_and_named() -> None:
    # a parallelogram four-bar: crank, coupler and rocker fall in line at input −90°
    pg = Mechanism("parallelogram", (Body("crank"), Body("coupler"), Body("rocker")),
                   (joint("A", "R", "ground", "crank", [0, 0, 0]),
                    joint("B", "R", "crank", "coupler", [0, 1, 0]),
                    joint("C", "R", "coupler", "rocker", [2, 1, 0]),
                    joint("D", "R", "rocker", "ground", [2, 0, 0])), ("A.theta",))
    m = solve_mechanism(pg, np.radians(np.arange(0.0, -120.0, -1.0))).modes[0]
    assert np.nonzero(m.singular)[0].tolist() == [90]
    # every joint in line: the closure Jacobian loses rank too, the parallelogram's change
    # point (it may go on as a parallelogram or an antiparallelogram)
    assert any("singular at A.theta = -90 deg: a bifurcation (change point)" in e
               for e in m.events)
    assert m.singular_class[90] == "bifurcation" and set(m.singular_class[:90]) == {""}
    assert m.jacobian_condition["passive"][90] > 1e7 > m.jacobian_condition["passive"][89]
    # up to the dead centre the rocker turns with the crank (D turns the ground on the rocker,
    # so its angle is the rocker's with the sign changed)
    np.testing.assert_allclose(m.variables["D.theta"][:90], -m.variables["A.theta"][:90],
                               atol=1e-12)


def test_a_drawing_at_a_dead_centre_is_refused_with_the_reason() -> None:
    dc = Mechanism("dead centre", (Body("crank"), Body("coupler"), Body("rocker")),
                   (joint("A", "R", "ground", "crank", [0, 0, 0]),
                    joint("B", "R", "crank", "coupler", [0, 1, 0]),
                    joint("C", "R", "coupler", "rocker", [2, 1, 0]),
                    joint("D", "R", "rocker", "ground", [3, 1, 0])), ("A.theta",))
    assert "the drawing is at a dead centre" in mechanism_topology(dc).verdict


def test_outputs_body_angle_and_point_travel() -> None:
    from screwkit.model.mechanism_outputs import BodyAngle, PointTravel

    base = rssr()
    x = np.array([1.0, 0.0, 0.0])
    mech = Mechanism(base.name, base.bodies, base.joints, base.inputs, base.points,
                     outputs=(BodyAngle("tilt", "rocker", np.array([0.0, 0.0, 1.0]), x),
                              PointTravel("rise", "mid", np.array([0.0, 0.0, 1.0]))))
    m = solve_mechanism(mech, np.radians(np.arange(0.0, 80.0, 1.0)), rates=2.0,
                        accelerations=0.5).modes[0]
    # the rocker turns about x by its joint angle (D turns the ground on the rocker: − sign)
    np.testing.assert_allclose(m.outputs["tilt"], -m.variables["D.theta"], atol=1e-12)
    np.testing.assert_allclose(m.output_rates["tilt"], -m.velocities["D.theta"], atol=1e-10)
    np.testing.assert_allclose(m.output_accelerations["tilt"], -m.accelerations["D.theta"],
                               atol=1e-9)
    np.testing.assert_allclose(m.outputs["rise"], m.points["mid"][:, 2] - 0.5, atol=1e-12)
    np.testing.assert_allclose(m.output_rates["rise"], m.point_velocities["mid"][:, 2],
                               atol=1e-12)
    with pytest.raises(sk.ScrewkitError, match="lies along 'about'"):
        Mechanism(base.name, base.bodies, base.joints, base.inputs, base.points,
                  outputs=(BodyAngle("bad", "rocker", x, x),))


def test_a_motion_over_the_time_limit_is_refused_up_front() -> None:
    import time

    spec = sk.load_spec(FOURBAR)
    t = time.perf_counter()
    with pytest.raises(sk.ScrewkitError, match="over the .* time limit; use fewer input samples"):
        solve_mechanism(spec.mechanism, np.zeros(20_000_000))
    assert time.perf_counter() - t < 5.0  # refused before any solving


#: the 80-column test's samples: every THIN-th of an example's rows, THIN × its step
THIN = 5


def thinned(path: Path, folder: Path) -> Path:
    """A copy of the example ``path`` in ``folder`` sampled THIN times more coarsely (its
    motion's ``rows``: every THIN-th and the last; its ``step``: THIN times longer): the same
    commands print the same kinds of line, fewer table rows (the Delta robot's and the Stewart
    platform's every mode ~5× faster)."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    motion = data.get("motion", {})
    if "rows" in motion:
        rows = motion["rows"]
        motion["rows"] = rows[::THIN] + ([rows[-1]] if (len(rows) - 1) % THIN else [])
    if "step" in motion:
        motion["step"] = motion["step"] * THIN
    copy = folder / path.name
    copy.write_text(tomli_w.dumps(data), encoding="utf-8")
    return copy


def test_a_thinned_example_keeps_its_first_and_last_rows(tmp_path: Path) -> None:
    spec = sk.load_spec(thinned(FOURBAR.parent / "delta_robot.toml", tmp_path))
    full = sk.load_spec(FOURBAR.parent / "delta_robot.toml")
    assert spec.inputs.shape[0] == 1 + (full.inputs.shape[0] - 1 + THIN - 1) // THIN
    np.testing.assert_array_equal(spec.inputs[[0, -1]], full.inputs[[0, -1]])
    np.testing.assert_array_equal(spec.inputs[:-1], full.inputs[::THIN][:spec.inputs.shape[0] - 1])
    for path in sorted(FOURBAR.parent.glob("*.toml")):  # every example loads, thinned
        coarse, fine = sk.load_spec(thinned(path, tmp_path)).inputs, sk.load_spec(path).inputs
        assert 2 <= coarse.shape[0] < fine.shape[0] / 4, path.name
        np.testing.assert_array_equal(coarse[0], fine[0])


@pytest.mark.parametrize("command", ["validate", "analyze", "mobility", "dynamics", "limits"])
def test_graph_commands_fit_80_columns(command: str, tmp_path: Path,
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """Every line a graph command prints fits 80 columns (errors excepted: one line each); on
    every example, sampled more coarsely (:func:`thinned`: the lines' width is what is checked,
    not their number), named as from the repository's root (examples/mechanisms/...)."""
    examples = sorted(FOURBAR.parent.glob("*.toml"))
    folder = tmp_path / "examples" / "mechanisms"
    folder.mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    for path in examples:
        thinned(path, folder)
        name = f"examples/mechanisms/{path.name}"
        r = CliRunner(env={"COLUMNS": "80"}).invoke(app, [command, name])
        lines = [line for line in r.output.splitlines() if not line.startswith("error:")]
        too_long = [line for line in lines if len(line) > 80]
        assert not too_long, (path.name, too_long[:2])


def test_analyze_plot_of_a_graph(tmp_path: Path) -> None:
    png = tmp_path / "watt.png"
    r = CliRunner().invoke(app, ["analyze", str(FOURBAR), "--plot", str(png), "-o",
                                 str(tmp_path / "a.npz")])
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_review_findings_stay_fixed() -> None:
    """What an independent review found: limits on a falling sweep, a long step away from a
    fold, an idle motion that is no rod spin, an unnormalised axis, a point off an idle rod."""
    spec = sk.load_spec(FOURBAR)
    down = solve_mechanism(spec.mechanism, np.radians(np.arange(360.0, -1.0, -5.0)))
    up = solve_mechanism(spec.mechanism, np.radians(np.arange(0.0, 361.0, 5.0)))
    got = [round(lim.input, 9) for lim in graph_limit_positions(down, "D.theta").limits]
    want = [round(lim.input, 9) for lim in graph_limit_positions(up, "D.theta").limits]
    assert got == want
    # a non-Grashof four-bar (crank 3, coupler 3, rocker 3, ground 4): from next to the crank's
    # limit at 117.28° straight back to −50° on the same branch
    c = [3.5, float(np.sqrt(9 - 0.25)), 0.0]
    ng = Mechanism("non-Grashof", (Body("crank"), Body("coupler"), Body("rocker")),
                   (joint("A", "R", "ground", "crank", [0, 0, 0]),
                    joint("B", "R", "crank", "coupler", [3, 0, 0]),
                    joint("C", "R", "coupler", "rocker", c),
                    joint("D", "R", "rocker", "ground", [4, 0, 0])), ("A.theta",))
    far = solve_mechanism(ng, np.radians([0.0, 116.0, -50.0])).modes[0]
    near = solve_mechanism(ng, np.radians(np.r_[0.0:117.0:1.0, 116.0:-51.0:-1.0])).modes[0]
    assert far.assembles.all() and not far.events
    np.testing.assert_allclose(far.variables["D.theta"][-1], near.variables["D.theta"][-1],
                               atol=1e-10)
    # a U joint whose rod lies in the plane of its axes: a singular drawing, not an idle spin
    rsur = Mechanism("RSUR", (Body("crank"), Body("rod"), Body("rocker")),
                     (joint("A", "R", "ground", "crank", [0, 0, 0]),
                      joint("B", "S", "crank", "rod", [1, 0, 0]),
                      joint("C", "U", "rod", "rocker", [3, 2, 1], [0, 1, 0.3],
                            axis2=np.array([1.0, 0.0, 0.2])),
                      joint("D", "R", "rocker", "ground", [3, 0, 1], [1, 0, 0])), ("A.theta",))
    assert "the drawing is at a dead centre" in mechanism_topology(rsur).verdict
    # an axis of any length is a direction
    long_axis = joint("A", "R", "ground", "crank", [0, 0, 0], 2 * Z)
    np.testing.assert_allclose(long_axis.axis, Z)
    # a point off an idle rod's line has no path
    base = rssr()
    with pytest.raises(sk.ScrewkitError, match="off their line"):
        Mechanism(base.name, base.bodies, base.joints, base.inputs,
                  (BodyPoint("off", "rod", np.array([2.0, 1.0, 0.0])),))
