"""Coupler points on any link of any loop: against Bagci's App. C (RSRC), circle intersections
(4R), forward kinematics composed by hand from the joint variables (a joint list), the ball
centres (RSSR); spec tables and their refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.io.errors import SpecError
from screwkit.io.spec import load_spec
from screwkit.kinematics.analysis.coupler_curves import coupler_point, coupler_point_path
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_coupler_point, rsrc_positions
from screwkit.pipeline import Pipeline

EXAMPLES = Path("examples")


def test_rsrc_coupler_frame_is_bagcis_app_c_frame():
    s = load_spec(EXAMPLES / "bagci_fig7_rsrc.toml")
    doc = Pipeline(s).analysis()
    dims = RSRCDimensions(**s.linkage.parameters)
    pos = rsrc_positions(dims, s.inputs)
    ref = rsrc_coupler_point(dims, pos, *s.coupler_point).global_xyz  # (N, 4, 3)
    for mode in doc["modes"]:
        cp = mode["coupler_points"]["coupler point"]
        assert cp["link"] == "coupler"
        p = np.stack([cp["x"], cp["y"], cp["z"]], -1)
        gap = np.linalg.norm(ref - p[:, None, :], axis=-1)
        assert np.nanmin(gap, axis=1).max() < 1e-12


def test_fourbar_coupler_point_from_circle_intersections():
    a, d1, d2, d3 = 0.3, 0.1, 0.28, 0.25
    lk = sk.fourbar(a=a, d1=d1, d2=d2, d3=d3)
    th = np.radians(np.arange(0.0, 360.0, 15.0))
    f, g = 0.12, 0.07
    cp = coupler_point(lk, [f, g, 0.0])
    assert cp.link_name == "coupler"
    for md in sk.solve_motion(lk, th).modes:
        p = coupler_point_path(md, cp.point, cp.link)
        A = np.stack([d1 * np.cos(th), d1 * np.sin(th)], -1)
        O = np.array([a, 0.0])
        dist = np.linalg.norm(O - A, axis=1)
        along = (d2**2 - d3**2 + dist**2) / (2 * dist)
        h = np.sqrt(d2**2 - along**2)
        e = (O - A) / dist[:, None]
        n = np.stack([-e[:, 1], e[:, 0]], -1)
        for sign in (1.0, -1.0):
            B = A + along[:, None] * e + sign * h[:, None] * n
            u = (B - A) / d2
            P = A + f * u + g * np.stack([-u[:, 1], u[:, 0]], -1)
            if np.allclose(P, p[:, :2], atol=1e-12):
                break
        else:
            pytest.fail("the coupler point is on neither assembly of the circle intersections")
        assert np.allclose(p[:, 2], 0.0, atol=1e-15)


def _hd(theta: float, s: float, alpha: float, a: float) -> np.ndarray:
    """Z(θ + εs)·X(α + εa) as a 4×4 matrix, typed from Rahman eq. 2.2."""
    c, sn, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    Z = np.array([[c, -sn, 0, 0], [sn, c, 0, 0], [0, 0, 1, s], [0, 0, 0, 1.0]])
    X = np.array([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1.0]])
    return Z @ X


def test_joint_list_coupler_point_by_hand_forward_kinematics():
    s = load_spec(EXAMPLES / "rccc_loop.toml")
    lk = s.linkage
    lengths = [0.6, 2.63, 3.34, 1.91]
    twists = [math.radians(v) for v in (24.1, -22.8, 31.9, 8.5)]
    point = np.array([0.03, -0.02, 0.05])
    cp = coupler_point(lk, point)  # the RCCC coupler (registry default): link2
    assert cp.link_name == "link2"
    for md in sk.solve_motion(lk, s.inputs).modes:
        path = coupler_point_path(md, cp.point, cp.link)
        for i in np.nonzero(md.assembles)[0][::5]:
            v = md.variables
            th = [v["input.theta"][i], v["C2.theta"][i]]
            ss = [0.0, v["C2.s"][i]]
            T = _hd(th[0], ss[0], twists[0], lengths[0] * 0.0254)
            Z2 = _hd(th[1], ss[1], 0.0, 0.0)
            P = (T @ Z2 @ np.append(point, 1.0))[:3]
            np.testing.assert_allclose(path[i], P, atol=1e-12)


def test_rssr_coupler_points_lie_on_the_ball_line_and_off_it_are_refused():
    s = load_spec(EXAMPLES / "rssr_spatial.toml")
    lk = s.linkage
    d2 = lk.parameters["d2"]
    cp = coupler_point(lk, [0.4 * d2, 0.0, 0.0])
    for md in sk.solve_motion(lk, s.inputs).modes:
        c = md.joint_centres
        assert np.allclose(np.linalg.norm(c[:, 2] - c[:, 1], axis=1), d2, atol=1e-12)
        p = coupler_point_path(md, cp.point, cp.link)
        np.testing.assert_allclose(p, c[:, 1] + 0.4 * (c[:, 2] - c[:, 1]), atol=1e-12)
    with pytest.raises(ValueError, match="turns freely about the line of their centres"):
        coupler_point(lk, [0.4 * d2, 0.01, 0.0])
    output = coupler_point(lk, [0.01, 0.02, 0.03], link="output")  # a rigid link: anything goes
    assert output.link == 2


def _spec(tmp_path: Path, body: str, base: str = "rssr_spatial") -> Path:
    text = (EXAMPLES / f"{base}.toml").read_text(encoding="utf-8")
    p = tmp_path / "s.toml"
    p.write_text(text + "\n" + body, encoding="utf-8")
    return p


def test_spec_coupler_point_tables(tmp_path):
    s = load_spec(_spec(tmp_path, '[coupler_point]\nf = 40\n\n[[coupler_points]]\nname = "tip"\n'
                                  'link = "output"\nf = -75\ng = 10\nh = -12.5\n'))
    assert [(p.name, p.link_name) for p in s.coupler_points] == [("coupler point", "coupler"),
                                                                 ("tip", "output")]
    doc = Pipeline(s).analysis()
    assert set(doc["modes"][0]["coupler_points"]) == {"coupler point", "tip"}
    assert doc["modes"][0]["coupler_points"]["tip"]["link"] == "output"
    with pytest.raises(SpecError, match=r"\[coupler_points\[0\]\.link\] .*no moving link"):
        load_spec(_spec(tmp_path, '[[coupler_points]]\nlink = "rod"\nf = 1\n'))
    with pytest.raises(SpecError, match=r"\[coupler_point\] .*only points on that line"):
        load_spec(_spec(tmp_path, "[coupler_point]\nf = 40\ng = 5\n"))
    with pytest.raises(SpecError, match="used twice"):
        load_spec(_spec(tmp_path, '[[coupler_points]]\nname = "a"\n[[coupler_points]]\n'
                                  'name = "a"\n'))
