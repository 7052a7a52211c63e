"""One progress bar for every long operation (multistart synthesis, Pareto sweeps, ``demo``;
anything that can take more than about 2 s): a rich bar on stderr with the count done, the rate
and the time left, removed when done; nothing at all when stderr is not a terminal (pipes, CI,
``--json`` into a file stay clean).

    with progress_bar("synthesising", total=40) as advance:
        run(progress=advance)        # the library calls advance(done, total)
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

#: what a long library call is given: ``advance(done, total)``
ProgressCallback = Callable[[int, int], None]


def _rate_column() -> Any:
    """A column of items per second (or seconds per item when slower than one a second);
    rich.progress is imported only when a bar is drawn (15 ms of every command's start-up,
    issue 30)."""
    from rich.progress import ProgressColumn, Task
    from rich.text import Text

    class RateColumn(ProgressColumn):
        def render(self, task: Task) -> Text:
            speed = task.finished_speed or task.speed
            if not speed:
                return Text("  —/s", style="progress.data.speed")
            text = f"{speed:.3g}/s" if speed >= 1 else f"{1 / speed:.3g} s each"
            return Text(text, style="progress.data.speed")

    return RateColumn()


def _silent(done: int, total: int) -> None:
    return None


@contextmanager
def progress_bar(description: str, total: int | None = None,
                 enabled: bool = True) -> Iterator[ProgressCallback]:
    """A callback ``advance(done, total)`` that drives a progress bar on stderr (module
    docstring); a no-op when stderr is not a terminal or ``enabled`` is false."""
    from screwkit.cli.common import err_console

    if not (enabled and err_console.is_terminal):
        yield _silent
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               _rate_column(), TextColumn("eta"), TimeRemainingColumn(), TimeElapsedColumn())
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task(description, total=total)

        def advance(done: int, new_total: int) -> None:
            bar.update(task, completed=done, total=new_total)

        yield advance


#: input samples from which a command over the whole sweep (``analyze``) shows its stages
SWEEP_PROGRESS_SAMPLES = 10_000
_STAGE_UNITS = 1000


@contextmanager
def staged_progress(description: str, stages: list[str],
                    enabled: bool = True) -> Iterator[Callable[[str], ProgressCallback]]:
    """A bar on stderr (terminals only, as :func:`progress_bar`) over a command's stages, each
    an equal share: ``stage(name)`` moves the bar to the start of stage ``name``, shows its name
    and returns the callback ``advance(done, total)`` that fills that share (a library's
    progress, e.g. the solver's). Messages on stderr appear above the bar; stdout is left
    alone (it may be a file or a pipe: print results after the bar is gone)."""
    from screwkit.cli.common import err_console

    def quiet(name: str) -> ProgressCallback:
        return _silent

    if not (enabled and err_console.is_terminal):
        yield quiet
        return
    from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(),
               TimeElapsedColumn())
    with Progress(*columns, console=err_console, transient=True, redirect_stdout=False) as bar:
        task = bar.add_task(description, total=len(stages) * _STAGE_UNITS)

        def stage(name: str) -> ProgressCallback:
            start = stages.index(name) * _STAGE_UNITS
            bar.update(task, completed=start, description=f"{description}: {name}")
            bar.refresh()  # a few stages: each is drawn, however short

            def advance(done: int, total: int) -> None:
                share = min(max(done / total, 0.0), 1.0) if total > 0 else 1.0
                bar.update(task, completed=start + share * _STAGE_UNITS)

            return advance

        yield stage
