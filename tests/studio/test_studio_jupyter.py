"""The studio's notebook controls (screwkit.studio.notebook, ipywidgets) in a real JupyterLab:
a server started here on 127.0.0.1 (a free port, its own token and config folders), a notebook
that makes the widget opened in headless Debian chromium, the cell run, a dimension slider
dragged with the mouse: the kernel's design takes the new value and the report's page in the
output takes the new design in place (the same iframe; its plots redraw with another curve). JupyterLab and ipykernel come from the dev extra."""

from __future__ import annotations

import json
import os
import secrets
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from browser_helpers import launch_chromium

EXAMPLES = Path(__file__).parents[2] / "examples"
SRC = Path(__file__).parents[2] / "src"
#: the test's bound (s): JupyterLab up, the page loaded, the kernel started, the cell run …
BOUND = 90.0

CELLS = [
    "from screwkit.studio.notebook import studio\nw = studio('rssr.toml', height=420)\nw",
    "print('d2 =', w.tab.state.as_dict['dimensions.d2'])",
]


def _notebook(folder: Path) -> None:
    cells = [{"cell_type": "code", "execution_count": None, "id": f"cell{k}", "metadata": {},
              "outputs": [], "source": src} for k, src in enumerate(CELLS)]
    nb = {"cells": cells, "nbformat": 4, "nbformat_minor": 5,
          "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3",
                                      "language": "python"}}}
    (folder / "studio.ipynb").write_text(json.dumps(nb), encoding="utf-8")
    (folder / "rssr.toml").write_text((EXAMPLES / "rssr_spatial.toml").read_text("utf-8"),
                                      encoding="utf-8")


@pytest.fixture(scope="module")
def jupyter(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """A JupyterLab server on 127.0.0.1 serving a folder with the notebook; its URL."""
    base = tmp_path_factory.mktemp("jupyter")
    root = base / "notebooks"
    root.mkdir()
    _notebook(root)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    token = secrets.token_hex(16)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]),
           "JUPYTER_CONFIG_DIR": str(base / "config"), "JUPYTER_RUNTIME_DIR": str(base / "run"),
           "JUPYTER_DATA_DIR": str(base / "data"), "IPYTHONDIR": str(base / "ipython")}
    args = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1",
            f"--port={port}", f"--IdentityProvider.token={token}",
            f"--ServerApp.root_dir={root}", "--ServerApp.terminals_enabled=False",
            "--LabApp.news_url=", "--LabApp.extension_manager=readonly",
            "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.append("--allow-root")  # a CI container runs as root
    log = (base / "jupyter.log").open("w")
    proc = subprocess.Popen(args, env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/api/status?token={token}",
                                       timeout=2).close()
                break
            except OSError:
                if time.monotonic() > deadline or proc.poll() is not None:
                    pytest.fail("JupyterLab did not start:\n"
                                + (base / "jupyter.log").read_text(encoding="utf-8")[-3000:])
                time.sleep(0.2)
        yield f"http://127.0.0.1:{port}/lab/tree/studio.ipynb?token={token}"
    finally:
        proc.terminate()
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()


def _viewer(page: Any) -> tuple[Any, Any]:
    """The iframe element of the report in the cell's output and its frame, once the report's
    viewer is up in it."""
    element = page.locator(".jp-OutputArea iframe").first.element_handle(timeout=60_000)
    frame = element.content_frame()
    assert frame is not None
    frame.wait_for_function("() => !!window.screwkitViewer && "
                            "document.querySelectorAll('#sk-plots canvas').length > 0",
                            timeout=60_000)
    return element, frame


def _plots(frame: Any) -> str:
    """The pixels of every plot of the report in the output, as PNG data URLs."""
    frame.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    return str(frame.evaluate(
        "[...document.querySelectorAll('#sk-plots canvas')].map(c => c.toDataURL()).join('|')"))


def test_the_controls_in_jupyterlab(jupyter: str, playwright_driver: Any,
                                    tmp_path: Path) -> None:
    start = time.monotonic()
    context = launch_chromium(playwright_driver, tmp_path / "profile", "Jupyter",
                              viewport={"width": 1400, "height": 1000})
    try:
        page = context.new_page()
        page.goto(jupyter)
        page.wait_for_selector(".jp-Notebook .jp-Cell .cm-content", timeout=60_000)
        page.wait_for_function(  # the kernel has started and is idle
            "() => / Idle/.test(document.querySelector('#jp-main-statusbar').textContent)",
            timeout=60_000)
        page.locator(".jp-Notebook .jp-Cell .cm-content").first.click()
        page.keyboard.press("Shift+Enter")
        output = page.locator(".jp-OutputArea .widget-slider")
        output.first.wait_for(timeout=60_000)
        names = page.locator(".jp-OutputArea .widget-slider .widget-label").all_inner_texts()
        assert names[:3] == ["d1", "d2", "d3"], names
        element, frame = _viewer(page)
        before = _plots(frame)
        # drag d2's slider to the right with the mouse; released, the kernel solves again
        handle = output.nth(1).locator(".noUi-handle")
        box = handle.bounding_box()
        assert box is not None
        y = box["y"] + box["height"] / 2
        page.mouse.move(box["x"] + box["width"] / 2, y)
        page.mouse.down()
        page.mouse.move(box["x"] + 60, y, steps=6)
        page.mouse.up()
        value = page.locator(".jp-OutputArea .widget-text input").nth(1)
        page.wait_for_function("el => +el.value > 100", arg=value.element_handle(),
                               timeout=30_000)
        shown = float(value.input_value())
        # the report shown takes the new design in place (the kernel posts its scene to the
        # viewer): the same iframe, still connected, and no second one; another curve drawn
        frame.wait_for_function("() => document.body.dataset.updates === '1'", timeout=30_000)
        assert element.evaluate("el => el.isConnected")
        assert page.locator(".jp-OutputArea iframe").count() == 1
        assert _plots(frame) != before
        # the kernel's design holds the value the box shows
        second = page.locator(".jp-Notebook .jp-Cell").nth(1)
        second.locator(".jp-InputPrompt").click()  # selects the cell (command mode)
        page.keyboard.press("Shift+Enter")
        printed = second.locator(".jp-OutputArea-output pre", has_text="d2 =")
        printed.wait_for(timeout=30_000)
        assert float(printed.inner_text().split("=")[1]) == pytest.approx(shown, abs=1e-9)
    finally:
        context.close()
    assert time.monotonic() - start < BOUND
