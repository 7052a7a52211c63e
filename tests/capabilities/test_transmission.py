"""Transmission quality: the 4R's transmission angle by the law of cosines and its index |sin μ|;
the RSSR's, RSRC's and CSSP's Sutherland–Roth index computed by hand from the joint centres and
axes; the smallest cone of known direction sets; the ball joints' cone angles."""

from __future__ import annotations

import math

import numpy as np
import pytest

import screwkit as sk
from screwkit.io.spec import load_spec
from screwkit.kinematics.analysis.transmission import smallest_cone, transmission

EXAMPLES = "examples"
THETA = np.radians(np.arange(0.0, 360.0, 5.0))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize("dims", [(3.0, 1.0, 3.0, 2.5), (0.3, 0.1, 0.28, 0.25), (2.0, 1.5, 2.2, 1.8)])
def test_fourbar_transmission_angle_is_the_law_of_cosines(dims):
    a, d1, d2, d3 = dims
    motion = sk.solve_motion(sk.fourbar(a=a, d1=d1, d2=d2, d3=d3), THETA)
    tr = transmission(motion)
    assert tr.planar and tr.output_joint == "output" and tr.driving_joint == "rocker_pin"
    cos_mu = (d2**2 + d3**2 - d1**2 - a**2 + 2 * a * d1 * np.cos(THETA)) / (2 * d2 * d3)
    for md, mt in zip(motion.modes, tr.modes, strict=True):
        ok = md.assembles
        np.testing.assert_allclose(mt.angle[ok], np.arccos(cos_mu[ok]), atol=1e-12)
        np.testing.assert_allclose(mt.index["phi0"][ok], np.sqrt(1 - cos_mu[ok] ** 2), atol=1e-12)
        summary = tr.summary(motion.input_values)[md.index]
        worst = np.minimum(mt.angle, np.pi - mt.angle)
        assert summary["angle"]["value"] == pytest.approx(np.nanmin(worst))


def test_rssr_index_is_the_cosine_of_the_force_to_the_ball_velocity():
    s = load_spec(f"{EXAMPLES}/rssr_spatial.toml")
    motion = sk.solve_motion(s.linkage, s.inputs)
    p = s.linkage.parameters
    u3 = np.array([math.cos(p["lambda0"]), 0.0, -math.sin(p["lambda0"])])
    O3 = np.array([p["b"], p["a"], 0.0])
    for md, mt in zip(motion.modes, transmission(motion).modes, strict=True):
        c = md.joint_centres  # world frame: input axis X, output axis u3 through O3
        force = _unit(c[:, 2] - c[:, 1])  # the coupler between the two balls
        v = np.cross(u3, c[:, 2] - O3)  # the velocity of the output ball
        hand = np.abs(np.einsum("ni,ni->n", force, v)) / np.linalg.norm(v, axis=1)
        np.testing.assert_allclose(mt.index["phi0"], hand, atol=1e-12)


def test_rsrc_index_of_both_output_freedoms_by_hand():
    s = load_spec(f"{EXAMPLES}/bagci_fig7_rsrc.toml")
    motion = sk.solve_motion(s.linkage, s.inputs)
    p = s.linkage.parameters
    u3 = np.array([math.cos(p["lambda0"]), 0.0, -math.sin(p["lambda0"])])
    O3 = np.array([p["b"], p["a"], 0.0])
    for md, mt in zip(motion.modes, transmission(motion).modes, strict=True):
        O1, cR, uR = md.joint_centres[:, 1], md.joint_centres[:, 2], md.joint_axes[:, 2]
        # forces through the sphere centre O1 meeting the coupler's R axis: the plane (O1, axis)
        n = _unit(np.cross(cR - O1, uR))
        f = _unit(np.cross(n, u3))  # for φ0: no work on the output's slide
        ti = []
        for k in range(len(O1)):
            t, _ = np.linalg.lstsq(np.stack([f[k], -uR[k]], 1), cR[k] - O1[k], rcond=None)[0]
            P = O1[k] + t * f[k]  # where it meets the R axis
            v = np.cross(u3, P - O3)
            ti.append(abs(f[k] @ v) / np.linalg.norm(v))
        np.testing.assert_allclose(mt.index["phi0"], ti, atol=1e-12)
        # for S: the force in that plane that meets the output axis (no moment about it)
        X = O3 + ((np.einsum("ni,ni->n", n, O1 - O3)) / (n @ u3))[:, None] * u3
        fs = _unit(X - O1)
        np.testing.assert_allclose(mt.index["S"], np.abs(fs @ u3), atol=1e-12)


