"""``screwkit export``'s computation: a solved motion of a spec (a single loop or a mechanism
graph, through :mod:`screwkit.exchange.geometry`) to a CAD exchange file — DXF
curves and skeleton (:mod:`screwkit.exchange.dxf`) or an animated glTF scene
(:mod:`screwkit.exchange.gltf`) or STEP link (body) solids at chosen inputs
(:mod:`screwkit.exchange.step`, the ``[step]`` extra); docs/exchange.md."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.exchange.samples import ExportError, ExportSamples, export_samples
from screwkit.io.units import UnitError, to_si, unit_factor
from screwkit.kinematics.motion import Motion

FORMATS = ("dxf", "gltf", "step")


@dataclass(frozen=True)
class Export:
    """An exchange file's bytes, its format and what the user should know about it."""

    data: bytes
    format: str
    notes: list[str] = field(default_factory=list)


#: the module each format is written with and the extra that installs it
LIBRARIES = {"dxf": ("ezdxf", "cad"), "gltf": ("pygltflib", "cad"),
             "step": ("OCP", "step")}
#: the package a user installs for each module
PACKAGES = {"ezdxf": "ezdxf", "pygltflib": "pygltflib", "OCP": "cadquery-ocp-novtk"}


def export_format(name: str) -> str:
    """The format ``name`` (``dxf``, ``gltf`` or its binary form's name ``glb``, ``step``)
    checked before any work: an unknown one, or one whose library is not installed (naming the
    extra that installs it) is an :class:`ExportError`."""
    import importlib.util

    fmt = str(name).strip().lower()
    fmt = "gltf" if fmt == "glb" else fmt
    if fmt not in LIBRARIES:
        raise ExportError(f"--format {name!r} is not an export format; choose dxf, gltf or step")
    module, extra = LIBRARIES[fmt]
    if importlib.util.find_spec(module) is None:
        raise ExportError(f"{fmt.upper()} export needs {PACKAGES[module]}: "
                          f"pip install 'screwkit[{extra}]'")
    return fmt


#: the file name endings of each format
SUFFIXES = {"dxf": (".dxf",), "gltf": (".glb", ".gltf"), "step": (".step", ".stp")}


def check_suffix(fmt: str, path: Any) -> None:
    """Refuse an output name whose ending does not match the format (a CAD program chooses its
    reader by it): ``out.json`` for a DXF is a slip, caught before any work."""
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES[fmt]:
        endings = " or ".join(SUFFIXES[fmt])
        raise ExportError(f"--output {path}: a {fmt.upper()} file's name ends in {endings}; "
                          f"rename it or choose the format that matches {suffix or 'no ending'}")


def input_values(spec: Any, texts: Sequence[str]) -> tuple[list[float], list[str]]:
    """The ``--at`` values (numbers in the spec's unit of the input, or with their own unit,
    ``"45 deg"``) in SI, and how each is labelled (with its unit)."""
    kind = "angle" if input_is_angle(spec) else "length"
    unit = spec.units.get(kind) or ("rad" if kind == "angle" else "m")
    values, labels = [], []
    for text in texts:
        try:
            values.append(to_si(str(text), kind, unit))
        except UnitError as exc:
            raise ExportError(f"--at {text!r}: {exc}") from None
        bare = str(text).strip()
        try:
            float(bare)
            labels.append(f"{bare} {unit}")
        except ValueError:
            labels.append(bare)
    return values, labels


def full_turn(x: Any, is_angle: bool) -> bool:
    """The sweep covers a whole turn of an angle input: one more step closes it."""
    x = np.asarray(x, dtype=float)
    if not is_angle or len(x) < 3:
        return False
    return bool(abs(abs(x[-1] - x[0] + (x[1] - x[0])) - 2 * np.pi) < 1e-9)


def export_motion(spec: Any, motion: Motion, samples: ExportSamples, fmt: str, *,
                  at_labels: Sequence[str], mode: int | None = None,
                  splines: bool = False, binary: bool = True, max_points: int = 5000
                  ) -> Export:
    """The export of ``motion`` (solved at ``samples.inputs``) of a single-loop ``spec`` in
    format ``fmt`` (from :func:`export_format`). DXF draws every mode (or ``mode``), glTF
    animates ``mode`` (default the spec's ``[motion] mode``), as GLB or (``binary=False``) glTF
    JSON; ``max_points`` bounds the samples of a DXF curve
    (:func:`screwkit.exchange.dxf.dxf_text`)."""
    from screwkit.exchange.geometry import loop_geometry

    if fmt == "step":  # link solids (exchange/step.py), of one mode at the --at inputs
        from screwkit.exchange.step import step_export

        k = spec.mode if mode is None else mode
        data, notes = step_export(motion, motion.mode(k).index, list(samples.at), at_labels,
                                  spec_unit=spec.units.get("length"))
        return Export(data, fmt, notes)
    points = list(getattr(spec, "coupler_points", []))
    modes = _modes(spec, motion, fmt, mode)
    return write_geometry(spec, loop_geometry(motion, modes, points), samples, fmt,
                          at_labels=at_labels, splines=splines, binary=binary,
                          max_points=max_points, speed=float(spec.speed))


