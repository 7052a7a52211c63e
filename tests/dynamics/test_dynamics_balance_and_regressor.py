"""Every link in Newton–Euler balance under its reported joint loads; passive freedoms carry
no generalised force; regressor·π = direct computation (DESIGN validation levels 2 and 3)."""

from __future__ import annotations

import numpy as np
import pytest
from mechanisms import FAMILIES, full_cycle

from screwkit.dynamics import ExternalLoad, inverse_dynamics, regressor
from screwkit.dynamics.screws import freedom_screws
from screwkit.model.linkage import Link
from screwkit.model.mass import equivalent_point_masses

GRAVITY = np.array([0.0, -9.81, -2.0])


def _link_loads_from_kinematics(linkage, mode):
    """d/dt of each link's momentum and of its angular momentum about its CoM, computed here
    independently of screwkit.dynamics: (m a_c, I_w α + ω × I_w ω), and the CoM positions."""
    out = []
    for l, link in enumerate(linkage.links):
        mp = link.mass
        R = mode.link_rotation[:, l]
        rc = R @ mp.com
        w = mode.link_angular_velocity[:, l]
        al = mode.link_angular_acceleration[:, l]
        a_c = mode.link_origin_acceleration[:, l] + np.cross(al, rc) + np.cross(w, np.cross(w, rc))
        I_w = R @ mp.inertia @ np.swapaxes(R, -1, -2)
        dh = np.einsum("nij,nj->ni", I_w, al) + np.cross(w, np.einsum("nij,nj->ni", I_w, w))
        out.append((mp.mass * a_c, dh, mode.link_origin[:, l] + rc))
    return out


@pytest.mark.parametrize("family", FAMILIES)
def test_every_link_balances_under_its_joint_loads(family: str) -> None:
    linkage, _, mode = full_cycle(family, 0)
    dyn = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    joints = [j.name for j in linkage.joints]
    centres = mode.joint_centres
    n = len(joints)
    scale = dyn.residual_scale * (1 + linkage.length_scale)
    for l, (dp, dh, p_c) in enumerate(_link_loads_from_kinematics(linkage, mode)):
        m = linkage.links[l].mass.mass
        # joint l acts on link l (its distal link); joint l+1 is the reaction of link l on the
        # next link, reported on the distal side, except the last joint, reported on link l
        sides = [(l, 1.0), (l + 1, -1.0 if l + 1 < n - 1 else 1.0)]
        force = m * GRAVITY - dp
        moment = -dh.copy()
        for j, sign in sides:
            f = sign * dyn.reactions[joints[j]]["force"]
            mo = sign * dyn.reactions[joints[j]]["moment"]
            force = force + f
            moment = moment + mo + np.cross(centres[:, j] - p_c, f)
        assert np.max(np.abs(force)) < 1e-10 * scale, f"{family} link {l} force balance"
        assert np.max(np.abs(moment)) < 1e-10 * scale, f"{family} link {l} moment balance"
    # shaking loads = what the two ground joints carry, reversed
    ground = -(dyn.reactions[joints[0]]["force"] + dyn.reactions[joints[-1]]["force"])
    np.testing.assert_allclose(dyn.shaking_force, ground, atol=1e-10 * scale)


@pytest.mark.parametrize("family", FAMILIES)
def test_passive_freedoms_carry_no_load_and_efforts_are_driven_components(family: str) -> None:
    linkage, _, mode = full_cycle(family, 0)
    dyn = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    fs = freedom_screws(linkage, mode)
    n = len(linkage.joints)
    for k, name in enumerate(fs.names):
        j = fs.joint_of[k]
        r = dyn.reactions[linkage.joints[j].name]
        sign = -1.0 if j == n - 1 else 1.0  # back to "proximal on distal"
        c = mode.joint_centres[:, j]
        m_origin = r["moment"] + np.cross(c, r["force"])
        generalised = sign * (np.sum(fs.screws[:, k, :3] * m_origin, -1)
                              + np.sum(fs.screws[:, k, 3:] * r["force"], -1))
        if fs.driven[k]:
            np.testing.assert_allclose(generalised, dyn.efforts[name], atol=1e-10 * dyn.residual_scale)
        else:
            assert np.max(np.abs(generalised)) < 1e-10 * dyn.residual_scale, name
    assert np.max(dyn.relative_residual) < 1e-12


