"""Curves and the link skeleton to **DXF** (ezdxf, MIT; docs/exchange.md), in the spec's length
unit with the drawing's ``$INSUNITS`` set to it, so a CAD program scales the drawing on import.

One layer per curve and mode: ``mode<k> <point>`` for the path of each coupler point (of a
loop) or ``[[points]]`` point (of a mechanism graph),
``mode<k> joint <name>`` for the path of each joint centre that moves, ``mode<k> skeleton at
<input>`` for the links or bodies at an asked input. Curves are 3-D polylines (POLYLINE), or fit-point
splines (SPLINE) with ``splines=True``; a curve is cut where its mode does not assemble, and a
polyline over a full turn of the input is closed. The skeleton draws each body as the report
does (:mod:`screwkit.exchange.geometry`): a loop's link from where it leaves its joint, along
the common normal, to the next joint's centre (:func:`screwkit.report.scene.link_polylines`);
a graph's body as the polyline through its joints and points
(:func:`screwkit.report.graph_scene.body_polylines`).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from screwkit.exchange.geometry import ExportGeometry
from screwkit.exchange.samples import Array, ExportError, ExportSamples, assembled_runs
from screwkit.io.units import UnitError, unit_factor

#: DXF ``$INSUNITS`` codes by the metres in one unit (AutoCAD DXF reference, HEADER section)
INSUNITS = ((0.0254, 1, "in"), (0.3048, 2, "ft"), (1609.344, 3, "mi"), (0.001, 4, "mm"),
            (0.01, 5, "cm"), (1.0, 6, "m"), (1000.0, 7, "km"), (2.54e-8, 8, "microinch"),
            (2.54e-5, 9, "mil"), (0.9144, 10, "yd"), (1e-10, 11, "angstrom"), (1e-9, 12, "nm"),
            (1e-6, 13, "um"), (0.1, 14, "dm"))
#: characters a DXF layer name cannot hold (ezdxf.lldxf.validator)
_BAD_LAYER_CHARS = '<>/\\":;?*|=`'


@dataclass(frozen=True)
class DxfUnit:
    """A DXF length unit: its name, metres per unit and ``$INSUNITS`` code."""

    name: str
    metres: float
    code: int


def dxf_unit(spec_unit: str | None) -> DxfUnit:
    """The spec's ``[units] length`` as a DXF unit (metres when the spec has none); a unit DXF
    has no code for is refused, naming the ones it has."""
    if spec_unit is None:
        return DxfUnit("m", 1.0, 6)
    try:
        metres = unit_factor(spec_unit, "length")
    except UnitError as exc:
        raise ExportError(f"[units] length {spec_unit!r}: {exc}") from None
    for m, code, _ in INSUNITS:
        if abs(metres - m) <= 1e-12 * m:
            return DxfUnit(spec_unit, metres, code)
    names = ", ".join(n for _, _, n in INSUNITS)
    raise ExportError(f"DXF has no unit code for the spec's length unit {spec_unit!r}; set "
                      f"[units] length to one of {names}")


def layer_name(text: str) -> str:
    """``text`` as a valid DXF layer name (the characters DXF forbids become ``_``)."""
    cleaned = "".join("_" if c in _BAD_LAYER_CHARS or ord(c) < 32 else c for c in text)
    return cleaned.strip() or "_"


def _add_curve(msp: Any, points: Array, layer: str, *, splines: bool, closed: bool,
               stride: int = 1) -> int:
    """Add one curve (K, 3) split at NaN rows, each piece through every ``stride``-th point and
    its last; returns the number of entities added."""
    added = 0
    for a, b in assembled_runs(np.asarray(np.isfinite(points).all(axis=1))):
        rows = list(range(a, b, stride))
        rows += [b - 1] if rows[-1] != b - 1 else []
        run = [tuple(map(float, p)) for p in points[rows]]
        whole = closed and a == 0 and b == len(points)
        if len(run) == 1:
            msp.add_point(run[0], dxfattribs={"layer": layer})
        elif splines and len(run) >= 3:
            msp.add_spline(fit_points=run + ([run[0]] if whole else []),
                           dxfattribs={"layer": layer})
        else:
            msp.add_polyline3d(run, close=whole, dxfattribs={"layer": layer})
        added += 1
    return added


def _moving(path: Array, scale: float) -> bool:
    finite = path[np.isfinite(path).all(axis=1)]
    return len(finite) > 1 and float(np.ptp(finite, axis=0).max()) > 1e-9 * scale


def dxf_text(geometry: ExportGeometry, samples: ExportSamples, *, unit: DxfUnit,
             at_labels: Sequence[str], splines: bool = False, full_turn: bool = False,
             max_points: int = 5000) -> tuple[str, list[str]]:
    """The DXF drawing (text, R2013) of every mode of ``geometry`` and notes for the user.

    ``samples`` says which samples are the sweep's (curves) and where the skeleton is drawn
    (``samples.at``, labelled ``at_labels`` in the layer names); ``full_turn`` closes the
    curves of a mode that assembles over a whole turn of the input. A curve over more than
    ``max_points`` samples (0: no limit) goes through every k-th of them (and the ends of each
    piece), exact samples all: ezdxf writes a 3-D polyline at about 14,000 vertices a
    second."""
    import ezdxf

    doc = ezdxf.new("R2013", units=unit.code)
    doc.header["$MEASUREMENT"] = 0 if unit.code in (1, 2, 3, 8, 9, 10) else 1
    msp = doc.modelspace()
    notes: list[str] = []
    colour = 1
    n = len(samples.sweep)
    stride = -(-n // max_points) if max_points > 0 and n > max_points else 1
    if stride > 1:
        notes.append(f"curves drawn through one in {stride} of the sweep's {n} samples "
                     f"(--max-points {max_points}; 0 draws every sample)")

    def layer(text: str) -> str:
        nonlocal colour
        name = layer_name(text)
        if name not in doc.layers:
            doc.layers.add(name, color=colour)
            colour = colour % 254 + 1
        return name

    sweep = samples.sweep
    for md in geometry.modes:
        k = md.index
        scale = md.scale() if md.assembles.any() else 1.0
        for point, path in md.points.items():
            _add_curve(msp, path[sweep] / unit.metres, layer(f"mode{k} {point}"),
                       splines=splines, closed=full_turn, stride=stride)
        for joint, path in md.joints.items():
            path = path[sweep] / unit.metres
            if _moving(path, scale / unit.metres):
                _add_curve(msp, path, layer(f"mode{k} joint {joint}"), splines=splines,
                           closed=full_turn, stride=stride)
        skeleton = md.skeleton / unit.metres
        tiny = 1e-12 * scale / unit.metres
        for i, label in zip(samples.at, at_labels, strict=True):
            if not md.assembles[i]:
                notes.append(f"mode {k} does not assemble at input {label}: no skeleton drawn")
                continue
            name = layer(f"mode{k} skeleton at {label}")
            for poly in skeleton[i]:
                msp.add_polyline3d([tuple(map(float, p)) for p in poly[_kept(poly, tiny)]],
                                   dxfattribs={"layer": name})
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue(), notes


def _kept(poly: Array, tiny: float) -> list[int]:
    """The vertices of a polyline that are not within ``tiny`` of the one before (padding and
    zero-length segments dropped), at least its two ends."""
    keep = [0] + [m for m in range(1, len(poly))
                  if np.linalg.norm(poly[m] - poly[m - 1]) > tiny]
    return keep if len(keep) > 1 else [0, len(poly) - 1]
