"""``screwkit export --format step`` of mechanism graphs: the file read back with OpenCASCADE's
XCAF reader holds one named part per body and the ground; each segment of a body's drawn
polyline (through its joints and points, carried by an independent ``solve_mechanism`` of the
spec) is a cylinder of radius r with those ends, every joint's solid sits on its first body at
its centre along its axis, and every volume is πr²L or 4/3·πR³, all to 1e-9 relative."""

import math
from pathlib import Path

import numpy as np
from tests.exchange.test_export_step import _read
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.exchange.step import JOINT_HALF_LENGTH
from screwkit.kinematics.graph import solve_mechanism
from screwkit.model.mechanism import GROUND
from screwkit.report.graph_scene import body_polylines

MECHANISMS = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
runner = CliRunner()


def _export(tmp_path: Path, spec: Path, *args: str) -> Path:
    out = tmp_path / "graph.step"
    r = runner.invoke(app, ["export", str(spec), "--format", "step", "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    return out


def _segments(poly: np.ndarray, tol: float) -> list[tuple[np.ndarray, np.ndarray]]:
    return [(a, b) for a, b in zip(poly[:-1], poly[1:], strict=True)
            if np.linalg.norm(b - a) > tol]


def _check_pose(parts: dict, mech, md, sample: int, suffix: str = "") -> None:
    ok = md.assembles
    size = float(np.linalg.norm(np.ptp(md.joint_centres[ok].reshape(-1, 3), axis=0)))
    r, tol = 0.012 * size, 1e-9 * size
    names = [*mech.body_names, GROUND]
    assert sorted(parts) == sorted(f"{n}{suffix}" for n in names)
    polylines = body_polylines(mech, md)[sample]
    centres, axes = md.joint_centres[sample], md.joint_axes[sample]
    for k, name in enumerate(names):
        solids = parts[f"{name}{suffix}"]
        for s in solids:
            if s["kind"] == "cylinder":
                a, b = s["ends"]
                want = math.pi * s["radius"] ** 2 * float(np.linalg.norm(b - a))
            else:
                want = 4 / 3 * math.pi * s["radius"] ** 3
            assert abs(s["volume"] - want) < 1e-9 * want
        bars = [s for s in solids if abs(s["radius"] - r) < tol]
        segs = _segments(polylines[k], 1e-9 * r)
        assert len(bars) == len(segs)
        for a, b in segs:  # each segment is one cylinder with those two ends
            assert any(min(np.linalg.norm(c["ends"][0] - a) + np.linalg.norm(c["ends"][1] - b),
                           np.linalg.norm(c["ends"][1] - a) + np.linalg.norm(c["ends"][0] - b))
                       < tol for c in bars), (name, a, b)
        mine = [i for i, j in enumerate(mech.joints) if j.bodies[0] == name]
        joints = [s for s in solids if abs(s["radius"] - 2 * r) < tol]
        assert len(joints) == len(mine)
        for i in mine:
            c, h = centres[i], JOINT_HALF_LENGTH * r * axes[i]
            if mech.joints[i].kind == "S":
                assert any(s["kind"] == "sphere" and np.linalg.norm(s["centre"] - c) < tol
                           for s in joints)
            else:
                assert any(s["kind"] == "cylinder" and min(
                    np.linalg.norm(s["ends"][0] - c + h) + np.linalg.norm(s["ends"][1] - c - h),
                    np.linalg.norm(s["ends"][1] - c + h) + np.linalg.norm(s["ends"][0] - c - h))
                    < tol for s in joints), mech.joints[i].name


def test_watt_sixbar_at_two_inputs_in_mm(tmp_path):
    """At 30° (a sample) and 30.5° (between samples, solved with the sweep): R joints as
    cylinders along their axes, millimetres as the file's unit."""
    path = MECHANISMS / "watt_sixbar.toml"
    out = _export(tmp_path, path, "--at", "30", "--at", "30.5 deg")
    assert "SI_UNIT(.MILLI.,.METRE.)" in out.read_text()
    parts = _read(out)
    spec = sk.load_spec(path)
    x = np.radians(np.concatenate([np.arange(0.0, 360.0, 1.0), [30.5]]))
    order = np.argsort(x, kind="stable")
    motion = solve_mechanism(spec.mechanism, x[order][:, None], rates=spec.speed)
    md = motion.mode(0)
    # the sweep's size is that of the whole sweep (0…360°), which the export solves too
    for label, value in (("30 deg", 30.0), ("30.5 deg", 30.5)):
        sample = int(np.flatnonzero(np.isclose(x[order], np.radians(value)))[0])
        mine = {n: s for n, s in parts.items() if n.endswith(f" at {label}")}
        _check_pose(mine, spec.mechanism, md, sample, f" at {label}")


def test_stewart_platform_spheres_and_prismatic_legs(tmp_path):
    """S joints as spheres, the legs' P joints as cylinders, at the first input."""
    path = MECHANISMS / "stewart_platform.toml"
    parts = _read(_export(tmp_path, path))
    spec = sk.load_spec(path)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed)
    kinds = {j.kind for j in spec.mechanism.joints}
    assert "S" in kinds and len(kinds) >= 2
    _check_pose(parts, spec.mechanism, motion.mode(spec.mode if hasattr(spec, "mode") else 0), 0)


def test_another_assembly_mode_of_the_six_bar(tmp_path):
    """``--mode 1``: the closed-form dyads' second mode, solved with every mode."""
    path = MECHANISMS / "watt_sixbar.toml"
    parts = _read(_export(tmp_path, path, "--mode", "1", "--at", "30"))
    spec = sk.load_spec(path)
    motion = solve_mechanism(spec.mechanism, spec.inputs, rates=spec.speed, every_mode=True)
    md = motion.mode(1)
    drawn = motion.mode(0)
    assert np.abs(md.joint_centres[30] - drawn.joint_centres[30]).max() > 1e-3  # another pose
    _check_pose(parts, spec.mechanism, md, 30)
