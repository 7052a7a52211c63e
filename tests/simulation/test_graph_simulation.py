"""Forward dynamics of mechanism graphs (simulation/graph_eom.py, graph_run.py): the equations
of motion against the graph inverse dynamics (an independent route through the joint
reactions), energy conservation and the energy balance with motor and friction, the closure
along the run, a single loop through the graph path against the loop path, the spec table and
the CLI, and the MuJoCo export (validation/mujoco/graph_crosscheck.py compares the motion)."""

from __future__ import annotations

import json
import sys
import tomllib
from pathlib import Path

import mujoco
import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.dynamics.checks import MissingMassError
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
from screwkit.io.drive_table import DriveConfig, JointFriction, MotorConfig
from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.motion import solve_mechanism
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.mass import MassProperties
from screwkit.model.mechanism import Body, Mechanism
from screwkit.simulation.drive import equation_of_motion
from screwkit.simulation.graph_eom import GraphEquationOfMotion
from screwkit.simulation.graph_mjcf import graph_mjcf_model
from screwkit.simulation.graph_run import simulate_graph
from screwkit.simulation.integrate import simulate_cycles
from screwkit.simulation.reduced import SimulationError
from screwkit.simulation.spec_run import spec_gravity

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
runner = CliRunner()


def graph_spec(name: str):  # type: ignore[no-untyped-def]
    path = EXAMPLES / "mechanisms" / f"{name}.toml"
    with path.open("rb") as f:
        return graph_spec_from_data(tomllib.load(f), path)


@pytest.fixture(scope="module")
def watt():  # type: ignore[no-untyped-def]
    return graph_spec("watt_sixbar")


@pytest.fixture(scope="module")
def wishbone():  # type: ignore[no-untyped-def]
    return graph_spec("double_wishbone")


@pytest.mark.parametrize(("name", "step"), [("watt_sixbar", 0.05), ("double_wishbone", 0.05),
                                           ("delta_robot", 0.05), ("stewart_platform", 0.002)])
def test_equations_of_motion_give_the_inverse_dynamics_efforts(name, step):
    """M ẍ + h − Q_g is every input's effort the graph inverse dynamics finds from the joint
    reactions (dynamics/graph_statics.py) at the same inputs, rates and accelerations: one
    crank, the suspension's rod spin held still, the Delta robot's three cranks with six idle
    rods, the Stewart platform's six slides."""
    spec = graph_spec(name)
    n = len(spec.mechanism.inputs)
    eom = GraphEquationOfMotion(spec.mechanism, gravity=spec.gravity_vector)
    rng = np.random.default_rng(7)
    direction = rng.uniform(0.5, 1.0, n)
    X = np.outer(np.arange(5) * step, direction)
    for k in range(1, 5):
        xd, xdd = rng.normal(size=n) * 3 * step / 0.05, rng.normal(size=n) * 10 * step / 0.05
        T = eom.terms(X[k], xd)
        expected = T["mass_matrix"] @ xdd + T["velocity_terms"] - T["gravity"]
        motion = solve_mechanism(spec.mechanism, X[: k + 1], rates=xd, accelerations=xdd)
        dyn = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
        np.testing.assert_allclose(expected, dyn.efforts[-1], rtol=1e-9,
                                   atol=1e-10 * np.max(np.abs(expected)))
        assert T["residual"] < 1e-12
        # M is symmetric positive definite
        M = T["mass_matrix"]
        np.testing.assert_allclose(M, M.T, rtol=1e-12, atol=1e-15 * np.max(np.abs(M)))
        assert np.min(np.linalg.eigvalsh(M)) > 0


def test_energy_is_conserved_and_the_loops_stay_closed(watt, wishbone):
    """No motor, no friction: kinetic + potential energy stays constant (drift below 1e-9 of
    the energy exchanged) and every sample closes the loops to 1e-12."""
    for spec, duration in ((watt, 0.15), (wishbone, 0.1)):
        eom = GraphEquationOfMotion(spec.mechanism, gravity=spec.gravity_vector)
        run = simulate_graph(eom, duration=duration, samples=11, rtol=1e-11)
        assert run.status == "completed", run.message
        assert run.energy_error < 1e-9
        assert np.max(run.closure_residual) < 1e-12
        assert np.ptp(run.inputs[:, 0]) > 0.05  # it moved: gravity did work
        E = run.kinetic_energy + run.potential_energy
        assert np.max(np.abs(E - E[0])) < 1e-9 * np.max(run.kinetic_energy)


