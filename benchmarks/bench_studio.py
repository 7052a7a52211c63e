"""``screwkit studio``: the time from a dimension change to the redrawn page for a single loop at
360 samples (target ≤ 100 ms, issue 29), side by side for the RSSR (closed form, with loads)
and the RRSRR joint list (the tracker, warm-started from the design before: docs/studio.md,
"Speed"). Server side: one tab's answer to a ``set`` message as sent (solve, curves, loads,
the 3-D scene in the same message, JSON) with its CPU breakdown, and the warm start's check
after it, wall and CPU time; in the
browser (headless Debian chromium, when installed): input event → curves redrawn, and → the
frame where the 3-D view shows the new design too (the whole page redrawn: the view updates in
place), median of 10 moves, with the page's phases; and the machine's load during the run."""

from __future__ import annotations

import json
import os
import statistics
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path("/usr/bin/chromium")


def _at_360(name: str, folder: Path) -> Path:
    text = (ROOT / "examples" / name).read_text(encoding="utf-8")
    path = folder / name
    path.write_text(text.replace("step = 10\n", "step = 1\n"), encoding="utf-8")
    return path


def _server_side(spec: Path, key: str, value: float) -> dict[str, float]:
    """Median wall and CPU time (ms) of a tab's answers to a ``set`` message as the server
    sends them — the ``state`` with its 3-D scene in one message (solve, curves, loads,
    scene, JSON without the parts the page holds) — and of a warm start's check after it
    (Tab.verify); how many answers were warm starts; and the CPU breakdown of one answer on a
    fresh pipeline (kinematics, transmission, loads, the rest of the curves, the scene, the
    JSON). CPU time (this thread's) is what the answer costs on an idle machine; wall time
    what it took here."""
    from screwkit.pipeline import Pipeline
    from screwkit.studio.design import Design
    from screwkit.studio.server import state_json
    from screwkit.studio.session import Tab
    from screwkit.studio.solve import (
        dynamics_document,
        packed_scene,
        shown_transmission,
        solve_spec,
    )

    tab = Tab(Design(spec))
    warm = 0
    times: dict[str, list[float]] = {"state": [], "state_cpu": [], "check": [], "check_cpu": []}
    parts: dict[str, list[float]] = {k: [] for k in (
        "spec", "kinematics", "transmission", "loads", "curves", "scene", "json")}
    state_json(tab.with_scene(tab.handle(json.dumps({"type": "state", "seq": 0}))), tab.sent)
    tab.verify()
    for k in range(7):
        message = json.dumps({"type": "set", "seq": k + 1, "values": {key: value + 0.01 * (k + 1)}})
        t, c = time.perf_counter(), time.thread_time()
        reply = tab.handle(message)
        assert reply["type"] == "state" and reply["result"]["ok"], reply
        state_json(tab.with_scene(reply), tab.sent)
        times["state"].append(time.perf_counter() - t)
        times["state_cpu"].append(time.thread_time() - c)
        t, c = time.perf_counter(), time.thread_time()
        checked = tab.verify()  # a warm start's confirmation (None: nothing to confirm)
        times["check"].append(time.perf_counter() - t)
        times["check_cpu"].append(time.thread_time() - c)
        assert checked is not True, "a warm start was replaced"
        warm += checked is False
        # the breakdown, on a fresh pipeline of the same values (solved anew)
        c = time.thread_time()
        pipe = Pipeline(tab.design.spec_with(tab.state.as_dict, tab.state.mode))
        parts["spec"].append(time.thread_time() - c)
        for name, job in (("kinematics", lambda p: p.motion),
                          ("transmission", shown_transmission),
                          ("loads", dynamics_document),
                          ("curves", lambda p: solve_spec(p, numbers=False, scene=False)),
                          ("scene", packed_scene)):
            c = time.thread_time()
            job(pipe)
            parts[name].append(time.thread_time() - c)
        whole = {**reply, "result": solve_spec(pipe, numbers=False, scene=False),
                 "scene": packed_scene(pipe)}
        c = time.thread_time()
        state_json(whole, {})
        parts["json"].append(time.thread_time() - c)
    out = {k: statistics.median(v) * 1e3 for k, v in times.items()}
    out.update({f"cpu_{k}": statistics.median(v) * 1e3 for k, v in parts.items()})
    return {**out, "warm": warm}


#: the page is idle: the last change's curves and 3-D view drawn, a warm start confirmed
IDLE = """() => { const s = window.studio; return s.inflight === null && !s.pending
          && +document.body.dataset.drawn === s.lastChange && s.viewReady
          && (!s.result || !s.result.warm || s.checked === s.state.seq); }"""


