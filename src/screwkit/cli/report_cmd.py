"""``screwkit report SPEC -o report.html``: one self-contained HTML report per mechanism — the
animated 3-D view, linked plots of every variable, the dynamics, balancing and synthesis
results the spec asks for, and the text of the spec, its units, the solver and the validation
status (docs/report.md). ``--plot`` also writes the same scene with matplotlib: an animation
(``.gif``, or ``.mp4`` where ffmpeg is installed) or one frame (``.png``, ``.svg``, ``.pdf``).
Registered on the main app by ``register(app)``; the scene and the page are built by
:mod:`screwkit.report.spec_report`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from screwkit.cli.common import MODES_HELP
from screwkit.errors import InputError

STILL_SUFFIXES = (".png", ".svg", ".pdf")
ANIMATION_SUFFIXES = (".gif", ".mp4")


def check_plot_paths(plots: list[Path]) -> None:
    """Each ``--plot`` file: a known suffix and an existing folder (checked before solving)."""
    for p in plots:
        if p.suffix.lower() not in STILL_SUFFIXES + ANIMATION_SUFFIXES:
            raise InputError(f"--plot {p}: give a file ending in .gif or .mp4 (an animation) or "
                             f".png, .svg or .pdf (one frame); got {p.suffix or 'no suffix'!r}")
        if p.is_dir():
            raise InputError(f"--plot {p}: is a folder; give a file name, e.g. {p / 'view.png'}")
        if not p.parent.is_dir():
            raise InputError(f"--plot {p}: folder {p.parent} does not exist; create it first")


def register(app: typer.Typer) -> None:
    """Add the ``report`` command to ``app``."""

    @app.command()
    def report(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
        output: Annotated[Path | None, typer.Option("--output", "-o", help="The HTML file to write (default: <spec name>.html in the current folder).")] = None,
        plot: Annotated[list[Path] | None, typer.Option("--plot", help="Also write the 3-D scene with matplotlib: .gif/.mp4 animates the cycle, .png/.svg/.pdf shows one frame (--frame). Repeatable.")] = None,
        mode: Annotated[int, typer.Option("--mode", help="Assembly mode of the --plot outputs (0, 1, …).", min=0)] = 0,
        frame: Annotated[int, typer.Option("--frame", help="Frame (input sample, from 0) of a still --plot.", min=0)] = 0,
        gravity: Annotated[bool, typer.Option("--gravity/--no-gravity", help="Include gravity in the dynamics (as `screwkit dynamics --gravity`).")] = False,
        modes: Annotated[str, typer.Option("--modes", help=MODES_HELP)] = "every",
    ) -> None:
        """Write a self-contained HTML report: animated 3-D view, linked plots of every variable, dynamics, balancing and synthesis results (works offline, from a file)."""
        from rich.markup import escape

        from screwkit.cli.common import console, every_modes
        from screwkit.cli.common import guard as _guard
        from screwkit.io.results import write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.report.spec_report import spec_scene
        from screwkit.report.viewer import render_report_html

        plots = list(plot or [])
        _guard(lambda: check_plot_paths(plots))
        s = _guard(lambda: load_spec(spec))
        every = every_modes(modes, s)
        out = output if output is not None else Path(f"{spec.stem}.html")
        if getattr(s, "family", None) == "graph":  # any mechanism (docs/mechanisms.md)
            from screwkit.cli.graph_views import solved
            from screwkit.report.graph_scene import graph_spec_scene

            scene = _guard(lambda: graph_spec_scene(s, solved(s, every_mode=every),
                                                    gravity=gravity))
        else:
            scene = _guard(lambda: spec_scene(s, gravity=gravity))
        if plots:
            from screwkit.report.animation import check_plots

            _guard(lambda: check_plots(scene, plots, mode=mode, frame=frame))
        page = render_report_html(scene)
        written: list[Path] = []
        try:
            _guard(lambda: write_atomic(out, page))
            written.append(out)
            n_modes = len(scene["modes"])
            console.print(f"wrote {escape(str(out))} ({len(page.encode()) / 1e6:.2f} MB; "
                          f"{len(scene['input']['values'])} frames, {n_modes} assembly "
                          "mode(s))", highlight=False)
            if plots:
                from screwkit.report.animation import render_animation, render_still

                for p in plots:
                    if p.suffix.lower() in ANIMATION_SUFFIXES:
                        _guard(lambda p=p: render_animation(scene, p, mode=mode))  # type: ignore[misc]
                    else:
                        _guard(lambda p=p: render_still(scene, p, mode=mode, frame=frame))  # type: ignore[misc]
                    written.append(p)
                    console.print(f"wrote {escape(str(p))}", highlight=False)
        except BaseException:
            for path in written:  # a failed run leaves no file behind (docs/cli.md)
                path.unlink(missing_ok=True)
            raise
