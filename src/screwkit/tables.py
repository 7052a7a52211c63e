"""Column tables of results: one row per sample (and assembly mode), one column per quantity,
each column with its quantity kind so that it can be shown in any unit.

A :class:`ResultTable` holds SI values (radians, metres, newtons …) and is what
``Motion.table()``, ``Dynamics.table()`` and ``BalanceResult.table()`` return; ``to_csv``,
``to_parquet``, ``to_npz`` and ``to_dataframe`` write it with a unit in every column header
(``phi0 [deg]``, ``shaking_force_x [N]``). Which units: SI unless a ``units`` object is given
(:class:`screwkit.io.display_units.DisplayUnits` gives the spec's ``[units]``; anything with a
``unit_of(kind) -> (label, SI value of one unit)`` method works).

This module needs numpy only (pandas and pyarrow are imported when asked for); every layer may
use it.
"""

from __future__ import annotations

import io
import json
import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import IO, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError, InputTypeError, UnknownNameError

#: the SI unit of every quantity kind a column can have; "flag", "index" and "text" columns
#: have no unit, "ratio" ones are plain numbers and "percent" ones are in %
SI_LABELS: dict[str, str] = {
    "length": "m", "angle": "rad", "time": "s", "mass": "kg", "force": "N", "moment": "N*m",
    "inertia": "kg*m^2", "velocity": "m/s", "acceleration": "m/s^2",
    "angular_velocity": "rad/s", "angular_acceleration": "rad/s^2", "mass_moment": "kg*m",
    "energy": "J",
    "ratio": "", "percent": "%", "flag": "", "index": "", "text": "",
}
#: kinds whose values are never converted
UNITLESS = frozenset({"ratio", "percent", "flag", "index", "text"})


class UnitChoice(Protocol):
    """What a table needs to show a kind of quantity: its unit label and the SI value of one
    such unit (``("deg", pi/180)``)."""

    def unit_of(self, kind: str) -> tuple[str, float]: ...


class SIUnits:
    """SI units for every kind (the default of every writer)."""

    def unit_of(self, kind: str) -> tuple[str, float]:
        return SI_LABELS[kind], 1.0


@dataclass(frozen=True)
class Column:
    """One quantity over the rows: ``name`` (``phi0``, ``shaking_force_x``), its ``kind`` (a key
    of :data:`SI_LABELS`) and its ``values`` (rows,) in SI; NaN where the row has no value (a
    mode that does not assemble)."""

    name: str
    kind: str
    values: NDArray[Any]

    def __post_init__(self) -> None:
        if self.kind not in SI_LABELS:
            raise InputError(f"column {self.name!r}: unknown kind {self.kind!r}; kinds are "
                             f"{', '.join(sorted(SI_LABELS))}")


