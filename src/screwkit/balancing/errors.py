"""Errors of the balancing layer: each message says what is wrong, where, and how to fix it."""

from __future__ import annotations

from screwkit.errors import InputError


class BalancingError(InputError):
    """A balancing problem that cannot be set up or solved as asked."""


class InfeasibleConstraintsError(BalancingError):
    """No design satisfies all the constraints; ``conflicting`` names the ones that clash."""

    def __init__(self, message: str, conflicting: list[str]) -> None:
        super().__init__(message)
        self.conflicting = conflicting


class SolverError(BalancingError):
    """The conic/QP solver stopped without an optimum (not an infeasibility)."""


class MissingSolverError(BalancingError, ImportError):
    """An optional solver package is not installed."""
