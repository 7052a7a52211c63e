"""Viscous joint friction in the forward simulation (``[drive.friction]``): its generalised
force −B(θ) θ̇ checked against the joint rates, the energy balance with the friction's work,
the loads over the simulated motion (shaking unchanged on the same motion, the shaft torque's
extra power exactly B θ̇², the friction moment in a revolute joint's reaction), the spec table
with its errors, and the MuJoCo export's joint damping."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.io.drive_table import DriveConfig, JointFriction, MotorConfig
from screwkit.simulation.drive import equation_of_motion
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.reactions import loop_loads
from screwkit.simulation.result import Simulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def drive(friction=(), motor=None, load=None, flywheel=0.0) -> DriveConfig:
    return DriveConfig(motor=motor or MotorConfig(), load=load, flywheel=flywheel,
                       initial_speed=1.0, cycles=1, samples_per_cycle=36, rtol=1e-10,
                       atol=None, gravity=False, max_time=None, friction=tuple(friction))


@pytest.fixture(scope="module")
def fourbar():
    return sk.load_spec(EXAMPLES / "fourbar_dynamics.toml")


@pytest.fixture(scope="module")
def rsrc():
    return sk.load_spec(EXAMPLES / "rsrc_fig7_dynamics.toml")


def test_friction_coefficient_from_the_joint_rates(fourbar):
    """B = Σ c |ω_rel|²: on the input joint ω_rel = θ̇ (B = c), on the planar 4R's output joint
    it is the output's velocity ratio, on the coupler pin the coupler's minus the crank's."""
    lk = fourbar.linkage
    c = (0.3, 0.05, 0.02)
    eom = equation_of_motion(lk, drive([JointFriction("input", c[0]),
                                        JointFriction("output", c[1]),
                                        JointFriction("crank_pin", c[2])]))
    md = eom.model.grid_mode
    r_out = md.velocities["output.theta"]
    r_coupler_rel = md.velocities["crank_pin.theta"]  # the pin's own freedom: coupler − crank
    expected = c[0] + c[1] * r_out ** 2 + c[2] * r_coupler_rel ** 2
    np.testing.assert_allclose(eom.model.samples["friction"], expected, rtol=1e-12)
    # the series the integrator evaluates reproduces the exact samples
    fitted = eom.model.series(eom.model.grid)[eom.model.row("friction")]
    np.testing.assert_allclose(fitted, expected, rtol=1e-10)


@pytest.mark.parametrize("example", ["fourbar_dynamics", "rsrc_fig7_dynamics"])
def test_energy_balance_with_friction(example):
    """No motor, no load: the loop coasts down; kinetic energy lost = the friction's work (the
    integrated −B θ̇²), to the integrator's tolerance, and the friction's work is negative."""
    spec = sk.load_spec(EXAMPLES / f"{example}.toml")
    joints = [j.name for j in spec.linkage.joints]
    friction = [JointFriction(joints[0], 1e-3)]
    if spec.linkage.joints[-1].kind == "C":
        friction.append(JointFriction(joints[-1], 1e-3, 0.5))
    eom = equation_of_motion(spec.linkage, drive(friction), start=float(spec.inputs[0]))
    run = simulate_cycles(eom, cycles=4, initial_speed=spec.speed, rtol=1e-12)
    assert run.status == "completed"
    assert run.energy_error < 1e-9
    work = run.cycle_work["friction"]
    assert np.all(work < 0)
    E = eom.energy(run.angle[:, 0], run.speed[:, 0])  # at each cycle's start
    np.testing.assert_allclose(np.diff(E), work[:-1], rtol=1e-7)
    st = Simulation(run, 36).cycle_statistics
    assert np.all(np.diff(st["mean_speed"]) < 0)  # it slows down


