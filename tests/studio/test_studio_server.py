"""The studio server without a browser: the token (HTTP 403 and a refused WebSocket without
it), malformed WebSocket messages answered with an error while the server goes on, the
command itself (prints its URL, Ctrl-C stops it cleanly), and the design's values and saving
(comments kept, units as written, joint lists)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from screwkit.io.spec import load_spec
from screwkit.pipeline import Pipeline
from screwkit.studio.design import Design, StudioError
from screwkit.studio.session import Tab

EXAMPLES = Path(__file__).parents[2] / "examples"


def status(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=10) as r:
            return int(r.status)
    except urllib.error.HTTPError as exc:
        return int(exc.code)


def test_requests_without_the_token_are_refused(served: Any) -> None:
    token = served.studio.token
    assert status(served.url) == 200
    assert status(served.base + "/") == 403
    assert status(served.base + "/?token=" + token[:-1] + "x") == 403
    assert status(served.base + "/static/studio.js") == 403
    assert status(served.base + "/static/studio.js?token=" + token) == 200
    assert status(served.base + "/static/..%2Fserver.py?token=" + token) == 404
    for bad in (served.ws_url.split("?")[0], served.ws_url.replace(token, "nope")):
        with pytest.raises(InvalidStatus) as info:
            connect(bad, open_timeout=10).close()
        assert info.value.response.status_code == 403
    with pytest.raises(InvalidStatus):  # a page of another site holding the token
        connect(served.ws_url, origin="http://evil.example", open_timeout=10).close()  # type: ignore[arg-type]


def test_malformed_messages_get_an_error_and_the_server_goes_on(served: Any) -> None:
    with connect(served.ws_url, open_timeout=10, max_size=None) as ws:
        first = json.loads(ws.recv(timeout=60))
        assert first["type"] == "state" and first["result"]["ok"]
        # a solved state carries its 3-D scene (one message: drawn in one frame)
        assert len(first["scene"]["modes"]) == len(first["result"]["modes"])
        bad = ["garbage", "[]", "null", '{"type": "set", "values": {"dimensions.d2": "ten"}}',
               '{"type": "set", "values": {"nowhere": 1}}', '{"type": "fly"}',
               '{"type": "set", "values": {"dimensions.d2": NaN}}', '{"type": "save", "x": 1}',
               '{"type": "export", "what": "../../etc/passwd"}', '{"type": "set", "mode": 99}',
               '{"type": "set", "seq": -1}', "[" * 100_000, '{"type": "set", "seq": true}']
        for text in bad:
            ws.send(text)
            reply = json.loads(ws.recv(timeout=60))
            assert reply["type"] == "error" and reply["message"], (text[:40], reply)
        ws.send(b"\x00\x01")
        assert json.loads(ws.recv(timeout=60))["type"] == "error"
        ws.send(json.dumps({"type": "set", "seq": 7, "values": {"dimensions.d2": 101}}))
        good = json.loads(ws.recv(timeout=60))
        assert good["type"] == "state" and good["seq"] == 7 and good["result"]["ok"]
    assert status(served.url) == 200


def test_a_tab_answers_with_the_pipelines_numbers(rssr_copy: Path) -> None:
    """The state after a change holds the curves of Pipeline on the spec with that value,
    the loads of its [motion] mode and where each mode assembles."""
    tab = Tab(Design(rssr_copy))
    reply = tab.handle(json.dumps({"type": "set", "seq": 3, "values": {"dimensions.b": 55},
                                   "mode": 1}))
    assert reply["seq"] == 3 and reply["can_undo"] and not reply["can_redo"]
    spec = Design(rssr_copy).spec_with({"dimensions.b": 55.0}, 1)
    assert spec.dimensions["b"] == pytest.approx(0.055, rel=1e-15)
    pipe = Pipeline(spec)
    dyn = pipe.dynamics()
    loads = reply["result"]["loads"]
    assert loads["mode"] == 1
    torque = np.array(loads["curves"]["input effort input.theta [N*m]"], dtype=float)
    np.testing.assert_allclose(torque, np.asarray(dyn.efforts["input.theta"], dtype=float),
                               rtol=1e-12, atol=1e-15)
    force = np.array(loads["curves"]["shaking force [N]"], dtype=float)
    np.testing.assert_allclose(force, np.linalg.norm(dyn.shaking_force, axis=1), rtol=1e-12)
    largest = np.array(loads["curves"]["largest joint reaction force [N]"], dtype=float)
    every = np.stack([np.linalg.norm(np.asarray(r.force, dtype=float), axis=1)
                      for r in dyn.reactions.values()])
    np.testing.assert_allclose(largest, every.max(axis=0), rtol=1e-12)
    peaks = {row[0]: row[1] for row in loads["summary"]}
    assert peaks["shaking_force [N]"] == pytest.approx(force.max(), rel=1e-12)
    assert peaks["effort input.theta [N*m]"] == pytest.approx(np.abs(torque).max(), rel=1e-12)
    assert tab.handle(json.dumps({"type": "undo"}))["mode"] == 0
    assert tab.handle(json.dumps({"type": "redo"}))["values"]["dimensions.b"] == 55


def test_where_the_changed_dimension_closes_the_loop(rssr_copy: Path) -> None:
    """A value where the loop closes nowhere: the answer names the values of that dimension
    where it closes, and Pipeline agrees at the scanned values on either side of each end."""
    from screwkit.kinematics.motion import AssemblyError
    from screwkit.studio.solve import scan_grid

    tab = Tab(Design(rssr_copy))
    r = tab.handle(json.dumps({"type": "set", "values": {"dimensions.d2": 1000}}))["result"]
    assert not r["ok"] and "does not close" in r["error"]
    where = r["where"]
    assert where.startswith("d2 closes the loop (somewhere over the input sweep) at ")
    d = tab.design.by_name["dimensions.d2"]
    grid = scan_grid(d)
    values = tab.state.as_dict

    def closes(v: float) -> bool:
        try:
            return any(np.asarray(m.assembles).any() for m in
                       Pipeline(tab.design.spec_with({**values, d.name: v}, 0)).motion.modes)
        except AssemblyError:
            return False

    first, last = (float(x) for x in where.split(" at ")[1].split(" mm")[0].split(" … "))
    i, j = int(np.argmin(abs(grid - first))), int(np.argmin(abs(grid - last)))
    assert closes(grid[i]) and closes(grid[j]) and closes(100.0)
    assert i == 0 or not closes(grid[i - 1])
    assert j == len(grid) - 1 or not closes(grid[j + 1])


def test_design_keeps_comments_and_written_units(tmp_path: Path) -> None:
    spec = tmp_path / "fig7.toml"
    source = (EXAMPLES / "bagci_fig7_rsrc.toml").read_text(encoding="utf-8")
    spec.write_text(source.replace("[dimensions]", "[dimensions]  # the link lengths")
                    + "\n# the end\n", encoding="utf-8")
    d = Design(spec)
    d2 = d.by_name["dimensions.d2"]
    assert d2.key.kind == "length" and d2.key.unit == "in" and d2.value == 4.5
    assert d2.low < 4.5 < d2.high
    new = d.text_with({**d.initial_values, "dimensions.d2": 4.75}, d.initial_mode)
    assert "# the link lengths" in new and "# the end" in new
    assert load_spec(spec).dimensions["d2"] != d.spec_with({"dimensions.d2": 4.75}, 0).dimensions["d2"]
    assert d.spec_with({"dimensions.d2": 4.75}, 0).dimensions["d2"] == pytest.approx(4.75 * 0.0254)
    # a value written with its unit is written back with it
    spec.write_text(source.replace("d2 = 4.5", 'd2 = "114.3 mm"  # in millimetres'),
                    encoding="utf-8")
    mm = Design(spec)
    assert mm.by_name["dimensions.d2"].key.unit == "mm" and mm.by_name["dimensions.d2"].value == 114.3
    written = mm.text_with({**mm.initial_values, "dimensions.d2": 120.0}, 0)
    assert 'd2 = "120.0 mm"  # in millimetres' in written
    with pytest.raises(StudioError, match="not a value this studio edits"):
        d.check({"../etc": 1.0}, 0)
    loop = Design(EXAMPLES / "rrsrr_loop.toml")
    names = [x.name for x in loop.dimensions]
    assert "joints[1].twist" in names and loop.by_name["joints[1].twist"].key.unit == "deg"
    assert loop.by_name["joints[1].twist"].value == -31.2


def test_the_command_prints_its_url_and_stops_on_ctrl_c(rssr_copy: Path) -> None:
    env = {**os.environ, "COLUMNS": "80", "PYTHONPATH": str(Path(__file__).parents[2] / "src")}
    proc = subprocess.Popen([sys.executable, "-m", "screwkit.cli.main", "studio", str(rssr_copy),
                             "--no-browser", "--port", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    try:
        url = ""
        deadline = time.monotonic() + 60
        while "token=" not in url and time.monotonic() < deadline:
            line = proc.stdout.readline()  # type: ignore[union-attr]
            if not line:
                break
            url = line.strip() if "http://127.0.0.1:" in line else url
        assert url.startswith("http://127.0.0.1:") and "token=" in url, proc.stderr.read()  # type: ignore[union-attr]
        while status(url) != 200 and time.monotonic() < deadline:
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "studio stopped" in out
    assert "Traceback" not in err


def test_the_command_refuses_bad_arguments_in_one_sentence(rssr_copy: Path) -> None:
    from typer.testing import CliRunner

    from screwkit.cli.main import app

    runner = CliRunner()
    cases = [(["studio", str(rssr_copy.with_name("missing.toml")), "--no-browser"],
              "no such spec file"),
             (["studio", str(rssr_copy), "--no-browser", "--save-as", str(rssr_copy)],
              "input of the command"),
             (["studio", str(rssr_copy), "--no-browser", "--host", "256.1.1.1"],
              "cannot listen on 256.1.1.1")]
    for args, words in cases:
        result = runner.invoke(app, args)
        # the sentence may wrap at the terminal's width (a long temporary path)
        assert result.exit_code == 2 and words in " ".join(result.output.split()), result.output


def test_answers_leave_out_the_parts_the_page_holds(rssr_copy: Path) -> None:
    """state_json leaves out each part of a state, and of its scene each entry and each
    mode's entry, whose JSON is the one sent last: a dimension change resends every curve but
    not the input values; a change of the mode alone resends the loads and the load arrows
    (moved to that mode), not the motion's curves or frames. The page's merge (each left-out
    path taken from the state before) is the whole answer of a fresh tab at that state; a
    state that is not solved is sent whole, and the next solved one whole again."""
    from screwkit.studio.server import state_json

    def whole(values: dict[str, float], mode: int) -> dict[str, Any]:
        fresh = Tab(Design(rssr_copy))
        reply = fresh.handle(json.dumps({"type": "set", "values": values, "mode": mode}))
        return json.loads(state_json(fresh.with_scene(reply), {}))

    tab = Tab(Design(rssr_copy))
    page: dict[str, Any] = {}
    sizes: list[int] = []

    def send(message: dict[str, Any]) -> dict[str, Any]:
        reply = tab.handle(json.dumps(message))
        if reply["result"]["ok"]:
            reply = tab.with_scene(reply)
        text = state_json(reply, tab.sent)
        sizes.append(len(text))
        msg = json.loads(text)
        for path in msg["unchanged"] if msg["result"]["ok"] else []:  # the page's merge
            if path == ["scene"]:
                msg["scene"] = page["scene"]
                continue
            source, target = page, msg
            for key in path[:-1]:
                source, target = source[key], target[key]
            target[path[-1]] = source[path[-1]]
        page.update(result=msg["result"], scene=msg.get("scene"))
        return msg

    first = send({"type": "state"})
    assert first["unchanged"] == [] and first["result"]["ok"]
    moved = send({"type": "set", "values": {"dimensions.d2": 101.0}})
    kept = {tuple(p) for p in moved["unchanged"]}
    assert ("result", "input") in kept and ("scene", "input") in kept
    assert not {p for p in kept if p[0] == "result"} - {("result", "input")}
    assert ("scene", "modes", 0, "joint_centres") not in kept
    picked = send({"type": "set", "values": {}, "mode": 1})
    kept = {tuple(p) for p in picked["unchanged"]}
    assert {("result", k) for k in ("modes", "paths", "transmission", "input")} <= kept
    assert ("result", "loads") not in kept and ("scene", "modes", 1, "arrows") not in kept
    assert ("scene", "modes", 0, "link_points") in kept and ("scene", "modes", 1, "joint_centres") in kept
    assert sizes[-1] < 0.3 * sizes[-2]  # the curves and frames stay on the page
    want = whole({"dimensions.d2": 101.0}, 1)
    assert picked["result"] == want["result"] and picked["scene"] == want["scene"]
    bad = send({"type": "set", "values": {"dimensions.d2": 1000.0}})
    assert not bad["result"]["ok"] and bad["unchanged"] == [] and tab.sent == {}
    back = send({"type": "undo"})
    assert back["unchanged"] == [] and back["result"] == want["result"]
    assert back["scene"] == want["scene"]
    same = send({"type": "state"})
    assert same["unchanged"][-1] == ["scene"] and "scene" not in json.loads(
        state_json(tab.with_scene(tab.handle('{"type": "state"}')), dict(tab.sent)))
    assert same["result"] == want["result"] and same["scene"] == want["scene"]
