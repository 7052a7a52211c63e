"""The studio's controls inline in Jupyter (ipywidgets): one slider and number box per
dimension, the mode picker, undo, redo and save, driving the same tab as the web page
(:class:`~screwkit.studio.session.Tab`: the same values, history, solve and save), with the
report's page (the animated 3-D view, the input slider with play/pause and its linked plots),
updated in place with each design (:mod:`screwkit.studio.notebook_view`: the viewer shown
takes the new scene, as the web page's does), and the table of the CLI's numbers.

>>> from screwkit.studio.notebook import studio
>>> studio("examples/rssr_spatial.toml")          # the last value of a cell: the controls

Needs ipywidgets (the ``notebook`` extra). A slider solves the loop again when it is released
(``continuous_update=False``).
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError, ScrewkitError
from screwkit.kinematics.motion import AssemblyError
from screwkit.studio.design import Design
from screwkit.studio.notebook_view import InPlaceView
from screwkit.studio.session import Tab, save_design


def _widgets() -> Any:
    try:
        import ipywidgets
    except ImportError:
        raise InputError("the studio's notebook controls need ipywidgets: "
                         "pip install 'screwkit[notebook]'") from None
    return ipywidgets


def _numbers_html(rows: list[list[str]], notes: list[str]) -> str:
    e = html.escape
    body = "".join(f"<tr><th style='text-align:left'>{e(k)}</th><td>{e(v)}</td></tr>"
                   for k, v in rows)
    warn = "".join(f"<p style='color:#8a5300'>{e(n)}</p>" for n in notes)
    return f"{warn}<table>{body}</table>"


class StudioWidget:
    """The controls of one design (module docstring); ``widget`` is the ipywidgets box to
    show, ``tab`` the design state shared with the web studio's code."""

    def __init__(self, spec: str | Path, *, height: int = 640) -> None:
        w = _widgets()
        self.tab = Tab(Design(spec))
        self.height = height
        self.sliders: dict[str, Any] = {}
        self.boxes: dict[str, Any] = {}
        self._quiet = False
        rows = []
        for d in self.tab.design.dimensions:
            slider = w.FloatSlider(value=d.value, min=d.low, max=d.high, step=(d.high - d.low) / 1000,
                                   description=d.name.removeprefix("dimensions."),
                                   continuous_update=False, readout=False,
                                   layout=w.Layout(width="420px"))
            box = w.FloatText(value=d.value, layout=w.Layout(width="110px"))
            for control in (slider, box):  # the box takes values beyond the slider's range
                control.observe(lambda change, name=d.name: self._changed({name: change["new"]}),
                                names="value")
            self.sliders[d.name] = slider
            self.boxes[d.name] = box
            rows.append(w.HBox([slider, box, w.Label(d.key.unit or "")]))
        self.mode = w.Dropdown(options=[("mode 0", 0)], value=0, description="mode")
        self.mode.observe(lambda change: self._changed({}, change["new"]), names="value")
        buttons = {name: w.Button(description=name) for name in ("undo", "redo", "save")}
        buttons["undo"].on_click(lambda _: self._step(True))
        buttons["redo"].on_click(lambda _: self._step(False))
        buttons["save"].on_click(lambda _: self.save())
        self.buttons = buttons
        self.message = w.HTML()
        self.report = InPlaceView(w, height)
        self.view = self.report.frame  # the report page's iframe (built again only for
        self.push = self.report.push  # another mechanism; each design is pushed to it)
        self.numbers = w.HTML()
        self.widget = w.VBox([w.HBox([self.mode, *buttons.values()]), *rows, self.message,
                              self.view, self.push, self.numbers])
        self.refresh()

    def _changed(self, values: dict[str, float], mode: int | None = None) -> None:
        if self._quiet:
            return
        try:
            self.tab.set(values, mode)
        except ScrewkitError as exc:
            self.message.value = f"<b style='color:#b71c1c'>{html.escape(str(exc))}</b>"
            return
        self.refresh()

    def _step(self, back: bool) -> None:
        self.tab.step(back)
        self.refresh()

    def save(self) -> Path:
        """Write the design into its spec file (a ``.bak`` keeps the old one)."""
        path = save_design(self.tab.design, self.tab.state.as_dict, self.tab.state.mode)
        self.message.value = f"saved {html.escape(str(path))}"
        return path

    def refresh(self) -> None:
        """Solve the current state and redraw: the sliders, the modes, the 3-D report, the
        numbers; where the loop does not close, the sentence saying so."""
        from screwkit.studio.solve import (
            assembly_notes,
            design_scene,
            dynamics_document,
            numbers_table,
        )

        state = self.tab.state
        self._quiet = True
        try:
            for name, value in state.values:
                slider = self.sliders[name]
                slider.min, slider.max = min(slider.min, value), max(slider.max, value)
                slider.value = value
                self.boxes[name].value = value
            self.buttons["undo"].disabled = not self.tab.history
            self.buttons["redo"].disabled = not self.tab.future
            try:
                pipe = self.tab.pipeline()
                modes = [(md.label or f"mode {md.index}", md.index) for md in pipe.motion.modes]
                if state.mode >= len(modes):
                    modes.append((f"mode {state.mode} (none)", state.mode))
                self.mode.options = modes
                self.mode.value = state.mode
                if self.tab.design.graph:  # a graph spec (studio/graph.py)
                    from screwkit.studio.graph import graph_notebook

                    scene, rows, notes = graph_notebook(pipe)
                else:
                    scene = design_scene(pipe, dynamics_document(pipe)[0])
                    units = pipe.spec.display_units()
                    kind = "angle" if pipe.spec.input_is_angle else "length"
                    x = units.show(kind, np.asarray(pipe.spec.inputs, dtype=float).reshape(
                        len(pipe.spec.inputs), -1)[:, 0])
                    rows = numbers_table(pipe)
                    notes = assembly_notes(pipe, np.asarray(x), units.label(kind))
                self.report.show(scene)
                self.numbers.value = _numbers_html(rows, notes)
                self.message.value = ""
            except AssemblyError as exc:
                where = self.tab.where_it_closes()
                self.message.value = (f"<b style='color:#b71c1c'>{html.escape(str(exc))}</b>"
                                      + (f"<p>{html.escape(where)}</p>" if where else ""))
            except ScrewkitError as exc:
                self.message.value = f"<b style='color:#b71c1c'>{html.escape(str(exc))}</b>"
        finally:
            self._quiet = False

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.widget)


def studio(spec: str | Path, *, height: int = 640) -> StudioWidget:
    """The studio's controls of ``spec`` inline in a notebook (module docstring)."""
    return StudioWidget(spec, height=height)
