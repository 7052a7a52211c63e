"""Every joint kind (R, P, C, H, U, S) in the generic solver: loops that use the helical and
universal joints close, and their rates are derivatives of their positions."""

import numpy as np
import pytest

from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.kinematics.tracker.loop import closure_twist, forward
from screwkit.model import Joint, Linkage

deg = np.radians


def _loops():
    # R S H C: 1 + 3 + 1 + 2 = 7 freedoms, one loop (6) -> one input (Bagci's RSHC family)
    rshc = Linkage.from_hartenberg_denavit(
        "RSHC", [Joint("in", "R"), Joint("ball", "S"), Joint("screw", "H", pitch=0.02),
                 Joint("cyl", "C")],
        [0.05, 0.2, 0.15, 0.18], [deg(20), deg(10), deg(-30), deg(40)], inputs=["in.theta"])
    # R U S R: 1 + 2 + 3 + 1 = 7
    rusr = Linkage.from_hartenberg_denavit(
        "RUSR", [Joint("in", "R"), Joint("u", "U", offset=0.01), Joint("ball", "S"),
                 Joint("out", "R", offset=0.02)],
        [0.05, 0.2, 0.15, 0.18], [deg(30), deg(0), deg(10), deg(60)], inputs=["in.theta"])
    # R P S S... keep a prismatic input too: P S S R with the slider driven
    pssr = Linkage.from_hartenberg_denavit(
        "PSSR", [Joint("slide", "P"), Joint("b1", "S"), Joint("b2", "S"), Joint("out", "R")],
        [0.0, 0.2, 0.1, 0.15], [deg(90), 0.0, 0.0, deg(70)], inputs=["slide.s"])
    return {"RSHC": rshc, "RUSR": rusr, "PSSR": pssr}


@pytest.mark.parametrize("name", ["RSHC", "RUSR", "PSSR"])
def test_loops_with_every_joint_kind_close_and_differentiate(name):
    lk = _loops()[name]
    h = 1e-4  # closure to 1e-11 leaves ~1e-12 position noise: FD noise ~1e-8 at this step
    x0 = 0.6 if name != "PSSR" else 0.01
    x = x0 + h * np.arange(-2, 3)
    m = motion(lk, x, 1.0, 0.0)
    assert m.modes, f"{name} found no assembly"
    checked = 0
    for md in m.modes:
        if not md.assembles.all():
            continue
        assert np.max(md.closure_residual) < 1e-10
        c = md.joint_centres
        vel_fd = (c[0] - 8 * c[1] + 8 * c[3] - c[4]) / (12 * h)
        for i in range(md.link_origin.shape[1]):
            p = c[2, i + 1]
            v = md.link_origin_velocity[2, i] + np.cross(md.link_angular_velocity[2, i], p - md.link_origin[2, i])
            np.testing.assert_allclose(v, vel_fd[i + 1], atol=1e-7)
        for key, values in md.variables.items():
            if key.split(".")[1].startswith("r"):  # spherical rotation vectors: not rates
                continue
            fd = (values[0] - 8 * values[1] + 8 * values[3] - values[4]) / (12 * h)
            acc_fd = (-values[0] + 16 * values[1] - 30 * values[2] + 16 * values[3] - values[4]) / (12 * h * h)
            np.testing.assert_allclose(md.velocities[key][2], fd, atol=1e-6, err_msg=key)
            # second differences lose ~8 digits at this step: 1e-3 of O(1-100) accelerations
            np.testing.assert_allclose(md.accelerations[key][2], acc_fd, atol=1e-3 * max(1.0, abs(acc_fd)), err_msg=key)
        checked += 1
    assert checked


def test_helical_joint_translation_follows_its_pitch():
    lk = _loops()["RSHC"]
    m = motion(lk, np.array([0.6, 0.61]))
    md = m.modes[0]
    fr = forward(lk, md.conf)
    assert np.abs(closure_twist(fr.closure_R, fr.closure_p)).max() < 1e-10
    # the H joint frame moves pitch·θ along its axis: the next joint frame's origin shifts
    th = md.variables["screw.theta"]
    shift = fr.before_p[:, 3] - fr.before_p[:, 2]
    axis = fr.before_R[:, 2, :, 2]
    along = np.sum(shift * axis, axis=-1)
    np.testing.assert_allclose(along, 0.02 * th, atol=1e-12)
