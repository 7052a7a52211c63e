"""Crank cycles, flywheel sizing, output loads and slide motors on mechanism graphs, and the
MJCF export of a loop whose own spanning tree closes it at a slide (docs/simulation.md,
"Graphs"). Every check is against something independent: the single-loop path (its Fourier
reduced model), a closed form, the energy balance, or MuJoCo."""

from __future__ import annotations

import json
import sys
import tomllib
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.io.drive_table import DriveConfigError, LoadConfig, MotorConfig
from screwkit.io.graph_drive import graph_drive_config
from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.io.spec import load_spec
from screwkit.model.mechanism import Mechanism
from screwkit.simulation.drive import equation_of_motion
from screwkit.simulation.flywheel import (
    SIZING_RTOL,
    size_flywheel,
    steady_simulation,
    with_flywheel,
)
from screwkit.simulation.graph_cycles import simulate_graph_cycles, size_graph_flywheel
from screwkit.simulation.graph_eom import GraphEquationOfMotion
from screwkit.simulation.graph_mjcf import graph_mjcf_layout, graph_mjcf_model
from screwkit.simulation.graph_run import simulate_graph
from screwkit.simulation.graph_spec_run import simulate_graph_spec_cycles
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.reduced import SimulationError
from screwkit.simulation.result import Simulation
from screwkit.simulation.spec_run import spec_equation_of_motion

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_graph_simulation import EXAMPLES, _loop_as_graph, graph_spec  # noqa: E402

SLIDER_CRANK = Path(__file__).resolve().parents[1] / "data" / "graphs" / "slider_crank_drive.toml"


def slider_crank():  # type: ignore[no-untyped-def]
    return graph_spec_from_data(tomllib.loads(SLIDER_CRANK.read_text(encoding="utf-8")),
                                SLIDER_CRANK)


@pytest.fixture(scope="module")
def cssp():  # type: ignore[no-untyped-def]
    """Rahman's CSSP with its [drive] (linear motor, 40 N load on the slider against its
    motion, friction in the crank bearing and the slider's guide) as a loop and as a graph."""
    spec = sk.load_spec(EXAMPLES / "rahman_cssp_drive.toml")
    return spec, _loop_as_graph(spec)


def _graph_eom(spec, mech: Mechanism, **changes):  # type: ignore[no-untyped-def]
    d = replace(spec.drive, **changes)
    return GraphEquationOfMotion(mech, motors=[d.motor], flywheel=d.flywheel,
                                 friction=d.friction, load=d.load), d


def test_an_output_load_through_the_graph_path_equals_the_loop_path(cssp):
    """The CSSP's slider load (Q_out carried to the crank by the slider's partial rate, against
    the motion), its friction, motor and flywheel: the graph path's crank angle and speed equal
    the loop path's (Fourier-series reduced model with the velocity ratio r = ds/dθ) over a
    quarter turn, and the graph's energy balance includes the load's work."""
    spec, mech = cssp
    d = spec.drive
    loop = simulate_cycles(spec_equation_of_motion(spec), cycles=1,
                           initial_speed=d.initial_speed, rtol=1e-12)
    eom, _ = _graph_eom(spec, mech)
    run = simulate_graph(eom, duration=0.25 * float(loop.cycle_times[-1]), samples=5,
                         initial_rates=[d.initial_speed], rtol=1e-12)
    y = loop.solution(run.time)
    assert np.max(np.abs(y[0] - float(spec.inputs[0]) - run.inputs[:, 0])) < 1e-9
    assert np.max(np.abs(y[1] - run.rates[:, 0])) < 1e-9 * d.initial_speed
    assert run.load_work is not None and run.load_work[-1] < 0  # the load resists
    assert run.energy_error < 1e-9
    assert run.output_force is not None and np.all(np.abs(run.output_force) == 40.0)


