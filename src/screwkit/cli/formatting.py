"""Tables for a terminal: fitted to its width (80 columns when ``COLUMNS=80``) by wrapping
columns into several tables that repeat the key columns, and long tables summarised — the first
and last rows and every column's extrema — unless ``--full`` asks for every row. Messages are
never wrapped (:mod:`screwkit.cli.common`); only tables are fitted."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from rich.console import Console

#: a table longer than this is summarised unless --full
MAX_ROWS = 40
#: rows shown at each end of a summarised table
END_ROWS = 6
#: columns of the border and padding around each cell of a rich table
CELL_FRAME = 3
#: a value below this fraction of its quantity's largest magnitude in the table is round-off
#: and printed as 0 (a zero computed as 1.7e-18 next to values of order 1)
NOISE_RTOL = 1e-12


def noise_floor(*values: np.ndarray | Sequence[float]) -> float:
    """The magnitude below which a value of these arrays (one quantity, one unit) is printed
    as 0: :data:`NOISE_RTOL` times their largest finite magnitude."""
    peak = 0.0
    for v in values:
        a = np.abs(np.asarray(v, dtype=float))
        a = a[np.isfinite(a)]
        if a.size:
            peak = max(peak, float(a.max()))
    return NOISE_RTOL * peak


def number(x: float | None, digits: int = 6, floor: float = 0.0) -> str:
    """``x`` to ``digits`` significant digits; "—" for a missing value (None or NaN); "0" for
    a value whose magnitude is below ``floor`` (:func:`noise_floor`) or a negative zero."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if isinstance(x, bool | np.bool_):
        return "yes" if x else "no"
    if isinstance(x, int | np.integer):
        return str(int(x))
    if abs(float(x)) < floor or float(x) == 0.0:
        return "0"
    return f"{float(x):.{digits}g}"


@dataclass(frozen=True)
class TextColumn:
    """A column of a terminal table: its header (may hold a newline, e.g. name and unit) and
    its cells as text."""

    header: str
    cells: Sequence[str]
    justify: str = "right"
    #: the noise floor its numbers were printed with (:func:`noise_floor`)
    floor: float = 0.0

    @property
    def width(self) -> int:
        head = max((len(line) for line in self.header.split("\n")), default=0)
        return max([head, *(len(c) for c in self.cells)])


def numeric_column(header: str, values: np.ndarray, digits: int = 6,
                   floor: float | None = None) -> TextColumn:
    """A column of numbers; values below ``floor`` (default: the column's own
    :func:`noise_floor`) print as 0."""
    fl = noise_floor(values) if floor is None else floor
    return TextColumn(header, [number(v, digits, fl) for v in np.asarray(values).tolist()],
                      floor=fl)


def _pack(widths: Sequence[int], cap: int) -> list[list[int]]:
    """Consecutive indices of ``widths`` in groups of total width at most ``cap`` (a column
    wider than ``cap`` gets a group of its own)."""
    groups: list[list[int]] = [[]]
    used = 0
    for i, w in enumerate(widths):
        if groups[-1] and used + w > cap:
            groups.append([])
            used = 0
        groups[-1].append(i)
        used += w
    return groups


def _groups(columns: Sequence[TextColumn], key: int, width: int) -> list[list[int]]:
    """Indices of the non-key columns in groups that fit ``width`` next to the key columns:
    as few groups as fit, and of widths as even as can be (the narrowest cap that still needs
    no more groups), so a split table does not end with a lone column."""
    base = 1 + sum(c.width + CELL_FRAME for c in columns[:key])
    widths = [c.width + CELL_FRAME for c in columns[key:]]
    if not widths:
        return [[]]
    room = max(width - base, 1)
    groups = _pack(widths, room)
    low, high = max(widths), room
    while len(groups) > 1 and low < high:  # the narrowest cap with as few groups
        mid = (low + high) // 2
        if len(_pack(widths, mid)) <= len(groups):
            high = mid
        else:
            low = mid + 1
    if len(groups) > 1:
        groups = _pack(widths, max(high, max(widths)))
    return [[key + i for i in g] for g in groups]


