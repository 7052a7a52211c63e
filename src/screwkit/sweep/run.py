"""A design sweep from start to table: read the spec, make the designs, run the job on every
design in batches on the engine (checkpointing each finished batch), and write the table in
design order (docs/sweeps.md)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from screwkit import __version__
from screwkit.io.errors import SpecError
from screwkit.io.spec import Spec, spec_from_data
from screwkit.io.toml_file import SpecFileError, read_toml
from screwkit.kinematics.registry import require
from screwkit.sweep.checkpoint import Checkpoint, check_resume_flags, fingerprint
from screwkit.sweep.designs import DesignSet, make_designs
from screwkit.sweep.engine import (
    EngineConfig,
    EngineError,
    batch_size,
    batches,
    start_engine,
)
from screwkit.sweep.evaluate import STATUS_ERROR, STATUS_FAILED, SweepTask, evaluate_batch
from screwkit.sweep.jobs import JobOptions, Row, check_job
from screwkit.sweep.table import write_table

#: progress(designs done, designs in all, designs computed by this run)
Progress = Callable[[int, int, int], None]


def read_spec_tables(path: Path) -> tuple[dict[str, Any], Spec]:
    """The spec file's TOML tables and the nominal :class:`Spec` (read as ``load_spec``)."""
    try:
        data = read_toml(path)
    except SpecFileError as exc:
        raise SpecError(str(exc)) from None
    from screwkit.io.mechanism_spec import graph_spec_from_data, is_graph_spec

    if is_graph_spec(data):
        return data, graph_spec_from_data(data, path)  # type: ignore[return-value]
    return data, spec_from_data(data, path)


@dataclass(frozen=True)
class SweepDefinition:
    """A sweep before it runs: the spec (its tables and nominal :class:`Spec`), the designs,
    the job and its options."""

    spec_path: Path
    data: dict[str, Any]
    spec: Spec
    designs: DesignSet
    job: str
    options: JobOptions

    def fingerprint(self) -> str:
        return fingerprint(self.data, self.designs.fingerprint(), self.job,
                           self.options.as_dict())

    def metadata(self) -> dict[str, Any]:
        """The sweep's description (stored with a Parquet table, shown on plots)."""
        return {"spec": str(self.spec_path), "mechanism": self.spec.name, "job": self.job,
                "options": self.options.as_dict(), "sampling": self.designs.sampling,
                "designs": len(self.designs),
                "keys": [{"key": k.text, "unit": k.unit, "column": k.column}
                         for k in self.designs.keys],
                "screwkit": __version__}

    def task(self) -> SweepTask:
        """What every batch shares; for the ``modes`` job with the topology's start solutions,
        found here once (sweep/modes_job.py) and shipped to the workers with the task."""
        starts: dict[str, Any] = {}
        if self.job == "modes":
            from screwkit.sweep.modes_job import sweep_starts

            starts = sweep_starts(self.spec)
        return SweepTask(self.data, str(self.spec_path), self.designs.keys, self.job,
                         self.options, starts)


def check_job_on_spec(spec: Spec, job: str) -> None:
    """Refuse, before any design runs, a job the spec cannot have (every row would fail)."""
    if getattr(spec, "family", None) == "graph":  # io.mechanism_spec.GraphSpec
        from screwkit.sweep.graph_jobs import check_graph_job

        check_graph_job(spec, job)
        return
    check_job(job)
    require(spec.linkage, job)
    if job == "dynamics" and any(link.mass is None for link in spec.linkage.links):
        raise SpecError(f"{spec.path}: --job dynamics needs mass properties for every link "
                        "([links.<name>] tables; docs/spec-format.md)")
    if job == "balance" and spec.balancing is None:
        raise SpecError(f"{spec.path}: --job balance needs a [balancing] table "
                        "(docs/balancing.md)")
    if job == "synthesize" and spec.synthesis is None:
        raise SpecError(f"{spec.path}: --job synthesize needs a [synthesis] table "
                        "(docs/synthesis.md)")


