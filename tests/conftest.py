"""Shared test set-up: the tests folder is importable (helpers such as analysis_helpers)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from collections.abc import Iterator  # noqa: E402
from typing import Any  # noqa: E402

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def playwright_driver() -> Iterator[Any]:
    """The one Playwright driver of the session: the report's and the studio's browser tests
    both launch Debian's chromium from it (a second sync driver in the same process is
    refused by Playwright)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        yield p

