"""``--help`` prints the help texts as written: a spec table such as ``[drive]`` or
``[motion] mode`` is plain text, not console markup that would silently vanish."""

from __future__ import annotations

import re

import pytest
import typer
from typer.testing import CliRunner

from screwkit.cli.main import app

GROUP = typer.main.get_command(app)
COMMANDS = sorted(GROUP.commands)  # type: ignore[attr-defined]


def _texts(name: str) -> str:
    cmd = GROUP.commands[name]  # type: ignore[attr-defined]
    return " ".join([cmd.help or "", *(getattr(p, "help", None) or "" for p in cmd.params)])


def test_some_help_texts_name_spec_tables():
    assert sum(bool(re.search(r"\[[a-z_.]+\]", _texts(n))) for n in COMMANDS) >= 3


@pytest.mark.parametrize("name", COMMANDS)
def test_help_shows_every_bracketed_word(name):
    r = CliRunner().invoke(app, [name, "--help"], env={"COLUMNS": "250"})
    assert r.exit_code == 0, r.output
    shown = " ".join(r.output.split())
    for token in re.findall(r"\[[a-z_.]+\]", _texts(name)):
        assert token in shown, (name, token)


def test_analyze_says_which_variables_it_does_not_show():
    from pathlib import Path

    spec = Path(__file__).resolve().parents[2] / "examples" / "rrsrr_loop.toml"
    r = CliRunner().invoke(app, ["analyze", str(spec)], env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    assert "4 of 6 variables shown; the others (ball.ry, ball.rz) are in --csv and --json" in (
        " ".join(r.output.split()))
