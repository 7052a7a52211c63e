"""Global synthesis: ``synthesize --starts N`` runs the multistart's starts on the sweep engine
and gives the serial run's results for the same seed (every field but the wall time)."""

from __future__ import annotations

import json

from sweep_helpers import EXAMPLES, runner

from screwkit.cli.main import app
from screwkit.io.documents import result_document
from screwkit.io.spec import load_spec
from screwkit.pipeline import Pipeline
from screwkit.sweep.engine import EngineConfig, start_engine
from screwkit.sweep.multistart import distributed_multistart
from screwkit.synthesis.solve import synthesize_multistart

SPEC = EXAMPLES / "bagci_example2_synthesis.toml"


def _without_time(doc: dict) -> dict:
    return {k: v for k, v in doc.items() if k not in ("time", "alternatives", "spec")}


def test_distributed_multistart_equals_the_serial_one():
    problem = load_spec(SPEC).synthesis.problem
    serial = synthesize_multistart(problem, n_starts=4, seed=11, keep=3)
    with start_engine(EngineConfig(workers=0)) as engine:
        spread = distributed_multistart(problem, engine, n_starts=4, seed=11, keep=3, spread=0.5)
    assert len(serial) == len(spread) >= 1
    for a, b in zip(serial, spread, strict=True):
        assert _without_time(result_document(a)) == _without_time(result_document(b))


def test_synthesize_starts_on_the_embedded_cluster_equals_the_serial_run():
    r = runner.invoke(app, ["synthesize", str(SPEC), "--starts", "4", "--workers", "2", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    serial = Pipeline(load_spec(SPEC)).synthesize(4).results  # the serial run
    docs = [doc, *doc["alternatives"]]
    assert len(docs) == len(serial)
    for got, want in zip(docs, serial, strict=True):
        want_doc = json.loads(json.dumps(result_document(want), default=float))
        got = {k: v for k, v in got.items() if k != "method"}
        assert _without_time(got) == _without_time(want_doc)
