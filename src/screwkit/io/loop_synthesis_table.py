"""The ``[synthesis]`` table of the generic route (any loop; docs/synthesis.md): the family's own
dimensions (a joint list's ``<joint>.length``, ``<joint>.twist``, ``<joint>.offset``) and
``theta01`` as unknowns, the loop's outputs generating the target, turned into a
:class:`~screwkit.synthesis.loop_route.LoopSynthesisProblem` in SI units. What the route cannot
take is refused here, at load, with the key named."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from screwkit.io.synthesis_table import (
    SynthesisConfigError,
    SynthesisTable,
    key_error,
    parse_synthesis,
)
from screwkit.kinematics.registry import default_outputs, family_of, output_freedom
from screwkit.kinematics.tracker.loop import layout
from screwkit.model.geometry import LoopGeometry, hartenberg_denavit_geometry
from screwkit.model.joints import Joint
from screwkit.model.linkage import Linkage
from screwkit.synthesis.loop_route import LoopSynthesisProblem

if TYPE_CHECKING:
    from screwkit.io.spec import MechanismSpec

__all__ = ["loop_problem_from_spec"]

Builders = tuple[Callable[[Mapping[str, float]], Linkage],
                 Callable[[Mapping[str, Any]], LoopGeometry], dict[str, str], dict[str, float]]


def _family_builders(spec: MechanismSpec) -> Builders:
    fam = family_of(spec.linkage)
    assert fam.build is not None and fam.geometry is not None
    dims = tuple(fam.dimensions)
    build, geometry = fam.build, fam.geometry

    def make(values: Mapping[str, float]) -> Linkage:
        return build(**{k: values[k] for k in dims})

    def geo(values: Mapping[str, Any]) -> LoopGeometry:
        return geometry(**{k: values[k] for k in dims})

    start = {**dict(fam.optional), **dict(spec.dimensions)}
    return make, geo, dict(fam.dimensions), start


def _joint_list_builders(spec: MechanismSpec) -> Builders:
    """A joint list's loop from its lengths, twists and offsets by name (``<joint>.length``,
    ``<joint>.twist``, ``<joint>.offset``; a C joint has no offset)."""
    raw = spec.raw.joints
    kinds: dict[str, str] = {}
    start: dict[str, float] = {}
    for k, j in enumerate(raw):
        key = f"joints[{k}]"
        kinds[f"{j.name}.length"] = "length"
        kinds[f"{j.name}.twist"] = "angle"
        start[f"{j.name}.length"] = spec.quantity(j.length, "length", key + ".length")
        start[f"{j.name}.twist"] = spec.quantity(j.twist, "angle", key + ".twist")
        if j.kind != "C":
            off = "angle" if j.kind == "P" else "length"
            kinds[f"{j.name}.offset"] = off
            start[f"{j.name}.offset"] = spec.quantity(j.offset, off, key + ".offset")
    joints = list(spec.linkage.joints)
    inputs = list(spec.linkage.inputs)
    name = spec.linkage.name

    def offsets(values: Mapping[str, Any]) -> list[Any]:
        return [values.get(f"{j.name}.offset", 0.0) for j in joints]

    def make(values: Mapping[str, float]) -> Linkage:
        js = [Joint(j.name, j.kind, float(o), j.pitch) for j, o in zip(joints, offsets(values),
                                                                      strict=True)]
        return Linkage.from_hartenberg_denavit(
            name, js, [values[f"{j.name}.length"] for j in joints],
            [values[f"{j.name}.twist"] for j in joints], inputs, family=None)

    def geo(values: Mapping[str, Any]) -> LoopGeometry:
        return hartenberg_denavit_geometry([values[f"{j.name}.length"] for j in joints],
                                           [values[f"{j.name}.twist"] for j in joints],
                                           offsets(values))

    return make, geo, kinds, start


def _outputs(spec: MechanismSpec, table: SynthesisTable) -> tuple[str | None, str | None]:
    """The loop's rotation and translation outputs (the first of each kind)."""
    lk = spec.linkage
    try:
        outputs = default_outputs(lk)
    except ValueError as exc:
        raise key_error(spec.path, "", str(exc)) from None
    lay = layout(lk)
    rotation = translation = None
    for name in outputs:
        freedom, _ = output_freedom(lk, name)
        if lay.is_translation[lay.names.index(freedom)]:
            translation = translation or name
        else:
            rotation = rotation or name
    fam = family_of(lk)
    if table.rotation is not None and rotation is None:
        raise key_error(spec.path, "rotation", f"the output of {fam.title} ({', '.join(outputs)})"
                        " is a translation: it generates no rotation; prescribe the translation")
    if table.translation is not None and translation is None:
        raise key_error(spec.path, "translation", f"the output of {fam.title} "
                        f"({', '.join(outputs)}) is a rotation: it generates no translation; "
                        "prescribe the rotation only")
    return rotation, translation


def loop_problem_from_spec(spec: MechanismSpec) -> tuple[LoopSynthesisProblem, SynthesisTable]:
    """Validate ``[synthesis]`` for the generic route and build its problem (SI units)."""
    fam = family_of(spec.linkage)
    make, geo, kinds, start0 = (_family_builders(spec) if fam.build is not None
                                else _joint_list_builders(spec))
    names = {**kinds, "theta01": "angle"}
    parsed = parse_synthesis(spec, names, start0)
    table, si, start = parsed.table, parsed.si, parsed.start
    path = spec.path
    refused = {"constraints": "Bagci's parameters of constraint (eqs. 5.13-5.21) construct the "
                              "output crank of an RSRC with delta0 = 0",
               "inversion": "inversion is the program label of Bagci's closed form; the generic "
                            "route numbers assembly modes as analyze does: use mode = 0, 1, …"}
    for key, why in refused.items():
        if getattr(table, key) not in (None, "all"):
            raise key_error(path, key, f"{why}; it is not a key of the generic route (a "
                                       f"{fam.name}): remove it")
    assert table.unknowns is not None
    for name in table.unknowns:
        if name not in names:
            raise key_error(path, "unknowns", f"unknown name {name!r}; the generic route solves "
                            f"for {', '.join(names)}")
    rotation, translation = _outputs(spec, table)
    bounds = {}
    for name, (lo, hi) in table.bounds.items():
        if name not in names:
            raise key_error(path, f"bounds.{name}", "not a dimension of this loop")
        bounds[name] = low, high = (si(lo, names[name], f"bounds.{name}"),
                                    si(hi, names[name], f"bounds.{name}"))
        if low < high and not low <= start.get(name, low) <= high:
            raise key_error(path, f"bounds.{name}", f"the start of {name} is outside its bounds: "
                            "move the start ([dimensions] or [synthesis.start]) or the bounds")
    try:
        make(start)
    except ValueError as exc:
        raise key_error(path, "start", f"the start is not a mechanism: {exc}") from None
    try:
        problem = LoopSynthesisProblem(
            fam.name, make, geo, kinds, parsed.target, start, tuple(table.unknowns),
            rotation, translation, bounds, None if table.mode == "all" else int(table.mode),
            1 if table.input_direction == "ccw" else -1,
            1 if table.output_direction == "ccw" else -1, parsed.length_scale,
            table.max_iterations, table.time_limit)
    except ValueError as exc:
        raise SynthesisConfigError(f"{path}: [synthesis] {exc}") from None
    return problem, table
