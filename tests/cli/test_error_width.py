"""Error messages keep the 80-column promise (issue 30): a ScrewkitError printed by the CLI is
wrapped between words at the terminal width (COLUMNS), continuation lines indented, never cut
inside a word; and messages name lists of names as prose ("crank, coupler and output"), not as
a Python list's repr."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.messages import listing

BAD = Path(__file__).resolve().parents[1] / "bad_inputs"
sys.path.insert(0, str(BAD))
from test_bad_inputs import CASES  # noqa: E402

#: bad-input cases whose one-sentence error is longer than 80 columns (from 140 to 270)
LONG = ["dynamics without masses", "unknown weight", "mass 1e300 kg (dynamics)",
        "expression with a call", "-o is the spec itself", "unknown dimension",
        "limits --at where it does not assemble", "graph: a body attached to nothing"]


def _run(case: dict, folder: Path, columns: int, monkeypatch: pytest.MonkeyPatch
         ) -> tuple[int, str]:
    """Run a corpus case in ``folder`` (its files named relative to it, so that the messages
    do not depend on the length of pytest's temporary folder); exit status and stderr."""
    folder.mkdir()
    for name in case.get("files", []):
        shutil.copyfile(BAD / "specs" / name, folder / name)
    monkeypatch.chdir(folder)
    # rich fixes a console's width from COLUMNS when the console is made (at import): under a
    # COLUMNS=80 run (CI) the wide run would be 80 too. Let the width follow this run's COLUMNS.
    from screwkit.cli import common

    for c in (common.console, common.err_console):
        monkeypatch.setattr(c, "_width", None)
    args = [a.replace("{d}", ".") for a in case["args"]]
    r = CliRunner().invoke(app, args, env={"COLUMNS": str(columns)})
    return r.exit_code, r.stderr


@pytest.mark.parametrize("name", LONG)
def test_an_error_wraps_at_80_columns_between_words(name: str, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    case = next(c for c in CASES if c["name"] == name)
    code_wide, wide = _run(case, tmp_path / "a", 400, monkeypatch)
    code, narrow = _run(case, tmp_path / "b", 80, monkeypatch)
    assert code == code_wide == case["status"] == 2
    # unwrapped, the message is one line over 80 columns: wrapping is needed ...
    assert max(len(line) for line in wide.splitlines()) > 80, wide
    # ... and at COLUMNS=80 every line fits, continuation lines are indented by two
    lines = narrow.splitlines()
    assert len(lines) > 1 and all(len(line) <= 80 for line in lines), narrow
    first = [k for k, line in enumerate(lines) if line.startswith("error: ")]
    assert first == [0], narrow
    block = lines[1:]
    if block and block[-1].endswith("spec file(s) failed"):  # validate's summary line
        block = block[:-1]
    assert block and all(line.startswith("  ") and not line.startswith("   ")
                         for line in block), narrow
    # the same words in the same order: nothing cut inside a word, nothing lost
    assert narrow.split() == wide.split()
    assert " ".join(case["message"].split()) in " ".join(narrow.split())


def test_a_path_longer_than_the_line_stays_whole(tmp_path: Path) -> None:
    folder = tmp_path / ("d" * 50) / ("e" * 50)
    folder.mkdir(parents=True)
    missing = folder / "no_such_spec.toml"
    r = CliRunner().invoke(app, ["analyze", str(missing)], env={"COLUMNS": "80"})
    assert r.exit_code == 2
    assert any(str(missing) in line for line in r.stderr.splitlines()), r.stderr
    assert all(len(line) <= 80 or str(missing) in line for line in r.stderr.splitlines())


def test_listing_reads_as_prose() -> None:
    assert listing(["crank", "coupler", "rocker"]) == "crank, coupler and rocker"
    assert listing(("a", "b")) == "a and b"
    assert listing(["F"]) == "F"
    assert listing([]) == "none"
    assert listing(iter(["x", "y", "z"]), "or") == "x, y or z"


def test_messages_list_names_without_python_reprs(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """The cases of the corpus that printed a list's repr (``['crank', 'coupler']``) name the
    items as prose now."""
    cases = {"dynamics without masses": "missing for crank, coupler and output",
             "unknown dimension": "expected a, b, d1, d2, d3, delta0, e and lambda0",
             "unknown link": "the links are crank, rod and slider",
             "variables of an unknown link": "the links are crank, rod and slider",
             "graph: a counterweight on a body that does not exist":
                 "the bodies are crank, coupler and rocker",
             "graph: a drive on an unknown body": "the bodies are crank, coupler and rocker",
             "graph: a motor on a freedom the joint lacks": "its freedoms are theta",
             "negative weight": "got F = -1",
             "function and expression both": "(got function and expression)",
             "unknown unknown": "unknown(s) zz cannot be solved for; choose among a, b, d1,"}
    for k, (name, fragment) in enumerate(cases.items()):
        case = next(c for c in CASES if c["name"] == name)
        code, err = _run(case, tmp_path / str(k), 1000, monkeypatch)
        assert code == 2, (name, err)
        flat = " ".join(err.split())
        assert fragment in flat, (name, err)
        assert "['" not in flat and "{'" not in flat, (name, err)