@dataclass(frozen=True)
class ResultTable:
    """Columns of equal length (see the module docstring); ``title`` says what the rows are."""

    columns: tuple[Column, ...]
    title: str = ""
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        lengths = {c.values.shape[0] for c in self.columns}
        if len(lengths) > 1:
            raise InputError(f"columns of different lengths ({', '.join(map(str, sorted(lengths)))}) in "
                             f"{self.title!r}")
        names = [c.name for c in self.columns]
        if len(set(names)) != len(names):
            raise InputError(f"repeated column names in {self.title!r}")

    @property
    def rows(self) -> int:
        return int(self.columns[0].values.shape[0]) if self.columns else 0

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.columns)

    def __len__(self) -> int:
        return self.rows

    def column(self, name: str) -> Column:
        for c in self.columns:
            if c.name == name:
                return c
        raise UnknownNameError(f"no column {name!r}; the columns are {', '.join(self.names)}")

    def __iter__(self) -> Iterator[Column]:
        return iter(self.columns)

    def where(self, keep: NDArray[np.bool_]) -> ResultTable:
        """The rows where ``keep`` is true."""
        return ResultTable(tuple(Column(c.name, c.kind, c.values[keep]) for c in self.columns),
                           self.title, self.notes)

    def converted(self, units: UnitChoice | None = None
                  ) -> list[tuple[str, str, NDArray[Any]]]:
        """(name, unit label, values in that unit) per column."""
        u = units if units is not None else SIUnits()
        if not callable(getattr(u, "unit_of", None)):
            raise InputTypeError(f"units must be display units (spec.display_units() or "
                                 f"screwkit.tables.SIUnits()); got {type(units).__name__}")
        out = []
        for c in self.columns:
            if c.kind in UNITLESS:
                out.append((c.name, SI_LABELS[c.kind], c.values))
                continue
            label, factor = u.unit_of(c.kind)
            values = np.asarray(c.values, dtype=float)
            out.append((c.name, label, values / factor if factor != 1.0 else values))
        return out

    def headers(self, units: UnitChoice | None = None) -> list[str]:
        """Column headers with their unit: ``phi0 [deg]`` (no brackets without a unit)."""
        return [header(n, label) for n, label, _ in self.converted(units)]

    def unit_labels(self, units: UnitChoice | None = None) -> dict[str, str]:
        return {n: label for n, label, _ in self.converted(units)}

    # --- writers ------------------------------------------------------------------------------
    def to_dataframe(self, units: UnitChoice | None = None) -> Any:
        """A pandas DataFrame (pandas is the ``table`` extra: ``pip install 'screwkit[table]'``),
        headers with units; the units also in ``df.attrs["units"]``."""
        pd = _optional("pandas", "to_dataframe")
        conv = self.converted(units)
        df = pd.DataFrame({header(n, label): v for n, label, v in conv})
        df.attrs["units"] = {n: label for n, label, _ in conv}
        if self.title:
            df.attrs["title"] = self.title
        return df

    def to_csv(self, path: str | os.PathLike[str] | IO[str],
               units: UnitChoice | None = None) -> None:
        """CSV: one header line with units, then one line per row; empty cells where a value is
        missing (NaN; ``null`` in the JSON); flags as ``true``/``false``. Numbers are written to
        full precision (the shortest text that reads back as the same double); with pyarrow
        installed the rows are formatted by its C++ writer (big tables)."""
        conv = self.converted(units)
        headers = [header(n, label) for n, label, _ in conv]
        columns = [v for _, _, v in conv]
        if isinstance(path, str | os.PathLike):
            with open(path, "w", encoding="utf-8", newline="") as fh:
                write_csv_text(fh, headers, columns)
            return
        write_csv_text(path, headers, columns)

    def csv_text(self, units: UnitChoice | None = None) -> str:
        buf = io.StringIO()
        self.to_csv(buf, units)
        return buf.getvalue()

    def to_parquet(self, path: str | os.PathLike[str], units: UnitChoice | None = None) -> None:
        """Parquet (pyarrow is the ``table`` extra), headers with units; the units, the title and
        the notes in the file's key-value metadata under ``screwkit``."""
        pa = _optional("pyarrow", "to_parquet")
        pq = _optional("pyarrow.parquet", "to_parquet")
        conv = self.converted(units)
        arrays = [arrow_array(v) for _, _, v in conv]
        meta = json.dumps({"title": self.title, "notes": list(self.notes),
                           "units": {n: label for n, label, _ in conv}})
        table = pa.Table.from_arrays(arrays, names=[safe_cell(header(n, lb))
                                                    for n, lb, _ in conv])
        table = table.replace_schema_metadata({"screwkit": meta})
        # no dictionary encoding: measured floats rarely repeat, and building the dictionaries
        # took 10x the rest of the write (benchmarks/bench_outputs.py)
        pq.write_table(table, str(path), compression="snappy", use_dictionary=False)

    def to_npz(self, path: str | os.PathLike[str] | IO[bytes],
               units: UnitChoice | None = None) -> None:
        """numpy ``.npz``: one array per column under its plain name (``phi0``), and
        ``units`` (a (columns, 2) string array: name, unit) — ``np.load(f)["phi0"]``."""
        conv = self.converted(units)
        arrays: dict[str, Any] = {n: v for n, _, v in conv}
        if "units" in arrays:
            raise InputError("a column is named 'units', which the .npz keeps for the units")
        arrays["units"] = np.array([[n, label] for n, label, _ in conv], dtype=str)
        np.savez(path, **arrays)  # type: ignore[arg-type]


def arrow_array(v: NDArray[Any]) -> Any:
    """A pyarrow array of the column ``v``, NaN (where a mode does not assemble) as null.
    Numbers and booleans go in through their buffers: ``pa.array`` imports pandas when it is
    installed (to recognise its types), 0.4 s of a 100,000-sample ``analyze -o .parquet``
    (benchmarks/bench_outputs.py)."""
    import pyarrow as pa

    v = np.ascontiguousarray(v)
    if v.dtype.kind == "b":
        return pa.Array.from_buffers(pa.bool_(), len(v), [
            None, pa.py_buffer(np.packbits(v, bitorder="little"))])
    if v.dtype.kind not in "fiu" or v.ndim != 1:
        return pa.array(v)
    valid = None
    nulls = 0
    if v.dtype.kind == "f":
        ok = ~np.isnan(v)
        nulls = int(len(v) - np.count_nonzero(ok))
        if nulls:
            valid = pa.py_buffer(np.packbits(ok, bitorder="little"))
    return pa.Array.from_buffers(pa.from_numpy_dtype(v.dtype), len(v),
                                 [valid, pa.py_buffer(v)], null_count=nulls)


