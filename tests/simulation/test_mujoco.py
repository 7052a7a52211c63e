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
