"""Helpers of the sweep tests: write a design as its own spec file (a small TOML writer for
the spec format's subset: tables, arrays of tables, strings, numbers, booleans, lists) and run
a single-spec command on it."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.toml_file import read_toml
from screwkit.sweep.keys import parse_key, with_values

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def _scalar(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        assert math.isfinite(v)
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_scalar(x) for x in v) + "]"
    raise TypeError(type(v))


def toml_text(data: dict[str, Any], prefix: str = "") -> str:
    """TOML for the spec format's tables (numbers written exactly: repr round-trips)."""
    lines = []
    plain = {k: v for k, v in data.items()
             if not isinstance(v, dict) and not (isinstance(v, list) and v and isinstance(v[0], dict))}
    if prefix and plain:
        lines.append(f"[{prefix}]")
    for k, v in plain.items():
        lines.append(f"{json.dumps(k)} = {_scalar(v)}")
    for k, v in data.items():
        name = f"{prefix}.{json.dumps(k)}" if prefix else json.dumps(k)
        if isinstance(v, dict):
            if not any(not isinstance(x, dict) for x in v.values()) and not v:
                lines.append(f"[{name}]")
            lines.append(toml_text(v, name))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines.append(f"[[{name}]]")
                lines.extend(f"{json.dumps(a)} = {_scalar(b)}" for a, b in item.items())
    return "\n".join(x for x in lines if x) + "\n"


def design_spec(spec: Path, overrides: dict[str, Any], folder: Path, name: str) -> Path:
    """The design ``spec`` with ``overrides`` (key text → TOML value) as its own file."""
    data = read_toml(spec)
    values = [(parse_key(k), v) for k, v in overrides.items()]
    path = folder / f"{name}.toml"
    path.write_text(toml_text(with_values(data, values)), encoding="utf-8")
    assert read_toml(path) == with_values(data, values)  # the writer is exact
    return path


def command_json(*args: str) -> dict[str, Any]:
    """The JSON document of a single-spec command (``--json``)."""
    r = runner.invoke(app, [*args, "--json"])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


@contextmanager
def real_dask(folder: Path, workers: int = 2, env: dict[str, str] | None = None) -> Iterator[str]:
    """A ``dask scheduler`` and ``workers`` ``dask worker`` processes on 127.0.0.1 (random free
    ports; ``env`` added to their environment), stopped on exit; yields the address."""
    dask = Path(sys.executable).with_name("dask")
    assert dask.exists(), "the dask command comes with the [sweep] extra"
    info = folder / "scheduler.json"
    full = {**os.environ, "PYTHONWARNINGS": "ignore", **(env or {})}
    procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(info)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=full)]
    try:
        deadline = time.monotonic() + 60
        while not info.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        time.sleep(0.3)
        address = json.loads(info.read_text())["address"]
        for _ in range(workers):
            procs.append(subprocess.Popen(
                [str(dask), "worker", address, "--nthreads", "1", "--nworkers", "1",
                 "--host", "127.0.0.1", "--no-dashboard"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=full))
        yield address
    finally:
        for p in procs:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=10)
