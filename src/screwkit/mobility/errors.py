"""The one error type of :mod:`screwkit.mobility`."""

from __future__ import annotations

from screwkit.errors import InputError


class MobilityInputError(InputError):
    """Bad input to a mobility count: a negative count, an unknown pair, a loop count that
    contradicts Bagci's eq. (B.3), a Jacobian of the wrong shape, ...

    It is a :class:`ValueError`, so ``except ValueError`` catches it.
    """


def check_count(value: object, what: str, *, minimum: int = 0) -> int:
    """``value`` as an int ≥ ``minimum``; bools and non-whole numbers are rejected by name."""
    count: int | None = None
    if not isinstance(value, bool):
        try:
            as_int = int(value)  # type: ignore[call-overload]
        except (TypeError, ValueError, OverflowError):
            as_int = None
        if as_int is not None and as_int == value:
            count = as_int
    if count is None:
        raise MobilityInputError(f"{what} must be a whole number; got {value!r}")
    if count < minimum:
        raise MobilityInputError(f"{what} must be ≥ {minimum}; got {count}")
    return count
