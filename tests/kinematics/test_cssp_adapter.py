"""The closed-form CSSP ModeMotion (screwkit.kinematics.closed_forms.cssp_motion) equals the generic solver's.

The rod of a CSSP is an S–S link: its spin angle about its own axis is not fixed by the loop,
so the two paths may give rod rotations that differ by a turn about the rod axis. Compared here
is everything that does not depend on that angle: link origins and their rates, ω and α of every
link (both use zero absolute rod spin), joint centres, the spin-free joint axes, the rod axis,
the ball-joint rates in world components, and the inverse-dynamics loads of a rod that is
axisymmetric about its axis. Tolerances: both sides are exact formulas, so agreement is to
round-off, 1e-10 of each quantity's natural scale (a2, ω·a2, ω²·a2, ω, ω², the peak load).
"""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.dual import ScrewMatrix
from screwkit.dynamics import inverse_dynamics
from screwkit.kinematics.closed_forms.cssp import CSSPAssemblyError
from screwkit.kinematics.closed_forms.cssp_motion import (
    NotACSSPError,
    cssp_dimensions,
    cssp_mode_motion,
)
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model.families import cssp, fourbar
from screwkit.model.linkage import Link, Linkage
from screwkit.model.mass import MassProperties

deg = np.radians
INCH = 0.0254
OMEGA, OMEGA_DOT = 314.159, 25.0
RTOL = 1e-10


def _with_masses(lk: Linkage, a1: float, a2: float) -> Linkage:
    # an axisymmetric rod (CoM on its axis, Iyy = Izz): its free spin carries no load
    return lk.with_links([
        Link("crank", MassProperties(0.9, [0.5 * a1, 0.01, -0.004],
                                     np.array([[2e-5, 1e-6, 0.0], [1e-6, 2e-4, 3e-6],
                                               [0.0, 3e-6, 2.1e-4]]))),
        Link("rod", MassProperties(3.4, [0.45 * a2, 0.0, 0.0], np.diag([9e-5, 1.2e-2, 1.2e-2]))),
        Link("slider", MassProperties(2.7, [0.003, -0.002, 0.001], np.diag([5e-4, 6e-4, 9e-4]))),
    ])


def _spin_free_agreement(lk: Linkage, fast: ModeMotion, slow: ModeMotion, a2: float) -> None:
    w = OMEGA
    scale = {
        "link_origin": a2, "joint_centres": a2, "link_origin_velocity": w * a2,
        "link_origin_acceleration": w**2 * a2, "link_angular_velocity": w,
        "link_angular_acceleration": w**2,
    }
    for name, s in scale.items():
        np.testing.assert_allclose(getattr(fast, name), getattr(slow, name), rtol=0,
                                   atol=RTOL * s, err_msg=name)
    # joint axes except the ball joint's (its z axis is the rod frame's, which turns with spin)
    np.testing.assert_allclose(fast.joint_axes[:, [0, 1, 3]], slow.joint_axes[:, [0, 1, 3]],
                               atol=RTOL)
    np.testing.assert_allclose(fast.link_rotation[:, [0, 2]], slow.link_rotation[:, [0, 2]],
                               atol=RTOL)
    np.testing.assert_allclose(fast.link_rotation[:, 1, :, 0], slow.link_rotation[:, 1, :, 0],
                               atol=RTOL)
    for name in lk.freedom_names:
        if name.startswith("pin."):
            continue
        np.testing.assert_allclose(fast.velocities[name], slow.velocities[name],
                                   atol=RTOL * w * a2, err_msg=name)
        np.testing.assert_allclose(fast.accelerations[name], slow.accelerations[name],
                                   atol=RTOL * w**2 * a2, err_msg=name)
    # the pin's rates are child-frame components: compare them in the world (R·q̇ and R·q̈
    # = α_rod − α_crank + ω_rod × ω_crank do not depend on the rod's spin angle)
    for table, s in (("velocities", w), ("accelerations", w**2)):
        world = []
        for mm in (fast, slow):
            comp = np.stack([getattr(mm, table)[f"pin.w{a}"] for a in "xyz"], -1)
            world.append(np.einsum("nij,nj->ni", mm.link_rotation[:, 1], comp))
        np.testing.assert_allclose(world[0], world[1], atol=RTOL * s, err_msg=f"pin {table}")
    np.testing.assert_allclose(fast.variables["slider.s"], slow.variables["slider.s"],
                               atol=RTOL * a2)
    assert np.all(fast.closure_residual < 1e-14)


def _matching_mode(fast: ModeMotion, slow_modes: list[ModeMotion]) -> ModeMotion:
    hits = [m for m in slow_modes
            if np.all(np.abs(m.variables["slider.s"] - fast.variables["slider.s"]) < 1e-9)]
    assert len(hits) == 1
    return hits[0]


