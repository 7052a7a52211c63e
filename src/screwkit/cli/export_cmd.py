"""``screwkit export SPEC --format dxf|gltf|step -o FILE``: the spec's motion as a CAD exchange
file — DXF coupler curves (a graph's point paths), joint paths and link (body) skeletons in
the spec's length unit, or the animated glTF (GLB) scene, of a single loop or a mechanism
graph, or STEP link (body) solids at chosen inputs (the ``[step]`` extra;
docs/exchange.md). Registered on the
main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from screwkit.cli.common import MODES_HELP


def register(app: typer.Typer) -> None:
    """Add the ``export`` command to ``app``."""

    @app.command("export")
    def export(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
        fmt: Annotated[str, typer.Option("--format", "-f", help="dxf (coupler curves, joint paths and link skeletons as 3-D polylines, in the spec's length unit), gltf (the animated scene, metres: glTF JSON for an -o name ending in .gltf, binary GLB otherwise) or step (link solids at the --at inputs, in the spec's length unit; needs the [step] extra).")],
        output: Annotated[Path, typer.Option("--output", "-o", help="The file to write (atomically): .dxf for DXF, .glb or .gltf for glTF, .step or .stp for STEP.")],
        at: Annotated[list[str] | None, typer.Option("--at", help="DXF and STEP: draw the links at this input, in the spec's unit of the input (or with a unit: '45 deg'); repeatable; default the sweep's first input. Inputs between samples are solved with the sweep.")] = None,
        mode: Annotated[int | None, typer.Option("--mode", help="Assembly mode: DXF draws every mode unless this is given; glTF and STEP show this one (default: the spec's [motion] mode).", min=0)] = None,
        splines: Annotated[bool, typer.Option("--splines", help="DXF: curves as fit-point splines instead of polylines.")] = False,
        max_points: Annotated[int, typer.Option("--max-points", help="DXF: a curve over more samples goes through every k-th of them (exact samples, about 14,000 vertices a second to write); 0 draws every sample.", min=0)] = 5000,
        method: Annotated[str, typer.Option("--method", help="auto, closed or generic (as for analyze).")] = "auto",
        modes: Annotated[str, typer.Option("--modes", help=MODES_HELP)] = "every",
    ) -> None:
        """Write the spec's motion for CAD: DXF curves and skeletons, an animated glTF scene, or STEP link solids."""
        from rich.markup import escape

        from screwkit.cli.common import (
            check_paths,
            console,
            err_console,
            every_modes,
            guard,
            prose,
        )
        from screwkit.exchange.export import check_suffix, export_format, graph_export
        from screwkit.io.outputs import write_bytes_atomic
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        check_paths([spec], {"--output": output})
        kind = guard(lambda: export_format(fmt))  # refused before the spec is solved
        guard(lambda: check_suffix(kind, output))
        binary = output.suffix.lower() != ".gltf"  # a .gltf file is JSON, anything else GLB
        s = guard(lambda: load_spec(spec))
        every = every_modes(modes, s)
        if getattr(s, "family", None) == "graph":  # bodies and joints: solve_mechanism
            result = guard(lambda: graph_export(s, kind, at or (), mode=mode, splines=splines,
                                                binary=binary, max_points=max_points,
                                                every_mode=every))
        else:
            pipe = Pipeline(s, method=method)
            result = guard(lambda: pipe.export(kind, at or (), mode=mode, splines=splines,
                                               binary=binary, max_points=max_points))
        guard(lambda: write_bytes_atomic(output, result.data, [spec], "--output"))
        for note in result.notes:
            prose(f"[yellow]note:[/] {escape(note)}", to=err_console)
        console.print(f"wrote {escape(str(output))}", highlight=False)
