"""A studio served in-process on a free port (one per test module) of a copy of a bundled
example, and a headless Debian chromium driven by Playwright (never a downloaded browser)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from studio_serving import EXAMPLES, Served, serve

from browser_helpers import launch_chromium


@pytest.fixture(scope="module")
def rssr_copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The spatial RSSR example (with its comments) at 360 input samples, in a temporary
    folder the studio may overwrite."""
    folder = tmp_path_factory.mktemp("studio")
    text = (EXAMPLES / "rssr_spatial.toml").read_text(encoding="utf-8")
    assert "step = 10\n" in text
    spec = folder / "rssr_spatial.toml"
    spec.write_text(text.replace("step = 10\n", "step = 1\n"), encoding="utf-8")
    return spec


@pytest.fixture(scope="module")
def serve_spec() -> Any:
    """:func:`serve`, for a test module that serves another spec (its own ``served``)."""
    return serve


@pytest.fixture(scope="module")
def served(rssr_copy: Path) -> Iterator[Served]:
    yield from serve(rssr_copy, save_as=rssr_copy.with_name("rssr_exported.toml"))


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory,
            playwright_driver: Any) -> Iterator[Any]:
    context = launch_chromium(playwright_driver, tmp_path_factory.mktemp("chromium-profile"),
                             "studio", viewport={"width": 1400, "height": 900},
                             accept_downloads=True)
    try:
        yield context
    finally:
        context.close()


@dataclass
class StudioPage:
    page: Any
    errors: list[str]

    def evaluate(self, script: str, arg: Any = None) -> Any:
        return self.page.evaluate(script, arg)

    def wait_drawn(self) -> None:
        """Until the answer to the page's last change is drawn (curves) and its 3-D view is
        loaded, and, for a warm-started answer (a joint list's motion from the design before),
        until the server has confirmed it (``checked``) or sent the answer solved anew."""
        self.page.wait_for_function(
            """() => { const s = window.studio; return s.inflight === null && !s.pending
              && +document.body.dataset.drawn === s.lastChange && s.viewReady
              && (!s.result || !s.result.warm || s.checked === s.state.seq); }""",
            timeout=30_000)

    def wait_numbers(self) -> None:
        """Until the numbers table of the last change has arrived."""
        self.page.wait_for_function(
            "() => +document.body.dataset.numbers > window.studio.lastChange", timeout=30_000)

    def result(self) -> Any:
        return self.evaluate("window.studio.result")


@pytest.fixture
def open_studio(browser: Any, served: Served) -> Iterator[Any]:
    pages: list[Any] = []

    def opener() -> StudioPage:
        page = browser.new_page()
        pages.append(page)
        out = StudioPage(page, [])
        page.on("console", lambda m: out.errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: out.errors.append(f"page error: {e}"))
        page.goto(served.url)
        out.wait_drawn()
        return out

    yield opener
    for page in pages:
        page.close()
