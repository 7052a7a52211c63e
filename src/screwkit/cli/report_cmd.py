"""``screwkit report SPEC -o report.html``: one self-contained HTML report per mechanism — the
animated 3-D view, linked plots of every variable, the dynamics, balancing and synthesis
results the spec asks for, and the text of the spec, its units, the solver and the validation
status (docs/report.md). ``--plot`` also writes the same scene with matplotlib: an animation
(``.gif``, or ``.mp4`` where ffmpeg is installed) or one frame (``.png``, ``.svg``, ``.pdf``).
Registered on the main app by ``register(app)``; :func:`write_spec_report` is what
``screwkit demo`` calls for each example."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

STILL_SUFFIXES = (".png", ".svg", ".pdf")
ANIMATION_SUFFIXES = (".gif", ".mp4")


def _matching_mode(modes: list[Any], target: Any) -> int:
    """Index of the mode of ``modes`` that is the same branch as ``target`` (joint centres
    equal on the samples both assemble), so the dynamics land on the right animation."""
    tc = np.asarray(target.joint_centres, dtype=float)
    best, best_d = -1, np.inf
    for k, m in enumerate(modes):
        both = np.asarray(m.assembles) & np.asarray(target.assembles)
        if not both.any():
            continue
        d = float(np.max(np.abs(np.asarray(m.joint_centres)[both] - tc[both])))
        if d < best_d:
            best, best_d = k, d
    if best < 0 or best_d > 1e-6:
        raise ValueError(f"the assembly mode of the dynamics (motion.mode) matches none of the "
                         f"{len(modes)} animated mode(s) (closest differs by {best_d:.3g} m)")
    return best


def dynamics_for_report(spec: Any, modes: list[Any], gravity: bool) -> tuple[dict[str, Any], int]:
    """Inverse dynamics of the spec's ``motion.mode`` (as ``screwkit dynamics`` computes it)
    and the index of that mode among ``modes``."""
    from screwkit.dynamics import inverse_dynamics
    from screwkit.kinematics.analysis import mode_motion

    lk = spec.linkage
    mm = mode_motion(lk, spec.inputs, spec.speed, spec.acceleration, spec.mode)
    ok = np.asarray(mm.assembles) & ~np.asarray(mm.singular)
    g = (spec.gravity_magnitude or 9.80665) * spec.gravity_direction if gravity else None
    dyn = inverse_dynamics(lk, mm, gravity=g, inputs=spec.inputs, allow_partial=not ok.all())
    return dyn.as_dict(), _matching_mode(modes, mm)


def spec_scene(spec: Any, *, gravity: bool = False, motion_result: Any = None,
               dynamics_doc: dict[str, Any] | None = None,
               balance_doc: dict[str, Any] | None = None,
               synthesis_doc: dict[str, Any] | None = None) -> dict[str, Any]:
    """The report scene of a loaded spec: the motion in every mode (generic solver, unless
    ``motion_result`` is given) and, when the spec has them, dynamics (masses), balancing
    ([balancing]) and synthesis ([synthesis]) — computed here unless their documents are
    given."""
    from screwkit.kinematics.motion import motion
    from screwkit.kinematics.named import seed_variables
    from screwkit.report.scene import scene_from_motion

    lk = spec.linkage
    m = motion_result if motion_result is not None else motion(lk, spec.inputs, spec.speed,
                                                               spec.acceleration)
    seeds = [seed_variables(lk, md) for md in m.modes]
    notes = []
    dyn_mode = None
    if all(link.mass is not None for link in lk.links):
        computed, dyn_mode = dynamics_for_report(spec, m.modes, gravity)
        dynamics_doc = dynamics_doc if dynamics_doc is not None else computed
        notes.append(f"Dynamics and balancing are of motion.mode = {spec.mode} of the spec "
                     f"(numbered as `screwkit analyze`), which is mode {dyn_mode} here.")
    else:
        dynamics_doc = None
    if balance_doc is None and spec.raw.balancing is not None:
        from screwkit.balancing.spec import balance_from_spec

        balance_doc = balance_from_spec(spec).as_dict()
    if synthesis_doc is None and spec.raw.synthesis is not None:
        from screwkit.cli.synthesize_cmd import synthesis_document

        synthesis_doc = synthesis_document(spec)
    text = Path(spec.path).read_text(encoding="utf-8")
    return scene_from_motion(spec, m, dynamics_doc=dynamics_doc, dynamics_mode=dyn_mode,
                             balance_doc=balance_doc, synthesis_doc=synthesis_doc,
                             spec_text=text, seed_variables=seeds, notes=notes)


def write_spec_report(spec: Any, path: str | Path, **docs: Any) -> dict[str, Any]:
    """Write the HTML report of a loaded spec to ``path`` (atomically); returns its scene.
    ``docs``: ``dynamics_doc``, ``balance_doc``, ``synthesis_doc`` already computed."""
    from screwkit.io.results import write_atomic
    from screwkit.report.viewer import render_report_html

    scene = spec_scene(spec, **docs)
    write_atomic(path, render_report_html(scene))
    return scene


def check_plot_paths(plots: list[Path]) -> None:
    """Each ``--plot`` file: a known suffix and an existing folder (checked before solving)."""
    for p in plots:
        if p.suffix.lower() not in STILL_SUFFIXES + ANIMATION_SUFFIXES:
            raise ValueError(f"--plot {p}: give a file ending in .gif or .mp4 (an animation) or "
                             f".png, .svg or .pdf (one frame); got {p.suffix or 'no suffix'!r}")
        if p.is_dir():
            raise ValueError(f"--plot {p}: is a folder; give a file name, e.g. {p / 'view.png'}")
        if not p.parent.is_dir():
            raise ValueError(f"--plot {p}: folder {p.parent} does not exist; create it first")


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
    ) -> None:
        """Write a self-contained HTML report: animated 3-D view, linked plots of every variable, dynamics, balancing and synthesis results (works offline, from a file)."""
        from rich.markup import escape

        from screwkit.cli.common import console
        from screwkit.cli.common import guard as _guard
        from screwkit.io.results import write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.report.viewer import render_report_html

        plots = list(plot or [])
        _guard(lambda: check_plot_paths(plots))
        s = _guard(lambda: load_spec(spec))
        out = output if output is not None else Path(f"{spec.stem}.html")
        scene = _guard(lambda: spec_scene(s, gravity=gravity))
        page = render_report_html(scene)
        _guard(lambda: write_atomic(out, page))
        n_modes = len(scene["modes"])
        console.print(f"wrote {escape(str(out))} ({len(page.encode()) / 1e6:.2f} MB; "
                      f"{len(scene['input']['values'])} frames, {n_modes} assembly mode(s))",
                      highlight=False)
        if plots:
            from screwkit.report.animation import render_animation, render_still

            for p in plots:
                if p.suffix.lower() in ANIMATION_SUFFIXES:
                    _guard(lambda p=p: render_animation(scene, p, mode=mode))  # type: ignore[misc]
                else:
                    _guard(lambda p=p: render_still(scene, p, mode=mode, frame=frame))  # type: ignore[misc]
                console.print(f"wrote {escape(str(p))}", highlight=False)