def define_sweep(spec_path: Path, vary: list[str], job: str, *, sample: str | None = None,
                 seed: int = 0, options: JobOptions | None = None) -> SweepDefinition:
    """Read the spec and make the designs (errors name the option and the fix)."""
    data, spec = read_spec_tables(spec_path)
    check_job_on_spec(spec, job)
    designs = make_designs(data, spec, vary, sample, seed)
    return SweepDefinition(spec_path, data, spec, designs, job, options or JobOptions())


@dataclass(frozen=True)
class SweepResult:
    """What a sweep did: its rows (design order), how many were computed now or resumed from a
    checkpoint, how many failed or hit an internal error, the time, the engine, and one
    sentence per fault recovered from or checkpoint discarded (``notes``)."""

    rows: list[Row]
    computed: int
    resumed: int
    seconds: float
    engine: str
    notes: tuple[str, ...] = ()

    @property
    def failed(self) -> int:
        return sum(1 for r in self.rows if r["status"] == STATUS_FAILED)

    @property
    def errors(self) -> int:
        return sum(1 for r in self.rows if r["status"] == STATUS_ERROR)


@dataclass(frozen=True)
class ComputedRows:
    """:func:`compute_rows`' answer: the rows in design order, how many were computed now and
    resumed, the engine's description and the notes (:class:`SweepResult`)."""

    rows: list[Row]
    computed: int
    resumed: int
    engine: str
    notes: tuple[str, ...]


def compute_rows(definition: SweepDefinition, engine_config: EngineConfig, *,
                 checkpoint: Checkpoint | None = None, resume: bool = False,
                 fresh: bool = False, batch: int | None = None,
                 progress: Progress | None = None) -> ComputedRows:
    """Every design's row in design order. An earlier run's checkpoint is continued with
    ``resume``, discarded with ``fresh``, and otherwise refused (``CheckpointError``) rather
    than silently lost."""
    n = len(definition.designs)
    done: dict[int, Row] = {}
    notes: list[str] = []
    if checkpoint is not None:
        check_resume_flags(resume, fresh)
        done = checkpoint.resume() if resume else {}
        discarded = checkpoint.start(resume, fresh)
        if discarded:
            notes.append(f"--fresh: discarded the {discarded} finished design(s) of an earlier "
                         f"run kept in {checkpoint.folder}")
    resumed = len(done)
    todo = [i for i in range(n) if i not in done]
    values = definition.designs.values
    if progress is not None:
        progress(len(done), n, 0)
    with start_engine(engine_config) as engine:
        size = batch_size(len(todo), engine.workers, batch)
        payloads = [(np.array(b, dtype=np.int64), values[b]) for b in batches(todo, size)]

        def finished(_: int, rows: list[Row]) -> None:
            if checkpoint is not None:
                checkpoint.save(rows)
            done.update((int(r["design"]), r) for r in rows)
            if progress is not None:
                progress(len(done), n, len(done) - resumed)

        try:
            engine.map(evaluate_batch, definition.task(), payloads, finished)
        except EngineError as exc:
            if checkpoint is None:
                raise
            raise EngineError(f"{exc}; the finished designs are kept in {checkpoint.folder} — "
                              "run the same command with --resume to continue") from None
        notes.extend(engine.notes("design"))
        description = engine.description
    return ComputedRows([done[i] for i in range(n)], n - resumed, resumed, description,
                        tuple(notes))


def run_sweep(definition: SweepDefinition, output: Path, engine_config: EngineConfig, *,
              resume: bool = False, fresh: bool = False, batch: int | None = None,
              progress: Progress | None = None) -> SweepResult:
    """Run the sweep and write its table to ``output`` (atomically, rows in design order);
    finished batches are checkpointed next to ``output`` until then. The checkpoint of an
    earlier run is continued with ``resume``, discarded with ``fresh`` and otherwise refused
    (docs/sweeps.md, "Resume")."""
    t0 = time.perf_counter()
    checkpoint = Checkpoint(output, definition.fingerprint())
    done = compute_rows(definition, engine_config, checkpoint=checkpoint, resume=resume,
                        fresh=fresh, batch=batch, progress=progress)
    write_table(output, done.rows, definition.metadata(), [definition.spec_path])
    checkpoint.discard()
    return SweepResult(done.rows, done.computed, done.resumed, time.perf_counter() - t0,
                       done.engine, done.notes)
