"""Start solutions kept on disk per topology (kinematics/modes/start_store.py, starts.py): a
process that has forgotten them reads them back without tracking a path, equal to what was
written; a file is written whole (no temporary file is left) and is trusted only when its key
matches and every point solves the start system again (a moved point, another key, a damaged
file, or fewer solutions than a known generic count are refused and solved anew);
``SCREWKIT_CACHE_DIR=off`` writes nothing; the folder follows the environment; a multi-homogeneous start with a failed path is
not trusted to be complete and the total-degree homotopy solves it; a total-degree start short
of a known generic count is found by monodromy instead."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.io.toml_file import read_toml
from screwkit.kinematics.modes import start_store, starts
from screwkit.kinematics.modes.planar import planar_formulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


@pytest.fixture(scope="module")
def sixbar():
    path = EXAMPLES / "stephenson3_sixbar.toml"
    return planar_formulation(graph_spec_from_data(read_toml(path), path).mechanism)


def _solve(form):
    return starts.start_solutions(form.system, grouping=form.grouping)


def test_a_forgetful_process_reads_them_back_without_tracking_a_path(store, sixbar):
    before = starts.first_solve_paths()
    first = _solve(sixbar)
    assert starts.first_solve_paths() - before == 6  # the multi-homogeneous paths, not 16
    assert first.how_found.startswith("multi-homogeneous") and first.generic_count == 6
    files = list(store.iterdir())
    assert [f.name for f in files] == [f"{starts.system_key(sixbar.system)[:40]}.npz"]
    starts.forget()
    again = _solve(sixbar)
    assert starts.first_solve_paths() - before == 6  # nothing tracked the second time
    assert again is not first
    np.testing.assert_array_equal(again.x, first.x)
    np.testing.assert_array_equal(again.p, first.p)
    assert (again.generic_count, again.how_found) == (first.generic_count, first.how_found)


@pytest.mark.parametrize("damage", ["moved point", "other key", "missing solution", "bytes"])
def test_a_file_that_fails_its_checks_is_solved_anew(store, sixbar, damage):
    good = _solve(sixbar)
    key = starts.system_key(sixbar.system)
    path = start_store.store_path(key)
    assert start_store.load(key, sixbar.system) is not None
    if damage == "moved point":
        x = good.x.copy()
        x[3, 1] += 1e-6
        start_store.save(key, replace(good, x=x))
    elif damage == "missing solution":
        start_store.save(key, replace(good, x=good.x[:-1], generic_count=5))
        assert start_store.load(key, sixbar.system, expected=6) is None
        assert start_store.load(key, sixbar.system) is not None  # a known count finds it
        path.unlink()
    elif damage == "other key":
        other = "f" * 64
        start_store.save(other, good)
        start_store.store_path(other).replace(path)
    else:
        path.write_bytes(path.read_bytes()[:100])
    assert start_store.load(key, sixbar.system) is None
    starts.forget()
    before = starts.first_solve_paths()
    fresh = _solve(sixbar)
    assert starts.first_solve_paths() - before == 6
    assert start_store.load(key, sixbar.system) is not None  # replaced by a good one
    assert fresh.generic_count == 6


def test_the_file_is_written_whole_and_the_cache_can_be_off(store, sixbar, monkeypatch):
    _solve(sixbar)
    assert sorted(p.name for p in store.iterdir() if p.name.startswith(".")) == []
    monkeypatch.setenv(start_store.CACHE_ENV, "off")
    assert start_store.cache_dir() is None
    starts.forget()
    assert start_store.save("k" * 64, _solve(sixbar)) is None


def test_the_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv(start_store.CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    if start_store.sys.platform.startswith("linux"):
        assert start_store.cache_dir() == tmp_path / "screwkit" / "starts"
    monkeypatch.setenv(start_store.CACHE_ENV, str(tmp_path / "mine"))
    assert start_store.cache_dir() == tmp_path / "mine" / "starts"


def test_a_multi_homogeneous_start_with_a_failed_path_falls_back_to_total_degree(
        store, sixbar, monkeypatch):
    from screwkit.algebraic.track import PathStatus

    real = starts.solve_multi_homogeneous

    def one_failed(*args, **kwargs):
        solved = real(*args, **kwargs)
        status = solved.result.status.copy()
        status[0] = PathStatus.FAILED
        return replace(solved, result=replace(solved.result, status=status))

    monkeypatch.setattr(starts, "solve_multi_homogeneous", one_failed)
    before = starts.first_solve_paths()
    found = _solve(sixbar)
    assert starts.first_solve_paths() - before == 6 + 16  # both homotopies' paths
    assert found.how_found.startswith("total-degree") and found.generic_count == 6


def test_a_total_degree_start_short_of_a_known_count_is_found_by_monodromy(store, monkeypatch):
    # a CCRR loop's quadrics (Bézout number 64: the total-degree homotopy first), one of its
    # 8 total-degree solutions dropped as if its path had failed: monodromy from a random
    # closing instance finds the 8 instead
    from screwkit.algebraic.solve import StartSolutions
    from screwkit.kinematics.modes.rpc_quadrics import random_rpc, rpc_system

    real = starts._by_total_degree

    def one_lost(system, seed):
        found = real(system, seed)
        return StartSolutions(found.p, found.x[1:], found.generic_count - 1, found.how_found,
                              found.paths)

    monkeypatch.setattr(starts, "_by_total_degree", one_lost)
    found = starts.start_solutions(rpc_system("CCRR"), lambda r: random_rpc("CCRR", r, 1), 8)
    assert found.how_found.startswith("monodromy") and found.generic_count == 8
    assert len(found.x) == 8
