"""What every ``screwkit`` subcommand shares: the consoles and the rule that a user mistake
exits with status 2 and a one-paragraph message (the output options: :mod:`screwkit.cli.outputs`).

Everything a command prints fits the width — the terminal's, or ``COLUMNS``, or 80 for a pipe
or a file: tables by :mod:`screwkit.cli.formatting`; prose (headers, notes, bullets) and error
messages by :func:`prose`, which breaks lines between words with a hanging indent and never
inside a word, so a path stays whole (on a line of its own if it is longer than the width) for
grep and copy-paste. ``wrote <path>`` lines are never wrapped (``soft_wrap``)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import NoReturn, TypeVar

import typer
from rich.console import Console
from rich.markup import escape
from rich.text import Text

console = Console(soft_wrap=True)
err_console = Console(stderr=True, soft_wrap=True)

T = TypeVar("T")


def prose(markup: str, *, hang: int | None = None, to: Console | None = None,
          width: int | None = None) -> None:
    """Print rich ``markup`` wrapped between words at the console's width, each of its lines
    on its own; continuation lines are indented by ``hang`` (default: under the text after a
    leading bullet ``  • ``, else two more than the line's own indent). A word longer than a
    line (a path) is kept whole on its own line."""
    out = to if to is not None else console
    limit = max(width or out.width, 20)
    for line in out.render_str(markup, highlight=False).split("\n", allow_blank=True):
        for piece in _wrapped(line, limit, hang):
            out.print(piece, soft_wrap=True, highlight=False)


def _wrapped(line: Text, limit: int, hang: int | None) -> list[Text]:
    """One line of text cut between words into lines of at most ``limit`` cells (module
    docstring of :func:`prose`)."""
    plain = line.plain
    if hang is None:  # under the text after a bullet; else two more than the line's indent
        lead = len(plain) - len(plain.lstrip(" •"))
        hang = lead if "•" in plain[:lead] else lead + 2
    cuts: list[int] = []
    start, last_space, pos = 0, -1, 0
    while pos < len(plain):
        if plain[pos] == " " and pos > start:
            last_space = pos
        if pos - start >= limit - (hang if cuts else 0) and last_space > start:
            cuts.append(last_space)
            start, last_space = last_space + 1, -1
            pos = start
            continue
        pos += 1
    pieces = list(line.divide(cuts)) if cuts else [line]
    return [pieces[0]] + [Text(" " * hang) + (p[1:] if p.plain.startswith(" ") else p)
                          for p in pieces[1:]]


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
    import numpy as np

    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"):
            return fn()
    except FloatingPointError as exc:
        print_error(f"the computation failed numerically ({exc}); the input values are "
                    "probably outside the range it can handle — check the magnitudes and "
                    "units in the spec (limits: docs/reliability.md)")
        raise typer.Exit(2) from None
    except user_errors() as exc:
        print_error(str(exc))
        raise typer.Exit(2) from None


def print_error(message: str) -> None:
    """Print ``message`` (plain text, not markup) on stderr after a red ``error:``, wrapped
    between words at the width of stderr with the continuation lines indented by two: one
    sentence, never cut inside a word (issue 30, the 80-column promise)."""
    prose(f"[bold red]error:[/] {escape(message)}", hang=2, to=err_console)


def user_error(message: str) -> NoReturn:
    """Print ``message`` as a user error (one sentence) and exit with status 2."""
    print_error(message)
    raise typer.Exit(2)


def loop_only(spec: T, command: str) -> T:
    """``spec`` if it is a single loop (a family or a joint list); a one-line refusal for a
    mechanism graph, which ``command`` does not take yet (docs/mechanisms.md)."""
    if getattr(spec, "family", None) == "graph":
        user_error(f"{getattr(spec, 'path', '')}: `screwkit {command}` does not take a mechanism "
                   "graph (bodies and joints) yet; graphs work with validate, analyze, mobility, "
                   "limits, report, dynamics, sweep, tolerance, balance, simulate, synthesize, "
                   "export-mjcf "
                   "and export (docs/mechanisms.md)")
    return spec


#: ``--modes`` of analyze, report and export (graph specs): every mode (the default) or the
#: drawn one only (no homotopy; docs/cli.md)
MODES_HELP = ("Graph specs: every (every assembly mode: closed-form sub-chains or the homotopy, "
              "the default) or drawn (the drawn mode only, by continuation: far faster where "
              "the homotopy is needed, e.g. a Stewart platform). Loop specs always give every "
              "mode their solver finds.")


def every_modes(modes: str, spec: object) -> bool:
    """``--modes`` as solve_mechanism's ``every_mode``: True for "every", False for "drawn";
    a one-line refusal (exit 2) for anything else, and for "drawn" with a loop spec, whose
    modes all come from one solve (docs/cli.md)."""
    if modes not in ("every", "drawn"):
        user_error(f"--modes {modes!r}: give every (every assembly mode, the default) or drawn "
                   "(the drawn mode only)")
    if modes == "drawn" and getattr(spec, "family", None) != "graph":
        user_error(f"--modes drawn: {getattr(spec, 'path', 'this spec')} is a single loop, "
                   "whose modes all come from one solve; --modes drawn is for mechanism graphs "
                   "(bodies and joints); pick a loop's mode with --mode where the command has "
                   "it")
    return modes == "every"


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