def test_cycle_statistics_equal_the_loop_path(cssp):
    """One turn of the CSSP with its [drive]: period, mean, least and greatest speed, C_s, the
    works and the motor's RMS torque from the graph's direct integration (speed extremes from
    the dense output) equal the loop's (the grid of its reduced model, parabola-refined)."""
    spec, mech = cssp
    d = spec.drive
    loop = Simulation(simulate_cycles(spec_equation_of_motion(spec), cycles=1,
                                      initial_speed=d.initial_speed, rtol=1e-12), 72)
    eom, _ = _graph_eom(spec, mech)
    run = simulate_graph_cycles(eom, cycles=1, initial_rate=d.initial_speed, rtol=1e-10)
    assert run.status == "completed" and run.cycles == 1
    assert run.energy_error < 1e-9
    ls, gs = loop.cycle_statistics, run.statistics
    for key, tol in (("period", 1e-8), ("mean_speed", 1e-8), ("min_speed", 1e-6),
                     ("max_speed", 1e-6), ("fluctuation", 1e-5), ("motor_work", 1e-8),
                     ("friction_work", 1e-8), ("load_work", 1e-6),
                     ("motor_torque_rms", 1e-8), ("motor_torque_peak", 1e-5)):
        assert abs(gs[key][0] / ls[key][0] - 1.0) < tol, key
    # the works of the cycle balance the energy change over it (independent of the stats)
    work = gs["motor_work"][0] + gs["friction_work"][0] + gs["load_work"][0]
    assert abs(work) < 0.1 * gs["motor_work"][0]  # near steady: little net work


def test_flywheel_sizing_on_a_graph_agrees_with_the_loop(cssp):
    """Size the CSSP's flywheel for C_s = 0.02 (a damping load on the slider) on the graph
    (steady state by shooting on its direct integration) and on the loop (its own reduced
    model and shooting): the flywheels agree within the methods' tolerance, and the loop's
    steady C_s with the graph's flywheel is the request within it."""
    spec, mech = cssp
    load = LoadConfig("slider.s", 0.0, 2.0)
    d = replace(spec.drive, load=load, flywheel=0.0)
    loop_eom = equation_of_motion(spec.linkage, d, start=float(spec.inputs[0]))
    loop = size_flywheel(loop_eom, 0.02, d.initial_speed)
    eom, _ = _graph_eom(spec, mech, load=load, flywheel=0.0)
    graph = size_graph_flywheel(eom, 0.02, d.initial_speed, rtol=1e-7)
    assert abs(graph.achieved / 0.02 - 1.0) < SIZING_RTOL
    assert abs(graph.flywheel / loop.flywheel - 1.0) < 5 * SIZING_RTOL
    check = steady_simulation(with_flywheel(loop_eom, graph.flywheel), d.initial_speed)
    assert abs(check.steady()["fluctuation"] / 0.02 - 1.0) < 2 * SIZING_RTOL


def _slide_position(theta: np.ndarray) -> np.ndarray:
    """The slider-crank's slider x (m) at crank angle θ from the drawing: closed form."""
    r, t0 = 0.05, np.arctan2(40.0, 30.0)
    L = np.hypot(0.15, 0.04)
    return r * np.cos(t0 + theta) + np.sqrt(L ** 2 - (r * np.sin(t0 + theta)) ** 2)


def test_a_fixed_load_does_the_work_of_its_closed_form():
    """A constant 30 N on the slider's freedom, not against the motion (so in the freedom's
    negative direction), does the work −30 N × Δs, with Δs from the slider-crank's closed-form
    position; with the motor and friction the energy balances."""
    spec = slider_crank()
    d = graph_drive_config(spec)
    load = LoadConfig("slide.s", 30.0, 0.0, against_motion=False)
    eom = GraphEquationOfMotion(spec.mechanism, motors=d.motors, friction=d.friction,
                                gravity=spec.gravity_vector, load=load)
    run = simulate_graph(eom, duration=0.03, samples=7, initial_rates=d.initial_rates,
                         rtol=1e-11)
    assert run.status == "completed" and run.energy_error < 1e-9
    x = _slide_position(run.inputs[:, 0])
    # the P joint runs from the slider to the ground: its freedom is the ground's slide
    # relative to the slider, s = −(x − x₀)
    s = -(x - x[0])
    assert run.load_work is not None
    assert np.max(np.abs(run.load_work - (-30.0 * s))) < 1e-9 * 30.0 * np.ptp(s)
    assert np.ptp(s) > 0.05


