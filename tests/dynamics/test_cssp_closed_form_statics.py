"""The CSSP's closed-form statics and its fused kinematics+dynamics path give the generic path's
results.

* ``inverse_dynamics(..., closed_form=True)`` (the CSSP's closed-form statics,
  screwkit.dynamics.cssp_statics) equals ``closed_form=False`` (the generic loop-statics solve)
  in every field of ``Dynamics``, on random CSSPs with random mass properties — including rods
  whose spin is loaded, where both return the same least-squares reactions and residual —,
  gravity, external loads, a moment point away from the origin, both assembly modes, a driven
  crank offset and a placed base. Both are exact, so they agree to round-off: 1e-12 of the
  largest joint load (moments divided by the length scale).
* ``cssp_inverse_dynamics`` (kinematics and dynamics fused block by block, no ModeMotion) equals
  the same chain through ``cssp_mode_motion`` and the generic solve.
* The lean CSSP kinematics (no ball-joint rotations) keeps everything the dynamics reads.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanisms import assert_same_dynamics, full_cycle, random_mass

from screwkit.dual import ScrewMatrix
from screwkit.dynamics import ExternalLoad, cssp_inverse_dynamics, inverse_dynamics
from screwkit.dynamics.cssp_statics import cssp_statics_for
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.model.families import cssp, fourbar
from screwkit.model.linkage import Link, Linkage
from screwkit.model.mass import MassProperties


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
    fused = cssp_inverse_dynamics(lk, theta, rate, rate_dot, root=mode,
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