def _browser(spec: Path, key: str, values: list[float]) -> dict[str, Any] | None:
    """Input event → curves redrawn and → page redrawn (curves and 3-D view) for slider moves
    of ``key`` to ``values`` (each after the page is idle), medians; the phases of the page
    (answer arrived, its JSON parsed, curves drawn, scene arrived, view updated); how many
    answers were warm starts."""
    if not CHROMIUM.exists():
        return None
    from playwright.sync_api import sync_playwright

    from screwkit.studio.server import bind, make_server, new_studio, url_of

    studio = new_studio(spec)
    sock = bind("127.0.0.1", 0)
    server = make_server(studio)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.02)
    n = len(values)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True,
                                        args=["--no-sandbox", "--disable-gpu"])
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            page.goto(url_of(sock, studio.token))
            page.wait_for_function(IDLE, timeout=60_000)
            slider = page.locator(f".dim[data-name='{key}'] input[type=range]")
            warm = 0
            for v in values:
                slider.fill(str(v))
                page.wait_for_function(IDLE, timeout=60_000)
                warm += bool(page.evaluate("window.studio.result.warm === true && "
                                           "window.studio.checked === window.studio.state.seq"))
            page.wait_for_function(f"window.studio.viewLatencies.length >= {n + 1}",
                                   timeout=60_000)
            curves = page.evaluate("window.studio.latencies")[-n:]
            view = page.evaluate("window.studio.viewLatencies")[-n:]
            assert page.evaluate("window.studio.viewUpdates") >= n  # in place, no reload
            phases = page.evaluate(f"window.studio.phases.slice(-{n})")
            browser.close()
    finally:
        server.should_exit = True
        thread.join(10)
        sock.close()
    out = {k: statistics.median(p[k] for p in phases)
           for k in ("answer", "parse", "draw", "scene", "update")}
    out.update(curves=statistics.median(curves), view=statistics.median(view),
               view_max=max(view), warm=warm, moves=n)
    return out


def run() -> list[dict[str, Any]]:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rssr = _at_360("rssr_spatial.toml", folder)
        loop = _at_360("rrsrr_loop.toml", folder)
        rows = []
        for label, spec, key, value in (
                ("RSSR (closed form, loads)", rssr, "dimensions.d2", 100.0),
                ("RRSRR joint list (tracker)", loop, "joints[1].length", 111.6)):
            t = _server_side(spec, key, value)
            rows += [
                {"name": f"server: state answer with its 3-D scene, {label}, 360 samples",
                 "value": t["state"], "unit": "ms", "target": "≤ 100",
                 "note": f"one message: solve, curves, loads, scene, JSON; CPU "
                         f"{t['state_cpu']:.1f} ms"},
                {"name": f"server: CPU breakdown of an answer solved anew, {label}",
                 "value": sum(t[f"cpu_{k}"] for k in ("spec", "kinematics", "transmission",
                                                       "loads", "curves", "scene", "json")),
                 "unit": "ms", "target": "",
                 "note": "; ".join(f"{k} {t[f'cpu_{k}']:.1f}" for k in (
                     "spec", "kinematics", "transmission", "loads", "curves", "scene", "json"))
                         + " (curves: the rest of the state; json: without the parts sent)"},
                {"name": f"server: the warm start's check after that, {label}",
                 "value": t["check"] if t["warm"] else None, "unit": "ms", "target": "",
                 "note": f"CPU {t['check_cpu']:.0f} ms; {t['warm']}/7 answers warm-started"
                         if t["warm"] else "not warm-started (a closed form)"},
            ]
        for label, spec, key, values in (
                ("RSSR (closed form, loads)", rssr, "dimensions.d2", [101.0 + k for k in range(10)]),
                ("RRSRR joint list (tracker)", loop, "joints[1].length",
                 [112.0 + k for k in range(10)])):
            shown = _browser(spec, key, values)
            if shown is None:
                rows.append({"name": f"browser: input → redraw, {label}", "value": None,
                             "unit": "ms", "target": "≤ 100",
                             "note": "no /usr/bin/chromium: not measured"})
                continue
            rows += [
                {"name": f"browser: input event → curves redrawn, {label}, 360 samples",
                 "value": shown["curves"], "unit": "ms", "target": "≤ 100",
                 "note": f"median of {shown['moves']}"},
                {"name": f"browser: input event → page redrawn (curves and 3-D view), {label}, "
                 "360 samples", "value": shown["view"], "unit": "ms", "target": "≤ 100",
                 "note": f"median of {shown['moves']} (max {shown['view_max']:.0f}); the view "
                         f"updated in place; answer at {shown['answer']:.0f} ms (its JSON "
                         f"parsed in {shown['parse']:.0f}), curves drawn in "
                         f"{shown['draw']:.0f}, scene at {shown['scene']:.0f} ms, the view's "
                         f"update {shown['update']:.0f} ms; warm starts confirmed: "
                         f"{shown['warm']}/{shown['moves']}"},
            ]
    rows.append({"name": "machine load during the run (1-min load average, 2 cores)",
                 "value": os.getloadavg()[0], "unit": "", "target": "",
                 "note": "wall times above grow with it; CPU times do not"})
    return rows
