"""Errors of the io layer."""

from __future__ import annotations

from screwkit.errors import InputError


class SpecError(InputError):
    """A spec file that cannot be used; the message says where and how to fix it."""