def test_loads_with_friction_on_the_same_motion(rsrc):
    """On one motion: the shaking force and moment do not change (they are −dḢ/dt + weight
    whatever the joints transmit), the shaft torque's power rises by exactly B θ̇², and a
    passive revolute joint's reaction carries the friction moment −c ω_rel about its axis."""
    lk = rsrc.linkage
    friction = [JointFriction("input", 0.02), JointFriction("coupler_R", 0.05),
                JointFriction("sphere", 0.01), JointFriction("output_C", 0.03, 4.0)]
    eom = equation_of_motion(lk, drive(friction), start=float(rsrc.inputs[0]))
    model = eom.model
    n = model.grid.size
    rng = np.random.default_rng(3)
    idx = np.arange(0, n, 4)
    speed = rng.uniform(5.0, 20.0, idx.size)
    acc = rng.uniform(-50.0, 50.0, idx.size)
    g = [0.0, 0.0, -9.81]
    plain, mm = loop_loads(model, idx, speed, acc, gravity=g)
    rough, _ = loop_loads(model, idx, speed, acc, gravity=g, friction=friction)
    scale_f = np.max(np.abs(plain.shaking_force))
    scale_m = np.max(np.abs(plain.shaking_moment))
    np.testing.assert_allclose(rough.shaking_force, plain.shaking_force, atol=1e-10 * scale_f)
    np.testing.assert_allclose(rough.shaking_moment, plain.shaking_moment, atol=1e-10 * scale_m)
    effort_plain = plain.efforts["input.theta"]
    effort_rough = rough.efforts["input.theta"]
    B = model.samples["friction"][idx]
    np.testing.assert_allclose((effort_rough - effort_plain) * speed, B * speed ** 2,
                               rtol=1e-9, atol=1e-12 * np.max(B * speed ** 2))
    # the coupler's revolute joint: an ideal hinge transmits no moment about its axis
    j = [jt.name for jt in lk.joints].index("coupler_R")
    u = mm.joint_axes[:, j]
    rel = mm.link_angular_velocity[:, j] - mm.link_angular_velocity[:, j - 1]
    axial_plain = np.einsum("ni,ni->n", plain.reactions["coupler_R"].moment, u)
    axial_rough = np.einsum("ni,ni->n", rough.reactions["coupler_R"].moment, u)
    assert np.max(np.abs(axial_plain)) < 1e-9 * np.max(np.abs(axial_rough))
    np.testing.assert_allclose(axial_rough, -0.05 * np.einsum("ni,ni->n", rel, u), rtol=1e-9)
    assert np.max(rough.residual) < 1e-9 * max(scale_f, scale_m)


def test_simulation_with_friction_balances_shaft_torque(rsrc):
    """A motor against friction alone: the steady shaft torque of the inverse dynamics equals
    τ_motor − J_f θ̈ (two methods) and the motor's work per cycle goes into friction."""
    friction = [JointFriction("input", 0.05), JointFriction("output_C", 0.02, 2.0)]
    d = drive(friction, MotorConfig("linear", stall_torque=5.0, no_load_speed=40.0),
              flywheel=0.02)
    eom = equation_of_motion(rsrc.linkage, d, start=float(rsrc.inputs[0]))
    sim = Simulation(simulate_cycles(eom, cycles=30, initial_speed=20.0, rtol=1e-11), 36)
    assert sim.shaft_torque_check() < 1e-9
    st = sim.steady()
    assert abs(st["motor_work"] + st["friction_work"]) < 1e-5 * st["motor_work"]
    assert sim.samples["friction_torque"].max() < 0


FRICTION = """
[drive]
cycles = 2
samples_per_cycle = 36
[drive.motor]
kind = "linear"
stall_torque = "5 N*m"
no_load_speed = "400 rpm"
[drive.friction]
input = "0.05 N*m*s/rad"
output_C = { rotation = "0.02 N*m*s/rad", translation = "2 N*s/m" }
"""


def _spec(tmp_path, friction_table: str, base: str = "rsrc_fig7_dynamics") -> Path:
    p = tmp_path / "spec.toml"
    p.write_text((EXAMPLES / f"{base}.toml").read_text() + friction_table)
    return p