def test_cssp_index_is_the_rod_angle_to_the_slide():
    s = load_spec(f"{EXAMPLES}/rahman_cssp.toml")
    motion = sk.solve_motion(s.linkage, s.inputs)
    for md, mt in zip(motion.modes, transmission(motion).modes, strict=True):
        rod = _unit(md.joint_centres[:, 2] - md.joint_centres[:, 1])
        slide = md.joint_axes[:, 3]
        np.testing.assert_allclose(mt.index["s4"], np.abs(np.einsum("ni,ni->n", rod, slide)),
                                   atol=1e-12)
        assert set(mt.cone_angle) == {"pin", "ball"}


def test_smallest_cone_of_a_circle_of_directions():
    rng = np.random.default_rng(3)
    axis = _unit(rng.normal(size=3))
    e1 = _unit(np.cross(axis, [1.0, 0.0, 0.0]))
    e2 = np.cross(axis, e1)
    half = math.radians(25.0)
    phi = rng.uniform(0, 2 * np.pi, 40)
    rim = (math.cos(half) * axis + math.sin(half) * (np.cos(phi)[:, None] * e1
                                                     + np.sin(phi)[:, None] * e2))
    inside = _unit(axis + 0.2 * rng.normal(size=(30, 3)) * 0.3)
    inside = inside[inside @ axis > math.cos(half)]
    got_axis, got_half = smallest_cone(np.vstack([rim, inside]))
    assert got_half == pytest.approx(half, abs=1e-6)
    assert np.linalg.norm(got_axis - axis) < 1e-5


def test_nonnegative_least_squares_matches_scipy():
    """The Lawson–Hanson solver written for the smallest cone (so that analyze need not import
    scipy.optimize) gives scipy's residual on random problems, with x ≥ 0."""
    from scipy.optimize import nnls

    from screwkit.kinematics.analysis.transmission import nonnegative_least_squares

    rng = np.random.default_rng(11)
    for _ in range(200):
        A = rng.normal(size=(int(rng.integers(2, 8)), int(rng.integers(1, 40))))
        b = rng.normal(size=A.shape[0])
        x = nonnegative_least_squares(A, b, 100 * A.shape[1])
        ref, _ = nnls(A, b)
        assert (x >= 0).all()
        assert np.linalg.norm(A @ x - b) == pytest.approx(np.linalg.norm(A @ ref - b), abs=1e-10)


def test_nonnegative_least_squares_stops_where_it_would_cycle(monkeypatch, tmp_path):
    """The RSSR example with d2 = 103 mm at 360 samples: the smallest cone of a ball's rod
    directions is a problem on which Lawson–Hanson cycles on round-off at the optimum (12 800
    iterations before a passive set met twice ended it): every problem now takes few
    least-squares solves and still gives scipy's residual."""
    from pathlib import Path

    from scipy.optimize import nnls

    import screwkit.kinematics.analysis.transmission as tr
    text = (Path(__file__).parents[2] / "examples" / "rssr_spatial.toml").read_text("utf-8")
    assert "d2 = 100.0\n" in text
    path = tmp_path / "rssr_d2_103.toml"
    path.write_text(text.replace("d2 = 100.0\n", "d2 = 103.0\n"), encoding="utf-8")
    spec = load_spec(path)
    steps = np.radians(np.arange(360.0))
    motion = sk.solve_motion(spec.linkage, steps)
    problems, solves = [], [0]
    real_nnls, real_lstsq = tr.nonnegative_least_squares, np.linalg.lstsq

    def spy(A, b, cap):
        x = real_nnls(A, b, cap)
        problems.append((A, b, x))
        return x

    def counted(*args, **kwargs):
        solves[0] += 1
        return real_lstsq(*args, **kwargs)

    monkeypatch.setattr(tr, "nonnegative_least_squares", spy)
    monkeypatch.setattr(np.linalg, "lstsq", counted)
    transmission(motion)
    monkeypatch.undo()
    assert problems and solves[0] < 200, solves[0]
    for A, b, x in problems:
        assert (x >= 0).all()
        ref, _ = nnls(A, b, maxiter=50 * A.shape[1])
        assert np.linalg.norm(A @ x - b) == pytest.approx(np.linalg.norm(A @ ref - b), abs=1e-10)


