"""The rule for a rod between two ball joints (docs/dynamics.md, "What is indeterminate"):
its idle spin carries no load when the rod is axisymmetric about the line of its ball centres
with its centre of mass on that line — whatever its axial moment of inertia. Measured on
Rahman's CSSP example through the spec file, as a user would; the residuals quoted in the docs
come from this test's cases."""

from pathlib import Path

import numpy as np
import pytest

from analysis_helpers import mode_motion
from screwkit.dynamics import inverse_dynamics
from screwkit.io.spec import load_spec

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rahman_cssp.toml"
ROD = "com = [4.0, 0.0, 0.0]\ninertia = [8.195304e-4, 0.105310, 0.105310]"


def _residual(tmp_path: Path, rod: str) -> float:
    text = EXAMPLE.read_text()
    assert ROD in text
    spec_file = tmp_path / "rod.toml"
    spec_file.write_text(text.replace(ROD, rod))
    s = load_spec(spec_file)
    mm = mode_motion(s.linkage, s.inputs, s.speed, s.acceleration, s.mode)
    return float(np.max(inverse_dynamics(s.linkage, mm).relative_residual))


@pytest.mark.parametrize("rod", [
    ROD,                                                    # the example: axial inertia 8.2e-4
    "com = [4.0, 0.0, 0.0]\ninertia = [0.05, 0.105310, 0.105310]",   # larger axial inertia
    "com = [4.0, 0.0, 0.0]\ninertia = [0.0, 0.105310, 0.105310]",    # a line mass
])
def test_axisymmetric_rods_balance_exactly_with_or_without_axial_inertia(tmp_path, rod):
    assert _residual(tmp_path, rod) < 1e-14  # measured 7.6e-18


@pytest.mark.parametrize("rod, at_least", [
    # transverse moments 10 % apart (axial raised so the triangle inequality holds)
    ("com = [4.0, 0.0, 0.0]\ninertia = [0.0106, 0.105310, 0.0948]", 1e-5),  # measured 1.1e-4
    # centre of mass 0.1 in off the line of the ball centres
    ("com = [4.0, 0.1, 0.0]\ninertia = [8.195304e-4, 0.105310, 0.105310]", 1e-4),  # 6.0e-4
])
def test_a_rod_that_breaks_the_rule_leaves_a_reported_residual(tmp_path, rod, at_least):
    assert _residual(tmp_path, rod) > at_least
