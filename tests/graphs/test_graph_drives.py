"""Driven body freedoms (issue 28, model/mechanism_drives.py, kinematics/graph/drives.py): a
Stewart platform driven by its pose gives the leg lengths of the closed-form inverse kinematics;
driving those leg lengths gives the pose back (and its rates and accelerations); the leg forces
do the work the energy takes; a wheel-travel-driven suspension equals the arm-driven one; wrong
counts, unknown bodies, poses out of reach and motors on missing freedoms are refused clearly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
from screwkit.errors import InputError, ScrewkitError
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.motion import AssemblyError
from screwkit.model.mechanism_drives import BodyDrive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
LEGS = [f"P{k}.s" for k in range(1, 7)]
G = np.array([0.0, 0.0, -9.81])


def _rpy(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll) (N, 3), by the textbook formulas."""
    return np.stack([np.arctan2(R[:, 2, 1], R[:, 2, 2]), -np.arcsin(R[:, 2, 0]),
                     np.arctan2(R[:, 1, 0], R[:, 0, 0])], axis=1)


def _pose_rows(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, n)[:, None]
    amp = np.array([0.03, 0.02, 0.04, 0.08, 0.06, 0.1]) * rng.uniform(0.5, 1.0, 6)
    return amp * np.sin(2 * np.pi * t * rng.uniform(0.5, 1.5, 6) + rng.uniform(0, 1, 6))


def test_pose_driven_leg_lengths_are_the_examples_inverse_kinematics() -> None:
    """stewart_platform.toml's leg rows were computed in closed form (|c + R p_i − b_i|) for
    its pose trajectory; driving that pose gives the same leg lengths."""
    legs = sk.load_spec(EXAMPLES / "stewart_platform.toml")
    pose = sk.load_spec(EXAMPLES / "stewart_platform_pose.toml")
    s = np.arange(50) / 49
    deg = np.pi / 180
    X = np.stack([0.04 * np.sin(2 * np.pi * s), 0.03 * np.sin(4 * np.pi * s),
                  0.025 * np.sin(np.pi * s), 5 * deg * np.sin(4 * np.pi * s),
                  4 * deg * np.sin(2 * np.pi * s), 6 * deg * np.sin(2 * np.pi * s)], axis=1)
    md = solve_mechanism(pose.mechanism, X).modes[0]
    assert md.assembles.all() and not md.events
    got = np.stack([md.variables[n] for n in LEGS], axis=1)
    np.testing.assert_allclose(got, legs.inputs, rtol=0, atol=1e-12)  # rows: 1e-10 mm


