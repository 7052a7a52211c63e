"""The studio's notebook controls (ipywidgets) drive the same tab as the web page: a slider
solves the spec with that value again (the report's 3-D page and the CLI's numbers redrawn),
a value where the loop does not close shows the sentence, undo/redo and save work."""

from __future__ import annotations

import html
import shutil
from pathlib import Path

import numpy as np

from screwkit.io.spec import load_spec
from screwkit.pipeline import Pipeline
from screwkit.studio.notebook import studio
from screwkit.studio.solve import numbers_table

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_notebook_controls(tmp_path: Path) -> None:
    spec = tmp_path / "rssr.toml"
    shutil.copy(EXAMPLES / "rssr_spatial.toml", spec)
    s = studio(spec)
    assert set(s.sliders) == {d.name for d in s.tab.design.dimensions}
    first = s.view.value
    assert first.startswith("<iframe srcdoc=")
    s.sliders["dimensions.d2"].value = 104.0
    assert s.tab.state.as_dict["dimensions.d2"] == 104.0
    assert s.view.value != first and s.boxes["dimensions.d2"].value == 104.0
    expected = numbers_table(Pipeline(s.tab.design.spec_with({"dimensions.d2": 104.0}, 0)))
    assert all(html.escape(v) in s.numbers.value for _, v in expected)
    assert not s.buttons["undo"].disabled
    # beyond the slider: the box widens it; where the loop does not close: the sentence
    s.boxes["dimensions.d2"].value = 1000.0
    assert s.sliders["dimensions.d2"].max >= 1000.0
    assert "does not close" in s.message.value and "d2 closes the loop" in s.message.value
    s.boxes["dimensions.d2"].value = 150.0
    assert "assembles only at input" in s.numbers.value and s.message.value == ""
    s.mode.value = 1
    assert s.tab.state.mode == 1 and '"initial_mode":1' in html.unescape(s.view.value)
    s._step(True)
    assert s.tab.state.mode == 0 and s.mode.value == 0
    s._step(True)
    assert s.sliders["dimensions.d2"].value == 1000.0
    s._step(False)
    s._step(False)
    assert s.tab.state.mode == 1
    path = s.save()
    loaded = load_spec(path)
    assert loaded.mode == 1 and np.isclose(loaded.dimensions["d2"], 0.150)
    assert "# Mass properties" in path.read_text(encoding="utf-8")
    assert path.with_name(path.name + ".bak").read_text(encoding="utf-8") == (
        EXAMPLES / "rssr_spatial.toml").read_text(encoding="utf-8")


def test_notebook_controls_on_a_graph_spec(tmp_path: Path) -> None:
    """A graph spec's hardpoints drive the graph report in the output (every mode) and the
    outputs' table, as the web page's graph answer has them."""
    from screwkit.studio.graph import GraphRun, graph_numbers

    spec = tmp_path / "double_wishbone.toml"
    shutil.copy(EXAMPLES / "mechanisms" / "double_wishbone.toml", spec)
    s = studio(spec)
    first = s.view.value
    assert first.startswith("<iframe srcdoc=") and '"family":"graph"' in html.unescape(first)
    assert [v for _, v in s.mode.options] == [0, 1, 2, 3]
    s.sliders["joints.LB.at[2]"].value = 150.0
    assert s.tab.state.as_dict["joints.LB.at[2]"] == 150.0 and s.view.value != first
    expected = graph_numbers(GraphRun(s.tab.design.spec_with(s.tab.state.as_dict, 0), 0))
    assert expected[0][0] == "camber, mode 0"
    assert all(html.escape(v) in s.numbers.value for _, v in expected)
    s.mode.value = 2
    assert '"initial_mode":2' in html.unescape(s.view.value)
