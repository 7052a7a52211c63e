"""The output conventions every command with per-sample results shares (docs/cli.md):

* ``-o FILE`` writes the result, the format by extension — ``.json`` (the SI document),
  ``.csv``, ``.parquet``, ``.npz`` (the table, units in the headers) — and prints one line;
* ``--json`` without ``-o`` prints the document; otherwise the terminal gets tables, long ones
  summarised (``--full`` prints every row);
* ``--csv FILE`` also writes the table as CSV;
* ``--units spec|si`` and ``--unit kind=unit`` choose the units of tables, CSV and plots.

A command declares the options with the ``Annotated`` types below and hands them to
:meth:`Outputs.prepare` before any work (paths, formats and units are checked first), then calls
:meth:`Outputs.deliver` with functions that build the document, the table and the terminal
view, so that only what is asked for is built.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import check_paths, console, err_console, guard, user_error
from screwkit.errors import InputError

JsonOpt = Annotated[bool, typer.Option("--json", help="Print the JSON document (SI units) instead of tables.")]
OutputOpt = Annotated[Path | None, typer.Option("--output", "-o", help="Write the result to this file (atomically) and print one line; the format by extension: .json (the SI document), .csv, .parquet, .npz (the per-sample table in the display units).")]
CsvOpt = Annotated[Path | None, typer.Option("--csv", help="Also write the per-sample table as CSV: one row per sample (and mode), one column per quantity, the unit in each header.")]
UnitsOpt = Annotated[str, typer.Option("--units", help="Units of tables, CSV and plots: spec (the spec's [units], the default) or si. JSON is always SI.")]
UnitOpt = Annotated[list[str] | None, typer.Option("--unit", help="One kind's unit, e.g. --unit length=mm or --unit moment=lbf*in (repeatable; wins over --units).")]
FullOpt = Annotated[bool, typer.Option("--full", help="Print every row of long tables (default: the first and last rows and each column's extrema).")]


def _size(n: int) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} B"


@dataclass
class Outputs:
    """What the user asked a command to produce (module docstring)."""

    inputs: list[Path]
    as_json: bool = False
    output: Path | None = None
    output_format: str | None = None
    csv: Path | None = None
    full: bool = False
    system: str = "spec"
    overrides: dict[str, str] = field(default_factory=dict)
    written: list[str] = field(default_factory=list)

    @classmethod
    def prepare(cls, inputs: Sequence[Path], *, as_json: bool = False,
                output: Path | None = None, csv: Path | None = None, units: str = "spec",
                unit: Sequence[str] | None = None, full: bool = False,
                files: Mapping[str, Path | None] | None = None,
                folders: Mapping[str, Path | None] | None = None,
                formats: Sequence[str] = ("json", "csv", "parquet", "npz")) -> Outputs:
        """Check every output path, the ``-o`` format and the units before any work (a user
        mistake exits with status 2)."""
        from screwkit.io.display_units import SYSTEMS, parse_unit_overrides
        from screwkit.io.tables import output_format

        check_paths(list(inputs), {"--output": output, "--csv": csv, **(files or {})}, folders)
        fmt = None if output is None else guard(lambda: output_format(output, "--output",
                                                                       formats))
        if units not in SYSTEMS:
            user_error(f"--units {units}: choose spec (the spec's [units], the default) or si")
        overrides = guard(lambda: parse_unit_overrides(unit or []))
        return cls(list(inputs), as_json, output, fmt, csv, full, units, overrides)

    def units_for(self, spec_units: Mapping[str, str] | None) -> Any:
        """The display units of a spec: its ``[units]`` (or SI), then the ``--unit``
        overrides (:func:`screwkit.io.display_units.display_units`)."""
        from screwkit.io.display_units import display_units

        return guard(lambda: display_units(spec_units, system=self.system,
                                           overrides=self.overrides))

    def needs_document(self) -> bool:
        """Whether :meth:`deliver` will build the document: ``-o`` JSON, ``--json``, or the
        terminal view (which reads it)."""
        if self.output is not None:
            return (self.output_format or "json") == "json"
        return True

    def needs_table(self) -> bool:
        """Whether :meth:`deliver` will build the table: ``-o`` CSV/Parquet/NPZ, ``--csv``, or
        the terminal view."""
        if self.csv is not None:
            return True
        if self.output is not None:
            return (self.output_format or "json") != "json"
        return not self.as_json

    def deliver(self, *, document: Callable[[], dict[str, Any]],
                table: Callable[[], Any] | None, show: Callable[[], None],
                units: Any = None) -> None:
        """Write ``-o`` and ``--csv``, then print: one line after ``-o``; the document with
        ``--json``; else ``show()`` (the terminal tables) and a line per file written. Only
        what is asked for is built: ``document()`` for JSON, ``table()`` for tables."""
        from screwkit.io.results import dumps, write_json_atomic
        from screwkit.io.tables import write_table

        doc: dict[str, Any] | None = None
        tab: Any = None

        def get_table() -> Any:
            nonlocal tab
            if tab is None:
                if table is None:
                    raise InputError("this command has no per-sample table; write .json")
                tab = guard(table)
            return tab

        line = ""
        output, csv = self.output, self.csv
        if output is not None:
            fmt = self.output_format or "json"
            if fmt == "json":
                doc = guard(document)
                size = guard(lambda: write_json_atomic(output, doc, self.inputs, "--output"))
                line = f"wrote {output} (JSON, SI units, {_size(size)})"
            else:
                t = get_table()
                size = guard(lambda: write_table(t, output, fmt, units, self.inputs,
                                                 "--output"))
                line = (f"wrote {output} ({t.rows} rows x {len(t.columns)} columns, "
                        f"{_size(size)})")
        if csv is not None:
            t = get_table()
            guard(lambda: write_table(t, csv, "csv", units, self.inputs, "--csv"))
            self.written.append(str(csv))
        if self.output is not None:
            extra = "".join(f"; wrote {p}" for p in self.written)
            console.print(line + extra, highlight=False, markup=False, emoji=False)
            return
        if self.as_json:
            if doc is None:
                doc = guard(document)
            text = guard(lambda: dumps(doc))
            sys.stdout.write(text + "\n")
            for p in self.written:
                err_console.print(f"wrote {p}", highlight=False, markup=False)
            return
        show()
        for p in self.written:
            console.print(f"wrote {p}", highlight=False, markup=False)

    def note_written(self, path: str | Path) -> None:
        """A file the command wrote itself (a plot), reported with the others."""
        self.written.append(str(path))
