"""``screwkit export --format step``: the file read back with OpenCASCADE's own STEP reader
(OCP, the ``[step]`` extra) holds one named part per link, each made of the primitive solids
docs/exchange.md describes, at the asked input, in the spec's length unit; their end points,
centres, radii and volumes match an independent solve of the spec's linkage to round-off."""

import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.exchange.export import export_format
from screwkit.exchange.samples import ExportError
from screwkit.exchange.step import JOINT_HALF_LENGTH, step_unit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FIG7 = EXAMPLES / "bagci_fig7_rsrc.toml"  # inches, degrees, 0…350° in 10° steps: R S R C
runner = CliRunner()


def _export(tmp_path: Path, spec: Path, *args: str, name: str = "out.step") -> Path:
    out = tmp_path / name
    r = runner.invoke(app, ["export", str(spec), "--format", "step", "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    assert r.stdout.strip() == f"wrote {out}"
    return out


def _read(path: Path) -> dict[str, list[dict]]:
    """Per part name, its solids as OCCT reads them, lengths converted to metres by OCCT (the
    document's unit): kind, volume and, for a cylinder, the centres of its two flat ends and
    its radius; for a sphere its centre and radius."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepGProp import BRepGProp
    from OCP.GeomAbs import GeomAbs_SurfaceType
    from OCP.GProp import GProp_GProps
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.OCP.collections import Sequence_TDF_Label
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 1.0)  # read into metres
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    assert reader.Transfer(doc)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    labels = Sequence_TDF_Label()
    tool.GetFreeShapes(labels)
    parts: dict[str, list[dict]] = {}
    for i in range(1, labels.Length() + 1):
        label = labels.Value(i)
        name = TDataStd_Name()
        assert label.FindAttribute(TDataStd_Name.GetID_s(), name)
        solids = []
        ex = TopExp_Explorer(tool.GetShape_s(label), TopAbs_SOLID)
        while ex.More():
            solid = TopoDS.Solid(ex.Current())
            props = GProp_GProps()
            BRepGProp.VolumeProperties_s(solid, props)
            item: dict = {"volume": props.Mass(), "ends": []}
            fx = TopExp_Explorer(solid, TopAbs_FACE)
            while fx.More():
                face = TopoDS.Face(fx.Current())
                surf = BRepAdaptor_Surface(face)
                kind = surf.GetType()
                if kind == GeomAbs_SurfaceType.GeomAbs_Cylinder:
                    item["kind"], item["radius"] = "cylinder", surf.Cylinder().Radius()
                elif kind == GeomAbs_SurfaceType.GeomAbs_Sphere:
                    s = surf.Sphere()
                    c = s.Location()
                    item.update(kind="sphere", radius=s.Radius(),
                                centre=np.array([c.X(), c.Y(), c.Z()]))
                elif kind == GeomAbs_SurfaceType.GeomAbs_Plane:
                    fp = GProp_GProps()
                    BRepGProp.SurfaceProperties_s(face, fp)
                    c = fp.CentreOfMass()
                    item["ends"].append(np.array([c.X(), c.Y(), c.Z()]))
                fx.Next()
            solids.append(item)
            ex.Next()
        parts[name.Get().ToExtString()] = solids
    return parts


def _cylinders(solids: list[dict]) -> list[dict]:
    return [s for s in solids if s["kind"] == "cylinder"]


def _has_end(cylinders: list[dict], p: np.ndarray, tol: float) -> bool:
    return any(min(np.linalg.norm(e - p) for e in c["ends"]) < tol for c in cylinders)


def _check_pose(parts: dict, spec: sk.Spec, md, sample: int, suffix: str = "") -> None:
    """Each link's part ends (a cylinder's flat end) at the next joint's centre (a link whose
    next joint is at its own joint's centre, the CSSP's slider, has no cylinder) and carries its
    joint's solid (a sphere for S, else a cylinder along the joint's axis) at its centre; radii
    are r and 2r, volumes πr²L and 4/3·πR³."""
    lk = spec.linkage
    centres, axes = md.joint_centres[sample], md.joint_axes[sample]
    size = float(np.linalg.norm(np.ptp(md.joint_centres[md.assembles].reshape(-1, 3), axis=0)))
    r = 0.012 * size
    tol = 1e-9 * size
    names = [link.name for link in lk.links] + ["ground"]
    assert sorted(parts) == sorted(f"{n}{suffix}" for n in names)
    for k, name in enumerate(names):
        solids = parts[f"{name}{suffix}"]
        for s in solids:
            if s["kind"] == "cylinder":
                (a, b) = s["ends"]
                length = float(np.linalg.norm(b - a))
                assert abs(s["volume"] - math.pi * s["radius"] ** 2 * length) < 1e-9 * s["volume"]
            else:
                assert abs(s["volume"] - 4 / 3 * math.pi * s["radius"] ** 3) < 1e-9 * s["volume"]
        links = [s for s in _cylinders(solids) if abs(s["radius"] - r) < tol]
        after = centres[(k + 1) % len(names)]
        if np.linalg.norm(after - centres[k]) > tol:  # a link with a length has cylinders
            assert links
        if links:  # ... and reaches the next joint's centre
            assert _has_end(links, after, tol)
        joint = [s for s in solids if abs(s["radius"] - 2 * r) < tol]
        assert len(joint) == 1
        (j,) = joint
        if lk.joints[k].kind == "S":
            assert j["kind"] == "sphere" and np.linalg.norm(j["centre"] - centres[k]) < tol
        else:
            a, b = j["ends"]
            h = JOINT_HALF_LENGTH * r * axes[k]
            assert j["kind"] == "cylinder"
            assert min(np.linalg.norm(a - centres[k] + h) + np.linalg.norm(b - centres[k] - h),
                       np.linalg.norm(b - centres[k] + h) + np.linalg.norm(a - centres[k] - h)) < tol


def test_parts_at_inputs_on_and_between_samples_in_inches(tmp_path):
    """At 40° (a sample) and 45° (between samples) of mode 1: the parts, named per input, match
    a separate solve over a 5° sweep; the file's unit is the inch."""
    out = _export(tmp_path, FIG7, "--at", "45", "--at", "40 deg", "--mode", "1")
    text = out.read_text()
    assert "CONVERSION_BASED_UNIT('INCH'" in text
    parts = _read(out)
    spec = sk.load_spec(FIG7)
    motion = sk.solve_motion(spec.linkage, np.radians(np.arange(0.0, 355.0, 5.0)), rates=1.0)
    for label, sample in (("45 deg", 9), ("40 deg", 8)):
        mine = {n: s for n, s in parts.items() if n.endswith(f" at {label}")}
        _check_pose(mine, spec, motion.mode(1), sample, f" at {label}")


