"""The 80-column promise: with COLUMNS=80 every table and every header, note and bullet line of
every command fits 80 columns (prose is wrapped between words); errors and ``wrote <path>``
lines are never wrapped — with a working directory of 150 characters an error names the whole
path on one line (grep and copy-paste work)."""

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


BOX = set("│┃┏┓┗┛┡┩━─└┘┌┐╇╈┳┻╋┼├┤┬┴")
DRIVER = r"""
import json, sys
from typer.testing import CliRunner
from screwkit.cli.main import app
runs = json.loads(sys.argv[1])
out = {}
for name, args in runs.items():
    r = CliRunner().invoke(app, args)
    out[name] = {"code": r.exit_code, "stdout": r.stdout, "stderr": r.stderr}
print(json.dumps(out))
"""


def test_every_command_fits_80_columns_in_a_long_working_directory(tmp_path):
    """COLUMNS=80 and a 150-character working directory: no table line is wider than 80
    columns; every message that names a path names it whole, on one line."""
    import json

    folder = _long_folder(tmp_path)
    ex = Path(__file__).parents[2] / "examples"
    demo = folder / "ex"
    demo.mkdir()
    (demo / "fourbar.toml").write_text((ex / "fourbar_dynamics.toml").read_text())
    missing = str(folder / "no_such_spec.toml")
    runs = {
        "validate": ["validate", str(ex / "rahman_cssp.toml")],
        "analyze": ["analyze", str(ex / "rahman_cssp.toml"), "--method", "generic"],
        "analyze -o": ["analyze", str(ex / "rssr_spatial.toml"), "-o", str(folder / "a.csv")],
        "limits": ["limits", str(ex / "bagci_fig9_dwell.toml"), "--at", "90"],
        "mobility": ["mobility", str(ex / "rccc_loop.toml")],
        "dynamics": ["dynamics", str(ex / "rsrc_fig7_dynamics.toml"), "--csv",
                     str(folder / "d.csv")],
        "balance": ["balance", str(ex / "rahman_cssp_balance.toml")],
        "synthesize": ["synthesize", str(ex / "bagci_example8_overlay.toml")],
        "report": ["report", str(ex / "bagci_example3_4r.toml"), "-o", str(folder / "r.html")],
        "demo": ["demo", str(demo), "--output-dir", str(folder / "out"), "--no-plots",
                 "--no-reports"],
        "simulate": ["simulate", str(ex / "rahman_cssp_drive.toml"), "--cycles", "3"],
        "export-mjcf": ["export-mjcf", str(ex / "rahman_cssp.toml"), "-o", str(folder / "m.xml")],
        "export": ["export", str(ex / "bagci_fig7_rsrc.toml"), "-f", "dxf", "-o",
                   str(folder / "c.dxf")],
    }
    errors = {f"{name} error": [name, missing] for name in
              ("analyze", "limits", "mobility", "dynamics", "balance", "synthesize", "report",
               "simulate")}
    errors["export-mjcf error"] = ["export-mjcf", missing, "-o", str(folder / "x.xml")]
    errors["export error"] = ["export", missing, "-f", "gltf", "-o", str(folder / "x.glb")]
    env = {**os.environ, "COLUMNS": "80"}
    r = subprocess.run([sys.executable, "-c", DRIVER, json.dumps({**runs, **errors})],
                       capture_output=True, text=True, cwd=folder, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    results = json.loads(r.stdout)
    for name in runs:
        res = results[name]
        assert res["code"] == 0, (name, res)
        table_lines = [line for line in res["stdout"].splitlines() if BOX & set(line)]
        assert table_lines or name in ("validate", "mobility", "analyze -o", "report",
                                       "export-mjcf", "export"), name
        wide = [line for line in table_lines if len(line) > 80]
        assert not wide, f"{name}: table lines over 80 columns:\n" + "\n".join(wide)
    assert f"wrote {folder / 'a.csv'} (" in results["analyze -o"]["stdout"]
    assert f"wrote {folder / 'd.csv'}" in results["dynamics"]["stdout"].splitlines()
    for name in errors:
        res = results[name]
        assert res["code"] == 2, (name, res)
        assert any(missing in line for line in res["stderr"].splitlines()), (name, res)
        assert "Traceback" not in res["stderr"]


def test_continued_tables_name_their_own_columns():
    import io
    import re

    from rich.console import Console

    from screwkit.cli.formatting import TextColumn, print_columns

    out = io.StringIO()
    console = Console(file=out, width=40, color_system=None)
    cols = [TextColumn("key", ["1", "2"])] + [TextColumn(f"column{i}", ["123456", "7"])
                                              for i in range(2, 11)]
    print_columns(console, "t", cols, width=40)
    ranges = [(int(a), int(b), int(n)) for a, b, n in
              re.findall(r"columns (\d+)–(\d+) of (\d+)", out.getvalue())]
    assert ranges and all(n == 10 for *_, n in ranges)
    starts = [a for a, _, _ in ranges]
    ends = [b for _, b, _ in ranges]
    pairs = list(zip(ends[:-1], starts[1:], strict=True))
    assert ends[-1] == 10 and all(a2 == b + 1 for b, a2 in pairs)  # no overlap, no gap


def test_sweep_summary_fits_80_columns(monkeypatch):
    # the engine used to be a table column, wrapped to one word a line; it is a sentence now
    import io
    from types import SimpleNamespace

    from rich.console import Console

    import screwkit.cli.sweep_cmd as sweep_cmd

    out = io.StringIO()
    monkeypatch.setattr(sweep_cmd, "console", Console(file=out, width=80, color_system=None))
    engine = "embedded Dask cluster of 2 worker processes on 127.0.0.1 (LocalCluster)"
    rows = [{"status": "ok", "reason": ""}] * 11 + [{"status": "failed",
                                                       "reason": "does not assemble"}]
    result = SimpleNamespace(rows=rows, computed=12, resumed=0, failed=1, errors=0,
                             seconds=3.81, engine=engine, notes=())
    sweep_cmd._summary(result, Path("sweep.csv"), None)
    lines = out.getvalue().splitlines()
    table = [line for line in lines if BOX & set(line)]
    assert table and all(len(line) <= 80 for line in lines)
    body = [line for line in table if line.startswith("│")]
    assert len(body) == 1  # one row, not wrapped
    assert f"engine: {engine}" in " ".join(line.strip() for line in lines)  # wrapped at 80
    assert "  • 1 × does not assemble" in lines


EVERY_COMMAND = r"""
import json, sys
from pathlib import Path
from typer.testing import CliRunner
import screwkit as sk
from screwkit.cli.main import app
examples = sorted(Path(sys.argv[1]).glob("*.toml"))
runs = {"validate": ["validate", *map(str, examples)]}
for f in examples:
    spec = sk.load_spec(f)
    jobs = ["analyze", "limits", "mobility"]
    if all(link.mass is not None for link in spec.linkage.links):
        jobs.append("dynamics")
    jobs += [job for job, table in (("balance", spec.balancing), ("synthesize", spec.synthesis))
             if table is not None]
    if "[drive]" in f.read_text(encoding="utf-8"):
        jobs.append("simulate")
    runs.update({f"{job} {f.name}": [job, str(f)] for job in jobs})
runs["tolerance"] = ["tolerance", str(examples[0].parent / "rsrc_fig7_dynamics.toml"),
                     "--tol", "d2=±0.1mm", "--monte-carlo", "0"]
out = {}
for name, args in runs.items():
    r = CliRunner().invoke(app, args)
    out[name] = {"code": r.exit_code, "stdout": r.stdout}
print(json.dumps(out))
"""


def test_every_command_on_every_example_fits_80_columns(tmp_path):
    """The 80-column promise (issue 30): with COLUMNS=80, every line every command prints on
    every bundled example fits 80 columns — tables, and the header, note and bullet lines,
    which are wrapped between words (a word longer than a line, a path, is kept whole)."""
    import json

    ex = Path(__file__).parents[2] / "examples"
    env = {**os.environ, "COLUMNS": "80"}
    r = subprocess.run([sys.executable, "-c", EVERY_COMMAND, str(ex)], capture_output=True,
                       text=True, cwd=tmp_path, env=env, timeout=900)
    assert r.returncode == 0, r.stderr
    results = json.loads(r.stdout)
    assert len(results) > 3 * len(list(ex.glob("*.toml")))
    for name, res in results.items():
        assert res["code"] == 0, (name, res["stdout"][-2000:])
        wide = [line for line in res["stdout"].splitlines()
                if len(line) > 80 and max(map(len, line.split()), default=0) < 60]
        assert not wide, f"{name}: lines over 80 columns:\n" + "\n".join(wide)


def test_prose_wraps_between_words_with_a_hanging_indent():
    import io

    from rich.console import Console

    from screwkit.cli.common import prose

    out = io.StringIO()
    console = Console(file=out, width=40, color_system=None)
    path = "/" + "p" * 50 + "/spec.toml"
    prose(f"  • stops assembling after input input.theta = 250 deg in {path} (limit)",
          to=console)
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("  • stops") and all(line.startswith("    ")
                                                    for line in lines[1:])
    assert any(line.strip() == path for line in lines)  # a path is never broken
    assert all(len(line) <= 40 for line in lines if path not in line)
    assert " ".join(line.strip() for line in lines) == (
        f"• stops assembling after input input.theta = 250 deg in {path} (limit)")


def test_prose_keeps_its_own_line_breaks():
    import io

    from rich.console import Console

    from screwkit.cli.common import prose

    out = io.StringIO()
    console = Console(file=out, width=40, color_system=None)
    prose("RSRC: F = 1\n  links n = 4; pairs 4; loops k = 1 (B.3) and a few more words", to=console)
    assert out.getvalue().splitlines() == [
        "RSRC: F = 1", "  links n = 4; pairs 4; loops k = 1", "    (B.3) and a few more words"]
