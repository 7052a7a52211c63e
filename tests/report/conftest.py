"""A headless Debian chromium driven by Playwright, one per test session (never a downloaded
browser: `make test` installs the `chromium` package when it is missing)."""

from __future__ import annotations

import io
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from browser_helpers import launch_chromium


@pytest.fixture(scope="session")
def browser_context(tmp_path_factory: pytest.TempPathFactory,
                    playwright_driver: Any) -> Iterator[Any]:
    context = launch_chromium(playwright_driver, tmp_path_factory.mktemp("chromium-profile"),
                             "report", viewport={"width": 1280, "height": 800})
    try:
        yield context
    finally:
        context.close()


@dataclass
class OpenPage:
    """A report page and everything it logged: console errors, uncaught exceptions and every
    request it made."""

    page: Any
    url: str
    errors: list[str] = field(default_factory=list)
    requests: list[str] = field(default_factory=list)

    def evaluate(self, script: str, arg: Any = None) -> Any:
        return self.page.evaluate(script, arg)

    def canvas_pixels(self) -> np.ndarray:
        from PIL import Image

        self.evaluate("screwkitViewer.renderNow()")
        png = self.page.locator(".sk-canvas canvas").screenshot()
        return np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)


@pytest.fixture
def open_report(browser_context: Any) -> Iterator[Any]:
    pages: list[Any] = []

    def opener(path: Path) -> OpenPage:
        page = browser_context.new_page()
        pages.append(page)
        url = path.resolve().as_uri()
        out = OpenPage(page, url)
        page.on("console", lambda m: out.errors.append(f"console: {m.text}") if m.type == "error" else None)
        page.on("pageerror", lambda e: out.errors.append(f"page error: {e}"))
        page.on("request", lambda r: out.requests.append(r.url))
        page.goto(url)
        page.wait_for_function("window.screwkitViewer !== undefined", timeout=20_000)
        return out

    yield opener
    for page in pages:
        page.close()
