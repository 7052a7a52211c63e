"""Click's own usage errors (unknown option, missing argument, bad value, unknown command) keep
the 80-column promise like screwkit's errors (issue 30): usage line and hint, then one
``error:`` paragraph wrapped between words at COLUMNS with continuation lines indented by two;
exit status 2."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app

#: a value click refuses with a message of 95 characters (one line at 400 columns)
LONG = ["limits", "--dwell-tol", "one in a million", "spec.toml"]


def _run(args: list[str], columns: int, monkeypatch: pytest.MonkeyPatch) -> tuple[int, str]:
    # rich fixes a console's width from COLUMNS when it is made (test_error_width.py)
    from screwkit.cli import common

    for c in (common.console, common.err_console):
        monkeypatch.setattr(c, "_width", None)
    r = CliRunner().invoke(app, args, env={"COLUMNS": str(columns)})
    return r.exit_code, r.stderr


def _error_block(err: str) -> list[str]:
    """The lines from ``error:`` to the end."""
    lines = err.rstrip("\n").splitlines()
    first = [k for k, line in enumerate(lines) if line.startswith("error: ")]
    assert len(first) == 1, err
    return lines[first[0]:]


def test_a_long_usage_error_wraps_at_80_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    code_wide, wide = _run(LONG, 400, monkeypatch)
    code, narrow = _run(LONG, 80, monkeypatch)
    assert code == code_wide == 2
    assert "Invalid value for '--dwell-tol'" in wide and "Usage:" in wide, wide
    # one line at 400 columns, longer than 80: wrapping is needed ...
    assert len(_error_block(wide)) == 1 and len(_error_block(wide)[0]) > 80, wide
    # ... and at 80 every line fits, continuation lines indented by two, no word cut
    block = _error_block(narrow)
    assert len(block) > 1 and all(len(line) <= 80 for line in narrow.splitlines()), narrow
    assert all(line.startswith("  ") and not line.startswith("   ") for line in block[1:])
    assert narrow.split() == wide.split()
    assert "Traceback" not in narrow


@pytest.mark.parametrize(("args", "fragment"), [
    (["analyze"], "Missing argument 'spec'."),
    (["analyze", "--no-such-option", "spec.toml"], "No such option: --no-such-option"),
    (["anlyze", "spec.toml"], "No such command 'anlyze'. Did you mean 'analyze'?"),
    (["--max-memory"], "Option '--max-memory' requires an argument."),
])
def test_usage_errors_print_as_screwkit_errors(args: list[str], fragment: str,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    for columns in (80, 400):
        code, err = _run(args, columns, monkeypatch)
        assert code == 2, err
        assert " ".join(_error_block(err)) == f"error: {fragment}", err
        assert all(len(line) <= 80 for line in err.splitlines()), err
        assert "Error:" not in err, err


def test_no_arguments_still_prints_the_help(monkeypatch: pytest.MonkeyPatch) -> None:
    r = CliRunner().invoke(app, [], env={"COLUMNS": "80"})
    assert "Commands" in r.output and "analyze" in r.output, r.output
    assert "error:" not in r.output
