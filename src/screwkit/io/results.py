"""Results to JSON-able documents (SI units; null where a mode does not assemble) and atomic
file writes (a failed run never leaves a half-written file)."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

SI_UNITS = {"length": "m", "angle": "rad", "time": "s", "mass": "kg", "force": "N",
            "moment": "N*m", "velocity": "per s (m/s or rad/s)", "acceleration": "per s^2"}


def jsonable(x: Any) -> Any:
    """numpy arrays/scalars → lists/floats with NaN → None."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        if x.dtype == bool:
            return x.tolist()
        return jsonable(x.tolist())
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, float | np.floating):
        f = float(x)
        return None if f != f or f in (float("inf"), float("-inf")) else f
    return x


def write_atomic(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename."""
    p = Path(path)
    if p.parent and not p.parent.exists():
        raise ValueError(f"cannot write {p}: folder {p.parent} does not exist")
    if p.is_dir():
        raise ValueError(f"cannot write {p}: it is a folder; give a file name, e.g. {p / 'result.json'}")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=str(p.parent or "."))
    except OSError as exc:
        raise ValueError(f"cannot write {p}: {exc.strerror}") from exc
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; results are ordinary files
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def dumps(doc: Any) -> str:
    return json.dumps(jsonable(doc), indent=1, allow_nan=False)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
