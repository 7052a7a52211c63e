"""The mechanism (a single loop or a graph of bodies) at chosen inputs to **STEP** (ISO
10303-21, AP214) solids through OpenCASCADE (OCP, the ``cadquery-ocp-novtk`` wheel: Apache-2.0
wrapper, OCCT LGPL-2.1; the ``[step]`` extra; docs/exchange.md "STEP").

The geometry is what the report and the glTF scene draw (:func:`screwkit.report.scene.
link_polylines`), as exact B-rep primitives in the world frame at the input: one named part per
link (moving links by name, then ``ground``), a compound of

- a cylinder of radius r along each segment of the link's polyline (from where it leaves its
  joint, along the common normal, to the next joint's centre) longer than round-off, and
- the solid of the joint it leaves: a sphere of radius 2r for an S joint, else (R, P, C, H, U)
  a cylinder of radius 2r and length 6r along the joint's axis, centred on the joint's centre.

A mechanism graph (:func:`graph_step_export`) has one named part per body (the moving bodies in
``[[bodies]]`` order, then ``ground``): a cylinder of radius r along each segment of the body's
drawn polyline (:func:`screwkit.report.graph_scene.body_polylines`: through its joints' centres
and points, round the polygon they span), and the solid of every joint whose first body it is
(the body whose frame carries the joint's centre and axis), as above.

In both, r = 0.012 × the size of the joint centres' cloud over the sweep (as the glTF scene).
Lengths are in the spec's ``[units] length`` (metres when it has none), written as the file's
length unit, so a CAD program scales on import.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.exchange.samples import Array, ExportError
from screwkit.io.units import UnitError, unit_factor

#: OCCT's ``write.step.unit`` names by the metres in one unit
STEP_UNITS = ((0.0254, "INCH"), (0.001, "MM"), (0.3048, "FT"), (1609.344, "MI"), (1.0, "M"),
              (1000.0, "KM"), (2.54e-5, "MIL"), (1e-6, "UM"), (0.01, "CM"), (2.54e-8, "UIN"))
#: the module that provides the kernel and the extra that installs it
KERNEL, EXTRA = "OCP", "step"
#: the joint solid's half length along its axis, in link radii
JOINT_HALF_LENGTH = 3.0


@dataclass(frozen=True)
class StepBody:
    """One named part: cylinders (a, b, radius) and spheres (centre, radius), in file units."""

    name: str
    cylinders: list[tuple[Array, Array, float]] = field(default_factory=list)
    spheres: list[tuple[Array, float]] = field(default_factory=list)


def step_unit(spec_unit: str | None) -> tuple[str, float]:
    """The spec's ``[units] length`` as a STEP unit name and its metres (metres when the spec
    has none); a unit OCCT cannot write is refused, naming the ones it can."""
    if spec_unit is None:
        return "M", 1.0
    try:
        metres = unit_factor(spec_unit, "length")
    except UnitError as exc:
        raise ExportError(f"[units] length {spec_unit!r}: {exc}") from None
    for m, name in STEP_UNITS:
        if abs(metres - m) <= 1e-12 * m:
            return name, metres
    names = ", ".join(n.lower() for _, n in STEP_UNITS)
    raise ExportError(f"STEP has no unit for the spec's length unit {spec_unit!r}; set "
                      f"[units] length to one of {names}")


def link_bodies(names: Sequence[str], kinds: Sequence[str], polylines: Array, centres: Array,
                axes: Array, radius: float, scale: float = 1.0, suffix: str = ""
                ) -> list[StepBody]:
    """The parts (module docstring) of one pose: link k (``names[k]``) has the polyline
    ``polylines[k]`` (3, 3) and carries joint k (``kinds[k]``, centre ``centres[k]``, unit axis
    ``axes[k]``), all world metres, divided by ``scale`` (metres per file unit)."""
    r = radius / scale
    bodies = []
    for k, name in enumerate(names):
        pts = np.asarray(polylines[k], dtype=float) / scale
        body = StepBody(f"{name}{suffix}")
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if np.linalg.norm(b - a) > 1e-9 * r:
                body.cylinders.append((a, b, r))
        c = np.asarray(centres[k], dtype=float) / scale
        if str(kinds[k]).upper() == "S":
            body.spheres.append((c, 2 * r))
        else:
            h = JOINT_HALF_LENGTH * r * np.asarray(axes[k], dtype=float)
            body.cylinders.append((c - h, c + h, 2 * r))
        bodies.append(body)
    return bodies


def _shape(body: StepBody) -> Any:
    """The body as an OCCT compound of its primitive solids."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.TopoDS import TopoDS_Compound

    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for a, b, r in body.cylinders:
        d = np.asarray(b) - np.asarray(a)
        length = float(np.linalg.norm(d))
        axis = gp_Ax2(gp_Pnt(*map(float, a)), gp_Dir(*map(float, d / length)))
        builder.Add(compound, BRepPrimAPI_MakeCylinder(axis, float(r), length).Shape())
    for c, r in body.spheres:
        builder.Add(compound, BRepPrimAPI_MakeSphere(gp_Pnt(*map(float, c)), float(r)).Shape())
    return compound


