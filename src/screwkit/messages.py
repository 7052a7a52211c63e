"""Numbers for people in notes and error messages: one helper, :func:`shown`, formats an SI
value of a quantity kind in the units the reader chose (issue 30: notes printed
``[np.float64(4.363323129985823)]`` in radians for a spec in degrees).

The units come from the caller (``units=``) or, where a message is built deep inside a solver
that knows no units, from :func:`message_units`: a context that :class:`screwkit.Pipeline`
enters with the spec's display units around every job (the CLI passes the units of
``--units``/``--unit``), so a note or an error of a mm/deg spec quotes mm and degrees. With no
units anywhere, angles are shown in degrees and everything else in SI.

Like :mod:`screwkit.tables`, this module needs numpy only; every layer may use it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np

from screwkit.tables import SI_LABELS, UNITLESS, UnitChoice

#: significant digits of a number in a message
DIGITS = 6


class ReadableUnits:
    """The default for messages without a spec: angles (and their rates) in degrees, every
    other kind in SI."""

    _DEG = {"angle": ("deg", math.pi / 180), "angular_velocity": ("deg/s", math.pi / 180),
            "angular_acceleration": ("deg/s^2", math.pi / 180)}

    def unit_of(self, kind: str) -> tuple[str, float]:
        return self._DEG.get(kind) or (SI_LABELS.get(kind, ""), 1.0)


_UNITS: ContextVar[UnitChoice | None] = ContextVar("screwkit_message_units", default=None)


@contextmanager
def message_units(units: UnitChoice | None) -> Iterator[None]:
    """Within the block, :func:`shown` (and every note and message built with it) uses
    ``units`` where its caller gives none; ``None`` keeps the units already in force."""
    if units is None:
        yield
        return
    token = _UNITS.set(units)
    try:
        yield
    finally:
        _UNITS.reset(token)


def current_units() -> UnitChoice:
    """The units messages use here: those of :func:`message_units`, else degrees and SI."""
    return _UNITS.get() or ReadableUnits()


def number(value: Any, digits: int = DIGITS) -> str:
    """A plain float as text with ``digits`` significant digits (no numpy repr, ``-0`` as
    ``0``)."""
    x = float(value)
    if x == 0.0:
        return "0"
    return f"{x:.{digits}g}"


def shown(value_si: Any, kind: str, units: UnitChoice | None = None,
          digits: int = DIGITS) -> str:
    """``value_si`` (SI; radians for angles) of quantity ``kind`` (a key of
    :data:`screwkit.tables.SI_LABELS`) as ``"250 deg"`` or ``"12.7 mm"``, in ``units`` (else
    those of :func:`message_units`, else degrees and SI). A non-finite value is ``"nan"``."""
    if kind in UNITLESS:
        return number(value_si, digits)
    label, factor = (units or current_units()).unit_of(kind)
    x = float(value_si)
    if not np.isfinite(x):
        return f"{x} {label}".rstrip()
    return f"{number(x / factor, digits)} {label}".rstrip()


def shown_range(low_si: Any, high_si: Any, kind: str, units: UnitChoice | None = None,
                digits: int = DIGITS) -> str:
    """``"[10, 250] deg"``: two values of one kind with the unit once."""
    label, factor = (units or current_units()).unit_of(kind)
    if kind in UNITLESS:
        label, factor = "", 1.0
    return (f"[{number(float(low_si) / factor, digits)}, "
            f"{number(float(high_si) / factor, digits)}] {label}").rstrip()


def listing(items: Any, last: str = "and") -> str:
    """Names for a sentence: ``"crank, coupler and rocker"`` (``last="or"`` for a choice:
    ``"a, b or c"``), each item as plain text (``str``), in the given order; ``"none"`` for no
    items. A message that lists names uses this rather than a Python list's repr
    (``['crank', 'coupler']``), which reads as code (issue 30)."""
    words = [str(x) for x in items]
    if not words:
        return "none"
    if len(words) == 1:
        return words[0]
    return f"{', '.join(words[:-1])} {last} {words[-1]}"


def shown_values(values: Any, kind: str | None = None, units: UnitChoice | None = None,
                 digits: int = DIGITS) -> str:
    """``"(0.1, 0, 2) m"``: several numbers (a vector, a shape, the values of a table) for a
    sentence, each with ``digits`` significant digits and the unit once: in ``units`` for a
    quantity ``kind`` (as :func:`shown`), plain numbers for ``kind=None``. Never a numpy
    repr (``array([...])``, ``np.float64(…)``) nor a Python list's brackets (issue 30)."""
    flat = np.asarray(values, dtype=float).ravel()
    label, factor = "", 1.0
    if kind is not None and kind not in UNITLESS:
        label, factor = (units or current_units()).unit_of(kind)
    text = ", ".join(number(x / factor, digits) if np.isfinite(x) else str(float(x))
                     for x in flat)
    return f"({text}) {label}".rstrip()


def given(value: Any) -> str:
    """What a caller passed, quoted in an error message: a number as a plain number
    (``-1.5``, never ``np.float64(-1.5)``), an array, list or tuple as ``(1, 2, 'x')`` (each
    item so; a large array by its shape), text and anything else by its repr."""
    if isinstance(value, bool | np.bool_):
        return str(bool(value))
    if isinstance(value, int | float | np.integer | np.floating):
        x = float(value)
        return number(x) if math.isfinite(x) else str(x)
    if isinstance(value, np.ndarray):
        if value.size > 12:
            return f"an array of shape {' × '.join(map(str, value.shape))}"
        return f"({', '.join(given(x) for x in value.ravel().tolist())})"
    if isinstance(value, list | tuple):
        return f"({', '.join(given(x) for x in value)})"
    return repr(value)
