"""A long ``analyze`` shows its progress (issue 30: a 36,000-sample sweep ran 5 s in silence):
a bar on stderr naming each stage, the solver's progress filling the first, only on a terminal;
nothing on stderr otherwise, and stdout the same either way."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from rich.console import Console
from typer.testing import CliRunner

import screwkit.cli.common as common
from screwkit.cli.main import app
from screwkit.cli.progress import SWEEP_PROGRESS_SAMPLES, staged_progress

EXAMPLES = Path(__file__).parents[2] / "examples"
STAGES = ["solving", "coupler curves and transmission", "tables"]


def _long_spec(tmp_path: Path, samples: int) -> Path:
    """The 4R example over a full turn in ``samples`` steps (the closed form)."""
    text = (EXAMPLES / "bagci_example3_4r.toml").read_text(encoding="utf-8")
    lines = [ln for ln in text.splitlines() if not ln.startswith(("start", "stop", "step"))]
    at = lines.index("[motion]") + 1
    lines[at:at] = ["start = 0", "stop = 360", f"step = {360 / samples!r}"]
    path = tmp_path / "long.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("terminal", [True, False])
def test_a_long_analyze_shows_its_stages_on_a_terminal_only(tmp_path: Path, monkeypatch,
                                                            terminal: bool) -> None:
    err = io.StringIO()
    monkeypatch.setattr(common, "err_console",
                        Console(file=err, force_terminal=terminal, width=100))
    spec = _long_spec(tmp_path, SWEEP_PROGRESS_SAMPLES)
    out = tmp_path / "out.npz"
    r = CliRunner().invoke(app, ["analyze", str(spec), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert out.is_file() and r.stdout.startswith(f"wrote {out}")
    shown = err.getvalue()
    assert "wrote" not in shown  # stdout stays stdout: the bar is gone before the output
    if terminal:
        for name in STAGES:
            assert f"analyze: {name}" in shown
    else:
        assert shown == ""


def test_json_on_stdout_stays_whole_under_the_bar(tmp_path: Path, monkeypatch) -> None:
    import json

    err = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=err, force_terminal=True, width=100))
    r = CliRunner().invoke(app, ["analyze", str(_long_spec(tmp_path, SWEEP_PROGRESS_SAMPLES)),
                                 "--json"])
    assert r.exit_code == 0, r.output
    assert len(json.loads(r.stdout)["input"]) == SWEEP_PROGRESS_SAMPLES
    assert "analyze: solving" in err.getvalue() and "{" not in err.getvalue()


def test_a_short_analyze_shows_no_bar(tmp_path: Path, monkeypatch) -> None:
    err = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=err, force_terminal=True, width=100))
    r = CliRunner().invoke(app, ["analyze", str(EXAMPLES / "bagci_example3_4r.toml"),
                                 "-o", str(tmp_path / "a.json")])
    assert r.exit_code == 0 and err.getvalue() == ""


def test_each_stage_is_drawn_at_its_share_of_the_bar(monkeypatch) -> None:
    err = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=err, force_terminal=True, width=100))
    with staged_progress("job", ["a", "b"]) as stage:
        advance = stage("a")
        advance(1, 2)
        advance(2, 2)
        stage("b")
    frames = [f for f in err.getvalue().split("\r") if "job: " in f]
    assert "job: a" in frames[0] and " 0%" in frames[0]
    assert any("job: b" in f and "50%" in f for f in frames)
