"""The studio on graph specs (docs/studio.md, "Graph specs"): the hardpoints and masses are the
dimensions, named as sweeps name them; a moved hardpoint gives the curves `screwkit analyze
--json` prints for a spec holding that value (every mode), the loads `graph_inverse_dynamics`
gives; save keeps the comments; a bad value is an error on the page and the server goes on; a
hardpoint where the mechanism assembles over part of the sweep is named with those inputs. In
the browser (headless Debian chromium) and on the tab directly."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomlkit
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.dynamics.graph_inverse import graph_inverse_dynamics
from screwkit.io.spec import load_spec
from screwkit.kinematics.graph import solve_mechanism
from screwkit.studio.design import Design
from screwkit.studio.session import Tab

MECHANISMS = Path(__file__).parents[2] / "examples" / "mechanisms"
LB_Z = "joints.LB.at[2]"
MASS = "bodies.upright.mass"


def analyze_json(text: str, folder: Path, name: str) -> dict[str, Any]:
    """`screwkit analyze SPEC --json` on a spec file holding ``text``."""
    path = folder / name
    path.write_text(text, encoding="utf-8")
    result = CliRunner().invoke(app, ["analyze", str(path), "--json"])
    assert result.exit_code == 0, result.output
    doc: dict[str, Any] = json.loads(result.output)
    return doc


def assert_outputs_equal_analyze(result: dict[str, Any], doc: dict[str, Any]) -> None:
    """Every mode's camber, toe (deg) and track change (mm) and point paths (mm) as the CLI's
    (SI) document has them."""
    assert [m["index"] for m in result["modes"]] == [m["mode"] for m in doc["modes"]]
    for shown, cli in zip(result["modes"], doc["modes"], strict=True):
        for name, scale in (("camber", np.degrees(1.0)), ("toe", np.degrees(1.0)),
                            ("track_change", 1000.0)):
            unit = "mm" if name == "track_change" else "deg"
            np.testing.assert_allclose(
                np.array(shown["outputs"][f"{name} [{unit}]"], dtype=float),
                scale * np.array(cli["outputs"][name]["value"], dtype=float),
                rtol=1e-12, atol=1e-12, equal_nan=True)
        path = result["paths"]["modes"][shown["index"]]["wheel_centre"]
        for axis, coords in zip("xyz", path, strict=True):
            np.testing.assert_allclose(
                np.array(coords, dtype=float),
                1000.0 * np.array(cli["coupler_points"]["wheel_centre"][axis], dtype=float),
                rtol=1e-12, atol=1e-9, equal_nan=True)


@pytest.fixture(scope="module")
def wishbone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The double-wishbone example (with its comments) in a folder the studio may write."""
    spec = tmp_path_factory.mktemp("studio-graph") / "double_wishbone.toml"
    spec.write_text((MECHANISMS / "double_wishbone.toml").read_text(encoding="utf-8"),
                    encoding="utf-8")
    return spec


def test_the_hardpoints_and_masses_are_the_dimensions(wishbone: Path) -> None:
    design = Design(wishbone)
    names = [d.name for d in design.dimensions]
    assert names[:3] == ["joints.L.at[0]", "joints.L.at[1]", "joints.L.at[2]"]
    assert "points.contact_patch.at[2]" in names and MASS in names
    assert len(names) == 3 * (6 + 2) + 4  # six joints, two points, four masses
    lb = design.by_name[LB_Z]
    assert (lb.value, lb.key.unit) == (130.0, "mm") and lb.low < 130.0 < lb.high
    mass = design.by_name[MASS]
    assert (mass.value, mass.key.unit) == (489.8595, "g")