def step_bytes(bodies: Sequence[StepBody], unit: str, metres: float) -> bytes:
    """A STEP AP214 file of the named ``bodies`` (coordinates in ``unit``, ``metres`` per
    unit), written by OCCT's XCAF writer (names as STEP products) into memory; OCCT's console
    messages are held back while it writes."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.Message import Message
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Controller
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    STEPControl_Controller.Init_s()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, metres)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    for body in bodies:
        label = tool.AddShape(_shape(body), False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(body.name))
    messenger = Message.DefaultMessenger_s()
    printers = list(messenger.Printers())
    for p in printers:
        messenger.RemovePrinter(p)
    try:
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
        Interface_Static.SetCVal_s("write.step.unit", unit)
        writer = STEPCAFControl_Writer()
        writer.SetNameMode(True)
        stream = io.BytesIO()
        if not writer.Transfer(doc, STEPControl_AsIs) or \
                writer.WriteStream(stream) != IFSelect_ReturnStatus.IFSelect_RetDone:
            raise ExportError("OpenCASCADE could not write the STEP file; export --format gltf "
                              "instead and report this with the spec")
    finally:
        for p in printers:
            messenger.AddPrinter(p)
    return stream.getvalue()


def step_export(motion: Any, mode: int, at: Sequence[int], at_labels: Sequence[str], *,
                spec_unit: str | None) -> tuple[bytes, list[str]]:
    """The STEP file of assembly mode ``mode`` of a single-loop ``motion`` at the samples
    ``at`` (indices into the motion, labelled ``at_labels``); each part's name gains
    `` at <label>`` when more than one input is asked. A mode that does not assemble at an
    input is refused, naming it."""
    from screwkit.report.scene import link_polylines

    unit, metres = step_unit(spec_unit)
    md = motion.mode(mode)
    lk = motion.linkage
    ok = np.asarray(md.assembles, dtype=bool)
    centres = np.asarray(md.joint_centres, dtype=float)
    size = float(np.linalg.norm(np.ptp(centres[ok].reshape(-1, 3), axis=0))) if ok.any() else 0
    radius = 0.012 * (size or 1.0)
    polylines = link_polylines(lk, md)
    names = [link.name for link in lk.links] + ["ground"]
    kinds = [str(j.kind) for j in lk.joints]
    bodies: list[StepBody] = []
    for i, label in zip(at, at_labels, strict=True):
        if not ok[i]:
            raise ExportError(f"assembly mode {md.index} does not assemble at {label}; choose "
                              "another input (--at) or mode (--mode)")
        suffix = f" at {label}" if len(at) > 1 else ""
        bodies += link_bodies(names, kinds, polylines[i], centres[i],
                              np.asarray(md.joint_axes)[i], radius, metres, suffix)
    return step_bytes(bodies, unit, metres), []


def _joint_solid(body: StepBody, kind: str, centre: Array, axis: Array, r: float) -> None:
    """Add a joint's solid (module docstring) centred on ``centre`` (file units) to ``body``."""
    if kind.upper() == "S":
        body.spheres.append((centre, 2 * r))
    else:
        h = JOINT_HALF_LENGTH * r * np.asarray(axis, dtype=float)
        body.cylinders.append((centre - h, centre + h, 2 * r))


def graph_bodies(names: Sequence[str], polylines: Array, owners: Sequence[int],
                 kinds: Sequence[str], centres: Array, axes: Array, radius: float,
                 scale: float = 1.0, suffix: str = "") -> list[StepBody]:
    """The parts (module docstring) of one pose of a graph: body k (``names[k]``) has the
    polyline ``polylines[k]`` (P, 3; a repeated vertex draws nothing); joint i (``kinds[i]``,
    centre ``centres[i]``, unit axis ``axes[i]``) is carried by body ``owners[i]``; world
    metres, divided by ``scale`` (metres per file unit)."""
    r = radius / scale
    bodies = [StepBody(f"{name}{suffix}") for name in names]
    for k, body in enumerate(bodies):
        pts = np.asarray(polylines[k], dtype=float) / scale
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if np.linalg.norm(b - a) > 1e-9 * r:
                body.cylinders.append((a, b, r))
    for i, kind in enumerate(kinds):
        _joint_solid(bodies[owners[i]], str(kind), np.asarray(centres[i], dtype=float) / scale,
                     axes[i], r)
    return bodies


def graph_step_export(motion: Any, mode: int, at: Sequence[int], at_labels: Sequence[str], *,
                      spec_unit: str | None) -> tuple[bytes, list[str]]:
    """:func:`step_export` for a mechanism graph's ``solve_mechanism`` motion: one part per
    body and the ground at each sample of ``at``."""
    from screwkit.model.mechanism import GROUND
    from screwkit.report.graph_scene import body_polylines

    unit, metres = step_unit(spec_unit)
    md = motion.mode(mode)
    mech = motion.mechanism
    ok = np.asarray(md.assembles, dtype=bool)
    centres = np.asarray(md.joint_centres, dtype=float)
    size = float(np.linalg.norm(np.ptp(centres[ok].reshape(-1, 3), axis=0))) if ok.any() else 0
    radius = 0.012 * (size or 1.0)
    names = [*mech.body_names, GROUND]
    owners = [names.index(j.bodies[0]) for j in mech.joints]
    kinds = [str(j.kind) for j in mech.joints]
    polylines = body_polylines(mech, md)
    axes = np.asarray(md.joint_axes, dtype=float)
    bodies: list[StepBody] = []
    for i, label in zip(at, at_labels, strict=True):
        if not ok[i]:
            raise ExportError(f"assembly mode {md.index} does not assemble at {label}; choose "
                              "another input (--at) or mode (--mode)")
        suffix = f" at {label}" if len(at) > 1 else ""
        bodies += graph_bodies(names, polylines[i], owners, kinds, centres[i], axes[i], radius,
                               metres, suffix)
    return step_bytes(bodies, unit, metres), []