@pytest.mark.parametrize("family", FAMILIES)
def test_regressor_times_parameters_equals_direct(family: str) -> None:
    linkage, _, mode = full_cycle(family, 0)
    loads = {linkage.links[-1].name: ExternalLoad([1.0, -2.0, 0.5], [0.1, 0.0, -0.3], [0.01, 0.02, 0.0])}
    direct = inverse_dynamics(linkage, mode, gravity=GRAVITY, moment_point=[0.1, 0.2, 0.3],
                              external_loads=loads)
    Y = regressor(linkage, mode, gravity=GRAVITY, moment_point=[0.1, 0.2, 0.3],
                  external_loads=loads)
    via = Y.apply(Y.parameters_of())
    scale = direct.residual_scale * (1 + linkage.length_scale)
    for a, b in [(direct.shaking_force, via.shaking_force),
                 (direct.shaking_moment, via.shaking_moment)]:
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * scale)
    for name, r in direct.reactions.items():
        for key in ("force", "moment"):
            np.testing.assert_allclose(r[key], via.reactions[name][key], rtol=0, atol=1e-11 * scale)
    for name, e in direct.efforts.items():
        np.testing.assert_allclose(e, via.efforts[name], rtol=0, atol=1e-11 * scale)
    assert len(Y.parameter_names) == 10 * len(linkage.links)
    # linearity: the π-part of the loads doubles with π
    twice = Y.apply(2 * Y.parameters_of())
    np.testing.assert_allclose(twice.shaking_force - Y.constant["shaking_force"][..., 0],
                               2 * (via.shaking_force - Y.constant["shaking_force"][..., 0]),
                               atol=1e-11 * scale)


@pytest.mark.parametrize("family", ["cssp", "fourbar", "rsrc"])
def test_seven_point_mass_models_give_the_same_loads(family: str) -> None:
    """Rahman's seven-point equivalents (with the ½ weights), summed point by point as
    parameters (m, m p, m(|p|²1 − p pᵀ)) through the regressor, equal the rigid bodies."""
    linkage, _, mode = full_cycle(family, 0)
    rigid = inverse_dynamics(linkage, mode, gravity=GRAVITY)
    pis = []
    for link in linkage.links:
        model = equivalent_point_masses(link.mass)
        pi = np.zeros(10)
        for m, p in zip(model.masses, model.positions, strict=True):
            I = m * (p @ p * np.eye(3) - np.outer(p, p))
            pi += np.array([m, *(m * p), I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])
        pis.append(pi)
    points = regressor(linkage, mode, gravity=GRAVITY).apply(np.concatenate(pis))
    scale = rigid.residual_scale * (1 + linkage.length_scale)
    np.testing.assert_allclose(points.shaking_force, rigid.shaking_force, atol=1e-10 * scale)
    np.testing.assert_allclose(points.shaking_moment, rigid.shaking_moment, atol=1e-10 * scale)
    for name, e in rigid.efforts.items():
        np.testing.assert_allclose(points.efforts[name], e, atol=1e-10 * scale)
    for name, r in rigid.reactions.items():
        np.testing.assert_allclose(points.reactions[name]["force"], r["force"], atol=1e-10 * scale)
    # and the rigid body rebuilt from the points (mass module) gives the same loads directly
    rebuilt = linkage.with_links(
        [Link(lk.name, equivalent_point_masses(lk.mass).to_mass_properties()) for lk in linkage.links]
    )
    again = inverse_dynamics(rebuilt, mode, gravity=GRAVITY)
    np.testing.assert_allclose(again.shaking_moment, rigid.shaking_moment, atol=1e-10 * scale)
