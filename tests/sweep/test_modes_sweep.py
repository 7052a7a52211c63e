"""The ``modes`` job of a graph sweep (sweep/modes_job.py; issue 27): on a real ``dask
scheduler`` with two ``dask worker`` processes that have no store of start solutions, every
design tracks exactly the generic count of paths per input row and none to find start
solutions (they are shipped from the scheduler's side), the table equals the in-process one,
and each count equals a direct ``every_mode`` call and, at the drawing, the real solutions of an
independent total-degree solve that close; without shipping, a process solves them once, for
its first design only; a graph without a polynomial formulation is refused before any run."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from sweep_helpers import EXAMPLES, real_dask, runner, toml_text

from screwkit.algebraic.total_degree import solve_total_degree
from screwkit.cli.main import app
from screwkit.errors import CapabilityError
from screwkit.io.mechanism_spec import graph_spec_from_data
from screwkit.io.toml_file import read_toml
from screwkit.kinematics.graph.closure import graph_forward
from screwkit.kinematics.modes import start_store, starts
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.sweep import EngineConfig, define_sweep, run_sweep
from screwkit.sweep.evaluate import evaluate_batch
from screwkit.sweep.keys import with_values
from screwkit.sweep.table import read_table

SIXBAR = EXAMPLES / "mechanisms" / "stephenson3_sixbar.toml"
VARY = ["joints.Q2.at[0]=70:90:2", "joints.c.at[1]=65:80:2"]  # 4 designs; 2 to 6 modes
ROWS = 7  # the crank at 0, 60, …, 360 degrees


@pytest.fixture(scope="module")
def spec(tmp_path_factory) -> Path:
    data = read_toml(SIXBAR)
    data["motion"]["step"] = 60.0
    path = tmp_path_factory.mktemp("modes") / "sixbar.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    return path


def _design(definition, i):
    values = [(k.path, v) for k, v in zip(definition.designs.keys,
                                          [v for _, v in definition.designs.overrides(i)],
                                          strict=True)]
    return graph_spec_from_data(with_values(definition.data, values), definition.spec_path)


def _total_degree_modes(design) -> int:
    """Real solutions at the drawing by the total-degree homotopy (its own start system, no
    stored start solutions) that close the mechanism's loops."""
    form = closure_formulation(design.mechanism)
    X = np.zeros((1, design.inputs.shape[1]))
    result = solve_total_degree(form.system, form.parameters(X)[0].astype(complex))
    x = result.x[result.regular]
    x = x[np.abs(x.imag).max(axis=1) < 1e-8].real
    if len(x) == 0:
        return 0
    conf, lay = form.configuration(x, X[0])
    residual = np.abs(graph_forward(design.mechanism, lay, conf).residual).max(axis=(1, 2))
    return int((residual < 1e-9 * design.mechanism.length_scale).sum())


def test_workers_track_only_the_generic_count_from_shipped_start_solutions(spec, tmp_path):
    definition = define_sweep(spec, VARY, "modes")
    run_sweep(definition, tmp_path / "here.csv", EngineConfig(workers=0))
    with real_dask(tmp_path, 2, {start_store.CACHE_ENV: "off"}) as address:
        run_sweep(definition, tmp_path / "there.csv", EngineConfig(scheduler=address), batch=1)
    assert (tmp_path / "there.csv").read_bytes() == (tmp_path / "here.csv").read_bytes()
    rows = read_table(tmp_path / "there.csv")
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    for row in rows:
        assert row["generic_count"] == 6
        assert row["paths_tracked"] == 6 * (ROWS + 1)  # the drawing, then each input row
        assert row["start_paths"] == 0  # the workers have no store: shipped, not solved
        design = _design(definition, row["design"])
        direct = every_mode(design.mechanism, np.vstack([np.zeros((1, 1)), design.inputs]))
        counts = [c.size for c in direct.configurations]
        assert row["modes"] == counts[0] == _total_degree_modes(design)
        assert (row["modes.min"], row["modes.max"]) == (min(counts[1:]), max(counts[1:]))
        assert row["modes.complex"] == direct.found[0] == 6
    assert {r["modes.max"] for r in rows} == {2, 4, 6}  # the designs differ