def test_force_motors_on_slide_inputs_do_the_work_of_their_closed_form():
    """The Stewart platform with a constant force motor on each of its six legs (different
    forces) under gravity: each motor's work is F_k Δs_k (closed form), and the energy
    balance holds; a linear force motor in N and m/s is read from [drive.motors]."""
    stewart = graph_spec("stewart_platform")
    forces = np.array([40.0, 35.0, 30.0, 45.0, 38.0, 33.0])
    eom = GraphEquationOfMotion(stewart.mechanism,
                                motors=[MotorConfig("constant", torque=f) for f in forces],
                                gravity=stewart.gravity_vector)
    run = simulate_graph(eom, duration=0.03, samples=4, rtol=1e-11)
    assert run.status == "completed" and run.energy_error < 1e-9
    ds = run.inputs - run.inputs[0]
    assert np.max(np.abs(run.motor_work - ds @ forces)) < 1e-9 * np.max(np.abs(ds @ forces))
    assert np.max(np.abs(run.motor[-1] - forces)) == 0.0
    assert np.ptp(ds[-1]) > 1e-6  # the legs move differently


def test_slide_motor_table_is_read_in_newtons(tmp_path):
    spec = _slider_spec_with(tmp_path, drive_motor={"slide.s": {
        "kind": "linear", "stall_force": "300 N", "no_load_speed": "2 m/s"}}, input_="slide")
    d = graph_drive_config(spec)
    assert d.motors[0] == MotorConfig("linear", stall_torque=300.0, no_load_speed=2.0)
    with pytest.raises(DriveConfigError, match="drives a slide: give force"):
        graph_drive_config(_slider_spec_with(tmp_path, drive_motor={"slide.s": {
            "kind": "constant", "torque": "3 N*m"}}, input_="slide"))


def _slider_spec_with(tmp_path: Path, *, drive_motor=None, load=None,  # type: ignore[no-untyped-def]
                      input_: str = "A"):
    data = tomllib.loads(SLIDER_CRANK.read_text(encoding="utf-8"))
    for j in data["joints"]:
        j.pop("input", None)
        if j["name"] == input_:
            j["input"] = True
    if input_ == "slide":
        data["drive"]["initial_speed"] = "0 m/s"
        data["drive"].pop("motors")
    if drive_motor is not None:
        data["drive"]["motors"] = drive_motor
    if load is not None:
        data["drive"]["load"] = load
    return graph_spec_from_data(data, tmp_path / "slider_crank.toml")


def test_a_piston_driven_slider_crank_balances_its_energy(tmp_path):
    """The slider-crank driven at its slide (the piston) by a linear force motor: the run
    balances the motor, load (a damping torque on the crank) and friction work against the
    energy."""
    spec = _slider_spec_with(tmp_path, drive_motor={"slide.s": {
        "kind": "linear", "stall_force": "300 N", "no_load_speed": "2 m/s"}},
        load={"freedom": "A.theta", "damping": "1e-3 N*m*s/rad"}, input_="slide")
    d = graph_drive_config(spec)
    eom = GraphEquationOfMotion(spec.mechanism, motors=d.motors, friction=d.friction,
                                gravity=spec.gravity_vector, load=d.load)
    run = simulate_graph(eom, duration=0.01, samples=5, rtol=1e-11)
    assert run.status == "completed" and run.energy_error < 1e-9
    assert run.motor_work[-1] > 0 > run.load_work[-1]  # type: ignore[index]
    # the force drives the freedom forward: s grows, so the slider moves in, x = x₀ − s
    assert run.inputs[-1, 0] > 1e-3


def test_bad_loads_and_crank_cycles_are_refused(tmp_path):
    with pytest.raises(DriveConfigError, match="ball joint"):
        graph_drive_config(_slider_spec_with_ball(tmp_path))
    with pytest.raises(DriveConfigError, match="no such freedom"):
        graph_drive_config(_slider_spec_with(tmp_path, load={"freedom": "Z.theta",
                                                             "torque": "1 N*m"}))
    with pytest.raises(DriveConfigError, match="is a translation: give force"):
        graph_drive_config(_slider_spec_with(tmp_path, load={"freedom": "slide.s",
                                                             "torque": "1 N*m"}))
    delta = graph_spec("delta_robot")
    with pytest.raises(SimulationError, match="3 inputs"):
        simulate_graph_cycles(GraphEquationOfMotion(delta.mechanism), cycles=1,
                              initial_rate=1.0)
    with pytest.raises(SimulationError, match="is a slide"):
        simulate_graph_cycles(GraphEquationOfMotion(
            _slider_spec_with(tmp_path, input_="slide").mechanism), cycles=1, initial_rate=1.0)


