"""The grammar of a quantity in a spec file: a number, then a unit expression — read by a small
parser of our own, never by an evaluator (docs/reliability.md, "Quantities").

::

    quantity  :=  number [unit]
    number    :=  [+|-] (digits [. digits] | . digits) [(e|E) [+|-] digits]
    unit      :=  factor ((* | · | /) factor)*          a / b / c  means  a / (b·c)
    factor    :=  name [power]
    power     :=  (^ | **) [+|-] digit  |  ² | ³ | ⁴      with |power| ≤ 4
    name      :=  a letter (or _ µ μ), then letters, digits or _   (at most 40 characters)

Blanks are allowed around every token. Nothing else is accepted: no sums, no power towers, no
parentheses, no function calls. The parser returns the magnitude and the unit names with their
powers; :mod:`screwkit.io.units` turns each *name* into a pint unit (a single identifier, which
pint only looks up) and multiplies them, so pint never evaluates user text. The work is linear
in the length of the text, which is limited to :data:`MAX_QUANTITY_CHARS`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from screwkit.errors import InputError

#: longest quantity string read (characters); a longer value is refused naming its key
MAX_QUANTITY_CHARS = 200
#: longest unit name (pint's longest ordinary names are ~30 characters)
MAX_NAME_CHARS = 40
#: largest |power| of a unit factor
MAX_POWER = 4
#: characters of user text echoed in an error message
EXCERPT_CHARS = 40

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
# a letter or _ first (Unicode letters include µ, μ), then letters, digits or _ — but not the
# superscript digits, which \w would take: "m²" is the name m with the power 2
_NAME = re.compile(r"[^\W\d](?:(?![¹²³⁴⁵⁶⁷⁸⁹⁰])\w)*")
_POWER = re.compile(r"(?:\^|\*\*)\s*([+-]?\d+)")
_SUPERSCRIPTS = {"²": 2, "³": 3, "⁴": 4}
_BLANK = re.compile(r"\s*")


class QuantitySyntaxError(InputError):
    """Text that is not a quantity of the grammar above; the message says what was expected."""


@dataclass(frozen=True)
class ParsedQuantity:
    """A number and its unit as written: ``units`` holds (name, power) pairs in order (empty
    when the text is a bare number)."""

    magnitude: float
    units: tuple[tuple[str, int], ...]


def excerpt(text: str, limit: int = EXCERPT_CHARS) -> str:
    """``repr`` of the start of ``text`` (at most ``limit`` characters), with its full length
    when it was cut, for error messages."""
    if len(text) <= limit:
        return repr(text)
    return f"{text[:limit]!r}… ({len(text)} characters)"


def _skip_blanks(text: str, pos: int) -> int:
    m = _BLANK.match(text, pos)
    return m.end() if m else pos


def _where(text: str, pos: int) -> str:
    if pos >= len(text):
        return "at the end"
    return f"at character {pos + 1} ({excerpt(text[pos:], 12)})"


def _power(text: str, pos: int) -> tuple[int, int]:
    """An optional power after a unit name: (power, position after it)."""
    if pos < len(text) and text[pos] in _SUPERSCRIPTS:
        return _SUPERSCRIPTS[text[pos]], pos + 1
    m = _POWER.match(text, _skip_blanks(text, pos))
    if m is None:
        if text.startswith(("^", "**"), _skip_blanks(text, pos)):
            raise QuantitySyntaxError(f"a power must be a whole number from -{MAX_POWER} to "
                                      f"{MAX_POWER} {_where(text, _skip_blanks(text, pos))}")
        return 1, pos
    digits = m.group(1)
    if len(digits.lstrip("+-")) > 2 or abs(int(digits)) > MAX_POWER or int(digits) == 0:
        raise QuantitySyntaxError(f"a unit power must be a whole number from -{MAX_POWER} to "
                                  f"{MAX_POWER}, not zero; got {digits}")
    return int(digits), m.end()


def parse_unit(text: str, pos: int = 0) -> tuple[tuple[str, int], ...]:
    """The unit expression starting at ``pos`` (to the end of ``text``), as (name, power) pairs."""
    out: list[tuple[str, int]] = []
    sign = 1
    pos = _skip_blanks(text, pos)
    while True:
        m = _NAME.match(text, pos)
        if m is None:
            raise QuantitySyntaxError(f"expected a unit name (e.g. in, mm, deg, rpm, kg) "
                                      f"{_where(text, pos)}")
        name = m.group(0)
        if len(name) > MAX_NAME_CHARS:
            raise QuantitySyntaxError(f"unit name {excerpt(name, 20)} is longer than "
                                      f"{MAX_NAME_CHARS} characters")
        power, pos = _power(text, m.end())
        out.append((name, sign * power))
        pos = _skip_blanks(text, pos)
        if pos == len(text):
            return tuple(out)
        op = text[pos]
        if text.startswith("**", pos):
            raise QuantitySyntaxError(f"a power must follow a unit name {_where(text, pos)}")
        if op in "*·/":
            sign = -1 if op == "/" else 1
        else:
            raise QuantitySyntaxError(
                f"unexpected {op!r} {_where(text, pos)}: a unit is names joined by *, · or / "
                f"with powers ^2, ^3, ^4 (e.g. \"kg*m^2\", \"in/s^2\")")
        pos = _skip_blanks(text, pos + 1)


def parse_quantity(text: str) -> ParsedQuantity:
    """Read ``"<number> [<unit>]"`` (module docstring). Raises :class:`QuantitySyntaxError`."""
    if len(text) > MAX_QUANTITY_CHARS:
        raise QuantitySyntaxError(f"the text is {len(text)} characters long; a quantity has at "
                                  f"most {MAX_QUANTITY_CHARS}")
    pos = _skip_blanks(text, 0)
    m = _NUMBER.match(text, pos)
    if m is None:
        raise QuantitySyntaxError(f"expected a number first (e.g. 2.5, -1e-3) {_where(text, pos)}")
    try:
        magnitude = float(m.group(0))
    except (ValueError, OverflowError) as exc:  # pragma: no cover - the regex admits floats only
        raise QuantitySyntaxError(f"cannot read the number {excerpt(m.group(0))}") from exc
    if not math.isfinite(magnitude):
        raise QuantitySyntaxError(f"the number {excerpt(m.group(0))} is too large for a double")
    pos = _skip_blanks(text, m.end())
    if pos == len(text):
        return ParsedQuantity(magnitude, ())
    if text[pos] in "*/^·" or text.startswith("**", pos):
        raise QuantitySyntaxError(
            f"only a number then a unit is read (no arithmetic); unexpected {text[pos]!r} "
            f"{_where(text, pos)}")
    return ParsedQuantity(magnitude, parse_unit(text, pos))
