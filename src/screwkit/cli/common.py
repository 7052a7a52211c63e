"""What every ``screwkit`` subcommand shares: the consoles, the ``--json``/``--output`` options,
and the rule that a user mistake exits with status 2 and a one-paragraph message."""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, TypeVar

import numpy as np
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
    from screwkit.errors import ScrewkitError

    return (ScrewkitError, ValueError, OSError)


def guard(fn: Callable[[], T]) -> T:
    """Run ``fn``; on a user error print it and exit with status 2.

    numpy's floating-point overflow, division by zero and invalid operations raise inside
    ``fn`` (code that expects them, e.g. at samples where a mechanism does not assemble, says
    so with its own ``np.errstate``): a warning printed halfway through a run would be a result
    that looks right but is not. They exit with status 2 and a sentence instead."""
    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"):
            return fn()
    except FloatingPointError as exc:
        err_console.print(
            f"[bold red]error:[/] the computation failed numerically ({escape(str(exc))}); the "
            "input values are probably outside the range it can handle — check the magnitudes "
            "and units in the spec (limits: docs/reliability.md)", highlight=False)
        raise typer.Exit(2) from None
    except user_errors() as exc:
        err_console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False)
        raise typer.Exit(2) from None


def attempt(fn: Callable[[], T]) -> tuple[bool, T | None]:
    """Like :func:`guard`, but a user error is printed and returned as ``(False, None)`` so
    that a command over several inputs can report every one."""
    try:
        return True, guard(fn)
    except typer.Exit:
        return False, None


def check_paths(inputs: Sequence[Path], files: Mapping[str, Path | None],
                folders: Mapping[str, Path | None] | None = None) -> None:
    """Refuse, before any work, outputs that would destroy an input or are not regular files or
    new names (screwkit.io.outputs.check_outputs); exits with status 2."""
    from screwkit.io.outputs import check_outputs

    guard(lambda: check_outputs(inputs, files, folders))


def emit(doc: dict[str, Any], as_json: bool, output: Path | None, table: Callable[[], None],
         inputs: Sequence[Path] = ()) -> None:
    """Write ``doc`` atomically to ``output`` if given; print it as JSON or as tables."""
    from screwkit.io.results import dumps, write_atomic

    text = guard(lambda: dumps(doc))
    if output is not None:
        guard(lambda: write_atomic(output, text + "\n", inputs, "--output"))
    if as_json:
        sys.stdout.write(text + "\n")
    else:
        table()
        if output is not None:
            console.print(f"wrote {output}")