def test_smallest_cone_of_many_directions_grows_its_working_set():
    """10 000 directions (the working set starts at 256 and must take in those its first cone
    leaves out): the cone holds every direction and touches the rim of a known cone."""
    rng = np.random.default_rng(4)
    axis = _unit(rng.normal(size=3))
    e1 = _unit(np.cross(axis, [0.0, 0.0, 1.0]))
    e2 = np.cross(axis, e1)
    half = math.radians(40.0)
    phi = rng.uniform(0, 2 * np.pi, 10_000)
    tilt = half * np.sqrt(rng.uniform(0, 1, 10_000))
    tilt[rng.choice(10_000, 7, replace=False)] = half  # a few on the rim, spread at random
    v = (np.cos(tilt)[:, None] * axis + np.sin(tilt)[:, None]
         * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))
    got_axis, got_half = smallest_cone(v)
    assert np.min(v @ got_axis) >= math.cos(got_half) - 1e-12
    assert got_half <= half + 1e-9


def test_rssr_ball_cone_angles_are_tilts_of_the_rod():
    s = load_spec(f"{EXAMPLES}/rssr_spatial.toml")
    motion = sk.solve_motion(s.linkage, s.inputs)
    for md, mt in zip(motion.modes, transmission(motion).modes, strict=True):
        rod = _unit(md.joint_centres[:, 2] - md.joint_centres[:, 1])
        # ball1's socket on the crank, ball2's on the output crank: the rod seen from each
        crank = np.einsum("nji,nj->ni", md.link_rotation[:, 0], rod)
        out = np.einsum("nji,nj->ni", md.link_rotation[:, 2], -rod)
        for joint, local in (("ball1", crank), ("ball2", out)):
            axis = mt.socket_axis[joint]
            np.testing.assert_allclose(mt.cone_angle[joint], np.arccos(local @ axis), atol=1e-9)
            assert mt.cone_limit[joint] == pytest.approx(np.max(mt.cone_angle[joint]), abs=1e-12)


@pytest.mark.parametrize("name", ["rssr_spatial.toml", "rahman_cssp.toml"])
def test_the_rod_wrench_is_the_null_space_of_the_balls(name: str, monkeypatch) -> None:
    """An S–S rod's transmission wrench in closed form (the force along the line of the ball
    centres) gives the index the SVD null space of the six ball freedoms gives, sample by
    sample (to round-off) and with the same missing samples; ``cones=False`` leaves the index
    and angle as they are and the cone angles out."""
    import screwkit.kinematics.analysis.transmission as tr_module
    from screwkit.pipeline import Pipeline

    motion = Pipeline(load_spec(f"{EXAMPLES}/{name}")).motion
    used: list[bool] = []
    closed_form = tr_module.rod_wrench

    def spy(*args):
        w = closed_form(*args)
        used.append(w is not None)
        return w

    monkeypatch.setattr(tr_module, "rod_wrench", spy)
    fast = transmission(motion, cones=False)
    assert used and all(used)
    monkeypatch.setattr(tr_module, "rod_wrench", lambda *args: None)
    general = transmission(motion)
    for a, b in zip(fast.modes, general.modes, strict=True):
        assert a.index.keys() == b.index.keys() and not a.cone_angle and b.cone_angle
        for key in a.index:
            np.testing.assert_array_equal(np.isnan(a.index[key]), np.isnan(b.index[key]))
            np.testing.assert_allclose(a.index[key], b.index[key], rtol=0, atol=1e-12)
        assert (a.angle is None) == (b.angle is None)
