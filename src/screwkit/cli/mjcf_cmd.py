"""``screwkit export-mjcf SPEC -o model.xml``: the loop of a spec as a MuJoCo model — bodies
with the spec's mass properties, hinge/slide/ball joints, the loop cut at a joint and closed by
equality constraints, a motor on the input (:mod:`screwkit.simulation.mjcf`, docs/simulation.md).
Registered on the main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    """Add the ``export-mjcf`` command to ``app``."""

    @app.command("export-mjcf")
    def export_mjcf(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with mass properties for every link.")],
        output: Annotated[Path, typer.Option("--output", "-o", help="The MJCF (XML) file to write.")],
        gravity: Annotated[bool, typer.Option("--gravity/--no-gravity", help="Include the spec's gravity in the model.")] = False,
        timestep: Annotated[float, typer.Option("--timestep", help="MuJoCo time step (s); the equality constraints' time constant is 20 steps.", min=1e-9, max=1.0)] = 1e-5,
    ) -> None:
        """Write a MuJoCo model (MJCF) of the spec's loop at its [motion] start, in its [motion] mode."""
        from rich.markup import escape

        from screwkit.cli.common import check_paths, console, guard, loop_only
        from screwkit.io.results import write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.simulation.mjcf import mjcf_model
        from screwkit.simulation.spec_run import spec_gravity

        check_paths([spec], {"--output": output})
        s = loop_only(guard(lambda: load_spec(spec)), "export-mjcf")
        text = guard(lambda: mjcf_model(s.linkage, start=float(s.inputs[0]), mode=s.mode,
                                        gravity=spec_gravity(s) if gravity else None,
                                        timestep=timestep, solref=(20 * timestep, 1.0),
                                        friction=s.drive.friction if s.drive else ()))
        guard(lambda: write_atomic(output, text, [spec], "--output"))
        console.print(f"wrote {escape(str(output))}", highlight=False)
