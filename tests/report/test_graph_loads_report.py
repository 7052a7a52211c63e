"""The loads in the report of a mechanism graph (report/graph_loads.py): an arrow at every joint
centre (its reaction) and on every body (its inertia force at its centre of mass), each equal to
what graph inverse dynamics gives; a plot of every input's effort; the balancing plots; and a real
browser that lists every arrow in the legend and draws them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
from screwkit.io.spec import load_spec
from screwkit.kinematics.graph import solve_mechanism
from screwkit.report.graph_scene import graph_spec_scene
from screwkit.report.viewer import render_report_html

ROOT = Path(__file__).resolve().parents[2]
BALANCED = ROOT / "examples" / "mechanisms" / "watt_sixbar_balance.toml"
STEWART = ROOT / "examples" / "mechanisms" / "stewart_platform.toml"


@pytest.fixture(scope="module")
def sixbar() -> tuple[Any, Any, dict[str, Any]]:
    spec = load_spec(BALANCED)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration)
    return spec, motion, graph_spec_scene(spec, motion, gravity=True)


def test_arrows_on_every_joint_and_body_equal_graph_inverse_dynamics(sixbar: Any) -> None:
    spec, motion, scene = sixbar
    mech, md = spec.mechanism, motion.modes[0]
    arrows = scene["modes"][0]["arrows"]
    dyn = graph_inverse_dynamics(motion, 0, spec.gravity_vector)
    assert set(arrows) == ({"shaking force"} | {f"reaction at {j.name}" for j in mech.joints}
                           | {f"inertia and weight force on {b.name}" for b in mech.bodies})
    for j, joint in enumerate(mech.joints):
        a = arrows[f"reaction at {joint.name}"]
        np.testing.assert_allclose(np.asarray(a["vectors"], dtype=float),
                                   dyn.reaction_force[:, j], rtol=1e-12, atol=0)
        np.testing.assert_array_equal(np.asarray(a["points"], dtype=float), md.joint_centres[:, j])
    np.testing.assert_allclose(np.asarray(arrows["shaking force"]["vectors"], dtype=float),
                               dyn.shaking_force, rtol=1e-12, atol=0)
    # each body's arrow: m·(g − a_G) at its centre of mass, from the body's own motion
    v = {b.name: np.asarray(arrows[f"inertia and weight force on {b.name}"]["vectors"],
                            dtype=float) for b in mech.bodies}
    at = {b.name: np.asarray(arrows[f"inertia and weight force on {b.name}"]["points"],
                             dtype=float) for b in mech.bodies}
    dt = float(np.diff(motion.inputs[:, 0])[0] / spec.speed[0])
    for k, body in enumerate(mech.bodies):
        com = np.einsum("nij,j->ni", md.link_rotation[:, k], body.mass.com) + md.link_origin[:, k]
        np.testing.assert_allclose(at[body.name], com, atol=1e-15)
        # a_G by central differences of the CoM path over the periodic cycle (independent)
        acc = (np.roll(com, -1, 0) - 2 * com + np.roll(com, 1, 0)) / dt**2
        want = body.mass.mass * (spec.gravity_vector - acc)
        scale = np.max(np.abs(want))
        assert np.max(np.abs(v[body.name] - want)) < 2e-2 * scale, body.name
    # Newton for the whole mechanism: Σ body forces = what the ground gives the bodies
    total = sum(v.values())
    ground = np.zeros_like(total)
    for j, joint in enumerate(mech.joints):
        if joint.bodies[0] == "ground":
            ground += dyn.reaction_force[:, j]
        elif joint.bodies[1] == "ground":
            ground -= dyn.reaction_force[:, j]
    np.testing.assert_allclose(ground + total, 0.0, atol=1e-9 * np.max(np.abs(total)))


def test_every_input_effort_and_the_balancing_are_plotted(sixbar: Any) -> None:
    spec, motion, scene = sixbar
    plots = {p["id"]: p for p in scene["plots"]}
    dyn = graph_inverse_dynamics(motion, 0, spec.gravity_vector)
    for k, name in enumerate(spec.mechanism.inputs):
        p = plots[f"dyn-effort-{name}"]
        y = np.asarray(p["series"][0]["y"], dtype=float)
        np.testing.assert_allclose(y, dyn.efforts[:, k], rtol=1e-12, atol=0)
    for key in ("shaking_force", "input_torque", "G"):
        assert f"bal-{key}" in plots
    note = next(g["note"] for g in scene["plot_groups"] if g["id"] == "dynamics")
    assert "first body on its second" in note and "centre of mass" in note


def test_every_input_of_a_stewart_platform_is_plotted() -> None:
    spec = load_spec(STEWART)
    assert all(b.mass is not None for b in spec.mechanism.bodies)
    motion = solve_mechanism(spec.mechanism, spec.inputs[:6], rates=spec.speed,
                             accelerations=spec.acceleration)
    scene = graph_spec_scene(spec, motion)
    ids = {p["id"] for p in scene["plots"]}
    assert len(spec.mechanism.inputs) == 6
    assert all(f"dyn-effort-{n}" in ids for n in spec.mechanism.inputs)


def test_graph_load_arrows_in_browser(sixbar: Any, tmp_path: Path, open_report: Any) -> None:
    spec, _, scene = sixbar
    path = tmp_path / "sixbar.html"
    path.write_text(render_report_html(scene), encoding="utf-8")
    page = open_report(path)
    page.evaluate("screwkitViewer.pause()")
    page.evaluate("i => screwkitViewer.setFrame(i)", 10)
    keys = page.evaluate("[...document.querySelectorAll('.sk-arrow-key')].map(e => "
                         "e.textContent)")
    assert sorted(keys) == sorted(scene["modes"][0]["arrows"])
    assert page.evaluate("document.querySelectorAll('[data-plot=\"dyn-effort-OA.theta\"]')"
                         ".length") == 1
    on = page.canvas_pixels()
    toggle = page.page.get_by_label("arrows")
    toggle.uncheck()
    off = page.canvas_pixels()
    assert page.evaluate("document.querySelectorAll('.sk-arrow-key').length") == 0
    assert np.mean(np.abs(on - off) > 30) > 1e-4, "the arrows draw nothing"
    toggle.check()
    assert page.errors == []
    assert page.requests == [page.url]