def test_default_is_the_first_input_of_the_spec_mode_in_mm(tmp_path):
    spec_path = EXAMPLES / "rssr_spatial.toml"  # millimetres: R S S R
    out = _export(tmp_path, spec_path, name="rssr.stp")
    assert "SI_UNIT(.MILLI.,.METRE.)" in out.read_text()
    spec = sk.load_spec(spec_path)
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    _check_pose(_read(out), spec, motion.mode(spec.mode), 0)


def test_units_and_refusals(tmp_path):
    assert step_unit(None) == ("M", 1.0)
    assert step_unit("in") == ("INCH", 0.0254)
    assert step_unit("mm") == ("MM", 0.001)
    with pytest.raises(ExportError, match="STEP has no unit for the spec's length unit 'yd'"):
        step_unit("yd")
    assert export_format("STEP") == "step"


def test_missing_kernel_names_the_extra(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "OCP" else real(name, *a))
    with pytest.raises(ExportError, match=r"^STEP export needs cadquery-ocp-novtk: "
                                          r"pip install 'screwkit\[step\]'$"):
        export_format("step")


def test_a_mode_that_does_not_assemble_at_the_input_is_refused():
    from screwkit.exchange.step import step_export

    spec = sk.load_spec(FIG7)
    motion = sk.solve_motion(spec.linkage, np.radians([0.0, 10.0]), rates=1.0)
    md = motion.mode(0)
    md.assembles[1] = False  # as if the mode stopped assembling at the second input
    with pytest.raises(ExportError, match="assembly mode 0 does not assemble at 10 deg"):
        step_export(motion, 0, [1], ["10 deg"], spec_unit="in")


@pytest.mark.parametrize("name", ["rahman_cssp.toml", "rccc_loop.toml"])
def test_prismatic_and_cylindric_joints(tmp_path, name):
    """A P joint (the CSSP's slider) and C joints (the RCCC) get their cylinders along their
    axes, at the spec mode's first input."""
    spec_path = EXAMPLES / name
    out = _export(tmp_path, spec_path)
    spec = sk.load_spec(spec_path)
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    _check_pose(_read(out), spec, motion.mode(spec.mode), 0)


def test_a_spec_in_metres(tmp_path):
    text = FIG7.read_text(encoding="utf-8").replace('length = "in"', 'length = "m"')
    spec_path = tmp_path / "fig7_m.toml"
    spec_path.write_text(text, encoding="utf-8")
    out = _export(tmp_path, spec_path, "--at", "90")
    assert "SI_UNIT($,.METRE.)" in out.read_text()
    spec = sk.load_spec(spec_path)
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    _check_pose(_read(out), spec, motion.mode(spec.mode), 9)
