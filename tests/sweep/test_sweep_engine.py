"""The same sweep in this process, on the embedded Dask cluster and on a real ``dask
scheduler`` with two ``dask worker`` processes (started here on 127.0.0.1, random free ports,
and stopped): byte-identical tables whatever the number of workers and the batching; a
scheduler that does not answer is a clear error."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from sweep_helpers import EXAMPLES, real_dask

from screwkit.sweep import EngineConfig, EngineError, define_sweep, run_sweep
from screwkit.sweep.engine import start_engine

SPEC = EXAMPLES / "rsrc_fig7_dynamics.toml"
VARY = ["d2=4.2:4.8:3", "e=0.5:1.5:3", "links.output.mass=0.6kg,0.8kg"]  # 18 designs


def _run(tmp_path: Path, name: str, config: EngineConfig, batch: int | None = None) -> bytes:
    definition = define_sweep(SPEC, VARY, "dynamics")
    out = tmp_path / name
    result = run_sweep(definition, out, config, batch=batch)
    assert result.failed == 0 and result.errors == 0 and result.computed == 18
    return out.read_bytes()


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> bytes:
    return _run(tmp_path_factory.mktemp("ref"), "ref.parquet", EngineConfig(workers=0), batch=18)


def test_embedded_cluster_gives_the_same_table(tmp_path, reference):
    t0 = time.perf_counter()
    assert _run(tmp_path, "embedded.parquet", EngineConfig(workers=2), batch=2) == reference
    assert time.perf_counter() - t0 < 120


def test_real_scheduler_and_two_workers_give_the_same_table(tmp_path, reference):
    with real_dask(tmp_path, workers=2) as address:
        assert address.startswith("tcp://127.0.0.1:")
        with start_engine(EngineConfig(scheduler=address)) as engine:
            engine.client.wait_for_workers(2, timeout=90)
            assert engine.workers == 2
        t0 = time.perf_counter()
        table = _run(tmp_path, "cluster.parquet", EngineConfig(scheduler=address), batch=3)
        assert table == reference
        assert time.perf_counter() - t0 < 120
        # the scheduler from the environment, as docs/sweeps.md says
        os.environ["SCREWKIT_SCHEDULER"] = address
        try:
            assert _run(tmp_path, "env.parquet", EngineConfig(), batch=5) == reference
        finally:
            del os.environ["SCREWKIT_SCHEDULER"]


def test_a_scheduler_that_does_not_answer_is_a_clear_error():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # nothing listens there once closed
    with pytest.raises(EngineError, match="cannot reach the Dask scheduler"), \
            start_engine(EngineConfig(scheduler=f"tcp://127.0.0.1:{port}", connect_timeout=2)):
        pass


def test_csv_and_parquet_hold_the_same_rows(tmp_path):
    from screwkit.sweep.table import read_table

    definition = define_sweep(SPEC, ["d2=4.2,4.8"], "dynamics")
    run_sweep(definition, tmp_path / "t.parquet", EngineConfig(workers=0))
    run_sweep(definition, tmp_path / "t.csv", EngineConfig(workers=0))
    a, b = read_table(tmp_path / "t.parquet"), read_table(tmp_path / "t.csv")
    assert a == b  # numbers written exactly (shortest round-trip repr)