def test_a_moved_hardpoint_gives_the_numbers_of_analyze(wishbone: Path, tmp_path: Path) -> None:
    design = Design(wishbone)
    tab = Tab(design)
    first = tab.handle(json.dumps({"type": "state"}))["result"]
    answer = tab.handle(json.dumps({"type": "set", "values": {LB_Z: 150.0}, "mode": 1}))
    r = answer["result"]
    assert r["ok"] and len(r["modes"]) == 4 and r["mode"] == 1
    assert r["modes"][0]["outputs"] != first["modes"][0]["outputs"]
    text = design.text_with({**design.initial_values, LB_Z: 150.0}, 1)
    assert_outputs_equal_analyze(r, analyze_json(text, tmp_path, "lb_150.toml"))
    # the loads of the picked mode, as graph_inverse_dynamics has them (no gravity)
    (tmp_path / "lb.toml").write_text(text, encoding="utf-8")
    spec = load_spec(tmp_path / "lb.toml")
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed,
                             accelerations=spec.acceleration, every_mode=True)
    dyn = graph_inverse_dynamics(motion, 1, None)
    np.testing.assert_allclose(
        np.array(r["loads"]["curves"]["input effort L.theta [N*m]"], dtype=float),
        dyn.efforts[:, 0], rtol=1e-12, atol=1e-15, equal_nan=True)
    np.testing.assert_allclose(
        np.array(r["loads"]["curves"]["shaking force [N]"], dtype=float),
        np.linalg.norm(dyn.shaking_force, axis=1), rtol=1e-12, atol=1e-15, equal_nan=True)
    numbers = dict(tab.handle(json.dumps({"type": "numbers"}))["numbers"])
    camber = np.degrees(np.array(motion.modes[1].outputs["camber"]))
    assert numbers["camber, mode 1"].startswith(f"{np.nanmin(camber):.6g} … "
                                                f"{np.nanmax(camber):.6g} deg")
    scene = tab.scene(3)["scene"]
    assert scene["family"] == "graph" and len(scene["modes"]) == 4


def test_save_keeps_comments_and_a_bad_value_is_an_error(wishbone: Path) -> None:
    original = wishbone.read_text(encoding="utf-8")
    tab = Tab(Design(wishbone))
    bad = tab.handle(json.dumps({"type": "set", "values": {MASS: -5.0}}))["result"]
    assert bad["ok"] is False and "mass must be > 0" in bad["error"]
    tab.handle(json.dumps({"type": "undo"}))
    tab.handle(json.dumps({"type": "set", "values": {LB_Z: 140.0, MASS: 500.0}, "mode": 2}))
    assert tab.handle(json.dumps({"type": "save"}))["type"] == "saved"
    saved = wishbone.read_text(encoding="utf-8")
    assert wishbone.with_name(wishbone.name + ".bak").read_text(encoding="utf-8") == original
    for line in original.splitlines():
        if line.startswith("#"):
            assert line in saved
    doc = tomlkit.parse(saved).unwrap()
    lb = next(j for j in doc["joints"] if j["name"] == "LB")
    assert lb["at"] == [5.0, 740.0, 140.0]
    assert next(b for b in doc["bodies"] if b["name"] == "upright")["mass"] == "500.0 g"
    assert "mode" not in doc["motion"]  # a graph spec has no [motion] mode
    wishbone.write_text(original, encoding="utf-8")


def test_a_hardpoint_where_part_of_the_turn_assembles(tmp_path: Path) -> None:
    spec = tmp_path / "fourbar_graph.toml"
    spec.write_text((MECHANISMS / "fourbar_graph.toml").read_text(encoding="utf-8"),
                    encoding="utf-8")
    tab = Tab(Design(spec))
    assert tab.handle(json.dumps({"type": "state"}))["result"]["assembly"][0].startswith(
        "2 assembly mode(s) of the loop")  # a single loop: the loop engine's modes
    r = tab.handle(json.dumps({"type": "set", "values": {"joints.B.at[0]": 20.0}}))["result"]
    assert r["ok"]
    assert r["assembly"][0] == "mode 0 (drawn) assembles only at input 0 … 128 deg"
    x = np.array(r["input"]["values"], dtype=float)
    ok = np.array(r["modes"][0]["assembles"])
    assert ok[x <= 128].all() and not ok[x > 128].any()


# ---- in the browser -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def served(wishbone: Path, serve_spec: Any) -> Iterator[Any]:
    yield from serve_spec(wishbone)


