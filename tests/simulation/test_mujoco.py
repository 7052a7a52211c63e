"""screwkit against MuJoCo (validation/mujoco/crosscheck.py, whose report justifies the
tolerances): the exported model compiles and is assembled, and Rahman's CSSP driven at its crank
speed gives MuJoCo's input torque and shaking loads; the free-running loop, screwkit simulate's
speed. (tests/validation runs the whole script on the three examples.)"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app

mujoco = pytest.importorskip("mujoco", reason="the validate extra (MuJoCo) is not installed")
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "validation" / "mujoco"))
import crosscheck  # noqa: E402


@pytest.mark.parametrize("name", ["rahman_cssp", "rsrc_fig7_dynamics", "rssr_spatial",
                                  "fourbar_dynamics"])
def test_exported_model_is_assembled_with_the_spec_masses(tmp_path, name):
    out = tmp_path / "model.xml"
    r = CliRunner().invoke(app, ["export-mjcf", str(ROOT / "examples" / f"{name}.toml"),
                                 "-o", str(out)])
    assert r.exit_code == 0, r.output
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert np.max(np.abs(d.efc_pos[: d.nefc])) < 1e-12  # qpos0 closes the loop
    spec = sk.load_spec(ROOT / "examples" / f"{name}.toml")
    masses = sorted(link.mass.mass for link in spec.linkage.links)
    assert np.allclose(sorted(m.body_mass[1:]), masses, rtol=1e-12)


def test_cssp_against_mujoco():
    spec = sk.load_spec(ROOT / "examples" / "rahman_cssp.toml")
    driven = crosscheck.compare_driven(spec, crosscheck.driven_run(spec, crosscheck.build(spec),
                                                                   turns=0.5, samples=36))
    for key in ("input torque", "shaking force", "shaking moment"):
        assert driven[key] < crosscheck.TOLERANCE[key], (key, driven[key])
    free = crosscheck.free_run(spec, crosscheck.build(spec), turns=1.0)
    assert free["free-run speed"] < crosscheck.TOLERANCE["free-run speed"]


def test_joint_friction_against_mujoco():
    """MuJoCo's joint damping is [drive.friction]'s viscous friction: the driven input torque
    (ideal inverse dynamics + B θ̇), the shaking loads (unchanged by friction) and the
    coast-down agree as the frictionless run does, with friction carrying several per cent of
    the torque."""
    spec = sk.load_spec(ROOT / "examples" / "rsrc_fig7_dynamics.toml")
    friction = crosscheck.friction_for(spec)
    assert {f.joint for f in friction} == {"input", "coupler_R", "output_C"}
    rec = crosscheck.driven_run(spec, crosscheck.build(spec, friction=friction), turns=0.5,
                                samples=36)
    driven = crosscheck.compare_driven_with_friction(spec, rec, friction)
    assert driven["friction share"] > 0.01
    for key in ("input torque (friction)", "shaking force (friction)",
                "shaking moment (friction)"):
        assert driven[key] < crosscheck.FRICTION_TOLERANCE[key], (key, driven[key])
    coast = crosscheck.free_run(spec, crosscheck.build(spec, friction=friction), turns=1.0,
                                friction=friction)
    assert coast["speed lost"] > 0.05
    key = "coast-down speed (friction)"
    assert coast[key] < crosscheck.FRICTION_TOLERANCE[key]


#: a coasting CSSP whose flywheel and gravity both change the motion by far more than the
#: agreement asked (without the flywheel the speed differs by ~60 %, without gravity by ~16 %)
COAST_DRIVE = """
[drive]
flywheel = "0.01 kg*m^2"
initial_speed = "300 rpm"
cycles = 2
gravity = true
rtol = 1e-11

[drive.motor]
kind = "none"

[drive.friction]
crank = "0.002 N*m*s/rad"
slider = "1 N*s/m"
"""


def _coast_spec(tmp_path: Path) -> Path:
    text = (ROOT / "examples" / "rahman_cssp_drive.toml").read_text(encoding="utf-8")
    head = text[: text.index("[drive]")].replace(
        'gravity = "386.4 in/s^2"', 'gravity = "386.4 in/s^2"\ngravity_direction = [0, -1, 0]', 1)
    path = tmp_path / "coast.toml"
    path.write_text(head + COAST_DRIVE, encoding="utf-8")
    return path


def test_simulate_equals_mujoco_on_the_export_as_written(tmp_path):
    """issue 30: ``export-mjcf`` writes the [drive] flywheel (the input's armature) and the
    gravity ``simulate`` uses, so MuJoCo on the file as written coasts as ``screwkit simulate``
    does, within the free-run tolerance of validation/mujoco."""
    import dataclasses

    from screwkit.simulation.flywheel import with_flywheel
    from screwkit.simulation.integrate import simulate_cycles
    from screwkit.simulation.spec_run import spec_equation_of_motion, spec_gravity

    path = _coast_spec(tmp_path)
    spec = sk.load_spec(path)
    out = tmp_path / "coast.xml"
    r = CliRunner().invoke(app, ["export-mjcf", str(path), "-o", str(out)])
    assert r.exit_code == 0, r.output
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    lay = crosscheck.loop_layout(spec.linkage)
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, lay.dofs["crank"][0])
    dof = int(m.jnt_dofadr[jid])
    assert np.allclose(m.opt.gravity, spec_gravity(spec), rtol=1e-15)
    assert m.dof_armature[dof] == pytest.approx(0.01, rel=1e-15)
    roots = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
    built = crosscheck.Built(m, d, dof, roots, 2 * np.pi / spec.drive.initial_speed)
    d.qvel[:] = crosscheck.consistent_velocity(spec, built, spec.drive.initial_speed)
    times, speeds = [], []
    for k in range(int(round(built.period / m.opt.timestep))):
        if k % 200 == 0:
            times.append(d.time)
            speeds.append(d.qvel[dof])
        mujoco.mj_step(m, d)
    t = np.array(times)

    def simulated(eom):
        run = simulate_cycles(eom, cycles=2, initial_speed=spec.drive.initial_speed, rtol=1e-12)
        assert run.status == "completed"
        return run.solution(t)[1]

    eom = spec_equation_of_motion(spec)
    ours = simulated(eom)
    tolerance = crosscheck.TOLERANCE["free-run speed"]
    assert crosscheck.rel(np.array(speeds), ours) < tolerance
    # the check can fail: leaving out the flywheel or the gravity moves the speed by far more
    for other in (with_flywheel(eom, 0.0),
                  spec_equation_of_motion(spec, dataclasses.replace(spec.drive, gravity=False))):
        assert crosscheck.rel(np.array(speeds), simulated(other)) > 100 * tolerance
    # --no-gravity leaves it out (the flywheel stays)
    r = CliRunner().invoke(app, ["export-mjcf", str(path), "-o", str(out), "--no-gravity"])
    assert r.exit_code == 0 and "no gravity" in r.output
    m = mujoco.MjModel.from_xml_path(str(out))
    assert not np.any(m.opt.gravity) and m.dof_armature[dof] == pytest.approx(0.01, rel=1e-15)
