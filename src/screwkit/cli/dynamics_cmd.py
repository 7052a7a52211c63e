"""``screwkit dynamics SPEC``: shaking force and moment, every joint reaction (with its point
of application) and the actuator efforts over the cycle, one assembly mode (docs/dynamics.md).
The terminal gets the RMS and peak of each load in the display units; ``--csv`` and ``-o`` get
every sample; the JSON document is built only when it is written or printed."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import prose
from screwkit.cli.outputs import CsvOpt, FullOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt


def load_note(pipe: Any) -> str | None:
    """The note naming the inputs where ``[motion] mode`` does not assemble (null loads)."""
    problem = pipe.not_assembling(pipe.mode())
    return None if problem is None else f"{problem}: the loads there are null"


def dynamics_job(pipe: Any, gravity: bool) -> dict[str, Any]:
    """The dynamics document of a pipeline's spec (``[motion] mode``; null loads, with a note,
    where the mode does not assemble)."""
    from screwkit.io.documents import dynamics_document

    dyn = pipe.dynamics(gravity)
    return dynamics_document(dyn, mode=pipe.spec.mode, note=load_note(pipe))


def summary_kind(name: str) -> str:
    """The quantity kind of a :meth:`Dynamics.summary` entry."""
    if name.startswith("effort "):
        return "force" if name.endswith(".s") else "moment"
    if name.endswith("force"):
        return "force"
    if name.endswith("moment"):
        return "moment"
    return "ratio"


def gravity_sentence(dyn: Any, pipe: Any) -> str:
    """"gravity on: 9.80665 m/s^2 along (0, 0, -1)" or "gravity off (--gravity to add it)"."""
    import numpy as np

    if not dyn.gravity_on:
        return "gravity off (add it with --gravity)"
    g = np.asarray(dyn.gravity, dtype=float)
    size = float(np.linalg.norm(g))
    d = ", ".join(f"{v:.4g}" for v in g / size)
    return f"gravity on: {size:.6g} m/s^2 along ({d})"


def summary_columns(summary: dict[str, dict[str, float]], units: Any,
                    input_is_angle: bool) -> list[Any]:
    """The terminal columns of :meth:`Dynamics.summary`: quantity, unit, RMS, peak and the
    input at the peak, in ``units``; a value below the noise floor of its kind (over every
    load of that kind) prints as 0."""
    from screwkit.cli.formatting import TextColumn, noise_floor, number

    shown = {name: (summary_kind(name), st) for name, st in summary.items()}
    floors = {kind: noise_floor([units.show(k, st["peak"]) for k, st in shown.values()
                                 if k == kind])
              for kind in {k for k, _ in shown.values()} if kind != "ratio"}
    in_kind = "angle" if input_is_angle else "length"
    names, unit, rms, peak, at = [], [], [], [], []
    for name, (kind, st) in shown.items():
        floor = floors.get(kind, 0.0)
        names.append(name)
        unit.append(units.label(kind))
        rms.append(number(units.show(kind, st["rms"]), floor=floor))
        peak.append(number(units.show(kind, st["peak"]), floor=floor))
        at.append(number(units.show(in_kind, st["peak_at"]), 5) if st["peak"] >= floor > 0
                  or kind == "ratio" and st["peak"] > 0 else "—")
    return [TextColumn("quantity", names, "left"), TextColumn("unit", unit, "left"),
            TextColumn("RMS", rms), TextColumn("peak", peak),
            TextColumn(f"peak at\ninput [{units.label(in_kind)}]", at)]


def show_dynamics(spec: Any, pipe: Any, dyn: Any, units: Any, note: str | None) -> None:
    """RMS and peak of every load, and the input where the peak is reached, in the display
    units; values below their quantity's noise floor print as 0."""
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import print_columns

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    prose(f"assembly mode {spec.mode}; {gravity_sentence(dyn, pipe)}; "
          f"{escape(dyn.indeterminacy.describe())}")
    if note is not None:
        prose(f"[yellow]note:[/] {escape(note)}")
    cols = summary_columns(dyn.summary(), units, spec.input_is_angle)
    print_columns(console, "loads over the cycle (vectors by magnitude)", cols)
    prose("reactions: on the distal link by the proximal link, world frame, moments "
          "about the joint centre (its path: --csv <joint>.point_x|y|z, or "
          "--json reactions.<joint>.point)")


def register(app: typer.Typer) -> None:
    """Add the ``dynamics`` command to ``app``."""

    @app.command()
    def dynamics(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with [links.<name>] mass properties.")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        full: FullOpt = False,
        gravity: Annotated[bool, typer.Option("--gravity/--no-gravity", help="Include gravity: magnitude 'gravity' (default 9.80665 m/s²) along 'gravity_direction' (default −z) of the spec.")] = False,
    ) -> None:
        """Shaking force and moment, every joint reaction and the actuator efforts over the cycle, with the RMS and peak of each (one assembly mode: motion.mode in the spec)."""
        from screwkit.cli.common import guard
        from screwkit.cli.outputs import Outputs
        from screwkit.io.documents import dynamics_document
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit, full=full)
        s = guard(lambda: load_spec(spec))
        if getattr(s, "family", None) == "graph":  # any mechanism (docs/mechanisms.md)
            from screwkit.cli.graph_views import dynamics_graph

            return dynamics_graph(s, out, gravity)
        du = out.units_for(s.units)
        pipe = Pipeline(s, units=du)
        dyn = guard(lambda: pipe.dynamics(gravity))
        note = guard(lambda: load_note(pipe))
        out.deliver(document=lambda: dynamics_document(dyn, mode=s.mode, note=note),
                    table=lambda: dyn.table(mode=s.mode),
                    show=lambda: show_dynamics(s, pipe, dyn, du, note), units=du)
