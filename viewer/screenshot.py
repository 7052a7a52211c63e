"""Make docs/report.png: the report of examples/rssr_spatial.toml in headless Debian chromium
(driven by Playwright, no downloaded browser). Run from the repository root:

    .venv/bin/python viewer/screenshot.py docs/report.png
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from playwright.sync_api import sync_playwright

from screwkit.cli.report_cmd import spec_scene
from screwkit.io.spec import load_spec
from screwkit.report.viewer import render_report_html


def main(out: str) -> None:
    page_text = render_report_html(spec_scene(load_spec("examples/rssr_spatial.toml")))
    with tempfile.TemporaryDirectory() as tmp:
        html = Path(tmp) / "rssr_spatial.html"
        html.write_text(page_text, encoding="utf-8")
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                str(Path(tmp) / "profile"), executable_path="/usr/bin/chromium", headless=True,
                args=["--no-sandbox", "--disable-gpu", "--disable-background-networking",
                      "--disable-component-update", "--disable-sync", "--no-first-run"],
                viewport={"width": 1400, "height": 860})
            page = context.new_page()
            page.goto(html.as_uri())
            page.wait_for_function("window.screwkitViewer !== undefined")
            page.evaluate("screwkitViewer.pause(); screwkitViewer.setFrame(7); "
                          "screwkitViewer.setView('iso'); screwkitViewer.renderNow()")
            page.wait_for_timeout(500)
            page.screenshot(path=out)
            context.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/report.png")
