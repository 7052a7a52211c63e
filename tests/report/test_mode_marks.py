"""Births, deaths and singular crossings of every mode marked in a graph's report
(report/mode_marks.py): homotopy modes of the Stephenson III six-bar (born and dying at folds
between anchors), a parallelogram's change point, and the marks drawn in a real browser."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from screwkit.io.spec import load_spec
from screwkit.kinematics.graph import solve_mechanism
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint
from screwkit.report.graph_scene import scene_from_mechanism
from screwkit.report.mode_marks import mode_marks
from screwkit.report.viewer import render_report_html

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def test_marks_of_a_mask_and_classes() -> None:
    ok = np.array([True, True, False, False, True, True, True, False])
    cls = np.array(["", "", "", "", "", "dead centre", "", ""])
    assert mode_marks(ok, cls) == [{"frame": 1, "kind": "dies"}, {"frame": 4, "kind": "born"},
                                   {"frame": 5, "kind": "dead centre"},
                                   {"frame": 6, "kind": "dies"}]
    assert mode_marks(np.ones(5, dtype=bool), None) == []  # assembled throughout: no marks


@pytest.fixture(scope="module")
def stephenson() -> tuple[Any, Any, dict[str, Any]]:
    spec = load_spec(EXAMPLES / "stephenson3_sixbar.toml")
    motion = solve_mechanism(spec.mechanism, spec.inputs, every_mode=True)
    assert motion.method.startswith("graph (homotopy")
    return spec, motion, scene_from_mechanism(spec, motion)


def test_homotopy_modes_births_and_deaths_are_marked(stephenson: Any) -> None:
    _, motion, scene = stephenson
    born_or_dead = 0
    for md, entry in zip(motion.modes, scene["modes"], strict=True):
        ok = md.assembles
        marks = entry["marks"]
        born = [m["frame"] for m in marks if m["kind"] == "born"]
        dies = [m["frame"] for m in marks if m["kind"] == "dies"]
        # from the mask alone: the first sample after one that does not assemble, the last
        # before one that does not
        assert born == [i for i in range(1, ok.size) if ok[i] and not ok[i - 1]]
        assert dies == [i for i in range(ok.size - 1) if ok[i] and not ok[i + 1]]
        # each is told in the events with its fold located between samples
        assert len(born) == sum(e.startswith("is born at") for e in md.events)
        assert len(dies) == sum(e.startswith("dies at") for e in md.events)
        born_or_dead += len(born) + len(dies)
    assert born_or_dead >= 4  # two modes of the Stephenson III are born and die over the turn
    chart = next(p for p in scene["plots"] if p["id"] == "modes-chart")
    assert scene["plot_groups"][0]["id"] == "modes"
    lines = [s for s in chart["series"] if s["style"] == "line"]
    assert len(lines) == len(motion.modes)
    for k, (s, md) in enumerate(zip(lines, motion.modes, strict=True)):
        y = np.asarray(s["y"], dtype=float)
        assert np.array_equal(np.isfinite(y), md.assembles) and np.all(y[md.assembles] == k)
    for s in chart["series"]:
        if s["name"].endswith("born / dies"):
            k = s["mode"]
            y = np.asarray(s["y"], dtype=float)
            frames = sorted(m["frame"] for m in scene["modes"][k]["marks"])
            assert np.flatnonzero(np.isfinite(y)).tolist() == frames


def test_a_change_point_is_marked_with_its_class() -> None:
    Z = np.array([0.0, 0.0, 1.0])

    def joint(name: str, a: str, b: str, at: list[float]) -> MechanismJoint:
        return MechanismJoint(name, "R", (a, b), np.array(at, dtype=float), Z)

    pg = Mechanism("parallelogram", (Body("crank"), Body("coupler"), Body("rocker")),
                   (joint("A", "ground", "crank", [0, 0, 0]),
                    joint("B", "crank", "coupler", [0, 1, 0]),
                    joint("C", "coupler", "rocker", [2, 1, 0]),
                    joint("D", "rocker", "ground", [2, 0, 0])), ("A.theta",))
    motion = solve_mechanism(pg, np.radians(np.arange(0.0, -120.0, -1.0)))
    scene = scene_from_mechanism(pg, motion)
    assert scene["modes"][0]["marks"] == [{"frame": 90, "kind": "bifurcation"}]
    chart = next(p for p in scene["plots"] if p["id"] == "modes-chart")
    pts = next(s for s in chart["series"] if s["name"] == "mode 0: singular")
    assert np.flatnonzero(np.isfinite(np.asarray(pts["y"], dtype=float))).tolist() == [90]


def test_mode_marks_in_browser(stephenson: Any, tmp_path: Path, open_report: Any) -> None:
    _, motion, scene = stephenson
    html_path = tmp_path / "stephenson.html"
    html_path.write_text(render_report_html(scene), encoding="utf-8")
    page = open_report(html_path)
    page.evaluate("screwkitViewer.pause()")
    assert page.evaluate("document.querySelector('#sk-group-modes h2').textContent") == \
        "Assembly modes: births, deaths and singular crossings"
    axes = page.evaluate("screwkitViewer.plotAxes()")["modes-chart"]
    assert axes["y"]["min"] <= 0 and axes["y"]["max"] >= len(motion.modes) - 1
    k = next(i for i, md in enumerate(motion.modes) if not md.assembles.all())
    page.evaluate("k => screwkitViewer.setMode(k)", k)
    shown = page.evaluate("[...document.querySelectorAll('.sk-events li')].map(e => e.textContent)")
    assert shown == motion.modes[k].events
    assert any(e.startswith("is born at") for e in shown)
    assert any(e.startswith("dies at") for e in shown)
    # the chart is drawn: its canvas has ink
    ink = page.evaluate("""() => {
        const c = document.querySelector('[data-plot="modes-chart"] canvas');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++;
        return n;
    }""")
    assert ink > 500
    assert page.errors == []
