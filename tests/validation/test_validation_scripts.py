"""The seed-reproduction scripts under validation/ run and pass their own checks (each exits
non-zero when a check fails), so the written reports cannot silently go stale."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted((ROOT / "validation").glob("*/*.py"))
#: bertini_crosscheck (minutes: Bertini's 1,024 total-degree paths per 6R loop in adaptive
#: precision) runs in tests/crosscheck through the same functions, on fewer instances
RUNNABLE = [p for p in SCRIPTS if p.stem not in ("rebuild_dimensions", "seed_program_reenactment",
                                                 "bertini_crosscheck")]


@pytest.mark.parametrize("script", RUNNABLE, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_validation_script_runs_and_passes(script):
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300,
                       cwd=ROOT)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert len(r.stdout) > 500  # it printed its report


def test_every_report_is_committed_next_to_its_script():
    for script in RUNNABLE:
        assert script.with_suffix(".md").exists(), script
