"""The demo's index is a gallery (issue 30: it was a 44,000-pixel list): one card per example
with a small picture of the mechanism and one line, the details folded below; the picture is
the mechanism where the motion puts it."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

import screwkit as sk
from screwkit.report.html import write_index
from screwkit.report.thumbnail import mechanism_svg

EXAMPLES = Path(__file__).parents[2] / "examples"


def _circles(svg: str) -> np.ndarray:
    return np.array([[float(x), float(y)] for x, y in
                     re.findall(r"<circle cx='([-\d.]+)' cy='([-\d.]+)'", svg)])


def test_the_thumbnail_draws_the_joints_where_the_motion_puts_them() -> None:
    spec = sk.load_spec(EXAMPLES / "rssr_spatial.toml")
    motion = sk.solve_motion(spec.linkage, spec.inputs)
    svg = mechanism_svg(spec.linkage, motion, spec.mode, spec.name)
    assert svg.startswith("<svg") and svg.endswith("</svg>") and len(svg) < 20_000
    drawn = _circles(svg)
    centres = np.asarray(motion.modes[spec.mode].joint_centres, dtype=float)[0]
    assert drawn.shape == (len(spec.linkage.joints), 2)
    # an isometric view (azimuth −60°, elevation 30°): picture right and up, y down in SVG
    az, el = np.radians(-60), np.radians(30)
    right = np.array([-np.sin(az), np.cos(az), 0.0])
    up = np.array([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), np.cos(el)])
    expected = np.stack([centres @ right, -(centres @ up)], axis=-1)
    # the drawing is the projection up to one scale and a shift (to the 0.1 px of the SVG)
    a, b = drawn - drawn.mean(0), expected - expected.mean(0)
    scale = np.linalg.norm(a) / np.linalg.norm(b)
    assert np.max(np.abs(a - scale * b)) < 0.2
    assert np.all((drawn >= 0) & (drawn <= [200, 140]))


def test_a_loop_that_never_assembles_gets_a_frame_saying_so() -> None:
    spec = sk.load_spec(EXAMPLES / "rssr_spatial.toml")
    motion = sk.solve_motion(spec.linkage, spec.inputs)
    broken = type("M", (), {"modes": [type("Mode", (), {"assembles": np.zeros(3, bool)})()]})()
    assert "does not assemble" in mechanism_svg(spec.linkage, broken)
    assert "<circle" in mechanism_svg(spec.linkage, motion)


def _entries(n: int) -> list[dict[str, Any]]:
    spec = sk.load_spec(EXAMPLES / "bagci_fig7_rsrc.toml")
    svg = mechanism_svg(spec.linkage, sk.solve_motion(spec.linkage, spec.inputs), 0, spec.name)
    return [{"name": f"example_{k}", "family": "RSRC", "description": spec.describe() * 2,
             "jobs": [("analysis", f"example_{k}.analysis.json")],
             "summary": [(f"row {r}", r) for r in range(12)], "picture": f"example_{k}.png",
             "report": f"example_{k}.html", "thumbnail": svg, "line": "RSRC · 2 mode(s)"}
            for k in range(n)]


def test_the_index_is_a_gallery_with_one_line_per_example(tmp_path: Path,
                                                          browser_context: Any) -> None:
    entries = _entries(30)
    page_text = write_index(tmp_path, entries).read_text(encoding="utf-8")
    cards = re.findall(r"<figure class='card'>(.*?)</figure>", page_text)
    assert len(cards) == 30
    for k, card in enumerate(cards):
        assert f"href='example_{k}.html'" in card and "<svg" in card
        assert card.count("<br>") == 1 and "RSRC · 2 mode(s)" in card
    # the details (numbers, the big picture) are folded, not gone
    assert page_text.count("<details id=") == 30 and "example_29.analysis.json" in page_text
    page = browser_context.new_page()
    try:
        page.set_viewport_size({"width": 1200, "height": 800})
        page.goto((tmp_path / "index.html").resolve().as_uri())
        height = page.evaluate("document.documentElement.scrollHeight")
        shown = page.evaluate("[...document.querySelectorAll('.card svg')]"
                              ".filter(s => s.getBoundingClientRect().height > 50).length")
    finally:
        page.close()
    assert shown == 30
    assert height < 4000, height