#: leading characters that make a spreadsheet read a cell as a formula (OWASP, "CSV
#: injection"): names starting with them are refused in spec files and neutralised here
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def safe_cell(text: str) -> str:
    """``text`` with a leading apostrophe when a spreadsheet would evaluate it as a formula
    (it starts with one of :data:`FORMULA_STARTS`), so a name such as ``=HYPERLINK(…)`` given
    through the Python API is shown, not run. Numbers are never passed here."""
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def header(name: str, label: str) -> str:
    """``name [label]``, or ``name`` for a column without a unit."""
    return f"{name} [{label}]" if label else name


def _text(values: NDArray[Any]) -> list[str]:
    """Shortest round-trip text of every value; '' for NaN; true/false for flags."""
    if values.dtype == bool:
        return np.where(values, "true", "false").tolist()
    if values.dtype.kind in "iu":
        return values.astype(str).tolist()
    if values.dtype.kind in "USO":
        import csv

        buf = io.StringIO()  # quoted as CSV (a name may hold a comma), formulas neutralised
        writer = csv.writer(buf, lineterminator="\n")
        out = []
        for v in values:
            buf.seek(0)
            buf.truncate()
            writer.writerow([safe_cell(str(v))])
            out.append(buf.getvalue()[:-1])
        return out
    v = np.asarray(values, dtype=float)
    text = v.astype(str)  # numpy's shortest repr: reads back as the same double
    if np.isnan(v).any():
        text = np.where(np.isnan(v), "", text)
    return text.tolist()  # type: ignore[no-any-return]


def write_csv_text(fh: IO[str], headers: Sequence[str], columns: Sequence[NDArray[Any]]) -> None:
    """Write a header line and the rows of ``columns`` to ``fh`` (module docstring)."""
    import csv

    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow([safe_cell(h) for h in headers])
    if not columns or not len(columns[0]):
        return
    if len(columns[0]) * len(columns) > 20_000 and all(c.dtype.kind in "biuf" for c in columns):
        try:
            fh.write(_arrow_csv_rows(columns))
            return
        except ImportError:
            pass
    texts = [_text(c) for c in columns]
    block = 50_000
    n = len(texts[0])
    for start in range(0, n, block):
        rows = zip(*(t[start:start + block] for t in texts), strict=True)
        fh.write("\n".join(map(",".join, rows)))
        fh.write("\n")


def _arrow_csv_rows(columns: Sequence[NDArray[Any]]) -> str:
    """The rows as CSV text by pyarrow's writer (shortest round-trip numbers, empty for NaN,
    true/false), without a header."""
    import pyarrow as pa
    import pyarrow.csv as pacsv

    arrays = [arrow_array(v) for v in columns]
    table = pa.Table.from_arrays(arrays, names=[f"c{k}" for k in range(len(arrays))])
    sink = io.BytesIO()
    pacsv.write_csv(table, sink, pacsv.WriteOptions(include_header=False))
    return sink.getvalue().decode("utf-8")


def _optional(module: str, what: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        top = module.split(".")[0]
        raise ImportError(f"{what} needs {top}: pip install 'screwkit[table]' (or pip install "
                          f"{top})") from None


def stack_tables(tables: Sequence[ResultTable], title: str = "") -> ResultTable:
    """Tables with the same columns one under the other (e.g. every assembly mode)."""
    if not tables:
        raise InputError("no tables to stack")
    first = tables[0]
    cols = []
    for k, c in enumerate(first.columns):
        parts = [t.columns[k].values for t in tables]
        cols.append(Column(c.name, c.kind, np.concatenate(parts)))
    return ResultTable(tuple(cols), title or first.title, first.notes)


def vector_columns(name: str, kind: str, values: NDArray[Any]) -> list[Column]:
    """Three columns ``<name>_x``, ``_y``, ``_z`` of an (N, 3) array."""
    return [Column(f"{name}_{axis}", kind, values[:, k]) for k, axis in enumerate("xyz")]


def table_from_mapping(columns: Mapping[str, tuple[str, NDArray[Any]]],
                       title: str = "") -> ResultTable:
    """A table from ``{name: (kind, values)}`` in order."""
    return ResultTable(tuple(Column(n, k, np.asarray(v)) for n, (k, v) in columns.items()), title)
