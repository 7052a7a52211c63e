"""``screwkit sweep SPEC --vary KEY=START:STOP:COUNT … --job JOB --output FILE``: one job on
every design of a grid or Latin-hypercube sample, one row per design, on Dask
(docs/sweeps.md). Registered on the main app by ``register(app)``; it parses options and
formats, the work is in :mod:`screwkit.sweep`."""

from __future__ import annotations

import signal
import threading
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Annotated, Any, NoReturn

import typer
from rich.markup import escape
from rich.table import Table

from screwkit.cli.common import check_paths, console, err_console, guard, print_error, prose

SchedulerOpt = Annotated[str | None, typer.Option(
    "--scheduler", help="Run on an existing Dask scheduler (tcp://HOST:PORT) and its workers "
                        "instead of an embedded cluster; default: $SCREWKIT_SCHEDULER.")]
WorkersOpt = Annotated[int | None, typer.Option(
    "--workers", min=0, max=1024, help="Worker processes of the embedded cluster (default: one "
                                       "per core; 0: run in this process without Dask).")]


@contextmanager
def progress_bar(label: str, total: int | None = None
                 ) -> Iterator[Callable[[int, int, int], None]]:
    """The engine's progress callback (done, total, computed now) on the shared progress bar
    (:mod:`screwkit.cli.progress`: count done, rate and ETA on stderr when it is a terminal,
    silent otherwise)."""
    from screwkit.cli.progress import progress_bar as shared_bar

    with shared_bar(label, total) as advance:
        yield lambda done, total, computed: advance(done, total)


class _Terminated(KeyboardInterrupt):
    """SIGTERM (a job scheduler's or ``kill``'s stop), raised in the main thread as Ctrl-C's
    KeyboardInterrupt is, so that the same clean-up runs: the cluster stopped, the checkpoint
    kept, one sentence printed."""


@contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """While the block runs, SIGTERM raises :class:`_Terminated` (a second one ends the process
    at once, as SIGTERM does by default). Python's default is to die without clean-up: no
    message, worker processes and their semaphores left behind."""
    if threading.current_thread() is not threading.main_thread():  # signals go to main only
        yield
        return

    def on_sigterm(signum: int, frame: Any) -> None:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        raise _Terminated

    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def engine_for(scheduler: str | None, workers: int | None, what: str = "task"
               ) -> Iterator[Any]:
    """The running engine (:func:`screwkit.sweep.engine.start_engine`), stopped on exit; one
    that cannot start (no Dask, no scheduler) is a user error (exit 2). SIGTERM stops it as
    Ctrl-C does (:func:`sigterm_as_interrupt`); faults it recovered from are printed as notes
    (``what``: the unit of work, for them) when the block ends normally."""
    from screwkit.sweep.engine import EngineConfig, start_engine

    with ExitStack() as stack:
        stack.enter_context(sigterm_as_interrupt())
        engine = guard(lambda: stack.enter_context(start_engine(EngineConfig(scheduler,
                                                                             workers))))
        yield engine
        print_notes(engine.notes(what))


def print_notes(notes: Iterable[str]) -> None:
    """One line per note on stderr."""
    for note in notes:
        prose(f"[yellow]note:[/] {escape(note)}", to=err_console)


def stopped(exc: KeyboardInterrupt, what: str) -> NoReturn:
    """Ctrl-C (exit 130) or SIGTERM (exit 143, 128 + the signal's number, as a shell reports
    it): one line saying so and ``what`` is kept or written."""
    how, code = ("terminated (SIGTERM)", 143) if isinstance(exc, _Terminated) \
        else ("interrupted", 130)
    prose(f"[yellow]{how}:[/] {what}", to=err_console)
    raise typer.Exit(code)


def interrupted(folder: Path, exc: KeyboardInterrupt) -> NoReturn:
    """A sweep stopped by Ctrl-C or SIGTERM: say what is kept and how to continue."""
    stopped(exc, f"no table written; the finished designs are kept in {escape(str(folder))} "
                 "— run the same command with --resume to continue")


def _summary(result: Any, output: Path, plot: Path | None) -> None:
    rows = result.rows
    n = len(rows)
    t = Table(title=f"sweep: {n} designs")
    for col in ("computed", "resumed", "ok", "failed", "internal errors", "time (s)",
                "ms per design, all in"):
        t.add_column(col, justify="right")
    per = 1000 * result.seconds / result.computed if result.computed else float("nan")
    t.add_row(str(result.computed), str(result.resumed), str(n - result.failed - result.errors),
              str(result.failed), str(result.errors), f"{result.seconds:.2f}", f"{per:.3g}")
    console.print(t)
    # a sentence, below the table: as a column it wrapped to one word a line in 80 columns
    prose(f"engine: {escape(result.engine)}", to=console)
    print_notes(result.notes)
    reasons = Counter(r["reason"] for r in rows if r["status"] != "ok")
    for reason, count in reasons.most_common(5):
        prose(f"  • {count} × {escape(reason)}", to=console)
    console.print(f"wrote {escape(str(output))}", highlight=False)
    if plot is not None:
        console.print(f"wrote {escape(str(plot))}", highlight=False)


