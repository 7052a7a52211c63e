"""``screwkit export --format dxf``: the drawing read back with ezdxf holds the coupler curves of
``screwkit analyze --json`` (in the spec's length unit, $INSUNITS set) and the link skeleton at
the asked inputs, whose joint centres match an independent solve of the spec's linkage."""

import json
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.exchange.dxf import dxf_unit, layer_name
from screwkit.exchange.samples import ExportError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FIG7 = EXAMPLES / "bagci_fig7_rsrc.toml"  # inches, degrees, 0…350° in 10° steps
INCH = 0.0254
runner = CliRunner()


def _export(tmp_path: Path, spec: Path, *args: str, name: str = "out.dxf") -> Path:
    out = tmp_path / name
    r = runner.invoke(app, ["export", str(spec), "--format", "dxf", "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    assert r.stdout.strip() == f"wrote {out}"
    return out


def _layers(doc: ezdxf.document.Drawing) -> dict[str, list]:
    found: dict[str, list] = {}
    for e in doc.modelspace():
        found.setdefault(e.dxf.layer, []).append(e)
    return found


def _analysis(spec: Path) -> dict:
    r = runner.invoke(app, ["analyze", str(spec), "--json"])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def test_coupler_curves_are_the_analysis_json_in_inches(tmp_path):
    doc = ezdxf.readfile(_export(tmp_path, FIG7))
    assert doc.header["$INSUNITS"] == 1 and doc.header["$MEASUREMENT"] == 0  # inches
    layers = _layers(doc)
    analysis = _analysis(FIG7)
    name = analysis["coupler_points"][0]["name"]
    assert len(analysis["modes"]) == 2
    for mode in analysis["modes"]:
        (curve,) = layers[f"mode{mode['mode']} {name}"]
        assert curve.dxftype() == "POLYLINE" and curve.is_closed  # a full turn, every sample
        got = np.array([tuple(v) for v in curve.points()])
        path = mode["coupler_points"][name]
        want = np.column_stack([path["x"], path["y"], path["z"]]) / INCH
        assert got.shape == (36, 3)
        assert np.max(np.abs(got - want)) < 1e-12 * np.max(np.abs(want))


def test_splines_pass_through_the_same_points(tmp_path):
    doc = ezdxf.readfile(_export(tmp_path, FIG7, "--splines", "--mode", "1"))
    layers = _layers(doc)
    analysis = _analysis(FIG7)
    name = analysis["coupler_points"][0]["name"]
    assert not any(layer.startswith("mode0") for layer in layers)  # --mode 1 only
    (spline,) = layers[f"mode1 {name}"]
    assert spline.dxftype() == "SPLINE"
    fit = np.array(spline.fit_points)
    path = analysis["modes"][1]["coupler_points"][name]
    want = np.column_stack([path["x"], path["y"], path["z"]]) / INCH
    assert np.max(np.abs(fit[:-1] - want)) < 1e-12 * np.max(np.abs(want))
    assert np.allclose(fit[-1], fit[0])  # closed over the full turn


def _skeleton(layers: dict, label: str, metres: float = INCH) -> list[np.ndarray]:
    polys = layers[label]
    assert [p.dxftype() for p in polys] == ["POLYLINE"] * 4  # 3 moving links and the ground
    return [np.array([tuple(v) for v in p.points()]) * metres for p in polys]


def test_skeleton_at_inputs_on_and_between_samples(tmp_path):
    """On the sweep (40°) and between samples (45°): every link ends at the next joint's
    centre, and an R or S joint's link starts at its centre, as an independent solve of the
    linkage over a 5° sweep gives them."""
    doc = ezdxf.readfile(_export(tmp_path, FIG7, "--at", "45", "--at", "40 deg"))
    layers = _layers(doc)
    spec = sk.load_spec(FIG7)
    motion = sk.solve_motion(spec.linkage, np.radians(np.arange(0.0, 355.0, 5.0)), rates=1.0)
    kinds = [j.kind for j in spec.linkage.joints]
    assert kinds == ["R", "S", "R", "C"]
    for k in (0, 1):
        centres = motion.mode(k).joint_centres
        for label, sample in (("45 deg", 9), ("40 deg", 8)):
            polys = _skeleton(layers, f"mode{k} skeleton at {label}")
            c = centres[sample]
            for i, poly in enumerate(polys):
                assert np.linalg.norm(poly[-1] - c[(i + 1) % 4]) < 1e-12
                if kinds[i] != "C":
                    assert np.linalg.norm(poly[0] - c[i]) < 1e-12
    # the crank (R to S) and coupler (S to R) keep their lengths between the two inputs
    a, b = (_skeleton(layers, f"mode0 skeleton at {x}") for x in ("45 deg", "40 deg"))
    for i in (0, 1):
        assert abs(np.linalg.norm(a[i][-1] - a[i][0]) - np.linalg.norm(b[i][-1] - b[i][0])) < 1e-12


def test_default_skeleton_is_at_the_first_input_and_joint_paths_in_mm(tmp_path):
    spec_path = EXAMPLES / "rssr_spatial.toml"  # millimetres, no coupler point
    doc = ezdxf.readfile(_export(tmp_path, spec_path))
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1
    layers = _layers(doc)
    spec = sk.load_spec(spec_path)
    motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    for md in motion.modes:
        polys = _skeleton(layers, f"mode{md.index} skeleton at 0 deg", metres=0.001)
        for i, poly in enumerate(polys):
            assert np.linalg.norm(poly[-1] - md.joint_centres[0, (i + 1) % 4]) < 1e-12
        moving = [j.name for j in spec.linkage.joints
                  if np.ptp(md.joint_centres[:, spec.linkage.joints.index(j)], axis=0).max() > 1e-9]
        assert moving  # the crank pin and the rocker's ball move, the ground pivots do not
        for j, joint in enumerate(spec.linkage.joints):
            layer = f"mode{md.index} joint {joint.name}"
            assert (layer in layers) == (joint.name in moving)
            if layer in layers:
                (curve,) = layers[layer]
                got = np.array([tuple(v) for v in curve.points()]) / 1000
                assert np.max(np.abs(got - md.joint_centres[:, j])) < 1e-15


def test_units_and_layer_names():
    assert dxf_unit(None).code == 6 and dxf_unit("inch").code == 1 and dxf_unit("um").code == 13
    with pytest.raises(ExportError, match="no unit code"):
        dxf_unit("furlong")
    assert layer_name('mode0 a/b:"c"') == "mode0 a_b__c_"


def test_curves_are_cut_where_the_mode_does_not_assemble(tmp_path):
    """Bagci's Example 7 does not assemble at its 7th input (305.35207°): each joint path is two
    open polylines around it, and asking for the skeleton there gives a note, not a layer."""
    spec_path = EXAMPLES / "bagci_example7_double_crank.toml"
    out = tmp_path / "ex7.dxf"
    r = runner.invoke(app, ["export", str(spec_path), "-f", "dxf", "-o", str(out),
                            "--at", "305.35207", "--at", "230.35207"])
    assert r.exit_code == 0, r.output
    assert "mode 0 does not assemble at input 305.35207 deg: no skeleton drawn" in r.stderr
    layers = _layers(ezdxf.readfile(out))
    spec = sk.load_spec(spec_path)
    md = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed).mode(0)
    assert np.flatnonzero(~md.assembles).tolist() == [6]
    assert "mode0 skeleton at 305.35207 deg" not in layers
    assert "mode0 skeleton at 230.35207 deg" in layers
    joint = [j.name for j in spec.linkage.joints].index("sphere")
    first, second = layers["mode0 joint sphere"]
    assert not first.is_closed and not second.is_closed
    got = [np.array([tuple(v) for v in p.points()]) * INCH for p in (first, second)]
    want = md.joint_centres[:, joint]
    assert len(got[0]) == 6 and len(got[1]) == 17
    assert np.abs(got[0] - want[:6]).max() < 1e-15 and np.abs(got[1] - want[7:]).max() < 1e-15


def test_a_fine_sweep_is_drawn_through_every_kth_sample(tmp_path):
    """7,200 samples and --max-points 1000: one in 8 samples, each exactly the analysis's."""
    spec_path = tmp_path / "fine.toml"
    spec_path.write_text(FIG7.read_text().replace('step = "10 deg"', 'step = "0.05 deg"'))
    out = _export_noted(tmp_path, spec_path, "--max-points", "1000", "--mode", "0")
    layers = _layers(ezdxf.readfile(out))
    analysis = _analysis(spec_path)
    name = analysis["coupler_points"][0]["name"]
    path = analysis["modes"][0]["coupler_points"][name]
    want = np.column_stack([path["x"], path["y"], path["z"]]) / INCH
    assert len(want) == 7200
    (curve,) = layers[f"mode0 {name}"]
    got = np.array([tuple(v) for v in curve.points()])
    rows = [*range(0, 7200, 8), 7199]
    assert got.shape == (len(rows), 3) and curve.is_closed
    assert np.max(np.abs(got - want[rows])) < 1e-12 * np.max(np.abs(want))
    full = _export_noted(tmp_path, spec_path, "--max-points", "0", "--mode", "0",
                         note=None, name="full.dxf")
    (curve,) = _layers(ezdxf.readfile(full))[f"mode0 {name}"]
    assert len(curve.vertices) == 7200


def _export_noted(tmp_path: Path, spec: Path, *args: str, name: str = "thin.dxf",
                  note: str | None = "curves drawn through one in 8 of the sweep's 7200 "
                                     "samples (--max-points 1000; 0 draws every sample)") -> Path:
    out = tmp_path / name
    r = runner.invoke(app, ["export", str(spec), "-f", "dxf", "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    err = " ".join(r.stderr.split())  # a note is wrapped at the terminal width
    assert (note in err) if note else ("note" not in err)
    return out
