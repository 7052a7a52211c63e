"""``--modes drawn|every`` on analyze, report and export of a graph spec (issue 27, "cost of
every mode"): ``drawn`` gives the drawn mode alone — the same numbers as that mode of the
default ``every`` — and skips the homotopy (the Stewart platform); a bad value, or ``drawn``
on a single-loop spec, is refused with exit 2 and one sentence."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from screwkit.cli.main import app

ROOT = Path(__file__).resolve().parents[2]
FOURBAR = ROOT / "examples" / "mechanisms" / "fourbar_graph.toml"
STEWART = ROOT / "examples" / "mechanisms" / "stewart_platform.toml"
LOOP = ROOT / "examples" / "bagci_example1.toml"
runner = CliRunner()


def _analyze(path: Path, *extra: str) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["analyze", str(path), "--json", *extra])
    assert r.exit_code == 0, r.output
    return json.loads(r.output)  # type: ignore[no-any-return]


def test_analyze_drawn_gives_the_default_runs_drawn_mode_alone() -> None:
    every = _analyze(FOURBAR)
    drawn = _analyze(FOURBAR, "--modes", "drawn")
    assert _analyze(FOURBAR, "--modes", "every")["modes"] == every["modes"]
    assert len(every["modes"]) == 2 and len(drawn["modes"]) == 1
    assert drawn["modes"][0]["label"] == "drawn"
    for key in ("variables", "velocities", "accelerations", "assembles"):
        assert drawn["modes"][0][key] == every["modes"][0][key], key


def test_drawn_skips_the_homotopy_of_a_stewart_platform() -> None:
    doc = _analyze(STEWART, "--modes", "drawn")
    assert len(doc["modes"]) == 1 and all(doc["modes"][0]["assembles"])
    assert not any("homotopy" in n or "every mode" in n for n in doc["notes"])


def test_report_and_export_take_modes(tmp_path: Path) -> None:
    r = runner.invoke(app, ["report", str(FOURBAR), "-o", str(tmp_path / "r.html"),
                            "--modes", "drawn"])
    assert r.exit_code == 0, r.output
    assert "1 assembly mode(s)" in r.output
    r = runner.invoke(app, ["report", str(FOURBAR), "-o", str(tmp_path / "e.html")])
    assert r.exit_code == 0 and "2 assembly mode(s)" in r.output
    sizes = {}
    for modes in ("drawn", "every"):
        out = tmp_path / f"{modes}.dxf"
        r = runner.invoke(app, ["export", str(FOURBAR), "-f", "dxf", "-o", str(out),
                                "--modes", modes])
        assert r.exit_code == 0, r.output
        sizes[modes] = out.read_text().count("POLYLINE")
    assert 0 < sizes["drawn"] < sizes["every"]  # DXF draws every mode it is given


def test_bad_modes_are_refused_with_exit_2(tmp_path: Path) -> None:
    for args in (["analyze", str(FOURBAR), "--modes", "all"],
                 ["analyze", str(LOOP), "--modes", "drawn"],
                 ["report", str(FOURBAR), "-o", str(tmp_path / "x.html"), "--modes", "one"],
                 ["export", str(FOURBAR), "-f", "dxf", "-o", str(tmp_path / "x.dxf"),
                  "--modes", "x"]):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, (args, r.output)
        assert "--modes" in r.output
    assert not list(tmp_path.iterdir())