def test_friction_table_in_the_spec_and_the_cli(tmp_path):
    spec = _spec(tmp_path, FRICTION)
    s = sk.load_spec(spec)
    assert s.drive is not None
    assert {f.joint: (f.rotation, f.translation) for f in s.drive.friction} == {
        "input": (0.05, 0.0), "output_C": (0.02, 2.0)}
    r = CliRunner().invoke(app, ["simulate", str(spec), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["drive"]["friction"]["output_C"] == {"rotation": 0.02, "translation": 2.0}
    assert all(c["friction_work"] < 0 for c in doc["cycles"])
    assert doc["shaft_torque_check"] < 1e-9
    assert "friction_torque" in doc["samples"]


@pytest.mark.parametrize("table, fragment", [
    ('[drive.friction]\nnowhere = "0.1 N*m*s/rad"\n', "no joint 'nowhere'"),
    ('[drive.friction]\noutput_C = "0.1 N*m*s/rad"\n', "turns and slides"),
    ('[drive.friction]\ninput = { translation = "1 N*s/m" }\n', "does not slide"),
    ('[drive.friction]\ninput = "-0.1 N*m*s/rad"\n', ">= 0"),
    ('[drive.friction]\ninput = "0.1 N*s/m"\n', "drive.friction.input"),
    ('[drive.friction]\ninput = {}\n', "rotation and/or translation"),
])
def test_bad_friction_tables_are_named(tmp_path, table, fragment):
    spec = _spec(tmp_path, "[drive]\ncycles = 1\n" + table)
    r = CliRunner().invoke(app, ["validate", str(spec)])
    assert r.exit_code == 2, r.output
    assert fragment in " ".join(r.output.split()), r.output


def test_friction_at_the_balls_of_an_s_s_rod_is_refused(tmp_path):
    spec = _spec(tmp_path, '[drive]\n[drive.friction]\npin = "0.01 N*m*s/rad"\n',
                 base="rahman_cssp")
    r = CliRunner().invoke(app, ["validate", str(spec)])
    assert r.exit_code == 2 and "spin" in r.output, r.output
    ok = _spec(tmp_path, '[drive]\n[drive.friction]\ncrank = "0.01 N*m*s/rad"\n'
                         'slider = "3 N*s/m"\n', base="rahman_cssp")
    assert CliRunner().invoke(app, ["validate", str(ok)]).exit_code == 0


def test_mjcf_export_carries_the_friction_as_joint_damping(tmp_path):
    spec = _spec(tmp_path, FRICTION)
    out = tmp_path / "model.xml"
    r = CliRunner().invoke(app, ["export-mjcf", str(spec), "-o", str(out)])
    assert r.exit_code == 0, r.output
    import xml.etree.ElementTree as ET

    damping = {j.get("name"): float(j.get("damping")) for j in ET.parse(out).iter("joint")}
    assert damping == {"input": 0.05, "output_C_theta": 0.02, "output_C_s": 2.0,
                       "coupler_R": 0.0}  # the sphere is the cut (an equality constraint)


def test_mjcf_export_refuses_friction_at_the_cut_joint(tmp_path):
    spec = _spec(tmp_path, '[drive]\n[drive.friction]\nsphere = "0.01 N*m*s/rad"\n')
    r = CliRunner().invoke(app, ["export-mjcf", str(spec), "-o", str(tmp_path / "m.xml")])
    assert r.exit_code == 2 and "equality constraint" in " ".join(r.output.split()), r.output
    assert not (tmp_path / "m.xml").exists()


def test_api_friction_is_checked_and_repeated_entries_add_up(rsrc):
    """The Python API applies the spec's rules (one function, io.drive_table.friction_problem)
    and merges repeated entries for a joint: a C joint's two parts given separately, or one
    coefficient split in two, give the same loads as one entry."""
    from screwkit.simulation.reduced import SimulationError

    lk = rsrc.linkage
    split = [JointFriction("coupler_R", 0.03), JointFriction("output_C", 0.03, 0.0),
             JointFriction("coupler_R", 0.02), JointFriction("output_C", 0.0, 4.0)]
    whole = [JointFriction("coupler_R", 0.05), JointFriction("output_C", 0.03, 4.0)]
    model = equation_of_motion(lk, drive(whole), start=float(rsrc.inputs[0])).model
    idx = np.arange(0, model.grid.size, 6)
    speed, acc = np.full(idx.size, 9.0), np.linspace(-20, 20, idx.size)
    a, _ = loop_loads(model, idx, speed, acc, friction=split)
    b, _ = loop_loads(model, idx, speed, acc, friction=whole)
    for name in b.reactions:
        np.testing.assert_allclose(a.reactions[name].moment, b.reactions[name].moment,
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(a.reactions[name].force, b.reactions[name].force,
                                   rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(a.shaking_moment, b.shaking_moment, rtol=1e-12, atol=1e-12)
    split_model = equation_of_motion(lk, drive(split), start=float(rsrc.inputs[0])).model
    np.testing.assert_allclose(split_model.samples["friction"], model.samples["friction"],
                               rtol=1e-14)
    cssp = sk.load_spec(EXAMPLES / "rahman_cssp.toml").linkage
    for bad, fragment in ((JointFriction("pin", 0.01), "spin"),
                          (JointFriction("crank", -0.01), ">= 0"),
                          (JointFriction("slider", 0.01), "does not turn"),
                          (JointFriction("crank", 0.0, 1.0), "does not slide"),
                          (JointFriction("nowhere", 0.01), "no joint")):
        with pytest.raises(SimulationError, match=fragment):
            equation_of_motion(cssp, drive([bad]))
        with pytest.raises(sk.ScrewkitError, match=fragment):
            from screwkit.simulation.mjcf import mjcf_model

            mjcf_model(cssp, friction=[bad])
