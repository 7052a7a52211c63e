"""The CSSP's fast route equals the general route, every field, on random CSSPs.

* fast: the closed form through ``solve_motion`` (kinematics/closed_forms/cssp_motion.py, block
  by block, by components: the rod's zero-spin pose of cssp_rod_pose.py, Rahman's angles and the
  ball joints' rotation vectors from the closed form's u, u̇, ü) and the CSSP's closed-form
  statics (dynamics/cssp_statics.py), also fused with the kinematics (``cssp_inverse_dynamics``);
* general: the generic loop solver (``method="generic"``: Newton, continuation, the rate
  equations and the zero-spin transport of tracker/idle_spin.py) and the general loop statics
  (``closed_form=False``, the Newton–Euler wrenches solved as a least-squares loop).

Random dimensions (the crank turns fully), random rates, random mass properties for every link
— the rod's too, so its loads depend on its spin pose and its idle spin is loaded (both routes
take the same least-squares reactions) —, gravity, a placed base on some draws. Both routes are
exact apart from the zero-spin transport, which both integrate by the same Hermite rule from
exact rates: they agree to round-off, 1e-10 of each quantity's peak over the sweep (loads: of
the largest joint load, moments over the length scale).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanisms import random_mass

from screwkit.dual import ScrewMatrix
from screwkit.dynamics import cssp_inverse_dynamics, inverse_dynamics
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import cssp
from screwkit.model.linkage import Link, Linkage

TOL = 1e-10
FIELDS = ("link_rotation", "link_origin", "link_angular_velocity", "link_origin_velocity",
          "link_angular_acceleration", "link_origin_acceleration", "joint_centres",
          "joint_axes")


def _random_cssp(rng: np.random.Generator) -> Linkage:
    lk = cssp(rng.uniform(0.04, 0.06), rng.uniform(0.2, 0.26), rng.uniform(0.0, 0.03),
              np.radians(rng.uniform(230.0, 270.0)), rng.uniform(0.0, 0.02))
    lk = lk.with_links([Link(name, random_mass(rng, 0.08))
                        for name in ("crank", "rod", "slider")])
    if rng.uniform() < 0.5:
        axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        axes *= np.sign(np.linalg.det(axes))
        lk = replace(lk, base=ScrewMatrix.from_rotation_translation(axes, rng.normal(size=3)))
    return lk


def _close(name: str, fast: np.ndarray, slow: np.ndarray, ok: np.ndarray) -> None:
    a, b = np.asarray(fast)[ok], np.asarray(slow)[ok]
    scale = max(float(np.max(np.abs(b))), 1e-300)
    np.testing.assert_allclose(a, b, rtol=0, atol=TOL * scale, err_msg=name)


def _same_mode(fast: ModeMotion, slow: ModeMotion) -> None:
    np.testing.assert_array_equal(fast.assembles, slow.assembles)
    ok = fast.assembles
    for name in FIELDS:
        _close(name, getattr(fast, name), getattr(slow, name), ok)
    tables = ("variables", "velocities", "accelerations")
    for table in tables:
        mine, theirs = getattr(fast, table), getattr(slow, table)
        assert set(mine) == set(theirs), table
        for key in mine:
            _close(f"{table}[{key}]", mine[key], theirs[key], ok)


@settings(max_examples=5, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_fast_cssp_route_equals_the_general_route(seed: int) -> None:
    rng = np.random.default_rng(seed)
    lk = _random_cssp(rng)
    theta = np.linspace(0.0, 2 * np.pi, 73) + rng.uniform(0.0, 1.0)
    rate, rate_dot = float(rng.uniform(5.0, 50.0)), float(rng.uniform(-100.0, 100.0))
    fast = solve_motion(lk, theta, rates=rate, accelerations=rate_dot)
    slow = solve_motion(lk, theta, rates=rate, accelerations=rate_dot, method="generic")
    assert fast.method == "closed" and slow.method == "generic"
    assert len(fast.modes) == len(slow.modes) == 2
    gravity = rng.normal(size=3) * 5.0
    point = rng.normal(size=3) * 0.1
    for root, f, s in zip((1, -1), fast.modes, slow.modes, strict=True):
        _same_mode(f, s)
        general = inverse_dynamics(lk, s, gravity, point, closed_form=False)
        peak = general.residual_scale
        assert peak > 0.0
        for dyn in (inverse_dynamics(lk, f, gravity, point),
                    cssp_inverse_dynamics(lk, theta, rate, rate_dot, gravity, point, root=root)):
            force, moment = TOL * peak, TOL * peak * lk.length_scale
            np.testing.assert_allclose(dyn.shaking_force, general.shaking_force, rtol=0,
                                       atol=force)
            np.testing.assert_allclose(dyn.shaking_moment, general.shaking_moment, rtol=0,
                                       atol=moment)
            for joint in general.reactions:
                np.testing.assert_allclose(dyn.reactions[joint]["force"],
                                           general.reactions[joint]["force"], rtol=0,
                                           atol=force, err_msg=joint)
                np.testing.assert_allclose(dyn.reactions[joint]["moment"],
                                           general.reactions[joint]["moment"], rtol=0,
                                           atol=moment, err_msg=joint)
            np.testing.assert_allclose(dyn.efforts["crank.theta"],
                                       general.efforts["crank.theta"], rtol=0, atol=moment)
            # the rod's idle spin is loaded (a random rod): the same least-squares residual
            np.testing.assert_allclose(dyn.residual, general.residual, rtol=0, atol=force)
            assert np.max(general.relative_residual) > 1e-8
