"""Messages are never hard-wrapped: with an 80-column terminal setting and a working directory
of 150 characters, an error names the whole path on one line (grep and copy-paste work)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

CLI = [sys.executable, "-c", "from screwkit.cli.main import app; app()"]


def _long_folder(tmp_path: Path) -> Path:
    folder = tmp_path / ("d" * 60) / ("e" * 60)
    folder.mkdir(parents=True)
    assert len(str(folder)) >= 150
    return folder


def test_error_with_a_long_path_is_one_unbroken_line(tmp_path):
    folder = _long_folder(tmp_path)
    missing = folder / "no_such_spec.toml"
    env = {**os.environ, "COLUMNS": "80"}
    r = subprocess.run([*CLI, "validate", str(missing)], capture_output=True, text=True,
                       cwd=folder, env=env, timeout=120)
    assert r.returncode == 2
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert any(str(missing) in line for line in lines), r.stderr
    assert "Traceback" not in r.stderr


def test_written_file_message_keeps_its_path_whole(tmp_path):
    folder = _long_folder(tmp_path)
    spec = Path(__file__).parents[2] / "examples" / "bagci_fig7_rsrc.toml"
    out = folder / "result.json"
    env = {**os.environ, "COLUMNS": "80"}
    r = subprocess.run([*CLI, "analyze", str(spec), "-o", str(out)], capture_output=True,
                       text=True, cwd=folder, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    assert any(f"wrote {out}" in line for line in r.stdout.splitlines())
