"""A :class:`~screwkit.balancing.result.BalanceResult` as a column table: one row per input
sample with every per-sample load before and after the balancing (``BalanceResult.table()``;
``screwkit balance --csv``), like Rahman 1996's Tables 5.2–5.7.

Columns: ``input`` (rad for a crank, m for a slide), then ``<load>_before`` and
``<load>_after`` for ``G`` (the objective per sample, non-dimensional), ``shaking_force`` (N),
``shaking_moment`` (N·m), ``bearing_force`` (N), ``bearing_moment`` (N·m) and ``input_torque``
(N·m; N for a driven slide) — magnitudes as in :data:`~screwkit.balancing.result.SAMPLE_LOADS`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from screwkit.tables import Column, ResultTable

if TYPE_CHECKING:
    from screwkit.balancing.result import BalanceResult

#: quantity kind of each per-sample load
LOAD_KINDS = {"G": "ratio", "shaking_force": "force", "shaking_moment": "moment",
              "bearing_force": "force", "bearing_moment": "moment", "input_torque": "moment"}


def balance_table(result: BalanceResult) -> ResultTable:
    """The per-sample loads before and after (module docstring)."""
    from screwkit.balancing.result import SAMPLE_LOADS

    driven = result.dynamics_before.input_names[0]
    slide = driven.rsplit(".", 1)[-1] == "s"
    cols = [Column("input", "length" if slide else "angle", result.inputs)]
    for key, _, _ in SAMPLE_LOADS:
        kind = "force" if (key == "input_torque" and slide) else LOAD_KINDS[key]
        cols.append(Column(f"{key}_before", kind, result.per_sample_before[key]))
        cols.append(Column(f"{key}_after", kind, result.per_sample_after[key]))
    return ResultTable(tuple(cols), "balancing: loads per input sample, before and after")