def test_pose_then_legs_round_trip_with_rates_and_accelerations() -> None:
    spec = sk.load_spec(EXAMPLES / "stewart_platform_pose.toml")
    mech = spec.mechanism
    X = _pose_rows(12, 3)
    rng = np.random.default_rng(5)
    Xd, Xdd = rng.normal(0, 0.1, X.shape), rng.normal(0, 0.5, X.shape)
    by_pose = solve_mechanism(mech, X, rates=Xd, accelerations=Xdd).modes[0]
    assert by_pose.assembles.all() and not by_pose.singular.any()
    legs = [np.stack([table[n] for n in LEGS], axis=1)
            for table in (by_pose.variables, by_pose.velocities, by_pose.accelerations)]
    leg_mech = mech.with_inputs(LEGS)
    by_legs = solve_mechanism(leg_mech, legs[0], rates=legs[1], accelerations=legs[2]).modes[0]
    k = mech.body_index("platform")
    for field in ("link_rotation", "link_origin", "link_angular_velocity",
                  "link_origin_velocity", "link_angular_acceleration",
                  "link_origin_acceleration"):
        a, b = getattr(by_pose, field)[:, k], getattr(by_legs, field)[:, k]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * max(1.0, np.abs(b).max()),
                                   err_msg=field)
    # the leg-driven platform's pose coordinates are the driven values (the drive's meaning)
    centre = by_legs.points["centre"]
    np.testing.assert_allclose(centre - [0, 0, 0.4], X[:, :3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(_rpy(by_legs.link_rotation[:, k]), X[:, 3:], rtol=0, atol=1e-12)
    # and their rates: the centre's velocity, and ω = ψ̇ z + θ̇ Rz y + φ̇ Rz Ry x
    np.testing.assert_allclose(by_legs.point_velocities["centre"], Xd[:, :3], atol=1e-11)
    pitch, yaw = X[:, 4], X[:, 5]
    cz, sz, cy, sy = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
    z = np.tile([0.0, 0.0, 1.0], (len(X), 1))
    y1 = np.stack([-sz, cz, 0 * cz], 1)
    x2 = np.stack([cz * cy, sz * cy, -sy], 1)
    w = Xd[:, 5, None] * z + Xd[:, 4, None] * y1 + Xd[:, 3, None] * x2
    np.testing.assert_allclose(by_legs.link_angular_velocity[:, k], w, atol=1e-11)
    # and accelerations: the centre's, and α = Σ angle'' axis + θ̇ ψ̇ z × y1 + φ̇ (ψ̇ z + θ̇ y1) × x2
    np.testing.assert_allclose(by_legs.point_accelerations["centre"], Xdd[:, :3], atol=1e-10)
    al = (Xdd[:, 5, None] * z + Xdd[:, 4, None] * y1 + Xdd[:, 3, None] * x2
          + Xd[:, 4, None] * np.cross(Xd[:, 5, None] * z, y1)
          + Xd[:, 3, None] * np.cross(Xd[:, 5, None] * z + Xd[:, 4, None] * y1, x2))
    np.testing.assert_allclose(by_legs.link_angular_acceleration[:, k], al, atol=1e-10)


def test_pose_driven_leg_forces_do_the_work_the_energy_takes() -> None:
    """Σ leg force · leg rate = d(kinetic + potential energy)/dt, exactly (dT/dt = Σ m v_c·a_c
    + ω·(I α + ω × I ω), dV/dt = −Σ m g·v_c from the body twists and accelerations, to 1e-9
    relative) along a pose path with random pose rates and accelerations, and by a five-point
    derivative of the energy along a constant-rate path (a second, independent route, to 1e-7);
    the platform's Newton–Euler balance holds with the reported ball reactions; the efforts
    equal those of the same motion driven by the legs."""
    from tests.graphs.test_graph_dynamics import _energy_and_momentum
    from tests.graphs.test_graph_dynamics_random import _body_motion, _dH

    spec = sk.load_spec(EXAMPLES / "stewart_platform_pose.toml")
    mech = spec.mechanism
    rows = _pose_rows(7, 11)
    rng = np.random.default_rng(5)
    scale = np.array([0.05 * mech.length_scale] * 3 + [1.0] * 3)
    exact = solve_mechanism(mech, rows, rates=rng.uniform(-1.0, 1.0, rows.shape) * scale,
                            accelerations=rng.uniform(-2.0, 2.0, rows.shape) * scale)
    dyn_x = graph_inverse_dynamics(exact, gravity=G)
    bodies = _body_motion(mech, exact.modes[0])
    q_dot = np.stack([exact.modes[0].velocities[n] for n in LEGS], axis=1)
    power_x = np.einsum("nk,nk->n", dyn_x.efforts, q_dot)
    dE_x = sum(bd["m"] * np.einsum("ni,ni->n", bd["v"], bd["a"] - G)
               + np.einsum("ni,ni->n", bd["w"], _dH(bd)) for bd in bodies)
    assert dyn_x.ok.all() and np.abs(dE_x).min() > 0
    np.testing.assert_allclose(power_x, dE_x, rtol=0, atol=1e-9 * np.abs(dE_x).max())
    x0 = rows[3]
    direction = np.array([0.02, -0.01, 0.03, 0.1, -0.05, 0.08])
    h = 1e-3
    X = x0 + np.arange(-2.0, 3.0)[:, None] * h * direction
    motion = solve_mechanism(mech, X, rates=direction, accelerations=0.0)
    md = motion.modes[0]
    dyn = graph_inverse_dynamics(motion, gravity=G)
    assert dyn.input_names == tuple(LEGS) and np.nanmax(dyn.residual) < 1e-10
    E, _, _ = _energy_and_momentum(mech, md, G)
    dE = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) @ E / (12.0 * h)
    rates_ = np.array([md.velocities[n][2] for n in LEGS])
    power = float(dyn.efforts[2] @ rates_)
    assert abs(power - dE) <= 1e-7 * abs(dE)
    # the platform: Σ ball reactions on it + weight − d(momentum)/dt = 0 (forces and moments)
    k = mech.body_index("platform")
    mp = mech.bodies[k].mass
    R, p = md.link_rotation[:, k], md.link_origin[:, k]
    w, al = md.link_angular_velocity[:, k], md.link_angular_acceleration[:, k]
    c = np.einsum("nij,j->ni", R, mp.com) + p
    ac = (md.link_origin_acceleration[:, k] + np.cross(al, c - p)
          + np.cross(w, np.cross(w, c - p)))
    Iw = np.einsum("nij,jk,nlk->nil", R, mp.inertia, R)
    force = mp.mass * (G - ac)
    moment = np.cross(c, force) - (np.einsum("nij,nj->ni", Iw, al)
                                   + np.cross(w, np.einsum("nij,nj->ni", Iw, w)))
    for j, joint in enumerate(mech.joints):
        if "platform" in joint.bodies:
            sign = 1.0 if joint.bodies[1] == "platform" else -1.0
            f = dyn.reaction_force[:, j]
            force = force + sign * f
            moment = moment + sign * (dyn.reaction_moment[:, j]
                                      + np.cross(md.joint_centres[:, j], f))
    scale = mp.mass * np.linalg.norm(G)
    assert np.abs(force).max() < 1e-9 * scale and np.abs(moment).max() < 1e-9 * scale * 0.4
    # the same motion driven by the legs: the same leg forces
    legs = [np.stack([t[n] for n in LEGS], axis=1)
            for t in (md.variables, md.velocities, md.accelerations)]
    by_legs = solve_mechanism(mech.with_inputs(LEGS), legs[0], rates=legs[1],
                              accelerations=legs[2])
    ref = graph_inverse_dynamics(by_legs, gravity=G)
    np.testing.assert_allclose(dyn.efforts, ref.efforts, rtol=0,
                               atol=1e-9 * np.abs(ref.efforts).max())


def test_wheel_travel_drive_equals_the_arm_driven_suspension() -> None:
    travel = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml")
    arm = sk.load_spec(EXAMPLES / "double_wishbone.toml")
    motion = solve_mechanism(travel.mechanism, travel.inputs, rates=travel.speed,
                             accelerations=0.0)
    md = motion.modes[0]
    assert md.assembles.all()
    wheel = md.points["wheel_centre"]
    np.testing.assert_allclose(wheel[:, 2] - 0.3, travel.inputs[:, 0], atol=1e-12)
    np.testing.assert_allclose(md.point_velocities["wheel_centre"][:, 2], travel.speed[0],
                               rtol=1e-10)
    np.testing.assert_allclose(md.point_accelerations["wheel_centre"][:, 2], 0.0, atol=1e-10)
    ref_motion = solve_mechanism(arm.mechanism, md.variables["L.theta"][:, None],
                                 rates=md.velocities["L.theta"][:, None],
                                 accelerations=md.accelerations["L.theta"][:, None])
    ref = ref_motion.modes[0]
    np.testing.assert_allclose(ref.points["wheel_centre"], wheel, atol=1e-12)
    np.testing.assert_allclose(ref.link_angular_acceleration, md.link_angular_acceleration,
                               atol=1e-9 * np.abs(ref.link_angular_acceleration).max())
    from screwkit.io.mechanism_documents import mechanism_table

    table = mechanism_table(motion)  # the drive is a column of its own, with its kind
    col = table.column("upright.z_dot")
    assert col.kind == "velocity" and np.allclose(col.values, travel.speed[0])
    assert np.array_equal(table.column("upright.z").values, travel.inputs[:, 0])
    dyn = graph_inverse_dynamics(motion, gravity=G)
    dref = graph_inverse_dynamics(ref_motion, gravity=G)
    assert dyn.input_names == ("L.theta",)
    np.testing.assert_allclose(dyn.efforts, dref.efforts, rtol=1e-9)
    # the arm's torque times its rate is the power the energy takes, exactly (no differences)
    from tests.graphs.test_graph_dynamics_random import _body_motion, _dH

    bodies = _body_motion(travel.mechanism, md)
    dE = sum(bd["m"] * np.einsum("ni,ni->n", bd["v"], bd["a"] - G)
             + np.einsum("ni,ni->n", bd["w"], _dH(bd)) for bd in bodies)
    power = dyn.efforts[:, 0] * md.velocities["L.theta"]
    np.testing.assert_allclose(power, dE, rtol=0, atol=1e-9 * np.abs(dE).max())


def _stewart(drives: list[str], inputs: tuple[str, ...] = (), actuated: tuple[str, ...] = ()
             ) -> sk.Mechanism:
    mech = sk.load_spec(EXAMPLES / "stewart_platform.toml").mechanism
    ds = [BodyDrive(f"platform.{f}", "platform", f, np.array([0, 0, 0.4])) for f in drives]
    return mech.with_inputs(inputs, ds, actuated)


def test_wrong_counts_and_repeated_freedoms_are_refused() -> None:
    few = _stewart(["x", "y", "z", "roll", "pitch"])
    with pytest.raises(InputError, match=r"5 driven freedom\(s\).*needs 6; add 1"):
        solve_mechanism(few, np.zeros((1, 5)))
    many = _stewart(["x", "y", "z", "roll", "pitch", "yaw"], inputs=("P1.s",))
    with pytest.raises(InputError, match=r"7 driven freedom\(s\).*needs 6; remove 1"):
        solve_mechanism(many, np.zeros((1, 7)))
    arm = sk.load_spec(EXAMPLES / "double_wishbone.toml").mechanism
    two = arm.with_inputs((), [BodyDrive("upright.z", "upright", "z", np.array([0, 0.77, 0.3])),
                               BodyDrive("lower_arm.roll", "lower_arm", "roll")])
    with pytest.raises(InputError, match=r"conflict: 2 driven.*mobility 1.*remove 1"):
        solve_mechanism(two, np.zeros((1, 2)))
    # the right count, but a point on the lower arm's hinge axis cannot travel: nothing fixed
    still = arm.with_inputs((), [BodyDrive("lower_arm.z", "lower_arm", "z",
                                           np.array([0.0, 0.355, 0.155]))])
    with pytest.raises(InputError, match="do not fix the mechanism.*free with these held"):
        solve_mechanism(still, np.zeros((1, 1)))


def test_bad_drives_and_motors_name_what_is_wrong() -> None:
    mech = sk.load_spec(EXAMPLES / "stewart_platform.toml").mechanism
    with pytest.raises(ScrewkitError, match="'wheel' is not a moving body"):
        mech.with_inputs((), [BodyDrive("wheel.z", "wheel", "z")])
    with pytest.raises(ScrewkitError, match="unknown freedom 'heave'"):
        mech.with_inputs((), [BodyDrive("platform.heave", "platform", "heave")])
    with pytest.raises(ScrewkitError, match=r"'P1.theta' is not a motorised freedom.*'P1' has"):
        _stewart(["z"], actuated=("P1.theta",))
    with pytest.raises(ScrewkitError, match="a ball joint has no freedom"):
        _stewart(["z"], actuated=("S1.wx",))
    with pytest.raises(ScrewkitError, match=r"2 actuated freedom\(s\).*for 1 driven"):
        _stewart(["z"], actuated=("P1.s", "P2.s"))
    pose = _stewart(["x", "y", "z", "roll", "pitch", "yaw"])  # no motors named
    motion = solve_mechanism(pose, np.zeros((2, 6)))
    with pytest.raises(ScrewkitError, match="need as many actuated joint freedoms"):
        graph_inverse_dynamics(motion)


def test_a_pose_out_of_reach_says_where_the_workspace_ends() -> None:
    spec = sk.load_spec(EXAMPLES / "double_wishbone_travel.toml")
    with pytest.raises(AssemblyError, match=r"after upright\.z = 0\.29\d* m"):
        solve_mechanism(spec.mechanism, np.array([[0.5]]))
    md = solve_mechanism(spec.mechanism, np.linspace(0.0, 0.5, 26)[:, None]).modes[0]
    assert md.assembles[:15].all() and not md.assembles[15:].any()
    assert md.events[0].startswith("stops assembling after input upright.z = 0.28 m")


def _spec_text(name: str, old: str, new: str) -> str:
    text = (EXAMPLES / f"{name}.toml").read_text(encoding="utf-8")
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize(("name", "old", "new", "message"), [
    ("double_wishbone_travel", 'name = "U"\n', 'name = "U"\nactuated = true\n',
     r"2 actuated freedom\(s\) \(L.theta, U.theta\) for 1 driven body freedom"),
    ("double_wishbone", 'name = "U"\n', 'name = "U"\nactuated = true\n',
     r"actuated = true is for mechanisms driven by body freedoms"),
    ("double_wishbone_travel", 'speed = "50 mm/s"', 'speed = ["50 mm/s", "1 deg/s"]',
     r"give one speed for every driven freedom \(1: upright.z\)"),
    ("double_wishbone_travel", 'point = "wheel_centre"\nfreedom = "z"',
     'body = "tie_rod"\nfreedom = "roll"', r"'tie_rod' is a rod between two balls"),
    ("double_wishbone_travel", 'point = "wheel_centre"\nfreedom = "z"',
     'body = "upright"\nfreedom = "z"', r"give at = \[x, y, z\]"),
    ("stewart_platform_pose", 'speed = ["5 mm/s", "0 mm/s", "10 mm/s",',
     'speed = ["5 mm/s", "0 deg/s", "10 mm/s",', r"motion.speed\[1\]"),
])
def test_spec_errors_of_drives_and_motors(tmp_path: Path, name: str, old: str, new: str,
                                          message: str) -> None:
    path = tmp_path / "spec.toml"
    path.write_text(_spec_text(name, old, new), encoding="utf-8")
    with pytest.raises(ScrewkitError, match=message):
        sk.load_spec(path)


def test_dynamics_command_reports_the_leg_forces_of_a_pose_driven_platform() -> None:
    import json

    from typer.testing import CliRunner

    from screwkit.cli.main import app

    path = EXAMPLES / "stewart_platform_pose.toml"
    r = CliRunner().invoke(app, ["dynamics", str(path), "--gravity", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["inputs"] == LEGS and set(doc["efforts"]) == set(LEGS)
    spec = sk.load_spec(path)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed)
    dyn = graph_inverse_dynamics(motion, gravity=spec.gravity_vector)
    np.testing.assert_allclose(doc["efforts"]["P3.s"], dyn.efforts[:, 2], rtol=1e-12)
    assert len(doc["input"]) == 41 and len(doc["input"][0]) == 6


def test_joint_inputs_and_body_drives_mix() -> None:
    """Five pose coordinates and one leg length: the leg read back from the pose-driven motion
    gives the same motion."""
    pose = _stewart(["x", "y", "z", "roll", "pitch", "yaw"])
    X = _pose_rows(6, 8)
    md = solve_mechanism(pose, X, rates=0.1).modes[0]
    mixed = _stewart(["x", "y", "z", "roll", "pitch"], inputs=("P4.s",))
    assert mixed.driven_names == ("P4.s", "platform.x", "platform.y", "platform.z",
                                  "platform.roll", "platform.pitch")
    rows = np.column_stack([md.variables["P4.s"], X[:, :5]])
    rates_ = np.column_stack([md.velocities["P4.s"], np.full((6, 5), 0.1)])
    got = solve_mechanism(mixed, rows, rates=rates_).modes[0]
    for n in LEGS:
        np.testing.assert_allclose(got.variables[n], md.variables[n], atol=1e-12)
        np.testing.assert_allclose(got.velocities[n], md.velocities[n], atol=1e-11)
