"""Every family, both solvers: every reported rate satisfies the loop's velocity equation
J q̇ = 0 and every acceleration its acceleration equation J q̈ + J̇ q̇ = 0 to 1e-9 (scaled);
every link's pose differentiates to its reported twist (the idle spin of an S–S rod included:
docs/conventions.md, "Idle spin"); angles start in (−π, π]."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.loop import forward, layout, lie_bracket
from screwkit.model import Joint, Linkage
from screwkit.model.families import cssp, fourbar, rccc, rsrc, rssr

deg = np.radians


def _loops():
    return {
        "RSRC": rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60)),
        "4R": fourbar(3.0, 1.0, 3.0, 2.5),
        "RSSR": rssr(1.0, 4.0, 3.0, 3.0, 2.0, deg(50), 0.5),
        "CSSP": cssp(0.0508, 0.2032, 0.0254, deg(250), 0.01016),
        "CSSP driven offset": cssp(0.0508, 0.2032, 0.0254, deg(250), 0.01016, s1_is_input=True),
        "RCCC": rccc((1.0, 3.0, 2.5, 3.0), (0.3, 0.2, -0.4, 0.5), 0.4),
        "RSHC": Linkage.from_hartenberg_denavit(
            "RSHC", [Joint("in", "R"), Joint("ball", "S"), Joint("screw", "H", pitch=0.02),
                     Joint("cyl", "C")],
            [0.05, 0.2, 0.15, 0.18], [deg(20), deg(10), deg(-30), deg(40)], inputs=["in.theta"]),
        "RUSR": Linkage.from_hartenberg_denavit(
            "RUSR", [Joint("in", "R"), Joint("u", "U", offset=0.01), Joint("ball", "S"),
                     Joint("out", "R", offset=0.02)],
            [0.05, 0.2, 0.15, 0.18], [deg(30), deg(0), deg(10), deg(60)], inputs=["in.theta"]),
        "PSSR": Linkage.from_hartenberg_denavit(
            "PSSR", [Joint("slide", "P"), Joint("b1", "S"), Joint("b2", "S"), Joint("out", "R")],
            [0.0, 0.2, 0.1, 0.15], [deg(90), 0.0, 0.0, deg(70)], inputs=["slide.s"]),
    }


def _sweep(name, lk, n, span, rate=1.3, acceleration=0.4):
    """n samples over ``span`` of the sweep parameter t; a slider input moves 0.01 sin t and a
    driven CSSP offset 0.005 sin t, with rates and accelerations d/dt of them; a crank turns
    with t at ``rate`` (then not d/dt of the samples) and ``acceleration``."""
    start = 2.0 if name == "RCCC" else 0.3  # the RCCC assembles for θ1 in 85°…275°
    t = np.linspace(start, start + span, n)
    if name == "PSSR":
        return 0.01 + 0.01 * np.sin(t), 0.01 * np.cos(t), -0.01 * np.sin(t)
    if len(lk.inputs) == 2:
        s1 = 0.01016 + 0.005 * np.sin(t)
        return (np.stack([t, s1], -1), np.stack([np.ones_like(t), 0.005 * np.cos(t)], -1),
                np.stack([np.zeros_like(t), -0.005 * np.sin(t)], -1))
    return t, rate, acceleration


CASES = [(name, method) for name in _loops() for method in ("closed", "generic")
         if method == "generic" or name in ("RSRC", "4R", "RSSR", "CSSP", "RCCC")]


def _motion(name, method, n, span, rate=1.3, acceleration=0.4):
    lk = _loops()[name]
    X, Xd, Xdd = _sweep(name, lk, n, span, rate, acceleration)
    return lk, solve_motion(lk, X, rates=Xd, accelerations=Xdd, method=method)


def _scaled_rows(lk):
    L = lk.length_scale
    return np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])


@pytest.mark.parametrize("name,method", CASES)
def test_reported_rates_satisfy_the_loop_equations(name, method):
    lk, m = _motion(name, method, 40, 2 * np.pi)
    lay = layout(lk)
    L = lk.length_scale
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    checked = 0
    for md in m.modes:
        ok = md.assembles & ~md.singular
        assert np.all(np.isfinite(md.link_angular_velocity[ok]))
        S = forward(lk, md.conf, lay).screws[ok]  # (n, 6, m), ground frame
        qd = np.stack([md.velocities[f][ok] for f in lay.names], -1)
        qdd = np.stack([md.accelerations[f][ok] for f in lay.names], -1)
        rows = _scaled_rows(lk)
        velocity = np.einsum("nif,nf->ni", S, qd) * rows
        # J̇q̇ = Σ_k [V before joint(k), S_k] q̇_k (a U joint's second axis turns with its first;
        # a ball's own axes cancel in pairs), written out here independently of the solver
        bias = np.zeros((qd.shape[0], 6))
        V = np.zeros((qd.shape[0], 6))
        for i, joint in enumerate(lk.joints):
            ks = [f for f in range(len(lay.names)) if lay.joint_of[f] == i]
            Vj = V.copy()
            for f in ks:
                bias += lie_bracket(Vj, S[:, :, f]) * qd[:, f:f + 1]
                if joint.kind == "U":
                    Vj = Vj + S[:, :, f] * qd[:, f:f + 1]
            V = V + np.einsum("nik,nk->ni", S[:, :, ks], qd[:, ks])
        acceleration = (np.einsum("nif,nf->ni", S, qdd) + bias) * rows
        size_v = 1.0 + np.linalg.norm(qd / cols, axis=1)
        size_a = 1.0 + np.linalg.norm(qdd / cols, axis=1) + size_v**2
        assert np.max(np.linalg.norm(velocity, axis=1) / size_v) < 1e-9
        assert np.max(np.linalg.norm(acceleration, axis=1) / size_a) < 1e-9
        checked += int(ok.sum())
    assert checked > 0


def _rotation_rate(R, h):
    """Central-difference angular velocity (world) of rotations R (N, 3, 3) sampled at step h."""
    rel = np.einsum("nij,nkj->nik", R[2:], R[:-2])
    return Rotation.from_matrix(rel).as_rotvec() / (2 * h)


@pytest.mark.parametrize("name,method", CASES)
def test_every_link_pose_differentiates_to_its_twist(name, method):
    # h = 0.2°: the central difference of a rotation is off by (h²/6)|ω̈| + (h²/12)|ω × ω̇| ≲ 1e-5
    # for these O(1) motions, and the S–S rod's zero-spin transport is exact to O(h⁴)
    n, span = 121, deg(24.0)
    h = span / (n - 1)
    lk, m = _motion(name, method, n, span, 1.0, 0.0)  # t is time: rates are d/dt of the sweep
    scale = 1e-4
    for md in m.modes:
        ok = md.assembles[:-2] & md.assembles[1:-1] & md.assembles[2:] & ~md.singular[1:-1]
        if not ok.any():
            continue
        for link in range(md.link_rotation.shape[1]):
            w = md.link_angular_velocity[1:-1, link]
            w_fd = _rotation_rate(md.link_rotation[:, link], h)
            size = max(1.0, float(np.nanmax(np.abs(w))))
            np.testing.assert_allclose(w_fd[ok], w[ok], atol=scale * size,
                                       err_msg=f"{name} {method} link {link}")
            o = md.link_origin[:, link]
            v_fd = (o[2:] - o[:-2]) / (2 * h)
            v = md.link_origin_velocity[1:-1, link]
            np.testing.assert_allclose(v_fd[ok], v[ok], atol=scale * max(1.0, float(
                np.nanmax(np.abs(v)))), err_msg=f"{name} {method} link {link} origin")


@pytest.mark.parametrize("name", ["RSSR", "CSSP"])
def test_an_idle_rod_keeps_zero_spin_and_returns_turned_after_a_turn(name):
    # the rod between two balls: ω·u = 0 at every sample, and after a full turn of the crank
    # its frame has turned about u by the holonomy of the path of u, the same in both solvers
    theta = np.linspace(0.0, 2 * np.pi, 721)
    lk = _loops()[name]
    closed = solve_motion(lk, theta, method="closed")
    generic = solve_motion(lk, theta, method="generic")
    for c, g in zip(closed.modes, generic.modes, strict=True):
        u = c.joint_centres[:, 2] - c.joint_centres[:, 1]
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        assert np.max(np.abs(np.sum(c.link_angular_velocity[:, 1] * u, axis=1))) < 1e-12
        np.testing.assert_allclose(g.link_rotation, c.link_rotation, atol=1e-8)
        turn = c.link_rotation[-1, 1] @ c.link_rotation[0, 1].T
        holonomy = Rotation.from_matrix(turn).as_rotvec()
        assert np.linalg.norm(holonomy) > 1e-3  # the spin is path dependent, not periodic
        np.testing.assert_allclose(np.cross(holonomy, u[0]), 0.0, atol=1e-9)  # about u


@pytest.mark.parametrize("name,method", CASES)
def test_angles_start_in_the_half_open_turn(name, method):
    lk, m = _motion(name, method, 30, 2 * np.pi)
    lay = layout(lk)
    angles = [f for f, t in zip(lay.names, lay.is_translation, strict=True)
              if not t and lay.scalar_col[lay.names.index(f)] >= 0 and f not in lk.inputs]
    angles += [k for k in ("phi0", "chi0", "theta2", "eta2") if k in m.modes[0].variables]
    for md in m.modes:
        ok = md.assembles
        starts = np.nonzero(ok & ~np.concatenate([[False], ok[:-1]]))[0]
        for a in angles:
            values = md.variables[a][starts]
            assert np.all((values > -np.pi) & (values <= np.pi)), (a, values)