def test_several_motors_and_slides_balance_the_energy():
    """The Delta robot's three cranks, each with its own motor law and flywheel, and the
    Stewart platform's six slides falling under gravity: E(t) − E(0) = W_motor, closure kept."""
    delta = graph_spec("delta_robot")
    motors = [MotorConfig("constant", torque=0.5), MotorConfig("constant", torque=-0.2),
              MotorConfig("linear", stall_torque=0.4, no_load_speed=20.0)]
    eom = GraphEquationOfMotion(delta.mechanism, motors=motors, flywheel=[1e-3, 2e-3, 0.0],
                                gravity=delta.gravity_vector)
    run = simulate_graph(eom, duration=0.05, samples=6, rtol=1e-11)
    assert run.status == "completed" and run.energy_error < 1e-9
    assert np.max(run.closure_residual) < 1e-12
    assert len(set(np.round(run.inputs[-1], 6))) == 3  # three different motions
    stewart = graph_spec("stewart_platform")
    eom = GraphEquationOfMotion(stewart.mechanism, gravity=stewart.gravity_vector)
    run = simulate_graph(eom, duration=0.03, samples=4, rtol=1e-11)
    assert run.status == "completed" and run.energy_error < 1e-9
    assert np.all(run.inputs[-1] < 0)  # the legs shorten: the platform falls
    assert np.max(run.closure_residual) < 1e-12


def test_motor_and_friction_work_balance_the_energy(watt):
    """A motor on the crank and friction in two joints: E(t) − E(0) = W_motor + W_friction,
    the friction's work is negative and the motor's positive."""
    fr = (JointFriction("OB", 2e-4), JointFriction("G", 1e-4))
    eom = GraphEquationOfMotion(
        watt.mechanism, motors=[MotorConfig("linear", stall_torque=0.2, no_load_speed=6.0)],
        flywheel=1e-4, friction=fr, gravity=watt.gravity_vector)
    run = simulate_graph(eom, duration=0.2, samples=11, rtol=1e-11)
    assert run.status == "completed"
    assert run.energy_error < 1e-9
    assert run.friction_work[-1] < 0 < run.motor_work[-1]
    assert np.all(np.diff(run.friction_work) <= 0)


def _loop_as_graph(spec):  # type: ignore[no-untyped-def]
    """The spec's loop drawn at its start as a graph, with each link's mass properties carried
    into the drawing (body frames = world there)."""
    lk = spec.linkage
    motion = solve_motion(lk, [float(spec.inputs[0]), float(spec.inputs[0]) + 1e-3],
                          rates=0.0, accelerations=0.0)
    md = motion.mode(0)
    mech = mechanism_from_loop(motion, 0, 0)
    bodies = []
    for k, (b, link) in enumerate(zip(mech.bodies, lk.links, strict=True)):
        R, o = md.link_rotation[0, k], md.link_origin[0, k]
        mp = link.mass
        bodies.append(Body(b.name, MassProperties(mp.mass, R @ mp.com + o,
                                                  R @ mp.inertia @ R.T)))
    return Mechanism(mech.name, tuple(bodies), mech.joints, mech.inputs)


def test_a_single_loop_through_the_graph_path_equals_the_loop_path():
    """The 4R with masses under gravity, a linear motor, a flywheel and friction in two joints:
    simulate's loop path (Fourier-series reduced model) and the graph path (closure at every
    step) give the same input angle and speed over two turns."""
    spec = sk.load_spec(EXAMPLES / "fourbar_dynamics.toml")
    lk = spec.linkage
    th0, w0 = float(spec.inputs[0]), spec.speed
    motor = MotorConfig("linear", stall_torque=3.0, no_load_speed=40.0)
    fr = (JointFriction(lk.joints[0].name, 2e-3), JointFriction(lk.joints[2].name, 1e-3))
    g = spec_gravity(spec)
    drive = DriveConfig(motor=motor, load=None, flywheel=0.01, initial_speed=w0, cycles=2,
                        samples_per_cycle=36, rtol=1e-12, atol=None, gravity=True,
                        max_time=None, friction=fr)
    loop = simulate_cycles(equation_of_motion(lk, drive, start=th0, gravity=g), cycles=2,
                           initial_speed=w0, rtol=1e-12)
    eom = GraphEquationOfMotion(_loop_as_graph(spec), motors=[motor], flywheel=0.01,
                                friction=fr, gravity=g)
    run = simulate_graph(eom, duration=float(loop.cycle_times[-1]), samples=25,
                         initial_rates=[w0], rtol=1e-12)
    y = loop.solution(run.time)
    assert np.max(np.abs(y[0] - th0 - run.inputs[:, 0])) < 1e-9
    assert np.max(np.abs(y[1] - run.rates[:, 0])) < 1e-9 * w0


