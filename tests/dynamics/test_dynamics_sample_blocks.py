"""Blocked evaluation of inverse dynamics (screwkit.dynamics.sample_blocks): results do not depend
on the block size, with or without non-assembling samples; the blocked closed-form CSSP
kinematics (cssp_mode_motion) does not depend on its block size; a NaN found late in an
assembled mode is named or skipped; peak memory is the outputs plus one block."""

from __future__ import annotations

import tracemalloc
from dataclasses import replace

import numpy as np
import pytest
from mechanisms import assert_same_dynamics, full_cycle, random_mass

import screwkit.kinematics.closed_forms.cssp_motion as cssp_motion_module
from screwkit.dynamics import cssp_inverse_dynamics, inverse_dynamics
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.model.families import cssp
from screwkit.model.linkage import Link


@pytest.mark.parametrize("family", ["cssp", "fourbar", "rccc"])
def test_results_do_not_depend_on_the_block_size(family: str) -> None:
    lk, _, mode = full_cycle(family, 1)
    whole = inverse_dynamics(lk, mode, [0, 0, -9.81], [0.2, 0.0, 0.1])
    blocks = inverse_dynamics(lk, mode, [0, 0, -9.81], [0.2, 0.0, 0.1], block_size=5)
    assert_same_dynamics(blocks, whole, lk.length_scale, tol=1e-15)


def test_blocks_with_non_assembling_samples() -> None:
    short = cssp(0.05, 0.06, 0.03, np.radians(250), 0.0)  # assembles over part of the turn
    rng = np.random.default_rng(5)
    short = short.with_links([Link(n, random_mass(rng, 0.05)) for n in ("crank", "rod",
                                                                           "slider")])
    theta = np.radians(np.arange(0.0, 360.0, 2.0))
    mm = cssp_mode_motion(short, theta, 10.0, 1.0, allow_partial=True)
    assert 0 < mm.assembles.sum() < theta.size
    ref = inverse_dynamics(short, mm, [0, 0, -9.81], allow_partial=True, closed_form=False)
    fused = cssp_inverse_dynamics(short, theta, 10.0, 1.0, [0, 0, -9.81], allow_partial=True,
                                  block_size=7)
    for closed_form in (True, False):
        got = inverse_dynamics(short, mm, [0, 0, -9.81], allow_partial=True,
                               closed_form=closed_form, block_size=7)
        assert_same_dynamics(got, ref, short.length_scale)
        assert np.all(np.isnan(got.shaking_force[~mm.assembles]))
        assert np.all(np.isfinite(got.shaking_force[mm.assembles]))
    assert_same_dynamics(fused, ref, short.length_scale)
    assert np.all(np.isnan(fused.joint_centres[~mm.assembles]))
    with pytest.raises(ValueError, match="block_size"):
        inverse_dynamics(short, mm, allow_partial=True, block_size=0)
    with pytest.raises(ValueError, match="does not assemble"):
        cssp_inverse_dynamics(short, theta, 10.0)


def test_cssp_kinematics_does_not_depend_on_its_block_size(monkeypatch: pytest.MonkeyPatch) -> None:
    lk = cssp(0.05, 0.2, 0.01, np.radians(250), 0.01)
    theta = np.linspace(0.0, 2 * np.pi, 50, endpoint=False)
    whole = cssp_mode_motion(lk, theta, 7.0, 3.0)
    monkeypatch.setattr(cssp_motion_module, "BLOCK_SAMPLES", 7)
    blocks = cssp_mode_motion(lk, theta, 7.0, 3.0)
    for name in ("link_rotation", "link_origin", "link_angular_velocity", "link_origin_velocity",
                 "link_angular_acceleration", "link_origin_acceleration", "joint_centres",
                 "joint_axes", "closure_residual"):
        np.testing.assert_array_equal(getattr(blocks, name), getattr(whole, name), err_msg=name)
    np.testing.assert_array_equal(blocks.conf.spherical, whole.conf.spherical)
    for table in ("variables", "velocities", "accelerations"):
        for key, value in getattr(whole, table).items():
            np.testing.assert_array_equal(getattr(blocks, table)[key], value, err_msg=key)


def test_peak_memory_is_the_outputs_plus_one_block() -> None:
    lk, _, _ = full_cycle("cssp", 2)
    n = 200_000
    mm = cssp_mode_motion(lk, np.linspace(0.0, 2 * np.pi, n, endpoint=False), 30.0, 0.0,
                          joint_rotations=False)
    tracemalloc.start()
    inverse_dynamics(lk, mm, [0, 0, -9.81])
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    outputs = (3 + 3 + 2 * 4 * 3 + 1 + 1 + 1) * 8  # loads, effort, residual, inputs per sample
    # the rest is what the validity check and one block need; the unblocked path took ~3 kB
    assert peak < outputs * n + 24 * 8 * n


def test_a_non_finite_sample_in_an_assembled_mode_is_named_or_skipped() -> None:
    # the blocked run checks finiteness block by block; a NaN found late restarts it with the
    # full check, which names the sample (or, with allow_partial, leaves it out)
    from screwkit.dynamics import NonAssemblingMotionError

    lk, _, mode = full_cycle("cssp", 4)
    acc = mode.link_origin_acceleration.copy()
    acc[17, 1, 2] = np.nan
    bad = replace(mode, link_origin_acceleration=acc)
    with pytest.raises(NonAssemblingMotionError, match="#17"):
        inverse_dynamics(lk, bad, block_size=4)
    part = inverse_dynamics(lk, bad, [0, 0, -9.81], allow_partial=True, block_size=4)
    whole = inverse_dynamics(lk, mode, [0, 0, -9.81])
    assert not part.valid[17] and part.valid.sum() == mode.assembles.size - 1
    assert np.all(np.isnan(part.shaking_force[17]))
    keep = part.valid
    np.testing.assert_allclose(part.shaking_force[keep], whole.shaking_force[keep], rtol=0,
                               atol=1e-12 * whole.residual_scale)
