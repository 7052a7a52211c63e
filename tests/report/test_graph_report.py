"""The report of any mechanism, a graph (report/graph_scene.py): the scene draws every body and
joint where the motion puts them, lists every loop, plots every joint variable; ``screwkit
report`` writes it atomically; a real browser plays it, draws the solver's joint centres and
picks out each loop."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.spec import load_spec
from screwkit.kinematics.graph import solve_mechanism
from screwkit.report.graph_scene import scene_from_mechanism
from screwkit.report.spec_report import spec_scene, write_spec_report
from screwkit.report.viewer import render_report_html

HERE = Path(__file__).parent
SPECS = [HERE / "data" / "slider_sixbar_graph.toml", HERE / "data" / "spatial_flag_graph.toml",
         HERE.parents[1] / "examples" / "mechanisms" / "fourbar_graph.toml"]
runner = CliRunner()


@pytest.fixture(scope="module", params=SPECS, ids=[p.stem for p in SPECS])
def solved(request: Any) -> tuple[Any, Any, dict[str, Any]]:
    spec = load_spec(request.param)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration)
    return spec, motion, scene_from_mechanism(spec, motion)


def _frames(n: int) -> list[int]:
    return sorted({0, 1, n // 3, n // 2, n - 1})


def test_scene_draws_every_body_and_joint_where_the_motion_puts_them(solved: Any) -> None:
    spec, motion, scene = solved
    mech, md, sm = spec.mechanism, motion.modes[0], scene["modes"][0]
    ok = md.assembles
    assert ok.sum() >= 11 and sm["assembles"] == ok.tolist()
    assert sm["events"] == md.events and (ok.all() or md.events)
    assert np.isnan(np.asarray(sm["link_points"], dtype=float)[~ok]).all()  # nothing drawn
    assert [j["name"] for j in scene["joints"]] == [j.name for j in mech.joints]
    assert [j["kind"] for j in scene["joints"]] == [j.kind for j in mech.joints]
    assert [lk["name"] for lk in scene["links"]] == [*mech.body_names, "ground"]
    centres = np.asarray(sm["joint_centres"], dtype=float)  # None (JSON) is NaN
    lp = np.asarray(sm["link_points"], dtype=float)
    ends = np.asarray(sm["rail_ends"], dtype=float)
    assert lp.shape[:2] == (md.joint_centres.shape[0], len(mech.bodies) + 1)
    np.testing.assert_array_equal(centres, md.joint_centres)
    tol = 1e-12 * float(np.nanmax(np.abs(centres)))
    for i in np.nonzero(ok)[0][_frames(int(ok.sum()))]:
        for b, link in enumerate(scene["links"]):
            drawn = lp[i, b]
            # where the body carries each of its joints and points, independently of the drawing
            want = []
            for jj in link["joints"]:
                j = mech.joints[jj]
                want.append(centres[i, jj] if j.bodies[0] == link["name"] else ends[i, jj])
                if j.kind in "RUS":  # a joint without travel: both bodies carry the same point
                    assert np.linalg.norm(ends[i, jj] - centres[i, jj]) < tol, (j.name, i)
            want += [md.points[name][i] for name in link["points"]]
            want_a = np.array(want)
            gap_in = np.linalg.norm(want_a[:, None] - drawn[None], axis=-1)
            assert gap_in.min(axis=1).max() < tol, (link["name"], i)  # every part is drawn
            assert gap_in.min(axis=0).max() < tol, (link["name"], i)  # nothing else is
    for name, path in md.points.items():
        np.testing.assert_array_equal(np.asarray(sm["traces"][name], dtype=float), path)
    slides = [jj for jj, j in enumerate(mech.joints) if j.kind == "P"]
    for jj in slides:  # a slide's rail runs along its axis, as far as the slide has moved
        d = ends[:, jj] - centres[:, jj]
        u = np.asarray(sm["joint_axes"])[:, jj]
        off = d - np.sum(d * u, axis=1)[:, None] * u
        assert np.nanmax(np.abs(off)) < tol
        s = motion.modes[0].variables[f"{mech.joints[jj].name}.s"]
        np.testing.assert_allclose(np.abs(np.sum(d * u, axis=1)), np.abs(s), atol=tol)


def test_every_loop_is_listed_with_its_joints(solved: Any) -> None:
    spec, _, scene = solved
    mech = spec.mechanism
    names = [lp["joint_names"] for lp in scene["loops"]]
    assert names == mech.loop_joint_names()
    assert len(names) == len(spec.topology.loops)
    bodies = [*mech.body_names, "ground"]
    for lp in scene["loops"]:
        assert [mech.joints[j].name for j in lp["joints"]] == lp["joint_names"]
        joined = {b for j in lp["joints"] for b in mech.joints[j].bodies}
        assert {bodies[k] for k in lp["links"]} == joined
    assert scene["text"]["topology"] == spec.topology.summary()
    page = render_report_html(scene)
    assert "<h2>Topology</h2>" in page and "loop 1: " in page


def test_every_joint_variable_is_plotted_against_the_first_input(solved: Any) -> None:
    spec, motion, scene = solved
    md = motion.modes[0]
    first = spec.mechanism.inputs[0]
    np.testing.assert_array_equal(np.asarray(scene["input"]["values"]), spec.inputs[:, 0])
    plotted = {p["id"]: p for p in scene["plots"]}
    wanted = [n for n in md.variables if n != first and n.split(".")[1] not in ("rx", "ry", "rz")]
    assert wanted
    for name in wanted:
        for key, table in enumerate((md.variables, md.velocities, md.accelerations)):
            series = plotted[f"kin-{name}-{key}"]["series"]
            np.testing.assert_allclose(np.asarray(series[0]["y"], dtype=float), table[name])
    # the validation lines are checks made from the poses: rigid bodies, joints that hold
    valid = " ".join(scene["text"]["validation"])
    rigid = float(valid.split("bodies rigid to ")[1].split(" m")[0])
    held = float(valid.split("joints hold to ")[1].split(" m")[0])
    assert rigid < 1e-12 and held < 1e-12


def test_report_of_a_graph_spec_is_written_atomically(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    spec = str(SPECS[0])
    out = tmp_path / "r.html"
    r = runner.invoke(app, ["report", spec, "-o", str(out), "--plot", str(tmp_path / "v.png")])
    assert r.exit_code == 0, r.output
    page = out.read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and "screwkitViewer" in page
    # every mode: the four-bar's RRR dyad and the slider's RRP dyad, 2 × 2 branches
    assert "181 frames, 4 assembly mode(s)" in r.output
    assert (tmp_path / "v.png").stat().st_size > 0
    assert not list(tmp_path.glob(".*"))  # no temporary file left behind
    out.write_text("old", encoding="utf-8")

    def fail(*args: Any) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", fail)
    r = runner.invoke(app, ["report", spec, "-o", str(out)])
    assert r.exit_code != 0
    assert out.read_text(encoding="utf-8") == "old"  # the old file is whole, not half-written
    assert not list(tmp_path.glob(".*"))
    monkeypatch.undo()
    scene = write_spec_report(load_spec(spec), out)  # the library's front door
    assert out.read_text(encoding="utf-8") == render_report_html(scene)
    assert spec_scene(load_spec(spec))["loops"] == scene["loops"]


def test_a_bad_graph_spec_writes_no_report(tmp_path: Path) -> None:
    text = SPECS[2].read_text(encoding="utf-8").replace('["coupler", "rocker"]',
                                                        '["coupler", "rockr"]')
    bad = tmp_path / "bad.toml"
    bad.write_text(text, encoding="utf-8")
    r = runner.invoke(app, ["report", str(bad), "-o", str(tmp_path / "r.html")])
    assert r.exit_code == 2 and "rockr" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "r.html").exists()


def test_graph_report_in_browser(solved: Any, tmp_path: Path, open_report: Any) -> None:
    spec, motion, scene = solved
    md = motion.modes[0]
    html_path = tmp_path / "graph.html"
    html_path.write_text(render_report_html(scene), encoding="utf-8")
    page = open_report(html_path)
    n = spec.inputs.shape[0]
    assert page.evaluate("screwkitViewer.frameCount") == n
    assert page.evaluate("screwkitViewer.playing") is True  # autoplay: the frame advances
    f0 = page.evaluate("screwkitViewer.frame")
    page.page.wait_for_function("f0 => screwkitViewer.frame !== f0", arg=f0, timeout=5_000)
    page.evaluate("screwkitViewer.pause()")
    frames = _frames(n)
    drawn = page.evaluate("frames => frames.map(i => [screwkitViewer.jointPositions(i), "
                          "document.querySelector('.sk-status').textContent])", frames)
    for i, (got, status) in zip(frames, drawn, strict=True):
        if not md.assembles[i]:  # past a limit: nothing is drawn, and the page says so
            assert got == [None] * len(scene["joints"]) and "does not assemble" in status
            continue
        np.testing.assert_allclose(np.asarray(got, dtype=float), md.joint_centres[i], rtol=0,
                                   atol=1e-12 * float(np.nanmax(np.abs(md.joint_centres))))
    shown = page.evaluate("[...document.querySelectorAll('.sk-events li')].map(e => e.textContent)")
    assert shown == md.events
    page.evaluate("i => screwkitViewer.setFrame(i)", 0)
    loops = scene["loops"]
    assert page.evaluate("screwkitViewer.loopCount") == len(loops)
    every = list(range(len(scene["joints"])))
    for k, lp in enumerate(loops):
        page.evaluate("k => screwkitViewer.setLoop(k)", k)
        assert page.evaluate("screwkitViewer.fullJoints()") == sorted(lp["joints"])
        assert page.evaluate("document.querySelector('.sk-loop').value") == str(k)
    page.evaluate("screwkitViewer.setLoop(-1)")
    assert page.evaluate("screwkitViewer.fullJoints()") == every
    pixels = page.canvas_pixels()
    assert pixels.std() > 10, f"the 3-D view looks blank (pixel std {pixels.std():.2f})"
    assert (pixels < 100).mean() > 0.002, "no dark pixels: the mechanism is not drawn"
    assert page.errors == []
    assert page.requests == [page.url], f"requests besides the page: {page.requests}"


def test_notebook_view_of_a_mechanism_motion() -> None:
    from screwkit.errors import InputError
    from screwkit.report.notebook import motion_html, view

    spec = load_spec(SPECS[2])
    motion = solve_mechanism(spec.mechanism, spec.inputs)
    shown = view(motion)  # the bare mechanism: its name, the topology at the drawing
    assert shown.scene["family"] == "graph" and shown.scene["loops"][0]["joint_names"] == [
        "A", "B", "C", "D"]
    assert shown.scene["text"]["topology"] == spec.topology.summary()
    assert motion_html(motion, spec).startswith("<iframe srcdoc=")
    with pytest.raises(InputError, match="kinematics only"):
        view(motion, spec, dynamics={"mode": 0})