def register(app: typer.Typer) -> None:
    """Add the ``sweep`` command to ``app``."""

    @app.command()
    def sweep(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML): the nominal design.")],
        vary: Annotated[list[str], typer.Option("--vary", help="KEY=START:STOP:COUNT (grid), KEY=START:STOP (with --sample lhs:N) or KEY=V1,V2,…; KEY is a dotted path into the spec (dimensions.d2 or d2, links.coupler.mass, motion.speed …); numbers in the spec's units unless written with theirs (d2=4in:5in:11). Repeatable.")],
        output: Annotated[Path, typer.Option("--output", "-o", help="The table: .parquet (needs pyarrow) or .csv; written atomically when every design is done.")],
        job: Annotated[str, typer.Option("--job", help="analyze, limits, mobility, dynamics, balance or synthesize; a graph spec: analyze, dynamics or modes (every assembly mode, docs/sweeps.md).")] = "analyze",
        sample: Annotated[str | None, typer.Option("--sample", help="grid (default) or lhs:N (N designs by Latin hypercube over the KEY=START:STOP box).")] = None,
        seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of --sample lhs:N (the same seed gives the same designs).")] = 0,
        plot: Annotated[Path | None, typer.Option("--plot", help="Write a PNG: a line over one key, a heat map over two (grid), a scatter matrix otherwise.")] = None,
        plot_column: Annotated[str | None, typer.Option("--plot-column", help="The column the picture shows (default: the job's headline, e.g. shaking_force.rms).")] = None,
        resume: Annotated[bool, typer.Option("--resume", help="Continue an interrupted run of the same sweep from its checkpoint of finished designs.")] = False,
        fresh: Annotated[bool, typer.Option("--fresh", help="Discard the checkpoint of an earlier run and start again (without --resume or --fresh, a checkpoint holding finished designs is refused, not lost).")] = False,
        scheduler: SchedulerOpt = None,
        workers: WorkersOpt = None,
        batch: Annotated[int | None, typer.Option("--batch-size", min=1, max=100000, help="Designs per task (default: about four tasks per worker, at most 64).")] = None,
        method: Annotated[str, typer.Option("--method", help="Kinematics: auto, closed or generic (as analyze).")] = "auto",
        gravity: Annotated[bool, typer.Option("--gravity/--no-gravity", help="dynamics: include the spec's gravity.")] = False,
        dwell_tolerance: Annotated[float, typer.Option("--dwell-tol", help="limits/analyze: dwell tolerance (as limits).")] = 1e-6,
        starts: Annotated[int | None, typer.Option("--starts", min=1, max=10000, help="synthesize: starts of each design's multistart.")] = None,
    ) -> None:
        """Run one job on every design of a grid or Latin-hypercube sample of spec values, on Dask (an embedded cluster, or --scheduler); one row per design in a Parquet or CSV table."""
        from screwkit.sweep.checkpoint import checkpoint_folder
        from screwkit.sweep.engine import EngineConfig
        from screwkit.sweep.jobs import JobOptions
        from screwkit.sweep.run import define_sweep, run_sweep
        from screwkit.sweep.table import table_format

        check_paths([spec], {"--output": output, "--plot": plot})
        guard(lambda: table_format(output))
        options = JobOptions(method=method, gravity=gravity, dwell_tolerance=dwell_tolerance,
                             starts=starts)
        definition = guard(lambda: define_sweep(spec, vary, job, sample=sample, seed=seed,
                                                options=options))
        config = EngineConfig(scheduler, workers)
        try:
            with sigterm_as_interrupt(), progress_bar("sweep") as update:
                result = guard(lambda: run_sweep(definition, output, config, resume=resume,
                                                 fresh=fresh, batch=batch, progress=update))
        except KeyboardInterrupt as exc:
            interrupted(checkpoint_folder(output), exc)
        if plot is not None:
            from screwkit.sweep.plots import default_column, plot_sweep

            column = plot_column or default_column(job, result.rows)
            guard(lambda: plot_sweep(result.rows, definition.metadata(), plot, column, [spec]))
        _summary(result, output, plot)
        if result.errors:
            print_error(f"{result.errors} design(s) hit an internal error (status 'error' in "
                        "the table); please report it")
            raise typer.Exit(1)
