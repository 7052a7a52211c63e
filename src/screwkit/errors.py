"""The exceptions screwkit raises for a user's mistake (docs/reliability.md).

Every one derives from :class:`ScrewkitError`, so ``except screwkit.ScrewkitError`` catches all
of them, and from the built-in exception a Python user expects (``ValueError`` for a wrong
value, ``TypeError`` for a wrong type, ``KeyError`` for an unknown name). Messages name the
argument or the spec key, what is wrong and how to fix it. Anything else raised from inside
screwkit is a bug.
"""

from __future__ import annotations

from collections.abc import Iterable
from types import UnionType


class ScrewkitError(Exception):
    """Base of every error screwkit raises for a user's mistake."""


class InputError(ScrewkitError, ValueError):
    """An argument or input value is wrong (the message names it)."""


class InputTypeError(ScrewkitError, TypeError):
    """An argument has the wrong type (the message names it and the type expected)."""


class UnknownNameError(ScrewkitError, KeyError):
    """A name (a variable, a link, a joint) that does not exist; the message lists those that do."""

    def __str__(self) -> str:  # KeyError would show the message in quotes
        return str(self.args[0]) if self.args else ""


class CapabilityError(InputError):
    """A capability that the mechanism's family does not offer; the message says why."""


def expect_instance(value: object, kind: type | UnionType | tuple[type, ...], name: str,
                    what: str) -> None:
    """Raise :class:`InputTypeError` naming the argument ``name`` unless ``value`` is a
    ``kind``; ``what`` says in words what to give, e.g. "a Motion (sk.solve_motion(...))"."""
    if not isinstance(value, kind):
        raise InputTypeError(f"{name} must be {what}; got {type(value).__name__}")


def expect_number(value: object, name: str, *, positive: bool = False,
                  integer: bool = False) -> float:
    """``value`` as a float if it is a real number (an integer where ``integer``; positive
    where ``positive``); otherwise an :class:`InputTypeError`/:class:`InputError` naming
    ``name``. Booleans and strings are refused rather than coerced."""
    import math
    import numbers

    from screwkit.messages import given  # messages → tables → errors: imported here

    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind):
        raise InputTypeError(f"{name} must be {'an integer' if integer else 'a number'}; got "
                             f"{type(value).__name__} {value!r:.40}")
    x = float(value)  # type: ignore[arg-type]
    if not math.isfinite(x):
        raise InputError(f"{name} must be finite; got {given(value)}")
    if positive and not x > 0:
        raise InputError(f"{name} must be positive; got {given(value)}")
    return x


def did_you_mean(name: object, choices: Iterable[str]) -> str:
    """``"did you mean 'length'? "`` for the choice closest to a misspelt ``name``, or ``""``."""
    import difflib

    close = difflib.get_close_matches(str(name), list(choices), n=1)
    return f"did you mean {close[0]!r}? " if close else ""