def _loads_agree(lk: Linkage, fast: ModeMotion, slow: ModeMotion) -> None:
    g = [0.0, -3.0, -9.80665]
    fd = inverse_dynamics(lk, fast, gravity=g, moment_point=[0.01, -0.02, 0.03])
    sd = inverse_dynamics(lk, slow, gravity=g, moment_point=[0.01, -0.02, 0.03])
    peak = sd.residual_scale
    np.testing.assert_allclose(fd.shaking_force, sd.shaking_force, atol=RTOL * peak)
    np.testing.assert_allclose(fd.shaking_moment, sd.shaking_moment, atol=RTOL * peak)
    for j in fd.reactions:
        for part in ("force", "moment"):
            np.testing.assert_allclose(fd.reactions[j][part], sd.reactions[j][part],
                                       atol=RTOL * peak, err_msg=f"{j} {part}")
    np.testing.assert_allclose(fd.efforts["crank.theta"], sd.efforts["crank.theta"],
                               atol=RTOL * peak)
    assert np.all(fd.relative_residual < 1e-12)


def test_rahman_example_both_modes_equal_generic():
    a1, a2 = 2 * INCH, 8 * INCH
    lk = _with_masses(cssp(a1, a2, INCH, deg(250), 0.4 * INCH), a1, a2)
    theta = deg(np.arange(0.0, 360.0, 15.0))
    slow = motion(lk, theta, OMEGA, OMEGA_DOT)
    for mode in (1, -1):
        fast = cssp_mode_motion(lk, theta, OMEGA, OMEGA_DOT, mode)
        md = _matching_mode(fast, slow.modes)
        _spin_free_agreement(lk, fast, md, a2)
        _loads_agree(lk, fast, md)


@settings(max_examples=4, deadline=None, derandomize=True)
@given(a1=st.floats(0.03, 0.06), a2=st.floats(0.18, 0.25), a4=st.floats(-0.03, 0.03),
       alpha4=st.floats(deg(200), deg(290)), s1=st.floats(-0.02, 0.02))
def test_random_cssp_equals_generic(a1, a2, a4, alpha4, s1):
    lk = _with_masses(cssp(a1, a2, a4, alpha4, s1), a1, a2)
    theta = deg(np.arange(0.0, 360.0, 30.0))
    slow = motion(lk, theta, OMEGA, OMEGA_DOT)
    fast = cssp_mode_motion(lk, theta, OMEGA, OMEGA_DOT, root=1)
    md = _matching_mode(fast, slow.modes)
    _spin_free_agreement(lk, fast, md, a2)
    _loads_agree(lk, fast, md)


def test_driven_offset_and_placed_base_equal_generic():
    a1, a2 = 2 * INCH, 8 * INCH
    lk = _with_masses(cssp(a1, a2, INCH, deg(250), 0.4 * INCH, s1_is_input=True), a1, a2)
    base = ScrewMatrix.from_rotation_translation(
        np.array([[0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.8, 0.0, 0.6]]), np.array([0.1, 0.2, -0.3])
    )
    lk = replace(lk, base=base)
    theta = deg(np.arange(0.0, 360.0, 30.0))
    s1 = 0.4 * INCH + 0.1 * INCH * np.sin(theta)
    s1_dot = 0.1 * INCH * OMEGA * np.cos(theta)
    s1_ddot = -0.1 * INCH * OMEGA**2 * np.sin(theta)
    slow = motion(lk, np.stack([theta, s1], -1), np.stack([np.full_like(theta, OMEGA), s1_dot], -1),
                  np.stack([np.full_like(theta, OMEGA_DOT), s1_ddot], -1))
    fast = cssp_mode_motion(lk, theta, OMEGA, OMEGA_DOT, s1=s1, s1_dot=s1_dot, s1_ddot=s1_ddot)
    md = _matching_mode(fast, slow.modes)
    _spin_free_agreement(lk, fast, md, a2)
    np.testing.assert_allclose(fast.variables["crank.s"], s1)


def test_errors_and_partial_assembly():
    with pytest.raises(NotACSSPError, match="families.cssp"):
        cssp_dimensions(fourbar(1.0, 0.3, 1.1, 0.8))
    lk = cssp(2 * INCH, 8 * INCH, INCH, deg(250), 0.4 * INCH)
    with pytest.raises(ValueError, match="s1_is_input=True"):
        cssp_mode_motion(lk, [0.0, 1.0], 1.0, s1=0.01)
    short = cssp(0.05, 0.06, 0.03, deg(250), 0.0)  # the rod cannot reach over the whole turn
    theta = deg(np.arange(0.0, 360.0, 10.0))
    with pytest.raises(CSSPAssemblyError, match="does not assemble"):
        cssp_mode_motion(short, theta, 1.0)
    part = cssp_mode_motion(short, theta, 1.0, allow_partial=True)
    assert part.assembles.any() and not part.assembles.all()
    assert np.all(np.isnan(part.link_origin[~part.assembles]))
    assert np.all(np.isfinite(part.link_origin[part.assembles]))
    assert np.all(np.isnan(part.variables["pin.rx"][~part.assembles]))
    no_rv = cssp_mode_motion(lk, theta, 1.0, joint_rotations=False)
    assert "pin.rx" not in no_rv.variables and "pin.wx" in no_rv.velocities
