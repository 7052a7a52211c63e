"""``screwkit export``'s computation: a solved motion of a spec to a CAD exchange file — DXF
curves and skeleton (:mod:`screwkit.exchange.dxf`) or an animated glTF scene
(:mod:`screwkit.exchange.gltf`) or STEP link solids at chosen inputs (:mod:`screwkit.exchange.step`,
the ``[step]`` extra); docs/exchange.md."""

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
    kind = "angle" if spec.input_is_angle else "length"
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
    """The export of ``motion`` (solved at ``samples.inputs``) of ``spec`` in format ``fmt``
    (from :func:`export_format`). DXF draws every mode (or ``mode``), glTF animates ``mode``
    (default the spec's ``[motion] mode``), as GLB or (``binary=False``) glTF JSON; STEP holds
    the link solids of ``mode`` (default the spec's) at the ``--at`` inputs;
    ``max_points`` bounds the samples of a DXF curve (:func:`screwkit.exchange.dxf.dxf_text`)."""
    points = list(getattr(spec, "coupler_points", []))
    if fmt == "dxf":
        from screwkit.exchange.dxf import dxf_text, dxf_unit

        modes = list(range(len(motion.modes))) if mode is None else [motion.mode(mode).index]
        if not modes:
            raise ExportError(f"{spec.name}: the motion has no assembly mode to export")
        text, notes = dxf_text(motion, samples, points=points, modes=modes,
                               unit=dxf_unit(spec.units.get("length")), at_labels=at_labels,
                               splines=splines, max_points=max_points,
                               full_turn=full_turn(spec.inputs, spec.input_is_angle))
        return Export(text.encode("utf-8"), fmt, notes)
    if fmt == "gltf":
        from screwkit.exchange.gltf import gltf_bytes

        k = spec.mode if mode is None else mode
        data = gltf_bytes(motion, motion.mode(k).index, samples.sweep, name=str(spec.name),
                          points=points, speed=float(spec.speed), binary=binary)
        return Export(data, fmt)
    if fmt == "step":
        from screwkit.exchange.step import step_export

        k = spec.mode if mode is None else mode
        data, notes = step_export(motion, motion.mode(k).index, list(samples.at), at_labels,
                                  spec_unit=spec.units.get("length"))
        return Export(data, fmt, notes)
    raise ExportError(f"--format {fmt!r} is not an export format; choose dxf, gltf or step")


def samples_for(spec: Any, at: Sequence[str] = ()) -> tuple[ExportSamples, list[str]]:
    """The spec's sweep with the ``--at`` inputs (:func:`input_values`) merged in, and their
    labels; with none, the sweep's first sample."""
    x = np.asarray(spec.inputs, dtype=float).reshape(len(spec.inputs), -1)[:, 0]
    kind = "angle" if spec.input_is_angle else "length"
    unit = spec.units.get(kind) or ("rad" if kind == "angle" else "m")
    factor = unit_factor(unit, kind)
    values, labels = input_values(spec, at)
    if not values:
        values = [float(x[0])]
        labels = [f"{x[0] / factor:.6g} {unit}"]
    span = f" ({x.min() / factor:.6g}…{x.max() / factor:.6g} {unit})"
    return export_samples(x, values, labels, span), labels
