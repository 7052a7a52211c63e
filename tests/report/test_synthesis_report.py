"""The report of a synthesis spec animates the synthesised mechanism (issue 30): the scene's
frames are the motion of the loop built from the synthesis's best dimensions, and its linked
output plot is that mechanism's output from θ01, which meets the synthesis's own generated output
and the target at the design points."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.io.documents import synthesis_document
from screwkit.report.spec_report import spec_scene

EXAMPLES = Path(__file__).parents[2] / "examples"
DEG = np.pi / 180


def _rows(doc: dict, key: str) -> np.ndarray:
    return np.array([np.nan if r.get(key) is None else r[key]
                     for r in sorted(doc["rows"], key=lambda r: r["theta"])], dtype=float)


@pytest.mark.parametrize(("name", "build"), [
    ("rssr_synthesis", sk.rssr),        # the generic route, rotation only
    ("bagci_example1_synthesis", sk.rsrc),  # Bagci's closed route, a translation target
])
def test_the_report_animates_the_synthesised_mechanism(name: str, build: object) -> None:
    spec = sk.load_spec(EXAMPLES / f"{name}.toml")
    doc = synthesis_document(sk.Pipeline(spec).synthesize(), spec.path)
    scene = spec_scene(spec, synthesis_doc=doc)
    dims = {k: v for k, v in doc["dimensions"].items() if k != "theta01"}
    synthesised = build(**dims)  # type: ignore[operator]
    x = np.asarray(scene["input"]["values"], dtype=float)
    theta01 = doc["dimensions"]["theta01"]
    design = theta01 + _rows(doc, "theta")
    # the frames run over the design range θ01 + θ and pass through every design input
    assert np.isclose(x.min(), design.min()) and np.isclose(x.max(), design.max())
    at = np.array([int(np.argmin(np.abs(x - d))) for d in design])
    assert np.allclose(x[at], design, atol=1e-12)
    # the drawn joint centres are the synthesised loop's motion (solved here, independently of
    # the report), and not the spec's start
    k = scene["initial_mode"]
    drawn = np.array(scene["modes"][k]["joint_centres"], dtype=float)
    motion = sk.solve_motion(synthesised, x, method="generic")
    err = [np.nanmax(np.abs(np.asarray(m.joint_centres) - drawn)) for m in motion.modes]
    assert min(err) < 1e-9
    start = sk.solve_motion(spec.linkage, x, method="generic")
    assert all(not np.allclose(np.asarray(m.joint_centres), drawn, equal_nan=True)
               for m in start.modes)
    # the linked output plot: the synthesised mechanism's ψ0 from θ01 equals the synthesis's
    # generated ψ_g0 at the design points, and its target curve the desired ψ_d0 there
    plot = next(p for p in scene["plots"] if p["id"] == "syn-follow-rot")
    assert plot["linked"] and plot["series"][0]["mode"] == k
    generated = np.array(plot["series"][0]["y"], dtype=float)
    target = np.array(plot["series"][1]["y"], dtype=float)
    assert len(generated) == len(x)
    ok = np.isfinite(_rows(doc, "psi_d0"))
    assert np.allclose(generated[at], _rows(doc, "psi_g0"), atol=1e-9)
    assert np.allclose(target[at][ok], _rows(doc, "psi_d0")[ok], atol=1e-12)
    phi0 = np.asarray(sk.solve_motion(synthesised, x).modes[k].variables["phi0"])
    ref = int(np.argmin(np.abs(x - theta01)))
    assert np.allclose(generated, np.angle(np.exp(1j * (phi0 - phi0[ref]))), atol=1e-9)
    # the output ψ0 of the shown mechanism spans the target's range (RSSR: 0…40°), not the
    # start's ~140°
    if name == "rssr_synthesis":
        assert np.nanmax(np.abs(generated)) < 41 * DEG
    if np.isfinite(_rows(doc, "S_d")).any():
        tr = next(p for p in scene["plots"] if p["id"] == "syn-follow-tr")
        assert np.allclose(np.array(tr["series"][0]["y"])[at], _rows(doc, "S_g"), atol=1e-9)
    assert "synthesised" in scene["description"]
    # the start stands still as a ghost: its links end at joint centres of the spec's motion
    ends = np.array([[np.nan if v is None else v for v in link[2]]
                     for link in scene["ghost"]["link_points"]], dtype=float)
    spec_motion = sk.solve_motion(spec.linkage, spec.inputs)
    assert any(np.allclose(np.roll(np.asarray(m.joint_centres)[i], -1, axis=0), ends, atol=1e-12)
               for m in spec_motion.modes for i in range(len(spec.inputs)))
    assert "synthesis start" in scene["ghost"]["label"]


def test_a_synthesis_spec_with_masses_draws_no_dynamics_of_the_start(tmp_path: Path) -> None:
    """Dynamics of the spec's [dimensions] beside the synthesised mechanism would mix two
    mechanisms: the report leaves them out and says so."""
    text = (EXAMPLES / "rssr_synthesis.toml").read_text(encoding="utf-8")
    links = (EXAMPLES / "rssr_spatial.toml").read_text(encoding="utf-8")
    links = links[links.index("[links.crank]"):]
    path = tmp_path / "rssr_synthesis_masses.toml"
    path.write_text(text.replace('angle = "deg"', 'angle = "deg"\ninertia = "kg*mm^2"', 1)
                    + "\n" + links, encoding="utf-8")
    spec = sk.load_spec(path)
    assert all(link.mass is not None for link in spec.linkage.links)
    scene = spec_scene(spec)
    assert not [p for p in scene["plots"] if p["group"] in ("dynamics", "balancing")]
    assert all(not m["arrows"] for m in scene["modes"])
    notes = scene["text"]["validation"]
    assert any("no dynamics or balancing" in n for n in notes)
    assert not any(n.startswith("Dynamics and balancing are of [motion] mode") for n in notes)
    assert any(p["id"] == "syn-follow-rot" for p in scene["plots"])
