"""The studio page on bundled examples of every kind of loop (families with a closed form, the
tracker on a joint list, a translation output, inches, with and without masses): it draws the
curves the pipeline solves, the 3-D view and the numbers, and logs no error."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from studio_serving import EXAMPLES, serving

from screwkit.io.spec import load_spec
from screwkit.kinematics.registry import default_outputs
from screwkit.pipeline import Pipeline

CASES = ["rrsrr_loop", "rahman_cssp", "bagci_fig7_rsrc", "fourbar_dynamics", "rccc_loop"]


@pytest.mark.parametrize("name", CASES)
def test_example_in_the_studio(name: str, browser: Any) -> None:
    spec_path = EXAMPLES / f"{name}.toml"
    with serving(spec_path) as served:
        page = browser.new_page()
        errors: list[str] = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        try:
            page.goto(served.url)
            page.wait_for_function("() => window.studio.viewReady && window.studio.numbers",
                                   timeout=60_000)
            r = page.evaluate("window.studio.result")
            assert r["ok"], r
            spec = load_spec(spec_path)
            mot = Pipeline(spec).motion
            assert len(r["modes"]) == len(mot.modes)
            out = (list(default_outputs(spec.linkage)) or [None])[0]
            if out is not None:  # in the display unit of its kind (Rahman's s4 in inches)
                units = spec.display_units()
                kind = "length" if (spec.family == "CSSP" and out == "s4") else (
                    "length" if out.endswith(".s") else "angle")
                key = f"{out} [{units.label(kind)}]"
                shown = np.array(r["modes"][0]["outputs"][key], dtype=float)
                np.testing.assert_allclose(shown * units.unit_of(kind)[1],
                                           mot.modes[0].variables[out], rtol=1e-12,
                                           atol=1e-12, equal_nan=True)
            assert page.evaluate("document.querySelectorAll('#plots svg').length") >= 3
            assert page.evaluate("document.querySelectorAll('#numbers tr').length") >= 1
            has_loads = all(link.mass is not None for link in spec.linkage.links)
            assert (r["loads"] is not None) == has_loads
            assert page.evaluate("document.getElementById('view').contentWindow"
                                 ".screwkitViewer.frameCount") == len(spec.inputs)
            traces = page.evaluate("""Object.keys(JSON.parse(document.getElementById('view')
                .contentDocument.getElementById('screwkit-scene').textContent).modes[0].traces)""")
            assert traces == [p.name for p in spec.coupler_points]  # their 3-D paths
            assert not errors, errors
        finally:
            page.close()
