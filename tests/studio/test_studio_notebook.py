"""The studio's notebook controls (ipywidgets) drive the same tab as the web page: a slider
solves the spec with that value again (the report's 3-D page and the CLI's numbers redrawn),
a value where the loop does not close shows the sentence, undo/redo and save work."""

from __future__ import annotations

import base64
import html
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.io.spec import load_spec
from screwkit.pipeline import Pipeline
from screwkit.studio.notebook import studio
from screwkit.studio.notebook_view import posted_scene
from screwkit.studio.solve import numbers_table


def pushed(s: Any) -> dict[str, Any]:
    """The message the widget's last push posts to the report page it shows."""
    (output,) = s.push.outputs
    return posted_scene(output["data"]["application/javascript"])


def unpacked(packed: dict[str, Any]) -> np.ndarray:
    """A packed array of a scene (base64 little-endian floats) as a numpy array."""
    dtype = "<f8" if packed["dtype"] == "f8" else "<f4"
    return np.frombuffer(base64.b64decode(packed["$b64"]), dtype=dtype).reshape(packed["shape"])

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_notebook_controls(tmp_path: Path) -> None:
    spec = tmp_path / "rssr.toml"
    shutil.copy(EXAMPLES / "rssr_spatial.toml", spec)
    s = studio(spec)
    assert set(s.sliders) == {d.name for d in s.tab.design.dimensions}
    first = s.view.value
    assert first.startswith("<iframe srcdoc=") and s.push.outputs == ()
    s.sliders["dimensions.d2"].value = 104.0
    assert s.tab.state.as_dict["dimensions.d2"] == 104.0
    # the report page shown takes the new design in place: the same iframe, a pushed scene
    assert s.view.value == first and s.boxes["dimensions.d2"].value == 104.0
    message = pushed(s)
    assert message["seq"] == 1 and f'data-screwkit-view="{message["screwkitStudio"]}"' in first
    moved = Pipeline(s.tab.design.spec_with({"dimensions.d2": 104.0}, 0))
    for mode, md in zip(message["scene"]["modes"], moved.motion.modes, strict=True):
        centres = np.asarray(md.joint_centres, dtype=float)
        np.testing.assert_allclose(unpacked(mode["joint_centres"]), centres, rtol=0,
                                   atol=1e-12 * np.nanmax(np.abs(centres)))
    assert "d2=104 mm" in message["description"] and message["scene"]["plots"] and message["text"]
    expected = numbers_table(moved)
    assert all(html.escape(v) in s.numbers.value for _, v in expected)
    assert not s.buttons["undo"].disabled
    # beyond the slider: the box widens it; where the loop does not close: the sentence
    s.boxes["dimensions.d2"].value = 1000.0
    assert s.sliders["dimensions.d2"].max >= 1000.0
    assert "does not close" in s.message.value and "d2 closes the loop" in s.message.value
    s.boxes["dimensions.d2"].value = 150.0
    assert "assembles only at input" in s.numbers.value and s.message.value == ""
    s.mode.value = 1
    assert s.tab.state.mode == 1 and pushed(s)["scene"]["initial_mode"] == 1
    assert s.view.value == first  # never rebuilt: every design of the RSSR is pushed
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
    assert s.tab.state.as_dict["joints.LB.at[2]"] == 150.0 and s.view.value == first
    assert pushed(s)["scene"]["family"] == "graph" and len(pushed(s)["scene"]["modes"]) == 4
    expected = graph_numbers(GraphRun(s.tab.design.spec_with(s.tab.state.as_dict, 0), 0))
    assert expected[0][0] == "camber, mode 0"
    assert all(html.escape(v) in s.numbers.value for _, v in expected)
    s.mode.value = 2
    assert pushed(s)["scene"]["initial_mode"] == 2
