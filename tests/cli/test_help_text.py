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
