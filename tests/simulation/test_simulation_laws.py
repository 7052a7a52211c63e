"""Physical laws of the forward simulation, flywheel sizing, and the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.io.drive_table import DriveConfig, LoadConfig, MotorConfig
from screwkit.simulation.drive import equation_of_motion
from screwkit.simulation.flywheel import size_flywheel, with_flywheel
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.result import Simulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def drive(motor: MotorConfig | None = None, load: LoadConfig | None = None,
          gravity: bool = False, flywheel: float = 0.0) -> DriveConfig:
    return DriveConfig(motor=motor or MotorConfig(), load=load, flywheel=flywheel, initial_speed=1.0, cycles=1,
                       samples_per_cycle=36, rtol=1e-10, atol=None, gravity=gravity,
                       max_time=None)


@pytest.fixture(scope="module")
def cssp():
    return sk.load_spec(EXAMPLES / "rahman_cssp.toml")


@pytest.mark.parametrize("name", ["rahman_cssp", "rsrc_fig7_dynamics"])
def test_free_loop_conserves_kinetic_energy(name):
    """No motor, no load, no gravity: T = ½ J ω² constant to 1e-8 over 10 cycles, with J the
    exact samples (not the series the integrator uses)."""
    spec = sk.load_spec(EXAMPLES / f"{name}.toml")
    eom = equation_of_motion(spec.linkage, drive(), start=float(spec.inputs[0]))
    run = simulate_cycles(eom, cycles=10, initial_speed=spec.speed, rtol=1e-12)
    assert run.status == "completed" and run.cycles == 10
    T = 0.5 * eom.model.samples["inertia"][None, :] * run.speed ** 2
    assert (T.max() - T.min()) / T.mean() < 1e-8
    assert np.ptp(np.diff(run.cycle_times)) < 1e-8 * run.cycle_times[1]  # a periodic motion


def test_gravity_exchanges_kinetic_and_potential_energy(cssp):
    eom = equation_of_motion(cssp.linkage, drive(gravity=True), gravity=[0, -9.81, -3.0])
    run = simulate_cycles(eom, cycles=3, initial_speed=30.0, rtol=1e-12)
    E = eom.energy(run.angle, run.speed)
    assert np.ptp(E) / np.mean(E) < 1e-8
    assert np.ptp(eom.model.potential(run.angle)) > 1e-3 * np.mean(E)  # gravity did matter


def test_constant_motor_torque_balancing_a_constant_load_gives_a_steady_mean_speed(cssp):
    """A resisting slider force F does 2F·stroke of work per turn; a motor torque of
    2F·stroke/2π balances it: the mean speed of every cycle is the same."""
    eom0 = equation_of_motion(cssp.linkage, drive(load=LoadConfig("slider.s", 40.0)))
    s = eom0.model.grid_mode.variables["slider.s"]
    stroke = float(np.max(s) - np.min(s))
    # the stroke from the positions on the grid; refine with the series of the velocity ratio
    r = eom0.model.series(np.linspace(0, 2 * np.pi, 20001)[:-1])[eom0.model.row("slider.s")]
    stroke = float(np.mean(np.abs(r)) * np.pi)  # ∫|r| dθ / 2
    torque = 2 * 40.0 * stroke / (2 * np.pi)
    eom = equation_of_motion(cssp.linkage, drive(MotorConfig("constant", torque=torque),
                                                 LoadConfig("slider.s", 40.0), flywheel=0.01))
    run = simulate_cycles(eom, cycles=12, initial_speed=100.0, rtol=1e-11)
    st = Simulation(run, 36).cycle_statistics
    assert np.ptp(st["mean_speed"]) < 1e-7 * st["mean_speed"][0]
    np.testing.assert_allclose(st["motor_work"], -st["load_work"], rtol=1e-7)
    # 10 % more torque: the machine speeds up every cycle
    eom_up = equation_of_motion(cssp.linkage, drive(MotorConfig("constant", torque=1.1 * torque),
                                                    LoadConfig("slider.s", 40.0), flywheel=0.01))
    up = Simulation(simulate_cycles(eom_up, cycles=4, initial_speed=100.0), 36)
    assert np.all(np.diff(up.cycle_statistics["mean_speed"]) > 0)


def test_sized_flywheel_gives_the_requested_fluctuation(cssp):
    """--fluctuation δ: an independent long run from another speed settles within 2 % of δ."""
    d = drive(MotorConfig("linear", stall_torque=20.0, no_load_speed=400.0),
              LoadConfig("slider.s", 50.0))
    eom = equation_of_motion(cssp.linkage, d)
    sizing = size_flywheel(eom, 0.05, 300.0)
    assert abs(sizing.achieved / 0.05 - 1) < 2e-3
    assert abs(sizing.estimate["flywheel"] / sizing.flywheel - 1) < 0.05  # the energy method
    sized = with_flywheel(eom, sizing.flywheel)
    w_steady = sizing.steady.run.initial_speed
    run = simulate_cycles(sized, cycles=60, initial_speed=0.97 * w_steady)
    last = Simulation(run, 36).steady()
    assert abs(last["fluctuation"] / 0.05 - 1) < 0.02
    steady_mean = sizing.steady.cycle_statistics["mean_speed"][0]
    first = Simulation(run, 36).cycle_statistics["mean_speed"][0]
    assert abs(last["mean_speed"] - steady_mean) < abs(first - steady_mean)  # settling
    smaller = Simulation(simulate_cycles(with_flywheel(eom, 0.5 * sizing.flywheel), cycles=1,
                                         initial_speed=w_steady), 36).steady()
    assert smaller["fluctuation"] > 0.05  # it is the smallest such flywheel


def test_reactions_and_shaft_torque_over_the_simulation(cssp):
    d = drive(MotorConfig("linear", stall_torque=20.0, no_load_speed=400.0),
              LoadConfig("slider.s", 50.0, 0.02), gravity=True, flywheel=0.05)
    eom = equation_of_motion(cssp.linkage, d, gravity=[0, 0, -9.81])
    sim = Simulation(simulate_cycles(eom, cycles=2, initial_speed=300.0), 36)
    assert sim.shaft_torque_check() < 1e-9
    assert sim.loads.shaking_force.shape == (72, 3)
    assert sim.run.energy_error < 1e-7


def test_a_weak_motor_stalls_with_a_message(cssp):
    d = drive(MotorConfig("constant", torque=0.1), LoadConfig("slider.s", 500.0))
    eom = equation_of_motion(cssp.linkage, d)
    run = simulate_cycles(eom, cycles=3, initial_speed=5.0)
    assert run.status == "stalled" and "cannot drive" in run.message


DRIVE = """
[drive]
flywheel = "0.05 kg*m^2"
cycles = 3
samples_per_cycle = 36
[drive.motor]
kind = "linear"
stall_torque = "20 N*m"
no_load_speed = "4000 rpm"
[drive.load]
force = "50 N"
"""


def test_cli_simulate_json_csv_and_sizing(tmp_path):
    spec = tmp_path / "cssp.toml"
    spec.write_text((EXAMPLES / "rahman_cssp.toml").read_text() + DRIVE)
    r = CliRunner().invoke(app, ["simulate", str(spec), "--json", "--csv",
                                 str(tmp_path / "s.csv"), "--fluctuation", "0.05"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert len(doc["cycles"]) == 3 and doc["status"] == "completed"
    assert abs(doc["flywheel_sizing"]["achieved_fluctuation"] / 0.05 - 1) < 2e-3
    assert doc["shaft_torque_check"] < 1e-9
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert len(rows) == 1 + 3 * 36 and rows[0].startswith("time [s],angle [deg]")  # the spec's units


@pytest.mark.parametrize(("table", "message"), [
    ('[drive.motor]\nkind = "linear"\nstall_torque = "2 N*m"\n', "needs stall_torque and no_load_speed"),
    ('[drive.motor]\nkind = "constant"\ntorque = "2 kg"\n', "torque"),
    ('[drive.load]\nfreedom = "crank.theta"\ntorque = "1 N*m"\n', "last joint"),
    ('[drive.load]\ntorque = "1 N*m"\n', "is a translation: give force"),
    ("cycles = 0\n", "drive.cycles"),
    ('flywheel = "-1 kg*m^2"\n', "drive.flywheel"),
])
def test_bad_drive_tables_are_named(tmp_path, table, message):
    spec = tmp_path / "bad.toml"
    spec.write_text((EXAMPLES / "rahman_cssp.toml").read_text() + "\n[drive]\n" + table)
    r = CliRunner().invoke(app, ["simulate", str(spec)])
    assert r.exit_code == 2
    assert message in " ".join(r.output.split())  # the error is wrapped at 80 columns
    assert "Traceback" not in r.output


def test_simulate_without_drive_table_says_how():
    r = CliRunner().invoke(app, ["simulate", str(EXAMPLES / "rahman_cssp.toml")])
    assert r.exit_code == 2 and "no [drive] table" in " ".join(r.output.split())


def test_a_load_against_the_motion_does_its_exact_work_every_cycle():
    """A constant force against the slider's motion jumps where the slider reverses; the
    integration restarts there (reversal_angles), so every cycle's load work is −2F·stroke to
    the integrator's tolerance at the default rtol (stepping across the jump gave 3.5e-4)."""
    from screwkit.simulation.integrate import reversal_angles
    from screwkit.simulation.spec_run import simulate_spec

    spec = sk.load_spec(EXAMPLES / "rahman_cssp_drive.toml")
    sim = simulate_spec(spec, cycles=6).simulation
    angles = reversal_angles(sim.eom)
    assert angles.size == 2
    ends = sk.solve_motion(spec.linkage, angles, method="closed").mode(spec.mode)
    stroke = float(np.ptp(ends.variables["slider.s"]))
    force = spec.drive.load.constant
    work = sim.cycle_statistics["load_work"]
    np.testing.assert_allclose(work, -2 * force * stroke, rtol=1e-7)
    assert sim.run.energy_error < 1e-7
