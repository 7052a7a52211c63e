"""Run the CLI in-process under a time bound, recording warnings (shared by the bad-input corpus
and the fuzz tests)."""

from __future__ import annotations

import threading
import warnings
from typing import Any

import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app


def invoke_bounded(args: list[str], timeout: float) -> tuple[Any, list[str]]:
    """Run ``screwkit args`` in a thread; fail the test on a hang. Returns (result, warnings)."""
    box: dict[str, Any] = {}

    def run() -> None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            box["result"] = CliRunner().invoke(app, args)
        box["warnings"] = [f"{w.category.__name__}: {w.message}" for w in caught]

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(timeout)
    if worker.is_alive():
        pytest.fail(f"hang: still running after {timeout} s: screwkit {' '.join(args)}")
    return box["result"], box["warnings"]
