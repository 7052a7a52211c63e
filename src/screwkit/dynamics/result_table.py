"""A :class:`~screwkit.dynamics.result.Dynamics` as a column table: one row per input sample
(``Dynamics.table()``; ``screwkit dynamics --csv``).

Columns: ``mode`` (when given), each input (``crank.theta``), ``valid``; the shaking force and
moment ``shaking_force_x|y|z`` (N) and ``shaking_moment_x|y|z`` (N·m, about ``moment_point``);
for every joint its reaction ``<joint>.force_x|y|z`` and ``<joint>.moment_x|y|z`` (on the distal
link by the proximal link, world frame) and the reaction's point of application, the joint
centre, ``<joint>.point_x|y|z`` (m; the moment is about it); every driven freedom's effort
``<freedom>.effort`` (N·m for a rotation, N for a slide); ``residual`` (N). SI values, NaN where
a sample is not valid, as in the JSON document.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from screwkit.tables import Column, ResultTable, vector_columns

if TYPE_CHECKING:
    from screwkit.dynamics.result import Dynamics


def _kind_of_freedom(name: str) -> str:
    return "length" if name.rsplit(".", 1)[-1] == "s" else "angle"


def dynamics_table(dyn: Dynamics, mode: int | None = None) -> ResultTable:
    """The loads of ``dyn`` as a table (module docstring)."""
    n = dyn.valid.shape[0]
    cols: list[Column] = []
    if mode is not None:
        cols.append(Column("mode", "index", np.full(n, mode, dtype=np.int64)))
    for k, name in enumerate(dyn.input_names):
        cols.append(Column(name, _kind_of_freedom(name), dyn.inputs[:, k]))
    cols.append(Column("valid", "flag", np.asarray(dyn.valid, dtype=bool)))
    cols += vector_columns("shaking_force", "force", dyn.shaking_force)
    cols += vector_columns("shaking_moment", "moment", dyn.shaking_moment)
    for joint, r in dyn.reactions.items():
        cols += vector_columns(f"{joint}.force", "force", r.force)
        cols += vector_columns(f"{joint}.moment", "moment", r.moment)
        cols += vector_columns(f"{joint}.point", "length", r.point)
    for name, e in dyn.efforts.items():
        kind = "force" if _kind_of_freedom(name) == "length" else "moment"
        cols.append(Column(f"{name}.effort", kind, e))
    cols.append(Column("residual", "force", dyn.residual))
    mp = ", ".join(f"{v:.6g}" for v in dyn.moment_point)
    gravity = "on" if np.any(dyn.gravity != 0) else "off"
    notes = (f"shaking moment about ({mp}) m (SI)", f"gravity {gravity}")
    return ResultTable(tuple(cols), "inverse dynamics, one row per input sample", notes)
