"""What every ``screwkit`` subcommand shares: the consoles, the ``--json``/``--output`` options,
and the rule that a user mistake exits with status 2 and a one-paragraph message."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape

# soft_wrap: a message is one line whatever the width (paths stay whole for grep and copy-paste);
# only tables are fitted to the width
console = Console(soft_wrap=True)
if not console.is_terminal:
    console.width = max(console.width, 160)  # files and pipes get the full tables
err_console = Console(stderr=True, soft_wrap=True)

T = TypeVar("T")

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON document (SI units) instead of tables.")]
OutputOpt = Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document to this file (atomically).")]


def user_errors() -> tuple[type[BaseException], ...]:
    """Exceptions that mean the user's input is wrong (every one is a ValueError subclass or a
    missing file); anything else is a bug and keeps its traceback."""
    from screwkit.io.spec import SpecError
    from screwkit.io.units import UnitError
    from screwkit.kinematics.motion import AssemblyError
    from screwkit.model.linkage import LinkageError

    return (SpecError, UnitError, AssemblyError, LinkageError, ValueError, OSError)


def guard(fn: Callable[[], T]) -> T:
    """Run ``fn``; on a user error print it and exit with status 2."""
    try:
        return fn()
    except user_errors() as exc:
        err_console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False)
        raise typer.Exit(2) from None


def emit(doc: dict[str, Any], as_json: bool, output: Path | None, table: Callable[[], None]) -> None:
    """Write ``doc`` atomically to ``output`` if given; print it as JSON or as tables."""
    from screwkit.io.results import dumps, write_atomic

    text = dumps(doc)
    if output is not None:
        guard(lambda: write_atomic(output, text + "\n"))
    if as_json:
        sys.stdout.write(text + "\n")
    else:
        table()
        if output is not None:
            console.print(f"wrote {output}")
