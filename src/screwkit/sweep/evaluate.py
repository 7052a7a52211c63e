"""One design, and a batch of designs, evaluated where the engine runs them (a Dask worker or
this process): replace the values, validate the spec as ``load_spec`` does, run the job through
a :class:`~screwkit.pipeline.Pipeline`, and summarise it into one row.

A design that cannot be built or analysed is a row with ``status`` ``"failed"`` and the reason
the single-spec command would have printed; an unexpected exception (a bug) is a row with
``status`` ``"error"`` naming it, so one bad design never stops a sweep. Numerical overflow and
invalid operations raise here as in the commands (:func:`screwkit.cli.common.guard`), so a row
never holds a number the single-spec command would have refused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.io.mechanism_spec import is_graph_spec
from screwkit.io.spec import spec_from_data
from screwkit.pipeline import Pipeline
from screwkit.sweep.jobs import JOB_ROWS, JobOptions, Row, assembly_columns
from screwkit.sweep.keys import SpecKey, with_values

STATUS_OK, STATUS_FAILED, STATUS_ERROR = "ok", "failed", "error"


@dataclass(frozen=True)
class SweepTask:
    """What every batch of a sweep shares: the spec's TOML tables and its path, the keys that
    vary, the job and its options. Small and picklable (it travels to the workers once)."""

    data: dict[str, Any]
    path: str
    keys: tuple[SpecKey, ...]
    job: str
    options: JobOptions
    #: start solutions by topology key, found on the scheduler's side (sweep/modes_job.py)
    starts: dict[str, Any] = field(default_factory=dict)


def numeric_failure(exc: FloatingPointError) -> str:
    return (f"the computation failed numerically ({exc}); the design's values are probably "
            "outside the range it can handle")


def evaluate_design(task: SweepTask, values: np.ndarray) -> Row:
    """The row of one design (``values`` in the keys' units) without its index and varied
    values: status, reason, where it assembles, and the job's columns."""
    overrides = [(k.path, k.toml_value(v)) for k, v in zip(task.keys, values, strict=True)]
    row: Row = {"status": STATUS_OK, "reason": None}
    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"):
            if is_graph_spec(task.data):  # a mechanism graph, re-drawn (sweep/graph_jobs.py)
                from screwkit.io.mechanism_spec import graph_spec_from_data
                from screwkit.sweep.graph_jobs import graph_row

                graph = graph_spec_from_data(with_values(task.data, overrides), task.path)
                try:
                    row.update(graph_row(graph, task.job, task.options))
                except ValueError:
                    row.update({"modes": 0, "assembles": False, "assembling_samples": 0,
                                "where": "nowhere"})
                    raise
                return row
            spec = spec_from_data(with_values(task.data, overrides), task.path)
            pipe = Pipeline(spec, method=task.options.method)
            try:
                row.update(assembly_columns(pipe))
            except ValueError:
                row.update({"modes": 0, "assembles": False, "assembling_samples": 0,
                            "where": "nowhere"})
                raise
            row.update(JOB_ROWS[task.job](pipe, task.options))
    except FloatingPointError as exc:
        row.update(status=STATUS_FAILED, reason=numeric_failure(exc))
    except (ValueError, OSError) as exc:  # every user error of screwkit is a ValueError
        row.update(status=STATUS_FAILED, reason=str(exc))
    except Exception as exc:  # a bug: keep the sweep going, name it in the row
        row.update(status=STATUS_ERROR, reason=f"internal error {type(exc).__name__}: {exc}")
    return row


def evaluate_batch(task: SweepTask, indices: np.ndarray, values: np.ndarray) -> list[Row]:
    """The rows of a batch of designs (``indices`` their numbers, ``values`` (n, k)), each with
    its design number first; what one engine task computes. Start solutions shipped with
    the task are kept in this process first (sweep/modes_job.py)."""
    if task.starts:
        from screwkit.kinematics.modes.starts import install

        install(task.starts)
    rows = []
    for i, v in zip(indices.tolist(), values, strict=True):
        row: Row = {"design": int(i)}
        row.update({k.column: (int(x) if k.kind == "integer" else float(x))
                    for k, x in zip(task.keys, v, strict=True)})
        row.update(evaluate_design(task, v))
        rows.append(row)
    return rows