def test_a_run_stops_at_a_limit_position_with_a_message(wishbone):
    """Released under gravity, the suspension falls to the lower arm's limit: the run ends
    there, saying when and at which input."""
    eom = GraphEquationOfMotion(wishbone.mechanism, gravity=wishbone.gravity_vector)
    run = simulate_graph(eom, duration=0.4, samples=41, rtol=1e-8)
    assert run.status == "stopped"
    assert "dead centre or limit position" in run.message and "L.theta" in run.message
    assert 0.2 < run.time[-1] < 0.3


def test_errors_name_what_is_wrong(watt):
    mech = watt.mechanism
    bare = Mechanism(mech.name, tuple(Body(b.name) for b in mech.bodies), mech.joints,
                     mech.inputs)
    with pytest.raises(MissingMassError, match="crank, coupler, rocker, link_eg, link_gf"):
        GraphEquationOfMotion(bare)
    with pytest.raises(SimulationError, match="2 motor"):
        GraphEquationOfMotion(mech, motors=[MotorConfig(), MotorConfig()])
    with pytest.raises(SimulationError, match="not a joint"):
        GraphEquationOfMotion(mech, friction=[JointFriction("Q", 1.0)])
    with pytest.raises(SimulationError, match="does not slide"):
        GraphEquationOfMotion(mech, friction=[JointFriction("OB", 0.0, 1.0)])


def test_friction_on_an_idle_rod_ball_is_refused(wishbone):
    with pytest.raises(SimulationError, match="rod 'tie_rod'"):
        GraphEquationOfMotion(wishbone.mechanism, friction=[JointFriction("TO", 1e-3)])


