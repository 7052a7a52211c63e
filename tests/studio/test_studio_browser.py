"""The studio in a real browser (headless Debian chromium): a dimension slider redraws the
curves with the numbers `screwkit analyze` prints for a spec holding that value; modes, play
and undo; save keeps the file's comments; a value where the loop does not close shows the
error and the server goes on; two tabs are independent; the exports are the CLI's files. The
input-event-to-redraw latency at 360 samples is measured and printed."""

from __future__ import annotations

import json
import statistics
from pathlib import Path
from typing import Any

import numpy as np
import tomlkit
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.spec import load_spec

D2 = "dimensions.d2"


def analyze_json(spec_text: str, folder: Path, name: str) -> dict[str, Any]:
    """`screwkit analyze SPEC --json` on a spec file holding ``spec_text``."""
    path = folder / name
    path.write_text(spec_text, encoding="utf-8")
    result = CliRunner().invoke(app, ["analyze", str(path), "--json"])
    assert result.exit_code == 0, result.output
    doc: dict[str, Any] = json.loads(result.output)
    return doc


def move_slider(page: Any, name: str, value: float) -> None:
    page.page.locator(f".dim[data-name='{name}'] input[type=range]").fill(str(value))
    page.wait_drawn()


def test_slider_redraws_with_the_numbers_of_analyze(open_studio: Any, served: Any,
                                                    tmp_path: Path) -> None:
    page = open_studio()
    before = page.evaluate("document.querySelector('#plots path.curve').getAttribute('d')")
    assert page.result()["input"]["values"].__len__() == 360
    move_slider(page, D2, 110)
    after = page.evaluate("document.querySelector('#plots path.curve').getAttribute('d')")
    assert after != before
    r = page.result()
    assert r["ok"] and page.evaluate(f"window.studio.state.values['{D2}']") == 110
    text = served.studio.design.text_with({**served.studio.design.initial_values, D2: 110.0}, 0)
    doc = analyze_json(text, tmp_path, "d2_110.toml")
    assert len(doc["modes"]) == len(r["modes"])
    for mode, entry in zip(r["modes"], doc["modes"], strict=True):
        shown = np.array(mode["outputs"]["phi0 [deg]"], dtype=float)
        cli = np.degrees(np.array(entry["variables"]["phi0"], dtype=float))
        np.testing.assert_allclose(shown, cli, rtol=1e-12, atol=1e-12, equal_nan=True)
    # the numbers table: the minimum transmission index of each mode, as analyze has it
    page.wait_numbers()
    numbers = page.evaluate("window.studio.numbers")
    rows = dict(numbers)
    for entry in doc["modes"]:
        st = entry["transmission"]["summary"]["index"]["phi0"]
        row = rows[f"min transmission index of phi0, mode {entry['mode']}"]
        assert row.startswith(f"{st['value']:.4f} at input {np.degrees(st['at']):.6g} deg")
    table = page.evaluate("[...document.querySelectorAll('#numbers th')].map(t => t.textContent)")
    assert table == [k for k, _ in numbers]
    assert not page.errors


def test_latency_of_a_slider_move(open_studio: Any, served: Any) -> None:
    """Input event → curves redrawn, and → the frame where the 3-D view shows the new design
    too (the page redrawn), at 360 samples (printed; the bound only catches a page that hangs
    on a loaded two-core machine: the target lives in benchmarks/bench_studio.py). The view
    takes each new scene in place (screwkitViewer.update), keeping its iframe and camera."""
    page = open_studio()
    frame = page.evaluate("document.getElementById('view') !== null")
    shown = page.page.locator("#view").element_handle()
    joints = "document.getElementById('view').contentWindow.screwkitViewer.jointPositions(5)"
    drawn = page.evaluate(joints)
    for k in range(8):
        move_slider(page, D2, 100 + 2 * k + 1)
    page.page.wait_for_function("window.studio.viewLatencies.length >= 9", timeout=30_000)
    curves = page.evaluate("window.studio.latencies")[-8:]
    view = page.evaluate("window.studio.viewLatencies")[-8:]
    print(f"\nstudio latency at 360 samples: input to curves median {statistics.median(curves):.0f} "
          f"ms (max {max(curves):.0f}); input to page redrawn (3-D view in place) median "
          f"{statistics.median(view):.0f} ms")
    assert frame and page.evaluate("el => el.isConnected && el.id === 'view'", shown)
    assert page.evaluate("window.studio.viewUpdates") >= 8
    assert page.evaluate(joints) != drawn  # the view in place draws the new design
    assert statistics.median(view) < 5000


def whole_answer(spec: Path, values: dict[str, float], mode: int) -> dict[str, Any]:
    """The whole ``state`` answer (every part, with its scene) of a fresh tab at a design."""
    from screwkit.studio.design import Design
    from screwkit.studio.server import state_json
    from screwkit.studio.session import Tab

    tab = Tab(Design(spec))
    reply = tab.handle(json.dumps({"type": "set", "values": values, "mode": mode}))
    doc: dict[str, Any] = json.loads(state_json(tab.with_scene(reply), {}))
    return doc


