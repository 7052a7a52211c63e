"""Keys of a graph spec (docs/sweeps.md, "Graph specs"): its values named through the names of
its joints, points and bodies, as ``links.crank.com[0]`` names a loop's link:

- ``joints.<joint>.at[0]`` … ``at[2]`` (or ``at.x``, ``at.y``, ``at.z``): a joint's point (a
  hardpoint), a length; ``joints.<joint>.axis[k]``, ``axis2[k]``: a component of a direction
  (a plain number); ``joints.<joint>.pitch``: an H joint's lead, a length;
- ``points.<point>.at[k]``: a point carried by a body, a length;
- ``bodies.<body>.mass``, ``bodies.<body>.com[k]``, ``bodies.<body>.inertia[i][j]``;
- ``motion.start``, ``motion.stop``, ``motion.step``, ``motion.speed``,
  ``motion.acceleration`` and ``gravity``.

A name that is not one of these is refused with the list of the spec's valid keys.
"""

from __future__ import annotations

from typing import Any

from screwkit.sweep.keys import Segment, SpecKeyError, parse_key

#: the vector fields of each list of a graph spec and their kinds (None: a plain number)
VECTORS: dict[str, dict[str, str | None]] = {
    "joints": {"at": "length", "axis": None, "axis2": None},
    "points": {"at": "length"},
    "bodies": {"com": "length"},
}
#: the scalar fields of each list and their kinds
SCALARS: dict[str, dict[str, str]] = {"joints": {"pitch": "length"}, "bodies": {"mass": "mass"}}
_XYZ = {"x": 0, "y": 1, "z": 2}


def _motion_kind(field: str, angle: bool) -> str | None:
    return {"start": "angle" if angle else "length", "stop": "angle" if angle else "length",
            "step": "angle" if angle else "length",
            "speed": "angular_velocity" if angle else "velocity",
            "acceleration": "angular_acceleration" if angle else "acceleration"}.get(field)


def valid_keys(data: dict[str, Any]) -> list[str]:
    """The keys of this graph spec, in the forms accepted (for error messages)."""
    out: list[str] = []
    for table, fields in (("joints", ("at[0..2]", "axis[0..2]", "axis2[0..2]", "pitch")),
                          ("points", ("at[0..2]",)),
                          ("bodies", ("mass", "com[0..2]", "inertia[0..2][0..2]"))):
        for item in data.get(table) or []:
            if isinstance(item, dict) and isinstance(item.get("name"), str):
                has = [f for f in fields if f.split("[")[0] in item
                       or (f == "pitch" and item.get("kind") == "H") or f == "mass"]
                out.extend(f"{table}.{item['name']}.{f}" for f in has)
    return out + ["motion.start", "motion.stop", "motion.step", "motion.speed",
                  "motion.acceleration", "gravity"]


def _refuse(data: dict[str, Any], text: str, why: str) -> SpecKeyError:
    keys = valid_keys(data)
    shown = ", ".join(keys[:40]) + (f" … ({len(keys)} in all)" if len(keys) > 40 else "")
    return SpecKeyError(f"{text}: {why}; the keys of this graph spec are {shown}")


def _index(data: dict[str, Any], table: str, name: Segment, text: str) -> int:
    items = data.get(table) or []
    names = [it.get("name") for it in items if isinstance(it, dict)]
    if isinstance(name, int) or name not in names:
        kind = table[:-1]
        raise _refuse(data, text, f"the spec has no {kind} {name!r} (its {table}: "
                                  f"{', '.join(str(n) for n in names) or 'none'})")
    return names.index(name)


def graph_key(data: dict[str, Any], angle_input: bool, text: str
              ) -> tuple[tuple[Segment, ...], str | None, str]:
    """(path into the TOML tables, kind, canonical name) of ``text`` in a graph spec."""
    path = parse_key(text)
    head = path[0]
    if head == "motion" and len(path) == 2 and isinstance(path[1], str):
        kind = _motion_kind(path[1], angle_input)
        if kind is not None:
            return path, kind, f"motion.{path[1]}"
    if path == ("gravity",):
        return path, "acceleration", "gravity"
    if head not in VECTORS or len(path) < 3 or not isinstance(path[2], str):
        raise _refuse(data, text, "not a key of a graph spec")
    k = _index(data, str(head), path[1], text)
    name, field, rest = path[1], path[2], list(path[3:])
    rest = [_XYZ.get(s, s) if isinstance(s, str) else s for s in rest]
    item = data[str(head)][k]
    if field in SCALARS.get(str(head), {}) and not rest:
        return (head, k, field), SCALARS[str(head)][field], f"{head}.{name}.{field}"
    if field == "inertia" and head == "bodies" and len(rest) == 2 and \
            all(isinstance(i, int) and 0 <= i < 3 for i in rest):
        if not isinstance(item.get("inertia"), list):
            raise _refuse(data, text, f"body {name!r} has no inertia in the spec; give it there "
                                      "first")
        return ((head, k, field, *rest), "inertia",
                f"{head}.{name}.inertia[{rest[0]}][{rest[1]}]")
    fields = VECTORS[str(head)]
    if field in fields and len(rest) == 1 and isinstance(rest[0], int) and 0 <= rest[0] < 3:
        if not isinstance(item.get(field), list):
            raise _refuse(data, text, f"{head[:-1]} {name!r} has no {field} in the spec; give it "
                                      "there first")
        return (head, k, field, rest[0]), fields[field], f"{head}.{name}.{field}[{rest[0]}]"
    raise _refuse(data, text, f"{head[:-1]} {name!r} has no value {field!r} with that index")
