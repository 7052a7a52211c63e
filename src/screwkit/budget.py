"""Bounded work: estimate the memory and the computing time a computation needs before running
it and refuse, with a sentence saying what to change, anything over a limit the user can raise
(``screwkit --max-memory 16GB …`` or ``SCREWKIT_MAX_MEMORY``; ``screwkit --max-time 10min …`` or
``SCREWKIT_MAX_TIME``; docs/reliability.md)."""

from __future__ import annotations

import os
import re

from screwkit.errors import InputError

#: the default limit: half the machine's memory, at most 16 GiB
_GIB = 1024**3


def _physical_memory() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return 8 * _GIB


DEFAULT_MEMORY_LIMIT = min(16 * _GIB, _physical_memory() // 2)
_limit: int | None = None

_UNITS = {"b": 1, "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40, "k": 10**3, "m": 10**6,
          "g": 10**9, "t": 10**12}


class ResourceLimitError(InputError):
    """A computation would need more memory than the limit; the message says how to shrink it
    or raise the limit."""


def parse_size(text: str) -> int:
    """``"16GB"``, ``"512 MiB"``, ``"2e9"`` → bytes."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)\s*", str(text))
    unit = (m.group(2).lower() if m else "") or "b"
    if m is None or unit not in _UNITS:
        raise InputError(f"a memory size is a number with an optional unit (B, kB, MB, GB, TB, "
                         f"KiB, MiB, GiB, TiB), e.g. '16GB'; got {str(text)[:40]!r}")
    size = float(m.group(1)) * _UNITS[unit]
    if not size > 0:
        raise InputError(f"a memory limit must be positive; got {text!r}")
    return int(size)


def set_memory_limit(size: int | str | None) -> None:
    """Set the limit (bytes, or a size text); ``None`` restores the default."""
    global _limit
    _limit = None if size is None else (parse_size(size) if isinstance(size, str) else int(size))


def memory_limit() -> int:
    """The limit in force: set by :func:`set_memory_limit`, else ``SCREWKIT_MAX_MEMORY``, else
    :data:`DEFAULT_MEMORY_LIMIT`."""
    if _limit is not None:
        return _limit
    env = os.environ.get("SCREWKIT_MAX_MEMORY")
    return parse_size(env) if env else DEFAULT_MEMORY_LIMIT


def human(size: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if size < 1000 or unit == "TB":
            return f"{size:.3g} {unit}"
        size /= 1000
    return f"{size:.3g} TB"


def check_memory(estimate: float, what: str, advice: str) -> None:
    """Refuse ``what`` if it needs about ``estimate`` bytes, more than the limit."""
    limit = memory_limit()
    if estimate > limit:
        raise ResourceLimitError(
            f"{what} needs about {human(estimate)}, over the {human(limit)} memory limit; "
            f"{advice}, or raise the limit with `screwkit --max-memory SIZE …` (or the "
            "environment variable SCREWKIT_MAX_MEMORY)")


#: the default limit on the estimated computing time of one solve, seconds
DEFAULT_TIME_LIMIT = 60.0
_time_limit: float | None = None
_SECONDS = {"": 1.0, "s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0}


def parse_duration(text: str) -> float:
    """``"90"``, ``"90s"``, ``"10min"``, ``"2h"`` → seconds."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)\s*", str(text))
    unit = m.group(2).lower() if m else ""
    if m is None or unit not in _SECONDS:
        raise InputError(f"a time limit is a number with an optional unit (s, min, h), e.g. "
                         f"'10min'; got {str(text)[:40]!r}")
    seconds = float(m.group(1)) * _SECONDS[unit]
    if not seconds > 0:
        raise InputError(f"a time limit must be positive; got {text!r}")
    return seconds


def set_time_limit(limit: float | str | None) -> None:
    """Set the limit on estimated computing time (seconds, or a duration text); ``None``
    restores the default."""
    global _time_limit
    _time_limit = (None if limit is None
                   else parse_duration(limit) if isinstance(limit, str) else float(limit))


def time_limit() -> float:
    """The limit in force: set by :func:`set_time_limit`, else ``SCREWKIT_MAX_TIME``, else
    :data:`DEFAULT_TIME_LIMIT`."""
    if _time_limit is not None:
        return _time_limit
    env = os.environ.get("SCREWKIT_MAX_TIME")
    return parse_duration(env) if env else DEFAULT_TIME_LIMIT


def human_time(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.2g} s"
    if seconds < 5400:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.2g} h"


def check_time(estimate: float, what: str, advice: str) -> None:
    """Refuse ``what`` if it needs about ``estimate`` seconds of computing, more than the
    limit."""
    limit = time_limit()
    if estimate > limit:
        raise ResourceLimitError(
            f"{what} needs about {human_time(estimate)} of computing, over the "
            f"{human_time(limit)} time limit; {advice}, or raise the limit with "
            "`screwkit --max-time DURATION …` (e.g. 10min; or the environment variable "
            "SCREWKIT_MAX_TIME)")