def test_modes_play_and_undo(open_studio: Any, served: Any) -> None:
    page = open_studio()
    assert page.evaluate("window.studio.mode") == 0
    page.page.select_option("#mode", "1")
    page.wait_drawn()
    r = page.result()
    assert page.evaluate("window.studio.mode") == 1 and r["mode"] == 1 and r["loads"]["mode"] == 1
    assert page.evaluate("document.getElementById('view').contentWindow.screwkitViewer.mode") == 1
    # the mode alone changed: the server left out the motion's curves and frames, and the
    # page's merge of them is the whole answer of a fresh tab at this design
    left_out = page.evaluate("window.studio.state.unchanged")
    assert ["result", "modes"] in left_out and ["scene", "modes", 0, "joint_centres"] in left_out
    whole = whole_answer(served.spec, page.evaluate("window.studio.state.values"), 1)
    assert r == whole["result"] and page.evaluate("window.studio.scene") == whole["scene"]
    # play: the frame advances by itself, and the 3-D view follows
    page.page.click("#play")
    f0 = page.evaluate("window.studio.frame")
    page.page.wait_for_function("f0 => window.studio.frame !== f0", arg=f0, timeout=10_000)
    page.page.click("#play")
    assert page.evaluate("window.studio.playing") is False
    f = page.evaluate("window.studio.frame")
    assert page.evaluate("document.getElementById('view').contentWindow.screwkitViewer.frame") == f
    move_slider(page, D2, 104)
    page.page.click("#undo")
    page.wait_drawn()
    assert page.evaluate(f"window.studio.state.values['{D2}']") == 100
    assert page.evaluate("window.studio.state.mode") == 1
    page.page.click("#undo")
    page.wait_drawn()
    assert page.evaluate("window.studio.state.mode") == 0
    assert page.evaluate("document.getElementById('undo').disabled") is True
    page.page.click("#redo")
    page.wait_drawn()
    assert page.evaluate("window.studio.state.mode") == 1
    assert page.evaluate(f"+document.querySelector(\".dim[data-name='{D2}'] input[type=number]\").value") == 100
    assert not page.errors


def test_out_of_range_value_shows_where_it_assembles(open_studio: Any) -> None:
    page = open_studio()
    box = page.page.locator(f".dim[data-name='{D2}'] input[type=number]")
    box.fill("1000")
    box.dispatch_event("change")
    page.wait_drawn()
    r = page.result()
    assert r["ok"] is False and "does not close" in r["error"]
    shown = page.evaluate("document.getElementById('assembly').textContent")
    assert "does not close" in shown and "d2 closes the loop" in shown
    assert page.evaluate("document.body.dataset.solved") == "error"
    # a value where the loop closes over part of the turn: the page names the input ranges
    move_slider(page, D2, 150)
    r = page.result()
    assert r["ok"] and r["assembly"], r["assembly"]
    shown = page.evaluate("document.getElementById('assembly').textContent")
    assert "assembles only at input" in shown and "deg" in shown
    # and the server goes on: a value where it turns fully clears the note
    move_slider(page, D2, 100)
    assert page.result()["ok"] and not page.result()["assembly"]
    assert not page.errors


def test_two_tabs_are_independent(open_studio: Any) -> None:
    a, b = open_studio(), open_studio()
    move_slider(a, D2, 108)
    assert a.evaluate(f"window.studio.state.values['{D2}']") == 108
    assert b.evaluate(f"window.studio.state.values['{D2}']") == 100
    move_slider(b, "dimensions.a", 70)
    assert a.evaluate("window.studio.state.values['dimensions.a']") == 75
    ya = a.result()["modes"][0]["outputs"]["phi0 [deg]"]
    yb = b.result()["modes"][0]["outputs"]["phi0 [deg]"]
    assert ya != yb


def _download(page: Any, button: str) -> str:
    with page.page.expect_download() as info:
        page.page.click(button)
    return Path(info.value.path()).read_text(encoding="utf-8")


def test_save_and_exports(open_studio: Any, served: Any, tmp_path: Path) -> None:
    spec = served.spec
    original = spec.read_text(encoding="utf-8")
    page = open_studio()
    move_slider(page, D2, 112)
    page.page.select_option("#mode", "1")
    page.wait_drawn()
    # the CSV of the curves: what `screwkit analyze --csv` writes for the saved spec
    csv = _download(page, "#export-csv")
    report = _download(page, "#export-report")
    page.page.click("#save")
    page.page.wait_for_function("window.studio.messages.some(m => m.text.startsWith('saved'))")
    saved = spec.read_text(encoding="utf-8")
    assert spec.with_name(spec.name + ".bak").read_text(encoding="utf-8") == original
    for line in original.splitlines():  # every comment and every untouched line kept
        if line.startswith("#") or "#" in line:
            assert line in saved
    assert "d2 = 112.0" in saved and "mode = 1" in saved
    loaded = load_spec(spec)
    assert loaded.dimensions["d2"] == 0.112 and loaded.mode == 1
    out = tmp_path / "cli.csv"
    result = CliRunner().invoke(app, ["analyze", str(spec), "--csv", str(out)])
    assert result.exit_code == 0, result.output
    assert csv == out.read_text(encoding="utf-8")
    assert report.startswith("<!doctype html>") and "screwkit-scene" in report
    assert "d2 = 112.0" in report
    # export spec: the --save-as file of the command line, never a name from the page
    page.page.click("#export-spec")
    target = spec.with_name("rssr_exported.toml")
    page.page.wait_for_function("window.studio.messages.some(m => m.text.includes('rssr_exported'))")
    assert tomlkit.parse(target.read_text(encoding="utf-8"))["dimensions"]["d2"] == 112.0
    spec.write_text(original, encoding="utf-8")
