"""Result files of the command line: a folder or a missing folder as output is a clear error
(exit 2), and a written result is an ordinary file readable under the user's umask."""

import os
import stat
from pathlib import Path

from typer.testing import CliRunner

from screwkit.cli.main import app

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_output_to_a_folder_or_a_missing_folder_is_a_clear_error(tmp_path):
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(tmp_path)])
    assert r.exit_code == 2 and "it is a folder" in " ".join(r.output.split())  # wrapped
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(tmp_path / "no" / "x.json")])
    assert r.exit_code == 2 and "does not exist" in " ".join(r.output.split())


def test_result_files_are_ordinary_readable_files(tmp_path):
    out = tmp_path / "r.json"
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(out)])
    assert r.exit_code == 0
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask
