"""The blocked evaluation and the CSSP closed-form statics give the generic path's results.

* ``inverse_dynamics(..., closed_form=True)`` (the CSSP's closed-form statics,
  screwkit.dynamics.cssp_statics) equals ``closed_form=False`` (the generic loop-statics solve)
  in every field of ``Dynamics``, on random CSSPs with random mass properties — including rods
  whose spin is loaded, where both return the same least-squares reactions and residual —,
  gravity, external loads, a moment point away from the origin, both assembly modes, a driven
  crank offset and a placed base. Both are exact, so they agree to round-off: 1e-12 of the
  largest joint load (moments divided by the length scale).
* ``cssp_inverse_dynamics`` (kinematics and dynamics fused block by block, no ModeMotion) equals
  the same chain through ``cssp_mode_motion`` and the generic solve.
* Results do not depend on the block size, with or without non-assembling samples.
* The blocked closed-form kinematics (cssp_mode_motion) does not depend on its block size.
* Peak memory of the blocked dynamics is the outputs plus one block.
"""

from __future__ import annotations

import tracemalloc
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanisms import full_cycle, random_mass

import screwkit.kinematics.cssp_motion as cssp_motion_module
from screwkit.dual import ScrewMatrix
from screwkit.dynamics import Dynamics, ExternalLoad, cssp_inverse_dynamics, inverse_dynamics
from screwkit.dynamics.cssp_statics import cssp_statics_for
from screwkit.kinematics.cssp_motion import cssp_mode_motion
from screwkit.model.families import cssp, fourbar
from screwkit.model.linkage import Link, Linkage
from screwkit.model.mass import MassProperties

AGREE = 1e-12  # of the largest joint load: both paths are exact, this is round-off


def assert_same_dynamics(a: Dynamics, b: Dynamics, ell: float, tol: float = AGREE) -> None:
    """Every field of two Dynamics equal, loads to ``tol`` of the largest joint load."""
    scale = b.residual_scale
    assert a.residual_scale == pytest.approx(scale, rel=tol)
    force, moment = tol * scale, tol * scale * ell
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_array_equal(a.inputs, b.inputs)
    assert a.input_names == b.input_names
    np.testing.assert_array_equal(a.moment_point, b.moment_point)
    np.testing.assert_array_equal(a.gravity, b.gravity)
    np.testing.assert_array_equal(a.joint_centres, b.joint_centres)
    np.testing.assert_allclose(a.shaking_force, b.shaking_force, rtol=0, atol=force)
    np.testing.assert_allclose(a.shaking_moment, b.shaking_moment, rtol=0, atol=moment)
    assert a.reactions.keys() == b.reactions.keys()
    for joint in a.reactions:
        np.testing.assert_allclose(a.reactions[joint]["force"], b.reactions[joint]["force"],
                                   rtol=0, atol=force, err_msg=joint)
        np.testing.assert_allclose(a.reactions[joint]["moment"], b.reactions[joint]["moment"],
                                   rtol=0, atol=moment, err_msg=joint)
    assert a.efforts.keys() == b.efforts.keys()
    for name in a.efforts:
        unit = moment if name.endswith(".theta") else force
        np.testing.assert_allclose(a.efforts[name], b.efforts[name], rtol=0, atol=unit,
                                   err_msg=name)
    np.testing.assert_allclose(a.residual, b.residual, rtol=0, atol=force)
    assert a.indeterminacy.count == b.indeterminacy.count
    assert a.indeterminacy.idle_freedoms == b.indeterminacy.idle_freedoms
    np.testing.assert_array_equal(a.indeterminacy.directions, b.indeterminacy.directions)


def _random_cssp(seed: int, driven_offset: bool, line_rod: bool) -> tuple[Linkage, float]:
    rng = np.random.default_rng(seed)
    a1, a2 = rng.uniform(0.03, 0.06), rng.uniform(0.18, 0.26)
    lk = cssp(a1, a2, rng.uniform(-0.03, 0.03), np.radians(rng.uniform(200, 290)),
              rng.uniform(-0.02, 0.02), s1_is_input=driven_offset)
    size = 0.1
    rod = (MassProperties(rng.uniform(0.5, 2.0), [0.4 * a2, 0.0, 0.0],
                          np.diag([0.0, 3e-3, 3e-3])) if line_rod else random_mass(rng, size))
    lk = lk.with_links([Link("crank", random_mass(rng, size)), Link("rod", rod),
                        Link("slider", random_mass(rng, size))])
    if rng.uniform() < 0.5:  # a placed base
        axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        axes *= np.sign(np.linalg.det(axes))
        lk = replace(lk, base=ScrewMatrix.from_rotation_translation(axes, rng.normal(size=3)))
    return lk, a2


