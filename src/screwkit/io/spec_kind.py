"""Which kind of spec a parsed TOML file is: a mechanism graph (docs/mechanisms.md) or a single
loop (docs/spec-format.md). Kept apart from :mod:`screwkit.io.mechanism_spec` so that loading a
single loop does not import the graph model (issue 30: ``analyze``'s start-up)."""

from __future__ import annotations

from typing import Any


def is_graph_spec(data: dict[str, Any]) -> bool:
    """Whether parsed TOML describes a mechanism graph (``[[bodies]]`` or ``between``)."""
    if "bodies" in data:
        return True
    joints = data.get("joints")
    return isinstance(joints, list) and any(isinstance(j, dict) and "between" in j
                                            for j in joints)
