"""``screwkit`` command line (typer + rich). Every subcommand prints readable tables in the
spec's units by default and, with ``--json``, one JSON document in SI units (keys in
docs/cli.md); ``-o`` writes the result (format by extension) and ``--csv`` the per-sample table.
A user mistake exits with status 2 and a one-paragraph message, never a traceback.

Each command lives in its own module (``cli/<name>_cmd.py``, registered below) and imports what
it needs when it runs, so ``screwkit --help`` and ``screwkit validate`` start quickly."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from screwkit import __version__
from screwkit.cli.common import attempt, console, err_console, guard, prose
from screwkit.cli.usage_errors import ScrewkitGroup

app = typer.Typer(
    name="screwkit",
    help="Analysis, synthesis and dynamic balancing of spatial linkages (dual-number screw calculus).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # help texts are plain text: "[drive]" is a spec table, not rich markup (which would eat it)
    rich_markup_mode=None,
    # click's usage errors print like screwkit's own, wrapped at the width (cli/usage_errors.py)
    cls=ScrewkitGroup,
)


@app.callback(invoke_without_command=True)
def main(
    version: Annotated[bool, typer.Option("--version", help="Print the version.")] = False,
    max_memory: Annotated[str | None, typer.Option("--max-memory", help="Refuse work estimated to need more memory than this (e.g. 16GB; default: half the machine's memory, at most 16 GiB; also SCREWKIT_MAX_MEMORY).")] = None,
    max_time: Annotated[str | None, typer.Option("--max-time", help="Refuse a solve estimated to need more computing time than this (e.g. 10min; default 60 s; also SCREWKIT_MAX_TIME).")] = None,
) -> None:
    from screwkit.budget import set_memory_limit, set_time_limit
    from screwkit.cli.interrupts import deliver_interrupts_from_callbacks

    deliver_interrupts_from_callbacks()  # Ctrl-C inside numba's compile stops the run too
    guard(lambda: set_memory_limit(max_memory))  # None: the default (or SCREWKIT_MAX_MEMORY)
    guard(lambda: set_time_limit(max_time))  # None: the default (or SCREWKIT_MAX_TIME)
    if version:
        console.print(f"screwkit {__version__}")
        raise typer.Exit(0)


@app.command()
def validate(specs: Annotated[list[Path], typer.Argument(help="Spec files (TOML).")]) -> None:
    """Load and validate spec files and say what each describes (in the spec's units) and which jobs it has: every table is checked against what the family offers (coupler points, limits, synthesis routes, balancing), so what a job would refuse is reported here."""
    from rich.markup import escape

    from screwkit.io.spec import load_spec

    failed = 0
    for path in specs:  # every file is reported, good or bad
        ok, spec = attempt(lambda p=path: load_spec(p))  # type: ignore[misc]
        if ok and spec is not None:
            prose(f"[green]ok[/] {escape(spec.describe())}")
            prose(f"   jobs: {escape(', '.join(spec.jobs()))}")
            if getattr(spec, "family", None) == "graph":
                for line in spec.topology.summary():  # type: ignore[attr-defined]
                    prose(f"   {escape(line)}")
        else:
            failed += 1
    if failed:
        err_console.print(f"{failed} of {len(specs)} spec file(s) failed", highlight=False)
        raise typer.Exit(2)


def _register_subcommands() -> None:
    from screwkit.cli.analyze_cmd import register as register_analyze
    from screwkit.cli.balance_cmd import register as register_balance
    from screwkit.cli.demo_cmd import register as register_demo
    from screwkit.cli.dynamics_cmd import register as register_dynamics
    from screwkit.cli.export_cmd import register as register_export
    from screwkit.cli.limits_cmd import register as register_limits
    from screwkit.cli.mjcf_cmd import register as register_mjcf
    from screwkit.cli.report_cmd import register as register_report
    from screwkit.cli.simulate_cmd import register as register_simulate
    from screwkit.cli.studio_cmd import register as register_studio
    from screwkit.cli.sweep_cmd import register as register_sweep
    from screwkit.cli.synthesize_cmd import register as register_synthesize
    from screwkit.cli.tolerance_cmd import register as register_tolerance

    register_analyze(app)
    register_limits(app)
    register_dynamics(app)
    register_demo(app)
    register_synthesize(app)
    register_balance(app)
    register_report(app)
    register_simulate(app)
    register_mjcf(app)
    register_export(app)
    register_sweep(app)
    register_tolerance(app)
    register_studio(app)


_register_subcommands()


if __name__ == "__main__":  # pragma: no cover
    app()
