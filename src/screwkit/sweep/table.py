"""The result table of a sweep: one row per design, ordered by design number, written as
Parquet (pyarrow) or CSV by the output's extension, atomically (docs/sweeps.md, "The table").

Columns: ``design``, the varied keys (``dimensions.d2 [in]``: in the sweep's units), ``status``
(``ok``, ``failed``, ``error``), ``reason`` (null when ok), where the design assembles, then the job's columns
in SI units. A column's type follows its values (booleans, whole numbers, numbers, text); a
value a design does not have is null (an empty CSV field). The columns are the union over all
rows in the order they first appear by design number, so the table does not depend on how the
designs were batched or which worker ran them.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from screwkit.errors import InputError
from screwkit.io.outputs import atomic_path, write_text_atomic
from screwkit.tables import safe_cell

Row = dict[str, Any]

FORMATS = {".parquet": "parquet", ".pq": "parquet", ".csv": "csv"}


class TableError(InputError):
    """A table that cannot be written as asked."""


def table_format(path: Path) -> str:
    """``"parquet"`` or ``"csv"`` from the output's extension."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise TableError(f"--output {path}: give a .parquet or a .csv file name (the extension "
                         "chooses the format)")
    if fmt == "parquet":
        parquet()
    return fmt


def parquet() -> Any:
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise TableError("Parquet output needs pyarrow, part of the optional extra: pip install "
                         "'screwkit[sweep]' (or write a .csv)") from None
    return pyarrow


def columns_of(rows: Sequence[Row]) -> list[str]:
    """Every column of ``rows``, in the order each first appears."""
    seen: dict[str, None] = {}
    for row in rows:
        for k in row:
            seen.setdefault(k, None)
    return list(seen)


def column_type(values: Iterable[Any]) -> str:
    """``bool``, ``int``, ``float`` or ``str``: the narrowest type holding every non-null value."""
    kinds = {type(v) for v in values if v is not None}
    if not kinds:
        return "float"
    if kinds == {bool}:
        return "bool"
    if kinds <= {int}:
        return "int"
    if kinds <= {int, float}:
        return "float"
    return "str"


def _cast(value: Any, kind: str) -> Any:
    if value is None:
        return None
    if kind == "float":
        return float(value)
    if kind == "str":
        return value if isinstance(value, str) else json.dumps(value)
    return value


def typed_columns(rows: Sequence[Row]) -> dict[str, tuple[str, list[Any]]]:
    """Column name → (type, values) over ``rows``."""
    out = {}
    for name in columns_of(rows):
        values = [row.get(name) for row in rows]
        kind = column_type(values)
        out[name] = (kind, [_cast(v, kind) for v in values])
    return out


def _csv_cell(value: Any, kind: str) -> str:
    if value is None:
        return ""
    if kind == "bool":
        return "true" if value else "false"
    if kind == "float":
        return "nan" if math.isnan(value) else repr(value)
    return safe_cell(str(value)) if kind == "str" else str(value)


def csv_text(rows: Sequence[Row]) -> str:
    """The table as CSV text (numbers exactly, as Python's shortest round-trip repr)."""
    cols = typed_columns(rows)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([safe_cell(name) for name in cols])
    for i in range(len(rows)):
        w.writerow([_csv_cell(values[i], kind) for kind, values in cols.values()])
    return buf.getvalue()


def write_table(path: Path, rows: Sequence[Row], metadata: dict[str, Any],
                inputs: Sequence[Path] = ()) -> None:
    """Write the rows (already in design order) to ``path`` atomically; ``metadata`` (the
    sweep's description) goes into the Parquet schema under ``screwkit.sweep``."""
    fmt = table_format(path)
    if fmt == "csv":
        write_text_atomic(path, csv_text(rows), inputs, "--output")
        return
    pa = parquet()
    types = {"bool": pa.bool_(), "int": pa.int64(), "float": pa.float64(), "str": pa.string()}
    cols = typed_columns(rows)
    arrays = [pa.array(values, type=types[kind]) for kind, values in cols.values()]
    schema = pa.schema([pa.field(safe_cell(name), types[kind])
                        for name, (kind, _) in cols.items()],
                       metadata={"screwkit.sweep": json.dumps(metadata, sort_keys=True)})
    table = pa.Table.from_arrays(arrays, schema=schema)
    with atomic_path(path, inputs, "--output") as tmp:
        pa.parquet.write_table(table, tmp)


def read_table(path: Path) -> list[Row]:
    """The rows of a sweep table written by :func:`write_table` (for plots and tests)."""
    fmt = table_format(path)
    if fmt == "parquet":
        pa = parquet()
        return list(pa.parquet.read_table(path).to_pylist())
    with open(path, encoding="utf-8", newline="") as fh:
        return [{k: _csv_value(v) for k, v in r.items()} for r in csv.DictReader(fh)]


def _csv_value(text: str) -> Any:
    """A CSV cell back as a value: empty → None, true/false, whole numbers, numbers, text."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
