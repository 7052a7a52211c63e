"""Result tables written to files: the format by the file's extension (``.json``, ``.csv``,
``.parquet``, ``.npz``), each written atomically like every output (:mod:`screwkit.io.outputs`);
and the tables of the jobs whose results are not a ``Motion``, ``Dynamics`` or
``BalanceResult`` (those have ``.table()``): the synthesis rows and the limit positions.

Tables carry their units in every column header, in the display units chosen
(:mod:`screwkit.io.display_units`: the spec's ``[units]`` by default); JSON documents stay SI.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.outputs import atomic_path
from screwkit.tables import Column, ResultTable, UnitChoice

#: file extension -> format
FORMATS = {".json": "json", ".csv": "csv", ".parquet": "parquet", ".npz": "npz"}
TABLE_FORMATS = ("csv", "parquet", "npz")


class OutputFormatError(InputError):
    """An output whose extension names no format the command writes."""


def output_format(path: str | Path, option: str = "-o",
                  allowed: Iterable[str] = ("json", *TABLE_FORMATS)) -> str:
    """The format of an output file from its extension (a name without one is JSON, as
    before); :class:`OutputFormatError` for an extension the command does not write."""
    allowed = tuple(allowed)
    suffix = Path(path).suffix.lower()
    fmt = "json" if suffix == "" else FORMATS.get(suffix)
    if fmt is None or fmt not in allowed:
        names = ", ".join(f".{f}" for f in allowed)
        what = f"unknown format {suffix!r}" if fmt is None else f"this command writes no {fmt} table"
        raise OutputFormatError(f"{option} {path}: {what}; give a file name ending in {names}")
    return fmt


def write_table(table: ResultTable, path: str | Path, fmt: str, units: UnitChoice | None = None,
                inputs: Iterable[str | Path] = (), option: str | None = None) -> int:
    """Write ``table`` as ``fmt`` (``csv``, ``parquet``, ``npz``) atomically; returns the
    bytes written."""
    with atomic_path(path, inputs, option) as tmp:
        if fmt == "csv":
            table.to_csv(tmp, units)
        elif fmt == "parquet":
            table.to_parquet(tmp, units)
        elif fmt == "npz":
            with open(tmp, "wb") as fh:
                table.to_npz(fh, units)
        else:
            raise OutputFormatError(f"{option or path}: {fmt!r} is not a table format")
        size = os.path.getsize(tmp)
    return size


def synthesis_table(doc: dict[str, Any]) -> ResultTable:
    """The design points of a synthesis document's best result (Bagci's Tables I–XII): θ from
    θ01, θ0, φ_g, ψ_g0, ψ_d0, their difference, S, S_g, S_d and their difference (SI)."""
    rows = sorted(doc["rows"], key=lambda r: r["theta"])

    def col(key: str) -> np.ndarray:
        return np.array([np.nan if r[key] is None else r[key] for r in rows], dtype=float)

    psi_d, psi_g, s_d, s_g = col("psi_d0"), col("psi_g0"), col("S_d"), col("S_g")
    cols = [Column("theta", "angle", col("theta")), Column("theta0", "angle", col("theta0")),
            Column("phi_g", "angle", col("phi_g")), Column("psi_g0", "angle", psi_g),
            Column("psi_d0", "angle", psi_d), Column("psi_d0_minus_psi_g0", "angle", psi_d - psi_g),
            Column("S", "length", col("S")), Column("S_g", "length", s_g),
            Column("S_d", "length", s_d), Column("S_d_minus_S_g", "length", s_d - s_g)]
    return ResultTable(tuple(cols), "synthesis: desired vs generated at the design points")


def limits_table(doc: dict[str, Any]) -> ResultTable:
    """The limit positions of a ``screwkit limits`` document, one row each (SI): the output, its
    kind, the mode (generic route) or branch (closed route; -1 where not given), the input, the
    value (``value`` for a rotation, ``value_length`` for a translation), the second derivative,
    the dwell order (-1: not computed, a closed-form translation limit) and the seed's variables
    there (RSRC θ0, φ0, χ0, S) when every limit has them."""
    from screwkit.kinematics.motion_table import variable_kind

    lims = doc["limits"]

    def col(key: str, keep: Any = None) -> np.ndarray:
        return np.array([np.nan if r.get(key) is None or (keep and not keep(r)) else r[key]
                         for r in lims], dtype=float)

    def index(key: str) -> np.ndarray:
        return np.array([-1 if r.get(key) is None else r[key] for r in lims], dtype=np.int64)

    def rotation(r: dict[str, Any]) -> bool:
        return bool(r["kind"] == "rotation")

    cols = [Column("output", "text", np.array([r["output"] for r in lims], dtype=str)),
            Column("kind", "text", np.array([r["kind"] for r in lims], dtype=str)),
            Column("mode", "index", index("mode")), Column("branch", "index", index("branch")),
            Column("input", doc.get("input_kind") or variable_kind(doc.get("input_name",
                                                                          "theta0")),
                   col("input")),
            Column("value", "angle", col("value", rotation)),
            Column("value_length", "length", col("value", lambda r: not rotation(r))),
            # d²y/dx² per rad² of the input: a rotation's is a plain number (rad/rad²), a
            # translation's a length per rad², in the display length unit
            Column("second_derivative", "ratio", col("second_derivative", rotation)),
            Column("second_derivative_length_per_rad2", "length",
                   col("second_derivative", lambda r: not rotation(r))),
            Column("dwell_order", "index", index("dwell_order"))]
    cols += [Column(n, variable_kind(n), col(n)) for n in ("theta0", "phi0", "chi0", "S")
             if lims and all(n in r for r in lims)]
    return ResultTable(tuple(cols), "limit positions (dwell_order -1: not computed)")
