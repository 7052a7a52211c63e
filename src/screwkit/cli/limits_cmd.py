"""``screwkit limits SPEC`` (limit positions and dwell orders of any output of any loop: Bagci
App. D's closed form or the generic route) and ``screwkit mobility SPEC`` (formula and Jacobian
mobility). Registered by ``register(app)``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from screwkit.cli.common import prose
from screwkit.cli.outputs import CsvOpt, JsonOpt, OutputOpt, UnitOpt, UnitsOpt


def show_limits(spec: Any, doc: dict[str, Any], units: Any) -> None:
    """The limit positions and the dwell orders asked for, angles and lengths in ``units``."""
    from rich.markup import escape

    from screwkit.cli.common import console
    from screwkit.cli.formatting import TextColumn, number, print_columns
    from screwkit.kinematics.motion_table import variable_kind

    prose(f"[bold]{escape(spec.describe(units))}[/]")
    prose(f"method: {doc['method']}; derivatives: {escape(doc['derivatives'])}")
    xk = doc.get("input_kind") or variable_kind(doc["input_name"] if doc["method"] == "generic"
                                                else "theta0")
    x_label = "row" if xk == "ratio" else units.label(xk)  # a position along input rows

    def shown(x: float | None, kind: str) -> str:
        return "—" if x is None else f"{number(units.show(kind, x), 7)} {units.label(kind)}"

    def kind_of(x: dict[str, Any]) -> str:
        return "angle" if x.get("kind", "rotation") == "rotation" else "length"

    def second(x: dict[str, Any]) -> str:
        """d²y/dx² with its unit: output unit per input unit squared, angles in rad (a
        derivative by an angle is per radian), lengths in the display unit."""
        v = x["second_derivative"]
        if v is None:
            return "—"
        out_label, out_factor = ("rad", 1.0) if kind_of(x) == "angle" else units.unit_of("length")
        in_label, in_factor = ("rad", 1.0) if xk == "angle" else ("row", 1.0) \
            if xk == "ratio" else units.unit_of("length")
        return f"{number(v / out_factor * in_factor**2, 4)} {out_label}/{in_label}²"

    generic = doc["method"] == "generic"
    lims = doc["limits"]
    cols = [TextColumn("output", [x["output"] for x in lims], "left"),
            TextColumn("kind", [x["kind"] for x in lims], "left"),
            TextColumn("mode" if generic else "branch",
                       [str(x.get("mode", x.get("branch"))) for x in lims]),
            TextColumn(f"input\n[{x_label}]",
                       [number(units.show(xk, x["input"]), 7) for x in lims]),
            TextColumn("value", [shown(x["value"], kind_of(x)) for x in lims]),
            TextColumn("2nd\nderivative", [second(x) for x in lims]),
            TextColumn("dwell\norder", ["—" if x["dwell_order"] is None else str(x["dwell_order"])
                                        for x in lims])]
    print_columns(console, f"limit positions (dwell tolerance {doc['dwell_tolerance']:g})", cols)
    if doc["dwells_at"]:
        d = doc["dwells_at"]
        kinds = {x["output"]: variable_kind(x["output"]) for x in d}
        cols = [TextColumn("output", [x["output"] for x in d], "left"),
                TextColumn(f"input\n[{x_label}]",
                           [number(units.show(xk, x["input"]), 7) for x in d]),
                TextColumn("mode" if generic else "inversion",
                           [str(x.get("mode", x.get("inversion_label"))) for x in d]),
                TextColumn("value", [shown(x["value"], kinds[x["output"]]) for x in d]),
                TextColumn("dwell\norder", [str(x["dwell_order"]) for x in d]),
                TextColumn("dᵏy/dxᵏ, k = 1 … [SI]",
                           [", ".join(f"{v:.3g}" for v in x["derivatives"]) for x in d], "left")]
        print_columns(console, "dwell order at given inputs", cols)
    for note in doc["notes"]:
        prose(f"[yellow]note:[/] {escape(note)}")


def register(app: typer.Typer) -> None:
    """Add the ``limits`` and ``mobility`` commands to ``app``."""

    @app.command()
    def limits(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
        as_json: JsonOpt = False,
        output: OutputOpt = None,
        csv: CsvOpt = None,
        units: UnitsOpt = "spec",
        unit: UnitOpt = None,
        variable: Annotated[str | None, typer.Option("--var", "--output-variable", help="The output variable: a joint freedom (e.g. output.theta) or a seed name (phi0, S, s4 …); default the loop's outputs (or [limits] output).")] = None,
        method: Annotated[str | None, typer.Option("--method", help="auto (Bagci's App. D closed form for the RSRC/4R φ0 and S, else generic), closed, or generic (any loop, over the [motion] sweep).")] = None,
        dwell_tolerance: Annotated[float | None, typer.Option("--dwell-tol", help="A derivative dᵏy/dxᵏ counts as vanishing below this (output unit / input unitᵏ; default 1e-6 or [limits]). Printed dimensions hold a designed dwell only to ~1e-4.")] = None,
        at: Annotated[list[float] | None, typer.Option("--at", help="Also give the dwell order at this input (degrees, or m for a translation input); repeatable.")] = None,
    ) -> None:
        """Limit positions of the output variables (d output/d input = 0) and the order of the instantaneous dwell at each (Bagci App. D for the RSRC and 4R; the generic route for any loop)."""
        import numpy as np

        from screwkit.cli.common import guard
        from screwkit.cli.outputs import Outputs
        from screwkit.io.spec import load_spec
        from screwkit.io.tables import limits_table
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, csv=csv, units=units,
                              unit=unit)
        s = guard(lambda: load_spec(spec))
        if getattr(s, "family", None) == "graph":
            from screwkit.cli.graph_views import graph_limits

            doc = guard(lambda: graph_limits(s, variable, dwell_tolerance))
            du = out.units_for(s.units)
            out.deliver(document=lambda: doc, table=lambda: limits_table(doc),
                        show=lambda: show_limits(s, doc, du), units=du)
            return
        where = None if at is None else [float(np.radians(x)) if s.input_is_angle else float(x)
                                         for x in at]
        du = out.units_for(s.units)
        doc = guard(lambda: Pipeline(s, units=du).limits(dwell_tolerance, where,
                                                         output=variable,
                                                         method=method).as_dict())
        out.deliver(document=lambda: doc, table=lambda: limits_table(doc),
                    show=lambda: show_limits(s, doc, du), units=du)

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
        from screwkit.messages import message_units
        from screwkit.pipeline import Pipeline

        out = Outputs.prepare([spec], as_json=as_json, output=output, formats=("json",))
        s = guard(lambda: load_spec(spec))
        if getattr(s, "family", None) == "graph":
            from screwkit.cli.graph_views import graph_mobility

            doc = guard(lambda: graph_mobility(s))
        else:
            pipe = Pipeline(s)
            with message_units(pipe.units):  # the summary's lines quote lengths: spec units
                doc = guard(lambda: pipe.mobility().as_dict())

        def show() -> None:
            prose(f"[bold]{escape(s.describe())}[/]")
            for line in doc["summary"]:
                prose(escape(str(line)))
                console.print()

        out.deliver(document=lambda: doc, table=None, show=show)
