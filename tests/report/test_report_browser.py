"""Every bundled example's HTML report in a real browser (headless Debian chromium): it plays,
draws the solver's joint centres exactly, shows a picture, logs no error and asks the network
for nothing."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from screwkit.io.documents import synthesis_document
from screwkit.io.spec import load_spec
from screwkit.pipeline import Pipeline
from screwkit.report.spec_report import spec_scene
from screwkit.report.synthesis_scene import synthesised_motion
from screwkit.report.viewer import render_report_html

EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.toml"))


def sample_frames(n: int, assembles: np.ndarray) -> list[int]:
    """First, last, middle and two seeded random frames, plus a frame where the mode does not
    assemble when there is one."""
    rng = np.random.default_rng(n)
    frames = {0, n - 1, n // 2, *rng.integers(0, n, 2).tolist()}
    missing = np.nonzero(~assembles)[0]
    if missing.size:
        frames.add(int(missing[0]))
    return sorted(frames)


def check_joint_positions(page: Any, mot: Any) -> int:
    """jointPositions(i) against the Motion's joint centres (1e-9 m) at several frames of
    every mode; a frame where the mode does not assemble draws nothing (nulls)."""
    checked = 0
    page.evaluate("screwkitViewer.pause()")
    assert page.evaluate("screwkitViewer.modeCount") == len(mot.modes)
    for k, md in enumerate(mot.modes):
        page.evaluate("k => screwkitViewer.setMode(k)", k)
        centres = np.asarray(md.joint_centres)
        ok = np.asarray(md.assembles)
        frames = sample_frames(centres.shape[0], ok)
        shown = page.evaluate("""frames => frames.map(i => ({drawn: screwkitViewer.jointPositions(i),
            frame: screwkitViewer.frame, data: document.body.dataset.frame,
            status: document.querySelector('.sk-status').textContent}))""", frames)
        for i, got in zip(frames, shown, strict=True):
            assert got["frame"] == i and got["data"] == str(i)
            if not ok[i]:
                assert got["drawn"] == [None] * centres.shape[1], (k, i, got)
                assert "does not assemble" in got["status"]
                continue
            np.testing.assert_allclose(np.asarray(got["drawn"], dtype=float), centres[i], rtol=0,
                                       atol=1e-9, err_msg=f"mode {k}, frame {i}")
            checked += 1
    return checked


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_report_in_browser(path: Path, tmp_path: Path, open_report: Any) -> None:
    spec = load_spec(path)
    pipe = Pipeline(spec)
    mot = pipe.motion
    n = len(spec.inputs)
    docs = {}
    if spec.synthesis is not None:  # the report shows the synthesised mechanism
        docs["synthesis_doc"] = synthesis_document(pipe.synthesize(), spec.path)
        shown = synthesised_motion(spec.synthesis, docs["synthesis_doc"], spec.family)
        mot, n = shown.motion, len(shown.theta)
    html_path = tmp_path / f"{path.stem}.html"
    html_path.write_text(render_report_html(spec_scene(pipe, **docs)), encoding="utf-8")
    page = open_report(html_path)
    assert page.evaluate("screwkitViewer.frameCount") == n
    assert page.evaluate("document.body.dataset.frames") == str(n)
    # autoplay: the frame advances by itself
    assert page.evaluate("screwkitViewer.playing") is True
    f0 = page.evaluate("screwkitViewer.frame")
    page.page.wait_for_function("f0 => screwkitViewer.frame !== f0", arg=f0, timeout=5_000)
    now = page.evaluate("[screwkitViewer.frame, document.body.dataset.frame]")
    assert now[1] == str(now[0])
    assert check_joint_positions(page, mot) >= len(mot.modes)
    # a picture, not a blank canvas: set a frame where the mode assembles and look at it
    k = int(np.argmax([np.sum(m.assembles) for m in mot.modes]))
    page.evaluate("k => screwkitViewer.setMode(k)", k)
    page.evaluate("i => screwkitViewer.setFrame(i)", int(np.argmax(mot.modes[k].assembles)))
    pixels = page.canvas_pixels()
    assert pixels.std() > 10, f"the 3-D view looks blank (pixel std {pixels.std():.2f})"
    assert (pixels < 100).mean() > 0.002, "no dark pixels: the mechanism is not drawn"
    assert page.errors == []
    assert page.requests == [page.url], f"requests besides the page: {page.requests}"
