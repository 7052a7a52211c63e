"""The CSSP's two modes share their checked inputs (issue 30): ``sweep_for_root`` gives the other
root's sweep from the same inputs, equal field for field to a sweep prepared for that root, and
the modes built from it equal ``cssp_mode_motion``'s bit for bit; through ``solve_motion`` the
link origins are stored once with the joint centres and the seed's θ1 and s4 are the joint
variables themselves (as the generic solver's seed names are)."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.kinematics.closed_forms.cssp_inputs import cssp_sweep, sweep_for_root
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion, sweep_mode_motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import cssp

INCH = 0.0254
THETA = np.linspace(0.0, 2 * np.pi, 700, endpoint=False)
#: a CSSP that assembles over the whole turn, one (short rod) that assembles over part of it
CASES = {"full turn": 8.0, "part of the turn": 2.5}
FIELDS = ("assembles", "link_rotation", "link_origin", "link_angular_velocity",
          "link_origin_velocity", "link_angular_acceleration", "link_origin_acceleration",
          "joint_centres", "joint_axes", "closure_residual")


def _linkage(a2: float):  # type: ignore[no-untyped-def]
    return cssp(2 * INCH, a2 * INCH, 1 * INCH, np.radians(250.0), 0.4 * INCH)


@pytest.mark.parametrize("a2", CASES.values(), ids=CASES.keys())
def test_the_other_roots_sweep_equals_its_own(a2: float) -> None:
    lk = _linkage(a2)
    plus = cssp_sweep(lk, THETA, 7.0, 2.0, 1, allow_partial=True)
    minus = cssp_sweep(lk, THETA, 7.0, 2.0, -1, allow_partial=True)
    shared = sweep_for_root(plus, -1)
    assert sweep_for_root(plus, 1) is plus
    assert shared.root == -1 and shared.cos is plus.cos  # the trigonometry is not redone
    for name in ("theta1", "cos", "sin", "discriminant", "assembles", "rod_turn"):
        np.testing.assert_array_equal(getattr(shared, name), getattr(minus, name), name)
    assert not np.array_equal(shared.rod_turn, plus.rod_turn)  # the turn is the root's own
    for root, sw in ((1, plus), (-1, shared)):
        got = sweep_mode_motion(lk, sw, seed_angles=True)
        ref = cssp_mode_motion(lk, THETA, 7.0, 2.0, root, allow_partial=True, seed_angles=True)
        for name in FIELDS:
            np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), name)
        for table in ("variables", "velocities", "accelerations"):
            assert list(getattr(got, table)) == list(getattr(ref, table))
            for key, value in getattr(ref, table).items():
                np.testing.assert_array_equal(getattr(got, table)[key], value, key)


@pytest.mark.parametrize("a2", CASES.values(), ids=CASES.keys())
def test_solve_motion_shares_what_is_the_same(a2: float) -> None:
    lk = _linkage(a2)
    motion = solve_motion(lk, THETA, rates=7.0, accelerations=2.0)
    assert len(motion.modes) == 2
    for md in motion.modes:
        # the link origins are the crank (R joint), pin and ball centres: one storage
        np.testing.assert_array_equal(md.link_origin, md.joint_centres[:, :3])
        assert np.shares_memory(md.link_origin, md.joint_centres)
        # and they are the link origins of the loop's own forward kinematics: the crank's on
        # its axis at s1, the rod's at the crank pin, the slider's on the slider axis
        ok = md.assembles
        np.testing.assert_allclose(md.link_origin[ok, 0], [[0.0, 0.0, 0.4 * INCH]] * ok.sum(),
                                   atol=1e-15)
        pin = 2 * INCH * np.stack([np.cos(THETA), np.sin(THETA)], -1)
        np.testing.assert_allclose(md.link_origin[ok, 1, :2], pin[ok], atol=1e-15)
        rod = np.linalg.norm(md.link_origin[ok, 2] - md.link_origin[ok, 1], axis=-1)
        np.testing.assert_allclose(rod, a2 * INCH, rtol=1e-12)
        for table in (md.variables, md.velocities, md.accelerations):
            assert table["theta1"] is table["crank.theta"]
            assert table["s4"] is table["slider.s"]
        assert np.all(np.isnan(md.variables["theta1"][~ok]))
        np.testing.assert_array_equal(md.variables["theta1"][ok], THETA[ok])
        np.testing.assert_array_equal(md.conf.scalars[:, 0], THETA)  # not masked
    for md in motion.modes:  # every mode's fields read back unchanged by the other's masking
        np.testing.assert_array_equal(md.velocities["theta1"][md.assembles], 7.0)
    # the crank rate as an array: one for both modes where nothing is masked, else each its own
    same = motion.modes[0].velocities["theta1"] is motion.modes[1].velocities["theta1"]
    assert same == bool(motion.modes[0].assembles.all())

