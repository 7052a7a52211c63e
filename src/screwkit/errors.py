"""The exceptions screwkit raises for a user's mistake (docs/reliability.md).

Every one derives from :class:`ScrewkitError`, so ``except screwkit.ScrewkitError`` catches all
of them, and from the built-in exception a Python user expects (``ValueError`` for a wrong
value, ``TypeError`` for a wrong type, ``KeyError`` for an unknown name). Messages name the
argument or the spec key, what is wrong and how to fix it. Anything else raised from inside
screwkit is a bug.
"""

from __future__ import annotations


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
