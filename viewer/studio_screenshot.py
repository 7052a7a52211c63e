"""Make docs/studio.png: ``screwkit studio`` on examples/rssr_spatial.toml in headless Debian
chromium (driven by Playwright, no downloaded browser), after one dimension was dragged; and
docs/studio_graph.png, the double-wishbone graph spec after its lower ball joint was raised.
Run from the repository root:

    .venv/bin/python viewer/studio_screenshot.py docs/studio.png
    .venv/bin/python viewer/studio_screenshot.py docs/studio_graph.png \
        examples/mechanisms/double_wishbone.toml 'joints.LB.at[2]' 150
"""

from __future__ import annotations

import sys
import threading
import time

from playwright.sync_api import sync_playwright

from screwkit.studio.server import bind, make_server, new_studio, url_of

READY = """() => { const s = window.studio; return s.inflight === null && !s.pending
  && +document.body.dataset.drawn === s.lastChange && s.viewReady
  && +document.body.dataset.numbers > s.lastChange; }"""


def main(out: str, spec: str = "examples/rssr_spatial.toml", name: str = "dimensions.d2",
         value: str = "92") -> None:
    studio = new_studio(spec)
    sock = bind("127.0.0.1", 0)
    server = make_server(studio)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.02)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True,
                                        args=["--no-sandbox", "--disable-gpu"])
            page = browser.new_page(viewport={"width": 1400, "height": 860})
            page.goto(url_of(sock, studio.token))
            page.wait_for_function(READY, timeout=60_000)
            page.locator(f".dim[data-name='{name}'] input[type=range]").fill(value)
            page.wait_for_function(READY, timeout=60_000)
            page.evaluate("window.studio.setFrame(7)")
            page.evaluate("document.getElementById('view').contentWindow.screwkitViewer"
                          ".setView('iso')")
            page.wait_for_timeout(500)
            page.screenshot(path=out, type="png")
            browser.close()
    finally:
        server.should_exit = True
        thread.join(10)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*(sys.argv[1:] or ["docs/studio.png"]))
