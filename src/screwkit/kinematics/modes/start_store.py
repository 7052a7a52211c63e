"""Start solutions kept on disk per topology, so that a process finds them once (issue 27).

A topology's :class:`~screwkit.algebraic.solve.StartSolutions` (every solution at one generic
complex parameter vector) cost a total-degree or multi-homogeneous homotopy, or a monodromy
run, to find; every later design of the topology needs only a parameter homotopy from them
(Sommese & Wampler, *The Numerical Solution of Systems of Polynomials*, 2005, §7.1). They are
written to one file per topology key (:func:`~screwkit.kinematics.modes.starts.system_key`)
in the user's cache folder: ``$SCREWKIT_CACHE_DIR`` when set, otherwise the platform's cache
folder (``$XDG_CACHE_HOME/screwkit`` or ``~/.cache/screwkit`` on Linux,
``~/Library/Caches/screwkit`` on macOS, ``%LOCALAPPDATA%\\screwkit\\Cache`` on Windows, as the
``platformdirs`` convention has it), under ``starts/``. ``SCREWKIT_CACHE_DIR=off`` keeps them
in memory only.

A file is written atomically (a temporary file in the same folder, then ``os.replace``), so a
reader never sees half of one, and is trusted only after a check on load: the key stored in it
equals the system's, the count is the generic count when the caller knows it (Stewart–Gough
40, 6R 16), the arrays fit the system's unknowns and parameters, every start solution
is distinct and solves the start system (one Newton step from it moves it by at most
:data:`NEWTON_TOLERANCE` relative, and its residual is at most that relative to the size of its
terms). A file that fails is ignored and replaced.
"""

from __future__ import annotations

import os
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from screwkit.algebraic.certify import term_magnitude
from screwkit.algebraic.polynomial import PolynomialSystem
from screwkit.algebraic.solve import StartSolutions

#: environment variable naming the cache folder ("off": nothing on disk)
CACHE_ENV = "SCREWKIT_CACHE_DIR"
#: the file layout's version (a file of another version is ignored)
FORMAT = 1
#: a stored start solution must move by at most this (relative) under one Newton step
NEWTON_TOLERANCE = 1e-8


def cache_dir() -> Path | None:
    """The folder of stored start solutions (module docstring), or None when switched off."""
    env = os.environ.get(CACHE_ENV)
    if env is not None and env.strip():
        return None if env.strip().lower() == "off" else Path(env).expanduser() / "starts"
    if sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches" / "screwkit"
    elif os.name == "nt":
        base = Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local")) \
            / "screwkit" / "Cache"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "screwkit"
    return base / "starts"


def store_path(key: str) -> Path | None:
    """The file of the topology ``key`` (None when the cache is off)."""
    folder = cache_dir()
    return None if folder is None else folder / f"{key[:40]}.npz"


def save(key: str, start: StartSolutions) -> Path | None:
    """Write ``start`` for ``key`` atomically; None (nothing written) when the cache is off or
    its folder cannot be written (the start solutions then live in memory only)."""
    path = store_path(key)
    if path is None:
        return None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".starts-", suffix=".npz", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, format=np.int64(FORMAT), key=np.str_(key), p=start.p, x=start.x,
                         generic_count=np.int64(start.generic_count),
                         how_found=np.str_(start.how_found), paths=np.int64(start.paths),
                         count_check=np.str_(start.count_check))
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return None
    return path


def load(key: str, system: PolynomialSystem,
         expected: int | None = None) -> StartSolutions | None:
    """The stored start solutions of ``key`` when a file holds them and they pass the checks
    of the module docstring (and number ``expected``, the generic count, when it is known);
    otherwise None."""
    path = store_path(key)
    if path is None or not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as f:
            if int(f["format"]) != FORMAT or str(f["key"]) != key:
                return None
            p = np.asarray(f["p"], dtype=complex)
            x = np.asarray(f["x"], dtype=complex)
            # (a file written before the trace test has no count_check: not checked)
            check = str(f["count_check"]) if "count_check" in f.files else ""
            start = StartSolutions(p, x, int(f["generic_count"]), str(f["how_found"]),
                                   int(f["paths"]), check)
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):  # damaged, foreign
        return None
    if expected is not None and start.generic_count != expected:
        return None
    return start if verified(system, start) else None


def verified(system: PolynomialSystem, start: StartSolutions) -> bool:
    """Whether ``start`` fits ``system`` and each of its points solves it at ``start.p`` (one
    Newton step moves it by at most :data:`NEWTON_TOLERANCE` relative), all distinct."""
    x, p = start.x, start.p
    if (x.ndim != 2 or x.shape[1] != system.n or p.shape != (system.k,)
            or len(x) != start.generic_count or len(x) == 0
            or not (np.isfinite(x).all() and np.isfinite(p).all())):
        return False
    with np.errstate(all="ignore"):
        F, J, _ = system.evaluate(x, p, want_jp=False)
        scale = 1.0 + np.abs(x).max(axis=1)
        try:
            step = np.linalg.solve(J, F[..., None])[..., 0]
        except np.linalg.LinAlgError:
            return False
        residual = np.abs(F).max(axis=1) / np.maximum(1.0, term_magnitude(system, x, p).max(
            axis=1))
    if not (np.abs(step).max(axis=1) <= NEWTON_TOLERANCE * scale).all():
        return False
    if not (residual <= NEWTON_TOLERANCE).all():
        return False
    gaps = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2)
    np.fill_diagonal(gaps, np.inf)
    return bool((gaps > 1e3 * NEWTON_TOLERANCE * np.maximum.outer(scale, scale)).all())
