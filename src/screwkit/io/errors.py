"""Errors of the io layer."""

from __future__ import annotations


class SpecError(ValueError):
    """A spec file that cannot be used; the message says where and how to fix it."""