@settings(max_examples=12, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6), mode=st.sampled_from([1, -1]),
       driven_offset=st.booleans(), line_rod=st.booleans())
def test_cssp_closed_form_statics_equals_generic(seed: int, mode: int, driven_offset: bool,
                                                 line_rod: bool) -> None:
    lk, _ = _random_cssp(seed, driven_offset, line_rod)
    rng = np.random.default_rng(seed + 1)
    theta = np.linspace(0.0, 2 * np.pi, 60, endpoint=False) + rng.uniform(0, 1)
    offset: dict[str, np.ndarray] = {}
    if driven_offset:
        s1 = lk.parameters.get("s1", 0.0)
        offset = {"s1": s1 + 0.005 * np.sin(theta), "s1_dot": 0.05 * np.cos(theta),
                  "s1_ddot": -0.5 * np.sin(theta)}
    rate, rate_dot = rng.uniform(5, 50), rng.uniform(-100, 100)
    mm = cssp_mode_motion(lk, theta, rate, rate_dot, mode, allow_partial=True,
                          **offset)  # type: ignore[arg-type]
    if not mm.assembles.any():
        return
    kwargs = {
        "gravity": rng.normal(size=3) * 5,
        "moment_point": rng.normal(size=3),
        "external_loads": {"slider": ExternalLoad(force=rng.normal(size=3) * 20,
                                                  moment=rng.normal(size=3),
                                                  point=rng.normal(size=3) * 0.05)},
        "allow_partial": True,
    }
    fast = inverse_dynamics(lk, mm, **kwargs)  # type: ignore[arg-type]
    generic = inverse_dynamics(lk, mm, closed_form=False, **kwargs)  # type: ignore[arg-type]
    assert_same_dynamics(fast, generic, lk.length_scale)
    fused = cssp_inverse_dynamics(lk, theta, rate, rate_dot, mode=mode,
                                  **offset, **kwargs)  # type: ignore[arg-type]
    assert_same_dynamics(fused, generic, lk.length_scale)
    assert fast.indeterminacy.count == 0 and fast.indeterminacy.idle_freedoms == 1
    if line_rod:  # the rod's spin carries no load: the residual is round-off
        assert np.nanmax(fast.relative_residual) < 1e-12
    else:
        assert np.nanmax(fast.relative_residual) > 1e-6


def test_closed_form_statics_on_the_generic_solvers_motion() -> None:
    lk, _, mode = full_cycle("cssp", 3)
    g = [0.3, -0.2, -9.81]
    assert_same_dynamics(inverse_dynamics(lk, mode, g, [0.1, 0.2, 0.3]),
                         inverse_dynamics(lk, mode, g, [0.1, 0.2, 0.3], closed_form=False),
                         lk.length_scale)


def test_which_linkages_get_the_closed_form() -> None:
    lk = cssp(0.05, 0.2, 0.01, np.radians(250), 0.01)
    assert cssp_statics_for(lk) is not None
    two = cssp_statics_for(cssp(0.05, 0.2, 0.01, np.radians(250), 0.01, s1_is_input=True))
    assert two is not None and [k for _, k in two.crank_inputs] == ["theta", "s"]
    assert cssp_statics_for(fourbar(1.0, 0.3, 1.1, 0.8)) is None
    assert cssp_statics_for(replace(lk, inputs=("slider.s",))) is None


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


def test_lean_cssp_kinematics_keeps_what_dynamics_reads() -> None:
    lk, _, _ = full_cycle("cssp", 5)
    theta = np.linspace(0.0, 2 * np.pi, 40, endpoint=False)
    full = cssp_mode_motion(lk, theta, 12.0, 2.0)
    lean = cssp_mode_motion(lk, theta, 12.0, 2.0, ball_joints=False)
    for name in ("link_rotation", "link_origin", "link_angular_velocity", "link_origin_velocity",
                 "link_angular_acceleration", "link_origin_acceleration", "joint_centres",
                 "joint_axes", "closure_residual"):
        np.testing.assert_array_equal(getattr(lean, name), getattr(full, name), err_msg=name)
    assert np.all(np.isnan(lean.conf.spherical)) and lean.conf.spherical.shape == (40, 2, 3, 3)
    np.testing.assert_array_equal(lean.conf.scalars, full.conf.scalars)
    assert set(lean.velocities) == {"crank.theta", "slider.s"}
    assert set(lean.variables) == {"crank.theta", "slider.s"}
    g = [0.0, -1.0, -9.81]
    assert_same_dynamics(inverse_dynamics(lk, lean, g), inverse_dynamics(lk, full, g),
                         lk.length_scale, tol=0.0)
