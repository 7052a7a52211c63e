"""Debian's chromium for the browser tests (tests/report, tests/studio), launched from the
session's one Playwright driver (tests/conftest.py: ``playwright_driver``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run",
                 "--disable-default-apps", "--disable-extensions"]


def launch_chromium(driver: Any, profile: Path, what: str, **options: Any) -> Any:
    """Debian's chromium, headless, in a fresh profile (a clear failure when it is missing)."""
    if not CHROMIUM.exists():
        pytest.fail(f"the {what} tests need Debian's chromium at /usr/bin/chromium: run "
                    "`make test` (it installs it) or `apt-get install -y chromium`")
    return driver.chromium.launch_persistent_context(
        str(profile), executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_ARGS,
        **options)
