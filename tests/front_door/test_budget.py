"""Bounded work: memory is estimated before solving and a run over the limit is refused with a
sentence saying what to change; the limit can be raised (docs/reliability.md)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.budget import ResourceLimitError, parse_size, set_memory_limit
from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def test_sizes_parse_and_bad_sizes_are_named():
    assert parse_size("16GB") == 16 * 10**9
    assert parse_size("512 MiB") == 512 * 2**20
    assert parse_size("2e9") == 2 * 10**9
    for bad in ("lots", "-1GB", "12 parsecs", "0"):
        with pytest.raises(sk.ScrewkitError, match="memory"):
            parse_size(bad)


def test_a_motion_over_the_limit_is_refused_before_solving():
    lk = sk.rsrc(d1=0.05, d2=0.11, d3=0.08, a=0.08, b=0.03, e=0.02, delta0=0.3, lambda0=1.0)
    set_memory_limit("1MB")
    try:
        t = time.perf_counter()
        with pytest.raises(ResourceLimitError, match=r"needs about .* over the 1 MB memory limit"):
            sk.solve_motion(lk, [0.1] * 100_000)
        assert time.perf_counter() - t < 1.0  # refused up front, not after solving
        sk.solve_motion(lk, [0.1, 0.2, 0.3])  # small runs still go through
    finally:
        set_memory_limit(None)


def test_the_cli_limit_can_be_lowered_and_raised():
    spec = str(EXAMPLES / "bagci_fig7_rsrc.toml")
    r = runner.invoke(app, ["--max-memory", "10kB", "analyze", spec, "--json"])
    assert r.exit_code == 2 and "--max-memory" in r.output and "memory limit" in r.output
    r = runner.invoke(app, ["--max-memory", "10GB", "analyze", spec, "--json"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["--max-memory", "plenty", "analyze", spec])
    assert r.exit_code == 2 and "memory size" in r.output


def test_a_huge_pareto_sweep_is_refused_at_load(tmp_path):
    text = (EXAMPLES / "rahman_cssp_balance.toml").read_text()
    text += "\n[balancing.pareto]\nmeasures = [\"F\", \"T\", \"T0\"]\ndivisions = 100000000\n"
    p = tmp_path / "huge.toml"
    p.write_text(text)
    t = time.perf_counter()
    r = runner.invoke(app, ["validate", str(p)])
    assert time.perf_counter() - t < 5.0
    assert r.exit_code == 2 and "weightings" in r.output and "fewer divisions" in r.output


@pytest.mark.parametrize("method", ["closed", "generic"])
def test_the_motion_estimate_bounds_the_measured_peak_without_overstating_it(method):
    """The estimate is an upper bound of the memory the solve really allocates (tracemalloc
    sees numpy's buffers), and not wildly more, so that 10⁶ samples of a family with two modes
    are accepted where they fit (docs/reliability.md)."""
    import subprocess
    import sys

    code = f"""
import tracemalloc, numpy as np, screwkit as sk
from screwkit.kinematics.solve_motion import motion_bytes
lk = sk.fourbar(3.0, 1.0, 3.0, 2.5)
theta = np.linspace(0.0, 2 * np.pi, 20000, endpoint=False)
sk.solve_motion(lk, theta[:50], method="{method}", progress=False)
tracemalloc.start()
m = sk.solve_motion(lk, theta, method="{method}", progress=False)
peak = tracemalloc.get_traced_memory()[1]
print(len(m.modes), peak, motion_bytes(lk, theta.size, sk.family("4R").max_modes))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    modes, peak, estimate = (float(v) for v in out.stdout.split())
    assert modes == 2
    assert peak < estimate < 4 * peak, (peak, estimate)
    # at that rate 10⁶ samples of the 4R need under 10 GB: accepted under a 12 GiB limit
    assert estimate * 50 < 10e9
