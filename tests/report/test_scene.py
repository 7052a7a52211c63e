"""The scene adapter and the page: geometry of the drawn links, every joint kind drawn, user
text escaped, the size budget, the notebook view, and the fixed plot glitches."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from screwkit.io.spec import load_spec
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model.joints import Joint
from screwkit.model.linkage import Linkage
from screwkit.pipeline import Pipeline
from screwkit.report.notebook import motion_html, view
from screwkit.report.plots import continuous_rotation_vectors, flatten_constant_axis
from screwkit.report.scene import link_polylines, scene_from_motion
from screwkit.report.scene_text import link_span_variation
from screwkit.report.spec_report import spec_scene
from screwkit.report.viewer import render_report_html

EXAMPLES = Path(__file__).parents[2] / "examples"
KINDS = "RPCHUS"


def every_kind_motion(names: list[str], n: int = 24) -> tuple[Linkage, Any]:
    """A six-joint loop with one joint of each kind and a made-up motion (the drawing does not
    need the loop to close): joints on a turning hexagon, tilted axes; frame 5 does not
    assemble and frame 7 is singular."""
    joints = [Joint(nm, k, pitch=0.01 if k == "H" else 0.0) for nm, k in zip(names, KINDS, strict=True)]
    lk = Linkage.from_hartenberg_denavit(names[0] + " loop", joints, [0.1] * 6, [0.3] * 6,
                                         [f"{names[0]}.theta"])
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ang = t[:, None] + np.arange(6)[None, :] * np.pi / 3
    centres = np.stack([0.1 * np.cos(ang), 0.1 * np.sin(ang), 0.02 * np.sin(2 * ang)], axis=-1)
    axes = np.stack([np.sin(ang) * 0.3, np.cos(ang) * 0.3, np.ones_like(ang)], axis=-1)
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    rot = Rotation.from_rotvec(np.stack([np.zeros(n), np.zeros(n), t], -1)).as_matrix()
    ok = np.ones(n, dtype=bool)
    ok[5] = False
    centres[5] = np.nan
    sing = np.zeros(n, dtype=bool)
    sing[7] = True
    mode = SimpleNamespace(
        assembles=ok, singular=sing, joint_centres=centres, joint_axes=axes,
        link_rotation=np.repeat(rot[:, None], 5, axis=1), link_origin=centres[:, :5] + 0.01,
        variables={f"{names[0]}.theta": t, f"{names[3]}.theta": np.sin(t)},
        velocities={f"{names[0]}.theta": np.ones(n), f"{names[3]}.theta": np.cos(t)},
        accelerations={f"{names[0]}.theta": np.zeros(n), f"{names[3]}.theta": -np.sin(t)},
        events=[f"event of <{names[1]}>"])
    return lk, SimpleNamespace(inputs=t[:, None], modes=[mode])


def test_every_joint_kind_is_drawn_where_the_motion_puts_it(tmp_path: Path, open_report: Any) -> None:
    names = ["crank", "slide", "cyl", "screw", "cross", "ball"]
    lk, mot = every_kind_motion(names)
    page_path = tmp_path / "kinds.html"
    page_path.write_text(render_report_html(scene_from_motion(lk, mot)), encoding="utf-8")
    page = open_report(page_path)
    page.evaluate("screwkitViewer.pause()")
    centres = mot.modes[0].joint_centres
    for i in (0, 3, 11, 23):
        drawn = np.asarray(page.evaluate("i => screwkitViewer.jointPositions(i)", i), dtype=float)
        np.testing.assert_allclose(drawn, centres[i], rtol=0, atol=1e-12)
    assert page.evaluate("screwkitViewer.jointPositions(5)") == [None] * 6
    assert "does not assemble" in page.evaluate("document.querySelector('.sk-status').textContent")
    page.evaluate("screwkitViewer.setFrame(7)")
    assert "singular" in page.evaluate("document.querySelector('.sk-status').textContent")
    page.evaluate("screwkitViewer.setFrame(2)")
    for view_name in ("front", "top", "side", "iso"):
        page.evaluate("v => screwkitViewer.setView(v)", view_name)
        assert page.canvas_pixels().std() > 10, view_name
    assert page.errors == [] and page.requests == [page.url]


def test_user_text_is_escaped(tmp_path: Path, open_report: Any) -> None:
    evil = ["</script><script>window['pwned']=1</script>", "<img src=x onerror=window['pwned']=2>",
            "a&amp;b", "q'\"", "u\u2028v", "ok"]
    lk, mot = every_kind_motion(evil)
    scene = scene_from_motion(lk, mot, spec_text="name = \"</script><b>bold</b>\"",
                              notes=["<i>note</i>"])
    page_text = render_report_html(scene)
    assert page_text.lower().count("</script") == 2  # the data block and the viewer, nothing else
    assert "<b>bold</b>" not in page_text and "<i>note</i>" not in page_text
    path = tmp_path / "evil.html"
    path.write_text(page_text, encoding="utf-8")
    page = open_report(path)
    assert page.evaluate("window.pwned") is None
    assert page.evaluate("document.querySelectorAll('img, b, i').length") == 0
    assert page.evaluate("document.title").startswith(evil[0] + " loop")
    events = page.evaluate("[...document.querySelectorAll('.sk-events li')].map(e => e.textContent)")
    assert events == [f"event of <{evil[1]}>"]
    assert "</script><b>bold</b>" in page.evaluate("document.querySelector('#sk-text pre').textContent")
    assert page.errors == []


def test_links_are_rigid_and_end_at_the_next_joint() -> None:
    spec = load_spec(EXAMPLES / "rccc_loop.toml")
    m = motion(spec.linkage, spec.inputs, spec.speed, spec.acceleration)
    for md in m.modes:
        pts = link_polylines(spec.linkage, md)
        c = md.joint_centres
        np.testing.assert_allclose(pts[:, :, 2], np.roll(c, -1, axis=1), atol=1e-15)
        np.testing.assert_allclose(pts[:, :-1, 0], md.link_origin, atol=1e-15)
        # the ground link does not move
        assert np.ptp(pts[:, -1, :2], axis=0).max() < 1e-12
        # every link keeps its shape over the cycle (an independent check of the picture)
        assert link_span_variation(pts, md.assembles) < 1e-12
        # the C joints slide: where the next link leaves a joint is not its centre
        assert np.abs(pts[:, 1, 0] - c[:, 1]).max() > 1e-3


def test_a_360_frame_report_stays_under_5_mb(tmp_path: Path, open_report: Any) -> None:
    spec = load_spec(EXAMPLES / "rsrc_fig7_dynamics.toml")
    spec.inputs = np.radians(np.arange(360.0))
    pipe = Pipeline(spec)
    mot = pipe.motion
    page_text = render_report_html(spec_scene(pipe))
    size = len(page_text.encode("utf-8"))
    assert size < 5e6, f"{size / 1e6:.2f} MB"
    path = tmp_path / "360.html"
    path.write_text(page_text, encoding="utf-8")
    page = open_report(path)
    assert page.evaluate("screwkitViewer.frameCount") == 360
    page.evaluate("screwkitViewer.pause()")
    for k, md in enumerate(mot.modes):
        page.evaluate("k => screwkitViewer.setMode(k)", k)
        for i in (0, 123, 359):
            drawn = np.asarray(page.evaluate("i => screwkitViewer.jointPositions(i)", i), dtype=float)
            np.testing.assert_allclose(drawn, md.joint_centres[i], rtol=0, atol=1e-9)
    assert page.errors == []


def test_clicking_a_linked_plot_moves_the_animation(tmp_path: Path, open_report: Any) -> None:
    spec = load_spec(EXAMPLES / "bagci_fig7_rsrc.toml")
    path = tmp_path / "click.html"
    path.write_text(render_report_html(spec_scene(spec)), encoding="utf-8")
    page = open_report(path)
    page.evaluate("screwkitViewer.pause(); screwkitViewer.setFrame(0)")
    canvas = page.page.locator(".sk-card[data-plot='kin-phi0-0'] canvas")
    canvas.scroll_into_view_if_needed()
    box = canvas.bounding_box()
    # the plot area spans 0…350 deg: a click near its right end picks a late frame
    page.page.mouse.click(box["x"] + 0.9 * box["width"], box["y"] + 0.6 * box["height"])
    page.page.wait_for_function("screwkitViewer.frame !== 0", timeout=5_000)  # Chart.js: next frame
    frame = page.evaluate("screwkitViewer.frame")
    assert 25 <= frame <= 35 and page.evaluate("screwkitViewer.playing") is False
    cursor = page.page.locator(".sk-card[data-plot='kin-phi0-0'] .sk-cursor")
    assert cursor.is_visible()
    assert page.errors == []


def test_notebook_view_is_an_iframe_of_the_same_page() -> None:
    lk, mot = every_kind_motion(["a", "b", "c", "d", "e", "f"])
    frame = motion_html(mot, lk)
    assert frame.startswith("<iframe srcdoc=\"&lt;!doctype html&gt;") and "allow-scripts" in frame
    assert 'srcdoc="' in frame and "</script>" not in frame  # all of it escaped in the attribute
    assert view(mot, lk)._repr_html_() == frame


def test_rotation_vectors_do_not_jump_at_pi() -> None:
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    angle = np.linspace(0.2, 5.5, 80)  # passes through π
    rv = Rotation.from_rotvec(angle[:, None] * axis).as_rotvec()  # |r| ≤ π: jumps
    assert np.abs(np.diff(rv, axis=0)).max() > 1.0
    smooth = continuous_rotation_vectors(rv)
    assert np.abs(np.diff(smooth, axis=0)).max() < 0.1
    np.testing.assert_allclose(smooth, angle[:, None] * axis, atol=1e-12)
    # the same rotations
    np.testing.assert_allclose(Rotation.from_rotvec(smooth).as_matrix(),
                               Rotation.from_rotvec(rv).as_matrix(), atol=1e-12)
    gap = rv.copy()
    gap[10] = np.nan  # a sample that does not assemble stays missing
    assert np.isnan(continuous_rotation_vectors(gap)[10]).all()


def test_a_constant_rate_is_a_flat_line_without_offset() -> None:
    from screwkit.report.plots import pyplot

    plt = pyplot()
    fig, ax = plt.subplots()
    y = 6.283185307 + 1e-10 * np.sin(np.arange(36.0))  # the Bennett linkage's constant rate
    ax.plot(np.arange(36.0), y)
    flatten_constant_axis(ax, [y])
    fig.canvas.draw()
    lo, hi = ax.get_ylim()
    assert hi - lo > 0.1 and lo < 6.2832 < hi
    assert ax.yaxis.get_offset_text().get_text() == ""
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert not any(re.search(r"e-1\d", s) for s in labels)
    plt.close(fig)


def test_analysis_plot_titles_use_one_angle_unit(tmp_path: Path) -> None:
    from analysis_helpers import analyze
    from screwkit.report import plots

    spec = load_spec(EXAMPLES / "bagci_fig7_rsrc.toml")
    _, doc = analyze(spec.linkage, spec.inputs, spec.speed, spec.acceleration)
    doc["mechanism"] = spec.name
    titles: list[str] = []
    real_save = plots.save_figure

    def keep_titles(fig: Any, path: Any) -> None:
        titles.extend(ax.get_title() for ax in fig.axes)
        real_save(fig, path)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plots, "save_figure", keep_titles)
        plots.plot_analysis(doc, tmp_path / "a.png")
    assert "phi0' (deg/s)" in titles and "phi0'' (deg/s²)" in titles
    assert not any("rad" in t for t in titles)