def design_step(served: Any) -> float:
    return float(served.studio.design.by_name[LB_Z].as_dict()["step"])


def test_graph_spec_in_the_browser(open_studio: Any, served: Any, tmp_path: Path) -> None:
    page = open_studio()
    r = page.result()
    assert r["ok"] and len(r["modes"]) == 4 and r["paths"]["title"] == "point paths"
    assert page.page.locator(".dim").count() == len(served.studio.design.dimensions)
    path_d = "document.querySelectorAll('#plots svg')[1].querySelector('path.curve')" \
             ".getAttribute('d')"
    before = page.evaluate(path_d)
    page.page.locator(f".dim[data-name='{LB_Z}'] input[type=range]").fill("150")
    page.wait_drawn()
    r = page.result()
    value = page.evaluate(f"window.studio.state.values['{LB_Z}']")  # 150 to the slider's step
    assert r["ok"] and abs(value - 150) < design_step(served) and value != 130
    assert page.evaluate(path_d) != before
    design = served.studio.design
    text = design.text_with({**design.initial_values, LB_Z: value}, 0)
    assert_outputs_equal_analyze(r, analyze_json(text, tmp_path, "lb_150.toml"))
    # a hardpoint where only two of the four modes assemble: the view in place shows two
    to_z = page.page.locator(".dim[data-name='joints.TO.at[2]'] input[type=number]")
    to_z.fill("135")
    to_z.dispatch_event("change")
    page.wait_drawn()
    assert len(page.result()["modes"]) == 2
    viewer = "document.getElementById('view').contentWindow.screwkitViewer"
    assert page.evaluate(f"{viewer}.modeCount") == 2 and page.evaluate("window.studio.viewUpdates") >= 2
    page.page.click("#undo")
    page.wait_drawn()
    assert len(page.result()["modes"]) == 4 and page.evaluate(f"{viewer}.modeCount") == 4
    # a bad value: the error on the page, and the server goes on
    box = page.page.locator(f".dim[data-name='{MASS}'] input[type=number]")
    box.fill("-5")
    box.dispatch_event("change")
    page.wait_drawn()
    assert page.result()["ok"] is False
    assert "mass must be > 0" in page.evaluate("document.getElementById('assembly').textContent")
    page.page.click("#undo")
    page.wait_drawn()
    assert page.result()["ok"]
    # save: the comments stay, the value changed
    original = served.spec.read_text(encoding="utf-8")
    page.page.click("#save")
    page.page.wait_for_function("window.studio.messages.some(m => m.text.startsWith('saved'))",
                                timeout=30_000)
    saved = served.spec.read_text(encoding="utf-8")
    assert "# lower arm hinge, on the line rear bushing -> front bushing" in saved
    assert f"at = [5.0, 740.0, {value!r}]" in saved
    served.spec.write_text(original, encoding="utf-8")
    assert not page.errors


def test_a_hardpoint_where_the_sweep_cannot_be_reached(tmp_path: Path) -> None:
    """A sweep that leaves out the drawing (150 … 200 deg): a crank too long to reach it gives
    the library's sentence and the crank lengths where the four-bar still closes."""
    text = (MECHANISMS / "fourbar_graph.toml").read_text(encoding="utf-8")
    assert "start = 0\n" in text and "stop = 360\n" in text
    spec = tmp_path / "fourbar_part.toml"
    spec.write_text(text.replace("start = 0\n", "start = 150\n").replace(
        "stop = 360\n", "stop = 200\n"), encoding="utf-8")
    tab = Tab(Design(spec))
    assert tab.handle(json.dumps({"type": "state"}))["result"]["ok"]
    r = tab.handle(json.dumps({"type": "set", "values": {"joints.B.at[0]": 19.0}}))["result"]
    assert r["ok"] is False and "cannot be followed to the first input row" in r["error"]
    assert r["where"].startswith("joints.B.at[0] closes the loop (somewhere over the input "
                                 "sweep) at ")
    assert "the other values held" in r["where"]
