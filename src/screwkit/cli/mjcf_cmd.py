"""``screwkit export-mjcf SPEC -o model.xml``: the loop of a spec as a MuJoCo model — bodies
with the spec's mass properties, hinge/slide/ball joints, the loop cut at a joint and closed by
equality constraints, a motor on the input, the ``[drive]`` flywheel as the input's armature and
the gravity ``screwkit simulate`` uses (:mod:`screwkit.simulation.mjcf`, docs/simulation.md).
Registered on the main app by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer


def register(app: typer.Typer) -> None:
    """Add the ``export-mjcf`` command to ``app``."""

    @app.command("export-mjcf")
    def export_mjcf(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) with mass properties for every link.")],
        output: Annotated[Path, typer.Option("--output", "-o", help="The MJCF (XML) file to write.")],
        gravity: Annotated[bool | None, typer.Option("--gravity/--no-gravity", help="Include the spec's gravity (its gravity, default 9.80665 m/s², along gravity_direction) or leave it out. Default: as screwkit simulate has it ([drive] gravity); on for a spec without [drive].", show_default=False)] = None,
        timestep: Annotated[float, typer.Option("--timestep", help="MuJoCo time step (s); the equality constraints' time constant is 20 steps.", min=1e-9, max=1.0)] = 1e-5,
    ) -> None:
        """Write a MuJoCo model (MJCF) of the spec's loop at its [motion] start, in its [motion] mode, with its [drive] flywheel (the input's armature), friction and gravity: the model screwkit simulate integrates, less the motor law and the load. A mechanism graph: its spanning tree as the body tree, its loops closed by connect constraints at the cut joints, a motor per input, a keyframe 'start' at its first [motion] row."""
        from rich.markup import escape

        from screwkit.cli.common import check_paths, console, guard, loop_only
        from screwkit.io.results import write_atomic
        from screwkit.io.spec import load_spec
        from screwkit.simulation.mjcf import mjcf_model
        from screwkit.simulation.spec_run import spec_gravity

        check_paths([spec], {"--output": output})
        s = guard(lambda: load_spec(spec))
        if getattr(s, "family", None) == "graph":
            from screwkit.cli.graph_simulate import export_graph_mjcf

            return export_graph_mjcf(s, output, spec, gravity, timestep)
        s = loop_only(s, "export-mjcf")
        with_gravity = export_gravity(s) if gravity is None else gravity
        flywheel = s.drive.flywheel if s.drive else 0.0
        text = guard(lambda: mjcf_model(s.linkage, start=float(s.inputs[0]), mode=s.mode,
                                        gravity=spec_gravity(s) if with_gravity else None,
                                        timestep=timestep, solref=(20 * timestep, 1.0),
                                        friction=s.drive.friction if s.drive else (),
                                        flywheel=flywheel))
        guard(lambda: write_atomic(output, text, [spec], "--output"))
        g = (f"gravity {float(sum(v * v for v in spec_gravity(s))) ** 0.5:.6g} m/s²" if with_gravity
             else "no gravity")
        console.print(f"wrote {escape(str(output))} (flywheel {flywheel:.6g} kg·m² as the "
                      f"input's armature; {g})", highlight=False)


def export_gravity(spec: Any) -> bool:
    """Whether the export has the spec's gravity by default: as ``screwkit simulate`` has it
    (the ``[drive]`` table's ``gravity``) and always for a spec without ``[drive]``."""
    return bool(spec.drive.gravity) if spec.drive is not None else True