def _slider_spec_with_ball(tmp_path: Path):  # type: ignore[no-untyped-def]
    spec = EXAMPLES / "mechanisms" / "double_wishbone.toml"
    data = tomllib.loads(spec.read_text(encoding="utf-8"))
    ball = next(j["name"] for j in data["joints"] if j["kind"] == "S")
    data.setdefault("drive", {"duration": "0.1 s"})["load"] = {"freedom": f"{ball}.theta",
                                                               "torque": "1 N*m"}
    return graph_spec_from_data(data, tmp_path / "wishbone.toml")


def test_cli_cycles_on_a_graph(tmp_path):
    """``simulate --cycles`` on a graph: per-cycle statistics as JSON (with the run's energy
    balance) and CSV; ``--plot`` draws the cycles (a bad suffix: exit 2, no file). The sizing
    itself (``--fluctuation``) is checked against the loop above."""
    runner = CliRunner()
    r = runner.invoke(app, ["simulate", str(SLIDER_CRANK), "--cycles", "2", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    c = doc["cycles"]
    assert doc["status"] == "completed" and len(c["period"]) == 2
    assert doc["energy_error"] < 1e-9
    assert all(0 < f < 1 for f in c["fluctuation"])
    csv = tmp_path / "c.csv"
    r = runner.invoke(app, ["simulate", str(SLIDER_CRANK), "--cycles", "1", "--csv", str(csv)])
    assert r.exit_code == 0, r.output
    assert "fluctuation" in csv.read_text(encoding="utf-8").splitlines()[0]
    png = tmp_path / "p.png"
    r = runner.invoke(app, ["simulate", str(SLIDER_CRANK), "--cycles", "2", "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    r = runner.invoke(app, ["simulate", str(SLIDER_CRANK), "--cycles", "1", "--plot",
                            str(tmp_path / "p.txt")])
    assert r.exit_code == 2 and "--plot" in r.output and not (tmp_path / "p.txt").exists()


def test_the_samples_of_crank_cycles_turn_the_crank_once_per_cycle():
    """The samples ``simulate --cycles --plot`` draws (equal time steps in every cycle, from
    the dense output): the speed integrated over a cycle (trapezoid, the next cycle's first
    sample closing it) is the turn 2π to the rule's O(Δt²) error; the samples lie within the
    cycle's least and greatest speed (found separately, parabola-refined, 8 points per step)
    and reach them within 1 %; the angle in the cycle starts at 0 and stays below 2π."""
    spec = load_spec(SLIDER_CRANK)
    run = simulate_graph_spec_cycles(spec, cycles=3, samples_per_cycle=72).run
    assert run.status == "completed" and run.samples is not None
    sm, st = run.samples, run.statistics
    assert sm["time"].shape == (3 * 72,)
    for k in range(3):
        sl = slice(72 * k, 72 * (k + 1))
        t = np.append(sm["time"][sl], run.cycle_times[k + 1])
        w = np.append(sm["speed"][sl], sm["speed"][72 * (k + 1)] if k < 2 else run.end[1])
        assert abs(np.trapezoid(w, t) / (2 * np.pi) - 1.0) < 1e-4
        assert st["min_speed"][k] <= w.min() < 1.01 * st["min_speed"][k]
        assert 0.99 * st["max_speed"][k] < w.max() <= st["max_speed"][k]
        a = sm["cycle_angle"][sl]
        assert a[0] == pytest.approx(0.0, abs=1e-9) and a.max() < 2 * np.pi
    plain = simulate_graph_spec_cycles(spec, cycles=3).run
    assert plain.samples is None
    np.testing.assert_array_equal(plain.cycle_times, run.cycle_times)  # same run


def test_export_mjcf_cuts_a_loop_closed_at_a_slide_at_an_r_joint():
    """The inverted slider-crank's own spanning tree closes its loop at the slide; the export
    cuts it at an R joint instead (the slide in the body tree): the model is assembled at its
    keyframe, and driven by a constant motor torque under gravity MuJoCo's crank angle agrees
    with screwkit's and converges onto it as MuJoCo's step is halved."""
    path = SLIDER_CRANK.parent / "inverted_slider_crank.toml"
    spec = graph_spec_from_data(tomllib.loads(path.read_text(encoding="utf-8")), path)
    mech = spec.mechanism
    assert mech.joints[mech.topology.chords[0]].name == "slide"
    lay = graph_mjcf_layout(mech)
    assert lay.chords in (("B",), ("D",))
    assert any(mech.joints[k].name == "slide" for k, _, _ in lay.tree)

    def mujoco_angle(dt: float) -> tuple[float, float]:
        xml = graph_mjcf_model(mech, gravity=spec.gravity_vector, timestep=dt,
                               solref=(20 * dt, 1.0), start=[0.3])
        assert 'type="slide"' in xml
        m = mujoco.MjModel.from_xml_string(xml)
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        mujoco.mj_forward(m, d)
        assert np.max(np.abs(d.efc_pos[: d.nefc])) < 1e-12
        adr = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "A_theta")])
        d.ctrl[0] = 0.05
        violation = 0.0
        for _ in range(int(round(0.03 / dt))):
            mujoco.mj_step(m, d)
            violation = max(violation, float(np.max(np.abs(d.efc_pos[: d.nefc]))))
        return float(d.qpos[adr]), violation

    eom = GraphEquationOfMotion(mech, motors=[MotorConfig("constant", torque=0.05)],
                                gravity=spec.gravity_vector)
    run = simulate_graph(eom, duration=0.03, samples=2, initial_inputs=[0.3], rtol=1e-11)
    coarse, v_coarse = mujoco_angle(1e-5)
    fine, _ = mujoco_angle(5e-6)
    assert run.inputs[-1, 0] - 0.3 > 0.05  # it moved
    assert v_coarse < 1e-9  # MuJoCo's own constraint accuracy (m)
    assert abs(coarse - run.inputs[-1, 0]) < 1e-8
    assert abs(fine - run.inputs[-1, 0]) < 0.5 * abs(coarse - run.inputs[-1, 0])


