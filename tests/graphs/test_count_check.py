"""The count check (kinematics/modes/starts.py with algebraic/trace_test.py) on the 3-RPS,
whose 16 start solutions monodromy finds without a known count:

- the trace test shows the 16 complete (the direct kinematics count of the general 3-RPS,
  Schadlbauer, Walter & Husty, "The 3-RPS parallel manipulator from an algebraic viewpoint",
  Mech. Mach. Theory 75, 2014: found here without being told it);
- a set with one solution left out fails the test, and the check's further monodromy loops
  find the missing one, then pass;
- the verdict is kept in the store and read back, so a topology is checked once (a file
  written before the check existed reads as not checked);
- ``screwkit analyze --check-count`` reports it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.algebraic.solve import LOWER_BOUND, StartSolutions
from screwkit.cli.main import app
from screwkit.kinematics.modes import start_store, starts
from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation

SPEC = Path(__file__).resolve().parents[2] / "examples" / "mechanisms" / "three_rps.toml"


@pytest.fixture(scope="module")
def three_rps():
    return spatial_point_formulation(sk.load_spec(SPEC).mechanism)


def _same_sets(a: np.ndarray, b: np.ndarray) -> bool:
    gaps = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    return len(a) == len(b) and bool((gaps.min(axis=0) < 1e-8).all()
                                     and (gaps.min(axis=1) < 1e-8).all())


def test_the_3rps_sixteen_are_shown_complete_and_the_verdict_is_kept(store, three_rps):
    system = three_rps.system
    unchecked = three_rps.start()
    assert unchecked.generic_count == 16 and unchecked.lower_bound
    assert unchecked.count_check == ""
    starts.forget()
    with starts.count_check():
        found = three_rps.start()
    assert found.count_check == "complete" and not found.lower_bound
    assert found.generic_count == 16 and _same_sets(found.x, unchecked.x)
    assert "trace test: complete" in found.how_found and LOWER_BOUND not in found.how_found
    # kept: a forgetful process reads the verdict back and tracks nothing to check again
    starts.forget()
    before = starts.first_solve_paths()
    with starts.count_check():
        again = three_rps.start()
    assert starts.first_solve_paths() == before
    assert (again.count_check, again.how_found) == (found.count_check, found.how_found)
    # a file written before the check existed (no count_check in it) reads as not checked
    path = start_store.store_path(starts.system_key(system))
    with np.load(path) as f:
        old = {k: f[k] for k in f.files if k != "count_check"}
    np.savez(path, **old)
    loaded = start_store.load(starts.system_key(system), system)
    assert loaded is not None and loaded.count_check == ""


def test_a_set_one_short_fails_and_the_check_finds_the_missing_one(store, three_rps):
    full = three_rps.start()
    short = StartSolutions(full.p, full.x[1:], 15, full.how_found, full.paths)
    assert short.lower_bound
    checked = starts.checked(three_rps.system, short)
    assert checked.count_check == "complete" and checked.generic_count == 16
    assert _same_sets(checked.x, full.x)
    # the first test failed, then monodromy ran again, then the second passed
    assert "trace test: complete" in checked.how_found
    assert checked.how_found.count("monodromy:") == short.how_found.count("monodromy:") + 1


def test_analyze_check_count_reports_the_trace_test(store):
    result = CliRunner().invoke(app, ["analyze", str(SPEC), "--check-count", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    notes = " ".join(str(n) for n in _notes(doc))
    assert "trace test: complete" in notes and LOWER_BOUND not in notes


def _notes(doc: object) -> list:
    """Every string under a "notes" key of the JSON document."""
    found: list = []
    if isinstance(doc, dict):
        for key, value in doc.items():
            if key == "notes" and isinstance(value, list):
                found.extend(value)
            else:
                found.extend(_notes(value))
    elif isinstance(doc, list):
        for value in doc:
            found.extend(_notes(value))
    return found


def test_incomplete_with_nothing_new_to_find_is_inconclusive(store, three_rps, monkeypatch):
    """When the test says incomplete but further monodromy loops find nothing new, the check
    does not claim a missing solution (the point the test misses may be one of its own slice
    witnesses): the verdict is inconclusive and the count stays a lower bound."""
    from dataclasses import replace

    full = three_rps.start()
    real = starts.trace_test

    def always_incomplete(system, p0, x0, options=None):
        return replace(real(system, p0, x0, options), verdict="incomplete",
                       reason="the traces are not on a line (forced)")

    monkeypatch.setattr(starts, "trace_test", always_incomplete)
    checked = starts.checked(three_rps.system, full)
    assert checked.count_check == "inconclusive" and checked.lower_bound
    assert checked.generic_count == 16 and _same_sets(checked.x, full.x)
    assert "found no further solution" in checked.how_found
