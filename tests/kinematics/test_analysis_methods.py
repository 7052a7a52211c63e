"""The two analysis paths — closed form (RSRC quartic / planar 4R) and the generic loop
solver — give the same modes, positions, velocities and accelerations."""

from pathlib import Path

import numpy as np
import pytest

from analysis_helpers import analyze
from screwkit.io.spec import load_spec

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("name", ["bagci_fig7_rsrc", "bagci_example1", "bagci_example3_4r", "rahman_cssp",
                                  "bagci_example7_double_crank", "bagci_fig10_double_crank",
                                  "rssr_spatial", "rccc_loop"])
def test_closed_form_and_generic_analyses_agree(name):
    s = load_spec(EXAMPLES / f"{name}.toml")
    speed = s.speed if s.family == "CSSP" else 1.3
    _, c = analyze(s.linkage, s.inputs, speed, 0.4, s.coupler_point, method="closed")
    _, g = analyze(s.linkage, s.inputs, speed, 0.4, s.coupler_point, method="generic")
    assert c["method"] == "closed" and g["method"] == "generic"
    lead = {"CSSP": "s4", "LOOP": "C4.theta"}.get(s.family, "phi0")
    keys = {"RSRC": ["phi0", "S", "chi0"], "4R": ["phi0"], "CSSP": ["s4", "theta2", "eta2"],
            "RSSR": ["phi0"], "LOOP": ["C2.theta", "C2.s", "C3.theta", "C3.s", "C4.theta", "C4.s"]
            }[s.family]
    scale = s.speed if s.family == "CSSP" else 1.0
    assert sum(np.sum(m["assembles"]) for m in c["modes"]) == sum(np.sum(m["assembles"]) for m in g["modes"])
    for mc in c["modes"]:
        ok = mc["assembles"]
        matches = []
        for mg in g["modes"]:
            both = ok & mg["assembles"]
            if not both.any():
                continue
            d = np.abs(np.angle(np.exp(1j * (mc["variables"][lead][both] - mg["variables"][lead][both]))))
            if d.max() < 1e-9:
                matches.append((mg, both))
        covered = np.zeros_like(ok)
        for mg, both in matches:
            covered |= both
            for k in keys:
                # both are exact formulas: agreement to round-off of O(1) quantities
                np.testing.assert_allclose(mc["velocities"][k][both], mg["velocities"][k][both], atol=1e-9 * scale)
                np.testing.assert_allclose(mc["accelerations"][k][both], mg["accelerations"][k][both], atol=1e-8 * scale**2)
            if "coupler_point" in mc:
                for ax in "xyz":
                    np.testing.assert_allclose(mc["coupler_point"][ax][both], mg["coupler_point"][ax][both], atol=1e-12)
        assert covered.sum() == ok.sum()
        assert np.nanmax(mc["closure_residual"]) < 1e-12


def test_closed_form_refuses_a_loop_without_one():
    from screwkit.model import Joint, Linkage

    loop = Linkage.from_hartenberg_denavit(
        "RSHC", [Joint("in", "R"), Joint("ball", "S"), Joint("screw", "H", pitch=0.02),
                 Joint("cyl", "C")],
        [0.05, 0.2, 0.15, 0.18], np.radians([20, 10, -30, 40]), inputs=["in.theta"])
    with pytest.raises(ValueError, match="no closed form"):
        analyze(loop, np.radians([0.0, 10.0]), method="closed")
