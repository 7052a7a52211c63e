"""Mobility of real Linkage objects: the formula next to the rank of the loop Jacobian."""

import numpy as np
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.kinematics.analysis.loop_mobility import linkage_mobility
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model import Joint, Linkage
from screwkit.model.families import fourbar, rsrc, rssr

deg = np.radians


def _mob(lk, x=0.7):
    return linkage_mobility(lk, np.array([x]))


def test_rsrc_formula_and_jacobian_agree():
    d = _mob(rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60)), deg(100))
    assert d["formula"]["mobility"] == 1 and d["numeric"]["mobility"] == 1
    assert d["numeric"]["redundant_constraints"] == 0


def test_planar_fourbar_as_a_spatial_loop_has_three_redundant_constraints():
    d = _mob(fourbar(3.0, 1.0, 3.0, 2.5))
    assert d["formula"]["mobility"] == -2
    assert d["numeric"]["mobility"] == 1 and d["numeric"]["redundant_constraints"] == 3


def test_rssr_rod_spin_is_found_and_named():
    d = _mob(rssr(1.0, 4.0, 3.0, 3.0, 2.0, deg(50), 0.5))
    assert d["numeric"]["mobility"] == 2
    text = " ".join(d["summary"])
    assert "ball1" in text and "ball2" in text


def test_bennett_linkage_moves_although_the_formula_says_minus_two():
    # Bennett: opposite links equal, a/sin α equal for both pairs (Bagci App. B)
    a1, al1, al2 = 1.0, deg(40), deg(70)
    a2 = a1 * np.sin(al2) / np.sin(al1)
    joints = [Joint(f"B{i + 1}", "R") for i in range(4)]
    lk = Linkage.from_hartenberg_denavit("Bennett", joints, [a1, a2, a1, a2], [al1, al2, al1, al2],
                                         inputs=["B1.theta"])
    m = motion(lk, deg(np.arange(0, 360, 30.0)))
    assert any(md.assembles.all() for md in m.modes)  # it really moves through a full turn
    d = _mob(lk, deg(30))
    assert d["formula"]["mobility"] == -2
    assert d["numeric"]["mobility"] == 1 and d["numeric"]["redundant_constraints"] == 3


def test_cli_mobility_json(tmp_path):
    examples = __import__("pathlib").Path(__file__).resolve().parents[2] / "examples"
    r = CliRunner().invoke(app, ["mobility", str(examples / "rahman_cssp.toml"), "--json"])
    assert r.exit_code == 0, r.output
    import json

    doc = json.loads(r.stdout)
    assert doc["formula"]["mobility"] == 2 and doc["numeric"]["mobility"] == 2