def test_without_shipping_a_process_solves_them_once(spec, monkeypatch):
    definition = define_sweep(spec, VARY, "modes")
    task = definition.task()
    assert len(task.starts) == 1 and next(iter(task.starts.values())).generic_count == 6
    monkeypatch.setenv(start_store.CACHE_ENV, "off")
    index, values = np.arange(4), definition.designs.values
    starts.forget()
    try:
        rows = evaluate_batch(replace(task, starts={}), index, values)
        assert [r["start_paths"] for r in rows] == [6, 0, 0, 0]  # multi-homogeneous: 6 paths
        starts.forget()
        rows = evaluate_batch(task, index, values)
        assert [r["start_paths"] for r in rows] == [0, 0, 0, 0]
    finally:
        starts.forget()


def test_a_graph_without_a_formulation_is_refused_before_any_run(tmp_path):
    # a 3-UPU whose platform U axes are not square: 90 point unknowns, over the limit
    from tests.graphs.three_upu import write_tilted

    tilted = write_tilted(tmp_path / "tilted.toml", (1, 2, 3))
    with pytest.raises(CapabilityError, match="--job modes solves every assembly mode.*90 unknowns"):
        define_sweep(tilted, ["joints.Up1.at.z=299:301:1"], "modes")
    r = runner.invoke(app, ["sweep", str(tilted), "--vary", "joints.Up1.at.z=299:301:1",
                            "--job", "modes", "-o", str(tmp_path / "t.csv"), "--workers", "0"])
    assert r.exit_code == 2 and "--job analyze follows the drawn mode" in " ".join(r.output.split())


def test_a_graph_driven_by_a_body_travel_sweeps_every_mode(tmp_path):
    """The double wishbone driven by its wheel's vertical travel (a body freedom): `--job
    modes` runs on the point formulation of its augmented mechanism (the travel one linear
    equation on the wheel centre): 8 modes of 32 complex at the drawing, for each design.
    (A body driven at its turns goes the same way: tests/graphs/test_point_drives.py; the
    pose-driven Stewart platform's 41 rows cost a design ~15 s, too long for this suite.)"""
    out = tmp_path / "travel.csv"
    r = runner.invoke(app, ["sweep", str(EXAMPLES / "mechanisms" / "double_wishbone_travel.toml"),
                            "--vary", "joints.UB.at.z=465:475:2", "--job", "modes", "-o",
                            str(out), "--workers", "0"])
    assert r.exit_code == 0, r.output
    import pandas as pd

    table = pd.read_csv(out)
    assert list(table["status"]) == ["ok"] * 2
    assert list(table["modes"]) == [8] * 2 and list(table["modes.certified"]) == [8] * 2
    assert list(table["generic_count"]) == [32] * 2


def test_a_spatial_graph_sweeps_every_mode_by_its_point_formulation(tmp_path):
    """The double wishbone (several loops, S joints): `--job modes` runs on the point
    formulation (issue 27), each design's 4 modes certified at all 41 samples."""
    out = tmp_path / "wb.csv"
    r = runner.invoke(app, ["sweep", str(EXAMPLES / "mechanisms" / "double_wishbone.toml"),
                            "--vary", "joints.UB.at.z=465:475:3", "--job", "modes", "-o",
                            str(out), "--workers", "0", "--fresh"])
    assert r.exit_code == 0, r.output
    import pandas as pd

    table = pd.read_csv(out)
    assert list(table["status"]) == ["ok"] * 3
    assert list(table["modes"]) == [4] * 3 and list(table["modes.certified"]) == [4] * 3
    assert list(table["generic_count"]) == [4] * 3 and list(table["assembling_samples"]) == [41] * 3