def test_export_refuses_a_loop_with_nothing_to_cut():
    """A loop of slides and inputs only has no R or S joint to cut: refused, naming it."""
    m = slider_crank().mechanism
    mech = Mechanism(m.name, m.bodies, m.joints, ("A.theta", "B.theta", "C.theta"))
    with pytest.raises(SimulationError, match="no R or S joint"):
        graph_mjcf_layout(mech)


def test_a_point_force_does_the_work_of_its_closed_form(tmp_path):
    """A constant force at the Watt six-bar's point P (on its output link) with the crank's
    motor: its work is F·(p(t) − p(0)) with p the point's path from the graph tracker at the
    simulated crank angles (an independent solve), and the energy balances."""
    data = tomllib.loads((EXAMPLES / "mechanisms" / "watt_sixbar_simulate.toml")
                         .read_text(encoding="utf-8"))
    data["drive"]["point_force"] = {"point": "P", "force": ["3 N", "-5 N", "0 N"]}
    data["drive"]["duration"] = "0.2 s"
    data["drive"]["samples"] = 5
    spec = graph_spec_from_data(data, tmp_path / "w.toml")
    d = graph_drive_config(spec)
    assert d.point_force == ("P", (3.0, -5.0, 0.0))
    from screwkit.simulation.graph_spec_run import simulate_graph_spec

    run = simulate_graph_spec(spec).simulation
    assert run.status == "completed" and run.energy_error < 1e-9
    from screwkit.kinematics.graph.motion import solve_mechanism

    path = solve_mechanism(spec.mechanism, run.inputs, rates=0.0,
                           accelerations=0.0).point("P")
    expected = (path - path[0]) @ np.array([3.0, -5.0, 0.0])
    assert run.load_work is not None and np.ptp(expected) > 1e-3
    assert np.max(np.abs(run.load_work - expected)) < 1e-9 * np.max(np.abs(expected))
    with pytest.raises(SimulationError, match="not a point of it"):
        GraphEquationOfMotion(spec.mechanism, point_force=("Q", [0, 0, 1]))
