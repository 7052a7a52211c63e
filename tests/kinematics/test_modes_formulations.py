"""The closure formulations of kinematics/modes/ checked without solving them (issue 27):
at a configuration built independently (a random pose, random joint axes, a configuration
the graph tracker reached) the system vanishes, its Jacobians match central differences, and the
way back to poses and joint values returns the configuration we started from."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from modes_helpers import check_jacobians, random_r_loop, relative_residual
from screwkit.errors import CapabilityError, InputError
from screwkit.kinematics.graph.closure import graph_forward, graph_layout, zero_configuration
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.modes.loop6r import loop6r_system, random_loop6r
from screwkit.kinematics.modes.planar import planar_formulation
from screwkit.kinematics.modes.r_loop import r_loop_instance
from screwkit.kinematics.modes.stewart import (
    leg_lengths,
    pose_from_study,
    random_stewart,
    stewart_parameters,
    stewart_system,
    study_from_pose,
)
from screwkit.model.mechanism import Mechanism

EXAMPLES = Path(__file__).parents[2] / "examples" / "mechanisms"


# --- Stewart–Gough ---------------------------------------------------------------------------

@pytest.mark.parametrize("complex_values", [False, True])
def test_stewart_system_vanishes_at_the_pose_the_legs_were_measured_at(complex_values: bool
                                                                       ) -> None:
    p, z = random_stewart(np.random.default_rng(1), 50, complex_values)
    S = stewart_system()
    assert (S.n, S.k, S.degrees) == (8, 42, (2, 2, 2, 2, 2, 2, 2, 1))
    assert relative_residual(S, z, p) <= 1e-12
    check_jacobians(S, z[:5], p[:5])


def test_study_coordinates_round_trip_and_give_back_the_leg_lengths() -> None:
    rng = np.random.default_rng(2)
    q = rng.normal(size=(20, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    w, x, y, z = q.T  # an independent rotation: Rodrigues' formula from axis and angle
    angle = 2 * np.arctan2(np.linalg.norm(q[:, 1:], axis=1), w)
    axis = q[:, 1:] / np.linalg.norm(q[:, 1:], axis=1)[:, None]
    K = np.zeros((20, 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    R = np.eye(3) + np.sin(angle)[:, None, None] * K + (1 - np.cos(angle))[:, None, None] * K @ K
    t = rng.normal(size=(20, 3))
    R2, t2 = pose_from_study(study_from_pose(R, t))
    assert np.allclose(R2, R, atol=1e-13) and np.allclose(t2, t, atol=1e-13)
    A, B = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    L = np.linalg.norm(np.einsum("nij,kj->nki", R, B) + t[:, None] - A, axis=2)
    p = stewart_parameters(np.broadcast_to(A, (20, 6, 3)), np.broadcast_to(B, (20, 6, 3)), L)
    assert relative_residual(stewart_system(), study_from_pose(R, t), p) <= 1e-12
    assert np.allclose(leg_lengths(R2, t2, A, B), L, atol=1e-12)


def test_stewart_parameters_refuse_a_wrong_shape() -> None:
    with pytest.raises(InputError, match="6 base points"):
        stewart_parameters(np.zeros((5, 3)), np.zeros((6, 3)), np.ones(6))


# --- 6R loop ---------------------------------------------------------------------------------

@pytest.mark.parametrize("complex_values", [False, True])
def test_loop6r_system_vanishes_at_random_axes(complex_values: bool) -> None:
    p, x = random_loop6r(np.random.default_rng(3), 50, complex_values)
    S = loop6r_system()
    assert (S.n, S.k) == (12, 23)
    assert relative_residual(S, x, p) <= 1e-12
    check_jacobians(S, x[:5], p[:5])


def test_a_7r_loop_at_one_input_is_a_6r_instance_the_tracker_agrees_with() -> None:
    rng = np.random.default_rng(4)
    S = loop6r_system()
    checked = 0
    for trial in range(12):
        mech = random_r_loop(rng, 7, [trial % 7])
        lay = graph_layout(mech)
        X = np.linspace(0.0, 0.3, 7)[:, None]
        followed = follow_drawn_mode(mech, lay, X)
        if not followed.mask.all():
            continue  # a limit position before 0.3 rad: another loop
        conf = followed.conf.take(slice(6, 7))
        inst = r_loop_instance(mech, [0.3])
        x = inst.solution_from_axes(graph_forward(mech, lay, conf).axes)
        assert relative_residual(S, x.astype(complex), inst.params.astype(complex)) <= 1e-12
        back, _ = inst.configuration(x)
        assert np.allclose(back.scalars, conf.scalars, atol=1e-9)
        checked += 1
    assert checked >= 6


def test_a_6r_loop_drawn_is_a_root_and_decodes_to_zero() -> None:
    rng = np.random.default_rng(5)
    for _ in range(5):
        mech = random_r_loop(rng, 6, [])
        inst = r_loop_instance(mech)
        lay = graph_layout(mech)
        frames = graph_forward(mech, lay, zero_configuration(lay))
        x = inst.solution_from_axes(frames.axes)
        assert relative_residual(loop6r_system(), x.astype(complex),
                                 inst.params.astype(complex)) <= 1e-12
        back, _ = inst.configuration(x)
        assert np.allclose(back.scalars, 0.0, atol=1e-12)


def test_r_loop_refuses_other_joints_and_the_wrong_count() -> None:
    rng = np.random.default_rng(6)
    with pytest.raises(CapabilityError, match="exactly six free joints"):
        r_loop_instance(random_r_loop(rng, 7, []))
    spec = sk.load_spec(EXAMPLES / "stewart_platform.toml")
    with pytest.raises(CapabilityError):
        r_loop_instance(spec.mechanism)


# --- planar ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name,unknowns", [("fourbar_graph", 2), ("stephenson3_sixbar", 6),
                                           ("watt_sixbar", 8)])
def test_planar_system_vanishes_along_the_tracked_motion(name: str, unknowns: int) -> None:
    mech = sk.load_spec(EXAMPLES / f"{name}.toml").mechanism
    form = planar_formulation(mech)
    assert form.system.n == unknowns
    lay = graph_layout(mech)
    X = np.linspace(0.0, 0.6, 7)[:, None]
    followed = follow_drawn_mode(mech, lay, X)
    assert followed.mask.all()
    frames = graph_forward(mech, lay, followed.conf)
    o, e1, e2, _ = form.plane
    points = (frames.centres - o) @ e1 + 1j * ((frames.centres - o) @ e2)
    x = form.solution_from_points(points)
    p = form.parameters(X).astype(complex)
    assert relative_residual(form.system, x, p) <= 1e-12
    check_jacobians(form.system, x[:2], p[:2])
    back, _ = form.configuration(x, X)
    assert np.allclose(back.scalars, followed.conf.scalars, atol=1e-9)


def test_planar_refuses_a_spatial_mechanism_and_a_free_one() -> None:
    with pytest.raises(CapabilityError, match="not planar|not R joints"):
        planar_formulation(sk.load_spec(EXAMPLES / "double_wishbone.toml").mechanism)
    mech = sk.load_spec(EXAMPLES / "fourbar_graph.toml").mechanism
    free = Mechanism(mech.name, mech.bodies, mech.joints, ())
    with pytest.raises(InputError, match="square only"):
        planar_formulation(free)


# --- RSSR, RSRC, RCCC at one input -----------------------------------------------------------

@pytest.mark.parametrize("family", ["RSSR", "RSRC", "RCCC"])
def test_loop_systems_vanish_at_the_closed_form_configuration(family: str) -> None:
    """The loop drawn where its closed form puts it: the drawing (output 0, slide 0) is a
    root at input 0, and the Jacobians match central differences there."""
    from screwkit.kinematics.graph.from_loop import mechanism_from_loop
    from screwkit.kinematics.modes.rccc import rccc_loop
    from screwkit.kinematics.modes.rod_loops import rod_loop
    from screwkit.kinematics.solve_motion import solve_motion
    from screwkit.model.families import rccc, rsrc, rssr

    lk = {"RSSR": rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.7, 0.2),
          "RSRC": rsrc(1.0, 4.0, 2.5, 3.0, 1.0, 0.2, 0.1, 0.8),
          "RCCC": rccc((1.0, 3.0, 2.5, 3.0), (0.3, 0.2, -0.4, 0.5))}[family]
    motion = solve_motion(lk, np.linspace(0.0, 2 * np.pi, 24, endpoint=False), method="closed")
    sample = int(np.argmax(motion.mode(0).assembles))
    mech = mechanism_from_loop(motion, 0, sample)
    if family == "RCCC":
        form = rccc_loop(mech)
        c3 = next(j for j in mech.joints if j.name == "C3")
        x = np.r_[c3.axis, np.cross(c3.at, c3.axis)][None]
        x = x * (1 if form._line(2)[1] @ c3.axis > 0 else -1)
    else:
        form = rod_loop(mech)
        x = np.array([[1.0, 0.0, 0.0][: form.system.n]])
    p = form.parameters([0.0]).astype(complex)
    assert relative_residual(form.system, x.astype(complex), p) <= 1e-12
    check_jacobians(form.system, x.astype(complex) + 0.1j, p)


def test_an_arm_at_home_is_a_root_that_decodes_to_zero() -> None:
    from screwkit.kinematics.modes.arm6r import arm6r_instance

    rng = np.random.default_rng(7)
    C, U = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    home = (np.eye(3), rng.normal(size=3))
    inst = arm6r_instance(C, U, home, home)
    x = U[1:5].reshape(1, 12)
    assert relative_residual(loop6r_system(), x.astype(complex), inst.params.astype(complex)
                             ) <= 1e-12
    assert np.abs(inst.joint_values(x)).max() <= 1e-12
    with pytest.raises(InputError, match="6 joint points"):
        arm6r_instance(C[:5], U, home, home)