def test_simulate_cli_on_the_example(tmp_path):
    """The bundled graph simulate example runs (shortened by its copy), writes JSON, CSV and
    the plots; --cycles, for a loop's crank cycles, is refused."""
    text = (EXAMPLES / "mechanisms" / "watt_sixbar_simulate.toml").read_text(encoding="utf-8")
    assert 'duration = "1 s"' in text
    spec = tmp_path / "w.toml"
    spec.write_text(text.replace('duration = "1 s"', 'duration = "0.05 s"')
                    .replace("samples = 101", "samples = 6"), encoding="utf-8")
    r = runner.invoke(app, ["simulate", str(spec), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["status"] == "completed" and len(doc["time"]) == 6
    assert doc["energy_error"] < 1e-8 and max(doc["closure_residual"]) < 1e-12
    assert doc["drive"]["motors"]["OA.theta"]["kind"] == "linear"
    r = runner.invoke(app, ["simulate", str(spec), "--csv", str(tmp_path / "s.csv")])
    assert r.exit_code == 0, r.output
    head = (tmp_path / "s.csv").read_text(encoding="utf-8").splitlines()[0]
    assert "OA.theta" in head and "closure_residual" in head
    r = runner.invoke(app, ["simulate", str(spec), "--plot", str(tmp_path / "s.png"), "--json"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    r = runner.invoke(app, ["simulate", str(spec), "--cycles", "2"])  # it starts at rest
    assert r.exit_code == 2 and "crank cycles need a nonzero initial rate" in r.output


@pytest.mark.parametrize("name", ["watt_sixbar", "double_wishbone"])
def test_export_mjcf_of_a_graph(tmp_path, name):
    """The exported model compiles, is assembled at qpos0 (every connect satisfied), has the
    spec's masses and one motor per input, and its kinetic energy at unit input rate (joint
    velocities in the null space of its constraint Jacobian) is screwkit's ½ M."""
    out = tmp_path / "model.xml"
    r = runner.invoke(app, ["export-mjcf", str(EXAMPLES / "mechanisms" / f"{name}.toml"),
                            "-o", str(out)])
    assert r.exit_code == 0, r.output
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert np.max(np.abs(d.efc_pos[: d.nefc])) < 1e-12
    spec = graph_spec(name)
    masses = sorted(b.mass.mass for b in spec.mechanism.bodies)
    assert np.allclose(sorted(m.body_mass[1:]), masses, rtol=1e-12)
    assert m.nu == len(spec.mechanism.inputs)
    # generalised inertia: velocities in the null space of MuJoCo's constraint Jacobian with
    # unit input rate (and no rod spin), then q̇ᵀ M q̇ against screwkit's M
    eq = d.efc_J.reshape(d.nefc, m.nv)
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, spec.mechanism.inputs[0].replace(
        ".", "_"))
    e = np.zeros((1, m.nv))
    e[0, m.jnt_dofadr[jid]] = 1.0
    rows = [eq, e]
    for body in ("tie_rod",) if name == "double_wishbone" else ():
        jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jacBody(m, d, jacp, jacr, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY,
                                                               body))
        j = {jj.name: jj for jj in spec.mechanism.joints}
        u = j["TO"].at - j["TI"].at
        rows.append((u / np.linalg.norm(u)) @ jacr[None])
    A = np.concatenate(rows)
    rhs = np.zeros(A.shape[0])
    rhs[eq.shape[0]] = 1.0
    qd = np.linalg.lstsq(A, rhs, rcond=None)[0]
    m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    d.qvel[:] = qd
    mujoco.mj_forward(m, d)  # MuJoCo's kinetic energy ½ q̇ᵀ M q̇ at unit input rate
    eom = GraphEquationOfMotion(spec.mechanism)
    J = eom.terms([0.0], [0.0])["mass_matrix"][0, 0]
    np.testing.assert_allclose(2.0 * d.energy[1], J, rtol=1e-9)


def test_against_mujoco_short():
    """The suspension released under gravity: MuJoCo's lower-arm angle and screwkit's agree
    within MuJoCo's measured step error (the full report: graph_crosscheck.md)."""
    sys.path.insert(0, str(ROOT / "validation" / "mujoco"))
    import graph_crosscheck as gc

    spec = gc.load("double_wishbone")
    angle, energy, closure = gc.screwkit_run(spec, 0.0, 0.05)
    coarse = gc.mujoco_run(spec, 0.0, 0.05, gc.TIMESTEP)
    assert np.max(np.abs(coarse.angle - angle)) < 1e-8
    assert coarse.violation < 1e-9 and energy < 1e-9 and closure < 1e-12


def test_export_refuses_friction_at_a_cut_joint(watt):
    chord = watt.mechanism.joints[watt.mechanism.topology.chords[0]].name
    with pytest.raises(SimulationError, match="cannot damp"):
        graph_mjcf_model(watt.mechanism, friction=[JointFriction(chord, 1e-3)])


@pytest.mark.parametrize(("name", "start"), [("double_wishbone", -0.17), ("watt_sixbar", 0.9)])
def test_export_keyframe_at_the_start_is_assembled_and_moves_as_screwkit(name, start):
    """The keyframe ``start`` is the drawn mode followed to the start inputs: MuJoCo's
    constraints hold there, its input joint is at the start, and released under gravity from it
    MuJoCo's input angle follows screwkit's run from the same start (as the cross-check does
    from the drawing)."""
    spec = graph_spec(name)
    mech = spec.mechanism
    dt = 1e-5
    xml = graph_mjcf_model(mech, gravity=spec.gravity_vector, timestep=dt,
                           solref=(20 * dt, 1.0), start=[start])
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    assert np.max(np.abs(d.efc_pos[: d.nefc])) < 1e-12
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, mech.inputs[0].replace(".", "_"))
    adr = int(m.jnt_qposadr[jid])
    assert d.qpos[adr] == pytest.approx(start, abs=1e-14)
    for _ in range(2000):  # 0.02 s
        mujoco.mj_step(m, d)
    eom = GraphEquationOfMotion(mech, gravity=spec.gravity_vector)
    run = simulate_graph(eom, duration=2000 * dt, samples=2, initial_inputs=[start])
    assert abs(run.inputs[-1, 0] - start) > 1e-4  # it moved
    assert d.qpos[adr] == pytest.approx(run.inputs[-1, 0], abs=1e-8)


def test_the_simulate_example_is_the_watt_six_bar(watt):
    """watt_sixbar_simulate.toml is watt_sixbar.toml plus its [drive] table: the same bodies,
    masses, joints and motion, so the Watt example's kinematics and loads tests cover it."""
    driven = graph_spec("watt_sixbar_simulate")
    a, b = watt.mechanism, driven.mechanism
    assert [x.name for x in a.bodies] == [x.name for x in b.bodies]
    for x, y in zip(a.bodies, b.bodies, strict=True):
        assert x.mass.mass == y.mass.mass
        assert np.array_equal(x.mass.com, y.mass.com)
        assert np.array_equal(x.mass.inertia, y.mass.inertia)
    for x, y in zip(a.joints, b.joints, strict=True):
        assert (x.name, x.kind, x.bodies) == (y.name, y.kind, y.bodies)
        assert np.array_equal(x.at, y.at) and np.array_equal(x.axis, y.axis)
    assert np.array_equal(watt.inputs, driven.inputs) and a.inputs == b.inputs
    assert watt.drive is None and driven.drive is not None
    assert driven.drive.motors[0].kind == "linear" and driven.drive.gravity


def test_a_jump_of_the_closure_is_refused(watt):
    """A closure far from the predictor (an input step of 2.5 rad at once) is refused rather
    than risk landing on another assembly branch; small steps pass."""
    eom = GraphEquationOfMotion(watt.mechanism)
    for x in np.linspace(0.0, 0.5, 11):
        eom.terms([x], [0.0])
    with pytest.raises(SimulationError, match="assembly branch"):
        eom.terms([2.5], [0.0])
