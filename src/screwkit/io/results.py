"""Results to JSON-able documents (SI units; null where a mode does not assemble) and atomic
file writes (a failed run never leaves a half-written file)."""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.outputs import write_text_atomic

SI_UNITS = {"length": "m", "angle": "rad", "time": "s", "mass": "kg", "force": "N",
            "moment": "N*m", "velocity": "per s (m/s or rad/s)", "acceleration": "per s^2"}


class NonFiniteResultError(InputError):
    """A result holding an infinite value (never written: strict JSON has no Infinity)."""


def jsonable(x: Any, where: str = "") -> Any:
    """numpy arrays/scalars → lists/floats. NaN becomes null: results use it only for the
    samples an ``assembles`` (or similar) mask leaves out, as docs/cli.md documents. An infinite
    value raises :class:`NonFiniteResultError` naming its key."""
    if isinstance(x, dict):
        return {str(k): jsonable(v, f"{where}.{k}" if where else str(k)) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [jsonable(v, f"{where}[{i}]") for i, v in enumerate(x)]
    if isinstance(x, np.ndarray):
        if x.dtype == bool:
            return x.tolist()
        if x.dtype.kind in "fc" and np.isinf(x).any():
            i = np.unravel_index(int(np.flatnonzero(np.isinf(x))[0]), x.shape)
            _infinite(f"{where}{list(map(int, i))}")
        return jsonable(x.tolist(), where)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, float | np.floating):
        f = float(x)
        if f in (float("inf"), float("-inf")):
            _infinite(where)
        return None if f != f else f
    return x


def _infinite(where: str) -> None:
    raise NonFiniteResultError(
        f"the result has an infinite value at {where or 'the top level'}; the inputs are "
        "probably outside the range the computation handles (see docs/reliability.md)")


def write_atomic(path: str | Path, text: str, inputs: Iterable[str | Path] = (),
                 option: str | None = None) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename,
    refusing an input of the command, a link, a FIFO, a device or a folder
    (:mod:`screwkit.io.outputs`)."""
    write_text_atomic(path, text, inputs, option)


def dumps(doc: Any) -> str:
    """Strict JSON (no NaN/Infinity tokens) of ``doc`` through :func:`jsonable`."""
    return json.dumps(jsonable(doc), indent=1, allow_nan=False)
