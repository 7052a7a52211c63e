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



@pytest.fixture(scope="session", autouse=True)
def start_solution_store(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """The store of start solutions (kinematics/modes/start_store.py) in a folder of this
    session, not the user's cache; Dask workers started by the tests inherit it."""
    import os

    folder = tmp_path_factory.mktemp("screwkit-cache")
    before = os.environ.get("SCREWKIT_CACHE_DIR")
    os.environ["SCREWKIT_CACHE_DIR"] = str(folder)
    yield folder
    if before is None:
        os.environ.pop("SCREWKIT_CACHE_DIR", None)
    else:
        os.environ["SCREWKIT_CACHE_DIR"] = before


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A store of start solutions of this test alone (its folder ``starts``), with the
    process's memory of them forgotten before and after."""
    from screwkit.kinematics.modes import start_store, starts

    monkeypatch.setenv(start_store.CACHE_ENV, str(tmp_path))
    starts.forget()
    yield tmp_path / "starts"
    starts.forget()