def export_graph_motion(spec: Any, motion: Any, samples: ExportSamples, fmt: str, *,
                        at_labels: Sequence[str], mode: int | None = None,
                        splines: bool = False, binary: bool = True, max_points: int = 5000
                        ) -> Export:
    """:func:`export_motion` for a mechanism graph's spec and its ``solve_mechanism`` motion:
    the bodies as the report draws them, the ``[[points]]`` paths; the keyframe times follow
    the first input's speed."""
    from screwkit.exchange.geometry import graph_geometry

    if fmt == "step":  # body solids (exchange/step.py), of one mode at the --at inputs
        from screwkit.exchange.step import graph_step_export

        k = getattr(spec, "mode", 0) if mode is None else mode
        data, notes = graph_step_export(motion, motion.mode(k).index, list(samples.at),
                                        at_labels, spec_unit=spec.units.get("length"))
        return Export(data, fmt, notes)
    modes = _modes(spec, motion, fmt, mode)
    speed = float(np.asarray(spec.speed, dtype=float).reshape(-1)[0])
    return write_geometry(spec, graph_geometry(motion, modes), samples, fmt,
                          at_labels=at_labels, splines=splines, binary=binary,
                          max_points=max_points, speed=speed)


def _modes(spec: Any, motion: Any, fmt: str, mode: int | None) -> list[int]:
    """The modes to export: DXF every one (or ``mode``), glTF ``mode`` or the spec's."""
    if fmt == "dxf":
        modes = list(range(len(motion.modes))) if mode is None else [motion.mode(mode).index]
        if not modes:
            raise ExportError(f"{spec.name}: the motion has no assembly mode to export")
        return modes
    k = getattr(spec, "mode", 0) if mode is None else mode
    return [motion.mode(k).index]


def write_geometry(spec: Any, geometry: Any, samples: ExportSamples, fmt: str, *,
                   at_labels: Sequence[str], splines: bool, binary: bool, max_points: int,
                   speed: float) -> Export:
    """The file of format ``fmt`` drawing ``geometry`` (:mod:`screwkit.exchange.geometry`)."""
    if fmt == "dxf":
        from screwkit.exchange.dxf import dxf_text, dxf_unit

        text, notes = dxf_text(geometry, samples, unit=dxf_unit(spec.units.get("length")),
                               at_labels=at_labels, splines=splines, max_points=max_points,
                               full_turn=full_turn(geometry.inputs[samples.sweep],
                                                   input_is_angle(spec)))
        return Export(text.encode("utf-8"), fmt, notes)
    if fmt == "gltf":
        from screwkit.exchange.gltf import gltf_bytes

        data = gltf_bytes(geometry, samples.sweep, name=str(spec.name), speed=speed,
                          binary=binary)
        return Export(data, fmt)
    raise ExportError(f"--format {fmt!r} is not an export format; choose dxf, gltf or step")


def input_is_angle(spec: Any) -> bool:
    """Whether the spec's (first) input is an angle: a loop spec says so, a graph's first
    driven freedom is a rotation."""
    if getattr(spec, "family", None) == "graph":
        return not bool(spec.mechanism.driven_is_translation()[0])
    return bool(spec.input_is_angle)


def graph_export(spec: Any, fmt: str, at: Sequence[str] = (), *, mode: int | None = None,
                 splines: bool = False, binary: bool = True, max_points: int = 5000,
                 every_mode: bool = True) -> Export:
    """``screwkit export`` of a mechanism graph's spec: its motion (with ``every_mode`` every
    mode solve_mechanism finds, else the drawn one only) over the spec's inputs, with the ``--at`` inputs
    solved with them. ``--at`` needs one input swept monotonically (a start/stop/step
    sweep); a graph driven by rows is drawn at its first row."""
    from screwkit.kinematics.graph import solve_mechanism

    kind = export_format(fmt)
    inputs = np.asarray(spec.inputs, dtype=float)
    steps = np.diff(inputs[:, 0])
    if at and (inputs.shape[1] != 1 or not (np.all(steps > 0) or np.all(steps < 0))):
        why = (f"this one has {inputs.shape[1]} inputs given as rows" if inputs.shape[1] != 1
               else "this one's rows are not in increasing or decreasing order")
        raise ExportError(f"{spec.name}: --at needs a graph with one input swept from start "
                          f"to stop; {why}: leave out --at (the skeleton is drawn at the first "
                          "row)")
    if at:
        samples, labels = samples_for(spec, at)
    else:  # the spec's samples in their order (rows need not be sorted), skeleton at the first
        N = len(inputs)
        samples = ExportSamples(inputs[:, 0], np.arange(N), np.zeros(1, dtype=np.intp))
        labels = samples_for(spec)[1] if inputs.shape[1] == 1 else ["row 1"]
    x = inputs if len(samples.inputs) == len(inputs) else samples.inputs[:, None]
    motion = solve_mechanism(spec.mechanism, x, rates=spec.speed,
                             accelerations=spec.acceleration, every_mode=every_mode)
    return export_graph_motion(spec, motion, samples, kind, at_labels=labels, mode=mode,
                               splines=splines, binary=binary, max_points=max_points)


def samples_for(spec: Any, at: Sequence[str] = ()) -> tuple[ExportSamples, list[str]]:
    """The spec's sweep with the ``--at`` inputs (:func:`input_values`) merged in, and their
    labels; with none, the sweep's first sample."""
    x = np.asarray(spec.inputs, dtype=float).reshape(len(spec.inputs), -1)[:, 0]
    kind = "angle" if input_is_angle(spec) else "length"
    unit = spec.units.get(kind) or ("rad" if kind == "angle" else "m")
    factor = unit_factor(unit, kind)
    values, labels = input_values(spec, at)
    if not values:
        values = [float(x[0])]
        labels = [f"{x[0] / factor:.6g} {unit}"]
    span = f" ({x.min() / factor:.6g}…{x.max() / factor:.6g} {unit})"
    return export_samples(x, values, labels, span), labels
