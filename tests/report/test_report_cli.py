"""``screwkit report`` and ``screwkit demo``'s reports: files written, static pictures, and
clear errors for bad options."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from screwkit.cli.main import app

EXAMPLES = Path(__file__).parents[2] / "examples"
runner = CliRunner()


def _image(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("L"), dtype=float)


def test_report_writes_html_and_static_pictures(tmp_path: Path) -> None:
    out, png, gif = tmp_path / "r.html", tmp_path / "view.png", tmp_path / "anim.gif"
    r = runner.invoke(app, ["report", str(EXAMPLES / "bagci_example1.toml"), "-o", str(out),
                            "--plot", str(png), "--plot", str(gif), "--frame", "4", "--mode", "1"])
    assert r.exit_code == 0, r.output
    page = out.read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and "screwkitViewer" in page
    assert "wrote" in r.output and "9 frames, 2 assembly mode(s)" in r.output
    assert _image(png).std() > 10  # a picture, not a blank page
    from PIL import Image

    with Image.open(gif) as im:
        assert im.n_frames == 9  # one frame per input sample
    assert not list(tmp_path.glob(".*"))  # no temporary file left behind


def test_report_mp4_needs_ffmpeg(tmp_path: Path) -> None:
    mp4 = tmp_path / "anim.mp4"
    r = runner.invoke(app, ["report", str(EXAMPLES / "bagci_example1.toml"), "-o",
                            str(tmp_path / "r.html"), "--plot", str(mp4)])
    if shutil.which("ffmpeg"):
        assert r.exit_code == 0 and mp4.stat().st_size > 0
    else:
        assert r.exit_code == 2 and "ffmpeg" in r.output and not mp4.exists()
        assert not any(tmp_path.glob("*.html"))  # the report is not written either


def _flat(text: str) -> str:
    """``text`` with its whitespace collapsed: an error is wrapped at the terminal width."""
    return " ".join(text.split())


def test_report_bad_options_are_clear_errors(tmp_path: Path) -> None:
    spec = str(EXAMPLES / "bagci_example1.toml")
    r = runner.invoke(app, ["report", spec, "--plot", str(tmp_path / "view.bmp")])
    assert r.exit_code == 2 and ".gif or .mp4" in _flat(r.output)
    r = runner.invoke(app, ["report", spec, "--plot", str(tmp_path / "nope" / "view.png")])
    assert r.exit_code == 2 and "does not exist" in _flat(r.output)
    r = runner.invoke(app, ["report", spec, "-o", str(tmp_path / "r.html"), "--plot",
                            str(tmp_path / "v.png"), "--frame", "99"])
    assert r.exit_code == 2 and "9 frames" in _flat(r.output) and not (tmp_path / "v.png").exists()
    assert not (tmp_path / "r.html").exists()  # refused before anything is written
    r = runner.invoke(app, ["report", spec, "-o", str(tmp_path / "r.html"), "--plot",
                            str(tmp_path / "v.png"), "--mode", "5"])
    assert r.exit_code == 2 and "2 assembly mode(s)" in _flat(r.output)
    assert not (tmp_path / "r.html").exists()
    r = runner.invoke(app, ["report", str(tmp_path / "missing.toml")])
    assert r.exit_code == 2 and "no such spec file" in _flat(r.output)


def test_demo_writes_a_report_per_example_and_links_them(tmp_path: Path) -> None:
    src = tmp_path / "examples"
    src.mkdir()
    for name in ("fourbar_dynamics.toml", "rahman_cssp_balance.toml", "bagci_example9_overlay.toml"):
        shutil.copy(EXAMPLES / name, src / name)
    out = tmp_path / "out"
    r = runner.invoke(app, ["demo", str(src), "--output-dir", str(out), "--no-plots"])
    assert r.exit_code == 0, r.output
    index = (out / "index.html").read_text(encoding="utf-8")
    for name in ("fourbar_dynamics", "rahman_cssp_balance", "bagci_example9_overlay"):
        page = (out / f"{name}.html").read_text(encoding="utf-8")
        assert "screwkitViewer" in page
        assert f"href='{name}.html'" in index
    # the balancing and synthesis results reach their reports
    assert "bal-shaking_force" in (out / "rahman_cssp_balance.html").read_text(encoding="utf-8")
    assert "syn-rot-err" in (out / "bagci_example9_overlay.html").read_text(encoding="utf-8")
    # a gallery: one card each, the synthesis spec's picture of the synthesised mechanism
    assert index.count("<figure class='card'>") == 3
    assert "Bagci Example 9 overlay (x^3/4 with an inflection dwell) (synthesised)</title>" in index
