"""``screwkit limits SPEC`` (limit positions and dwell orders, Bagci App. D) and ``screwkit
mobility SPEC`` (formula and Jacobian mobility). Registered by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.outputs import CsvOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt


def show_limits(spec: Any, doc: dict[str, Any], units: Any, tolerance: float) -> None:
    """The limit positions and the dwell orders asked for, angles and lengths in ``units``."""
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, number, print_columns

    console.print(f"[bold]{escape(spec.describe(units))}[/]", highlight=False)
    a, length = units.label("angle"), units.label("length")

    def ang(x: float | None) -> str:
        return number(None if x is None else units.show("angle", x), 7)

    lims = doc["limits"]
    cols = [TextColumn("kind", [x["kind"] for x in lims], "left"),
            TextColumn("branch", [str(x["branch"]) for x in lims]),
            TextColumn(f"θ0\n[{a}]", [ang(x["theta0"]) for x in lims]),
            TextColumn(f"φ0\n[{a}]", [ang(x["phi0"]) for x in lims]),
            TextColumn(f"S\n[{length}]", [number(None if x["S"] is None else
                                                  units.show("length", x["S"])) for x in lims]),
            TextColumn("2nd\nderivative", [number(x["second_derivative"], 4) for x in lims]),
            TextColumn("dwell\norder", [str(x.get("dwell_order", "—")) for x in lims])]
    print_columns(console, f"limit positions (dwell tolerance {tolerance:g})", cols)
    if doc["dwells_at"]:
        d = doc["dwells_at"]
        cols = [TextColumn(f"θ0\n[{a}]", [ang(x["theta0"]) for x in d]),
                TextColumn("inversion", [str(x["inversion_label"]) for x in d]),
                TextColumn(f"φ0\n[{a}]", [ang(x["phi0"]) for x in d]),
                TextColumn("dwell\norder", [str(x["dwell_order"]) for x in d]),
                TextColumn("dφ0/dθ0 … [rad/radᵏ]",
                           [", ".join(f"{v:.3g}" for v in x["derivatives"]) for x in d], "left")]
        print_columns(console, "dwell order at given inputs", cols)


def register(app: typer.Typer) -> None:
    """Add the ``limits`` and ``mobility`` commands to ``app``."""

    @app.command()
    def limits(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML) of an RSRC or a planar 4R.")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        dwell_tolerance: Annotated[float, typer.Option("--dwell-tol", help="A derivative dᵏφ0/dθ0ᵏ counts as vanishing below this (rad/radᵏ). Printed dimensions hold a designed dwell only to ~1e-4.")] = 1e-6,
        at: Annotated[list[float] | None, typer.Option("--at", help="Also give the dwell order at this input angle (degrees); repeatable.")] = None,
    ) -> None:
        """Limit positions of the output rotation and translation over a full turn, and the order of the instantaneous dwell at each rotation limit (Bagci App. D)."""
        import numpy as np

        from screwkit.cli.common import guard
        from screwkit.cli.outputs import Outputs
        from screwkit.io.spec import load_spec
        from screwkit.io.tables import limits_table
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit)
        s = guard(lambda: load_spec(spec))
        at_rad = [float(np.radians(x)) for x in at or []]
        doc = guard(lambda: Pipeline(s).limits(dwell_tolerance, at=at_rad).as_dict())
        du = out.units_for(s.units)
        out.deliver(document=lambda: doc, table=lambda: limits_table(doc),
                    show=lambda: show_limits(s, doc, du, dwell_tolerance), units=du)

    @app.command()
    def mobility(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
        as_json: JsonOpt = False,
        output: Annotated[Path | None, typer.Option("--output", "-o", help="Write the JSON document to this file (.json, atomically) and print one line.")] = None,
    ) -> None:
        """Mobility by formula (each term shown) and from the loop's screw Jacobian at a sample configuration: redundant constraints and undetermined (passive) motions named by joint."""
        from rich.markup import escape

        from screwkit.cli.common import console, guard
        from screwkit.cli.outputs import Outputs
        from screwkit.io.spec import load_spec
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, formats=("json",))
        s = guard(lambda: load_spec(spec))
        doc = guard(lambda: Pipeline(s).mobility().as_dict())

        def show() -> None:
            console.print(f"[bold]{escape(s.describe())}[/]", highlight=False)
            for line in doc["summary"]:
                console.print(escape(str(line)), highlight=False)
                console.print()

        out.deliver(document=lambda: doc, table=None, show=show)
