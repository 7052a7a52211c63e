"""The example notebooks (jupytext py:percent scripts in examples/notebooks/) run from top to
bottom, offline, and their own checks hold; the family drawings of docs/families.md are made by
docs/draw_families.py from the constructors."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "examples" / "notebooks").glob("*.py"))


def test_there_are_three_notebooks_in_jupytext_percent_format():
    assert {p.stem for p in NOTEBOOKS} >= {"rssr_analyse_and_animate", "rahman_balancing",
                                           "bagci_synthesis"}
    for p in NOTEBOOKS:
        text = p.read_text(encoding="utf-8")
        assert "format_name: percent" in text and "# %% [markdown]" in text, p.name


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(notebook):
    pytest.importorskip("matplotlib")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    r = subprocess.run([sys.executable, notebook.name], cwd=notebook.parent, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-4000:]
    assert "Traceback" not in r.stderr


def test_family_drawing_is_made_from_the_constructors(tmp_path):
    pytest.importorskip("matplotlib")
    r = subprocess.run([sys.executable, str(ROOT / "docs" / "draw_families.py"), str(tmp_path),
                        "CSSP"], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    png = tmp_path / "cssp.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    doc = (ROOT / "docs" / "families.md").read_text(encoding="utf-8")
    for family in ("rsrc", "cssp", "4r", "rssr", "loop"):
        assert f"(families/{family}.png)" in doc and (ROOT / "docs" / "families" /
                                                     f"{family}.png").is_file()


def test_mechanism_pictures_are_drawn_and_linked(tmp_path: Path) -> None:
    """docs/draw_mechanisms.py draws a bundled graph example, and docs/mechanisms.md shows every
    example's picture."""
    r = subprocess.run([sys.executable, str(ROOT / "docs" / "draw_mechanisms.py"), str(tmp_path),
                        "watt_sixbar"], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    png = tmp_path / "watt_sixbar.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    doc = (ROOT / "docs" / "mechanisms.md").read_text(encoding="utf-8")
    for spec in sorted((ROOT / "examples" / "mechanisms").glob("*.toml")):
        assert f"(mechanisms/{spec.stem}.png)" in doc
        assert (ROOT / "docs" / "mechanisms" / f"{spec.stem}.png").is_file()