def print_columns(console: Console, title: str, columns: Sequence[TextColumn], *,
                  key: int = 1, width: int | None = None) -> None:
    """Print ``columns`` as one or more rich tables no wider than ``width`` (the console's):
    the first ``key`` columns repeat in every table; a cell wider than the whole width is
    folded by rich. ``title`` heads the first table ("(columns i–j of n)" when wrapped)."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    width = width or console.width
    groups = _groups(columns, key, width)
    n = len(columns)
    for k, group in enumerate(groups):
        shown = list(range(key)) + group
        t_title = title if k == 0 else (f"{title} (continued: columns {group[0] + 1}–"
                                        f"{group[-1] + 1} of {n})")
        t = Table(title=Text(t_title), box=box.HEAVY_HEAD, title_justify="left",
                  padding=(0, 1))
        for i in shown:
            c = columns[i]
            t.add_column(Text(c.header), justify=c.justify,  # type: ignore[arg-type]
                         overflow="fold")
        rows = len(columns[0].cells) if columns else 0
        for r in range(rows):
            t.add_row(*(Text(columns[i].cells[r]) for i in shown))
        console.print(t, width=width, crop=False)


def rows_shown(rows: int, full: bool) -> list[int | None]:
    """Row indices to print: all with ``full`` or a short table, else the first and last
    :data:`END_ROWS` with ``None`` standing for the rows left out."""
    if full or rows <= MAX_ROWS:
        return list(range(rows))
    return [*range(END_ROWS), None, *range(rows - END_ROWS, rows)]


def summarised(columns: Sequence[TextColumn], full: bool) -> tuple[list[TextColumn], int]:
    """The columns cut to :func:`rows_shown`; also the number of rows left out."""
    rows = len(columns[0].cells) if columns else 0
    shown = rows_shown(rows, full)
    omitted = rows - sum(1 for i in shown if i is not None)
    if omitted == 0:
        return list(columns), 0
    out = []
    for k, c in enumerate(columns):
        cells = [c.cells[i] if i is not None else ("⋮" if k else f"⋮ {omitted} more")
                 for i in shown]
        out.append(TextColumn(c.header, cells, c.justify, c.floor))
    return out, omitted


def extrema_columns(names: Sequence[str], values: Sequence[np.ndarray], at: np.ndarray,
                    at_header: str, floors: Sequence[float] | None = None) -> list[TextColumn]:
    """A transposed table of extrema: one row per quantity with its minimum and maximum and
    the input where each is reached (NaN samples skipped); values below the quantity's
    ``floors`` entry (default: its own :func:`noise_floor`) print as 0."""
    lo: list[str] = []
    lo_at: list[str] = []
    hi: list[str] = []
    hi_at: list[str] = []
    for k, v in enumerate(values):
        v = np.asarray(v, dtype=float)
        fl = noise_floor(v) if floors is None else floors[k]
        ok = np.isfinite(v)
        if not ok.any():
            for lst in (lo, lo_at, hi, hi_at):
                lst.append("—")
            continue
        i_lo = int(np.flatnonzero(ok)[np.argmin(v[ok])])
        i_hi = int(np.flatnonzero(ok)[np.argmax(v[ok])])
        lo.append(number(v[i_lo], floor=fl))
        lo_at.append(number(at[i_lo], 5))
        hi.append(number(v[i_hi], floor=fl))
        hi_at.append(number(at[i_hi], 5))
    return [TextColumn("quantity", list(names), "left"), TextColumn("min", lo),
            TextColumn(f"at\n{at_header}", lo_at), TextColumn("max", hi),
            TextColumn(f"at\n{at_header}", hi_at)]


def table_columns(table: object, names: Sequence[str], units: object = None,
                  digits: int = 6) -> tuple[list[TextColumn], list[np.ndarray]]:
    """Terminal columns (``name`` over ``[unit]``) of some columns of a
    :class:`screwkit.tables.ResultTable` in ``units``, with their converted values. A value
    below the noise floor of its quantity — :func:`noise_floor` over every column of the table
    with the same kind and unit (a column without a unit: its own) — prints as 0."""
    from screwkit.tables import UNITLESS, ResultTable

    assert isinstance(table, ResultTable)
    conv = {n: (label, v) for n, label, v in table.converted(units)}  # type: ignore[arg-type]
    kinds = {c.name: c.kind for c in table.columns}
    scale: dict[tuple[str, str], list[np.ndarray]] = {}
    for n, (label, v) in conv.items():
        if kinds[n] not in UNITLESS and np.asarray(v).dtype.kind == "f":
            scale.setdefault((kinds[n], label), []).append(v)
    cols, values = [], []
    for name in names:
        label, v = conv[name]
        same = scale.get((kinds[name], label))
        floor = noise_floor(*same) if same is not None else None
        cols.append(numeric_column(f"{name}\n[{label}]" if label else name, v, digits, floor))
        values.append(np.asarray(v))
    return cols, values


def print_long_table(console: Console, title: str, columns: Sequence[TextColumn],
                     values: Sequence[np.ndarray], full: bool, *, key: int = 1) -> None:
    """Print a per-sample table fitted to the width; a long one (more than :data:`MAX_ROWS`
    rows) as its first and last rows and, below, each column's extrema and where they are
    reached (by the first key column), unless ``full``."""
    shown, omitted = summarised(columns, full)
    print_columns(console, title, shown, key=key)
    if omitted:
        at = np.asarray(values[0], dtype=float)
        names = [c.header.replace("\n", " ") for c in columns[key:]]
        ext = extrema_columns(names, values[key:], at, columns[0].header.split("\n")[-1],
                              [c.floor for c in columns[key:]])
        print_columns(console, f"{title}: extrema over all {len(columns[0].cells)} rows "
                               "(--full prints every row)", ext, key=1)
