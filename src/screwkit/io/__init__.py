"""Spec files (TOML with units), results to JSON/CSV, atomic writes."""

from screwkit.io.spec import MechanismSpec, SpecError, load_spec

__all__ = ["MechanismSpec", "SpecError", "load_spec"]
