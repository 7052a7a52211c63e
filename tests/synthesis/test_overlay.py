"""The overlay technique (Bagci 1969, §5.4): exact recovery, dwell geometry, the spec route for
Examples 8 and 9 re-analysed independently with the RSRC closed form, bad input and limits."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from screwkit.cli.synthesize_cmd import register
from screwkit.dual.spatial import wrap_angle
from screwkit.io.spec import load_spec
from screwkit.io.synthesis_table import (
    SynthesisConfigError,
    overlay_problem_from_spec,
    problem_from_spec,
)
from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_motion, rsrc_positions
from screwkit.synthesis.overlay import (
    OverlayDwell,
    ellipse_curvature_radius,
    ellipse_normal,
    fit_overlay_circles,
    mechanism_from_circle,
)
from screwkit.synthesis.overlay_synthesis import OverlayOutcome, OverlayProblem, synthesize_overlay
from screwkit.synthesis.solve import SynthesisError
from screwkit.synthesis.targets import ScrewTarget, data_function, library_function

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
IN = 0.0254
D = math.radians
app = typer.Typer()
register(app)


@app.command()
def _placeholder() -> None:  # a second command keeps typer's subcommand form
    """(unused)"""


runner = CliRunner()


def _generated_psi(dims: RSRCDimensions, theta01: float, theta: np.ndarray, root: int = 0,
                   input_direction: int = 1) -> np.ndarray:
    phi = rsrc_positions(dims, theta01 + input_direction * theta).phi0[:, root]
    return np.unwrap(phi - phi[0])


def _phi_near(dims: RSRCDimensions, theta0: np.ndarray, phi_ref: float) -> np.ndarray:
    """The closed-form root nearest phi_ref at each theta0 (a few samples close together)."""
    pos = rsrc_positions(dims, theta0)
    gap = np.where(pos.assembles, np.abs(wrap_angle(pos.phi0 - phi_ref)), np.inf)
    return pos.phi0[np.arange(theta0.size), np.argmin(gap, axis=1)]


def _psi_on_branch(outcome: OverlayOutcome, problem: OverlayProblem) -> np.ndarray:
    """Independent re-analysis: `rsrc_motion` (branch-tracked closed form) over a 0.25-deg sweep
    through the design points; the branch is the one through the overlay's output angle at
    theta = 0; returns the generated psi at the rotation design points."""
    dims_d = outcome.result.dimensions
    dims = RSRCDimensions(*(dims_d[k] for k in ("d1", "d2", "d3", "a", "b", "e", "delta0",
                                                 "lambda0")))
    theta = problem.target.theta_rotation
    sweep = np.union1d(np.arange(theta.min(), theta.max(), D(0.25)), np.append(theta, 0.0))
    theta0 = dims_d["theta01"] + problem.input_direction * sweep
    order = np.argsort(theta0)
    motion = rsrc_motion(dims, theta0[order])
    k0 = int(np.flatnonzero(sweep[order] == 0.0)[0])
    phi0_overlay = outcome.circle.phi01
    if abs(math.sin(dims.lambda0)) < 1e-12:  # plane case: frame turned by the centre's angle
        phi0_overlay -= math.atan2(outcome.circle.centre[1], outcome.circle.centre[0])
    gap = np.where(motion.assembles[k0], np.abs(wrap_angle(motion.phi0[k0] - phi0_overlay)),
                   np.inf)
    branch = int(np.argmin(gap))
    assert motion.assembles[:, branch].all()
    phi = np.empty_like(sweep)
    phi[order] = motion.phi0[:, branch]
    at = np.searchsorted(sweep, theta)
    return outcome.output_direction * wrap_angle(phi[at] - phi[np.searchsorted(sweep, 0.0)])


def _check_reanalysis(outcome: OverlayOutcome, problem: OverlayProblem) -> float:
    """The reported errors are those of the mechanism, re-analysed independently; returns the
    independent RMSE (rad)."""
    psi_g = _psi_on_branch(outcome, problem)
    psi_d = problem.target.desired_rotation(problem.target.theta_rotation)
    err = wrap_angle(psi_d - psi_g)
    rmse = float(np.sqrt(np.mean(err**2)))
    # both analyses solve the same closed form: they agree to rounding
    assert rmse == pytest.approx(outcome.result.rmse_phi, rel=1e-9, abs=1e-12)
    assert float(np.max(np.abs(err))) <= abs(outcome.result.max_dev_phi) * (1 + 1e-9) + 1e-12
    assert outcome.result.range_check.ok
    return rmse


# --- geometry ------------------------------------------------------------------------------------
def test_ellipse_normal_is_eq_5_13_and_curvature_of_example_9() -> None:
    t = np.radians([10.0, 100.0, 210.0, 300.0])
    nx, ny = ellipse_normal(3.0, D(60), t, "exterior")
    # eq. 5.13: tan q = tan(theta0) / cos(lambda0) (mod pi)
    q = np.arctan(np.tan(t) / math.cos(D(60)))
    assert np.allclose(np.sin(np.arctan2(ny, nx) - q), 0.0, atol=1e-12)
    px, py = 3.0 * np.cos(t), 1.5 * np.sin(t)
    assert np.all(nx * px + ny * py > 0)  # exterior = outward
    inx, iny = ellipse_normal(3.0, D(60), t, "interior")
    assert np.allclose([inx, iny], [-nx, -ny])
    # Ex. 9: the seed's q1 = 49.06 deg (eq. 5.13: 49.107) is the inward normal at 210 deg
    q1 = math.degrees(math.atan2(float(iny[2]), float(inx[2])))
    assert q1 == pytest.approx(49.1066, abs=1e-4)
    # SPEC §12 (L2295): the ellipse's radius of curvature at 210 deg is ~1.736 in, not 1.96
    assert float(ellipse_curvature_radius(3.0, D(60), D(210))) == pytest.approx(1.73627, abs=1e-5)
    # a circle (lambda0 = 0) has radius of curvature d1 everywhere
    assert np.allclose(ellipse_curvature_radius(2.0, 0.0, t), 2.0, rtol=1e-12)


@pytest.mark.parametrize("lambda0_deg", [60.0, 0.0])
def test_exact_mechanism_recovered_with_refined_d2(lambda0_deg: float) -> None:
    # a delta0 = 0 mechanism generates psi at 7 points; started from a wrong d2 (2.6 instead of 3),
    # the overlay with d2 refined finds it again: circles met exactly, a, b, d3, d2 recovered.
    # lambda0 = 0 is the plane 4R, re-referenced so that the output axis is on +x (a = |centre|).
    lam = D(lambda0_deg)
    b = 1.1 if lambda0_deg else 0.0
    dims = RSRCDimensions(2.0, 3.0, 2.5, 3.2, b, 0.0, 0.0, lam)
    theta01 = D(100)
    theta = np.radians(np.arange(0.0, 91.0, 15.0))
    psi = _generated_psi(dims, theta01, theta)
    circles = fit_overlay_circles(d1=2.0, d2=2.6, lambda0=lam, theta01=theta01, theta=theta,
                                  psi=psi, refine_d2=True)
    best = circles[0]
    assert np.max(np.abs(best.circle_residual)) < 1e-9
    got, th01, _ = mechanism_from_circle(best, d1=2.0, lambda0=lam, theta01=theta01)
    for name in ("d2", "d3", "a", "b"):
        assert getattr(got, name) == pytest.approx(getattr(dims, name), abs=1e-8)
    assert th01 == pytest.approx(theta01, abs=1e-9)


def test_interior_dwell_with_curvature_radius_gives_a_higher_order_dwell() -> None:
    # the overlay point on the inward normal at theta = 0 with d2 = the ellipse's radius of
    # curvature: the output crank tip is the centre of curvature, so psi = O(theta^3) there
    # (psi' = psi'' = 0); with the exterior normal (a rotation limit, target (theta/60)^2)
    # only psi' = 0.
    theta = np.radians(np.arange(-60.0, 61.0, 15.0))
    d1, lam, theta01 = 3.0, D(60), D(210)
    rho = float(ellipse_curvature_radius(d1, lam, theta01))
    h = 1e-3
    for tangency, second_order in (("interior", True), ("exterior", False)):
        d2 = rho if tangency == "interior" else 4.0
        psi = (D(60) * (theta / D(60)) ** 3 if second_order
               else D(-30) * (theta / D(60)) ** 2)
        problem = OverlayProblem(ScrewTarget(data_function(theta, psi), theta), d1=d1, d2=d2,
                                 lambda0=lam, theta01=theta01,
                                 dwells=(OverlayDwell(0.0, tangency),), length_scale=1.0)
        out = synthesize_overlay(problem)[0]
        assert abs(out.circle.circle_residual[4]) < 1e-14  # the dwell point is on its circle
        d = out.result.dimensions
        dims = RSRCDimensions(*(d[k] for k in ("d1", "d2", "d3", "a", "b", "e", "delta0",
                                               "lambda0")))
        phi = _phi_near(dims, theta01 + np.array([-h, 0.0, h]), out.result.rows[0]["phi_g"])
        slope = (phi[2] - phi[0]) / (2 * h)
        curvature = (phi[2] - 2 * phi[1] + phi[0]) / h**2
        # central differences: truncation ~h^2 |psi'''| ~ 1e-6, rounding ~1e-16 / h^2 = 1e-10
        assert abs(slope) < 1e-5
        if second_order:
            assert abs(curvature) < 1e-5
        else:
            assert abs(curvature) > 1e-2


def test_two_dwells_are_program_c_construction_of_example_5() -> None:
    # Example 5 (Table IX): rotation limits at theta0 = 90 deg (exterior normal, q1 = 90 deg)
    # and 330 deg (interior, q2 = 130.893 deg), output range 35 deg, d2 = 9.886017 in.  Two
    # dwells fix the overlay circle: it must be eqs. 5.19-5.21, i.e. the tables/ reconstruction
    # d3 = 10.219795, a = 3.835118, b = 1.631712 in (tests/data/bagci1969/table_IX.json).
    ls_problem, _ = problem_from_spec(load_spec(EXAMPLES / "bagci_example5_synthesis.toml"))
    table = json.loads((Path(__file__).resolve().parents[1] / "data" / "bagci1969"
                        / "table_IX.json").read_text())
    expect = table["q_reconstruction"]["gives"]
    problem = OverlayProblem(ls_problem.target, d1=2 * IN, d2=9.886017 * IN, lambda0=D(60),
                             theta01=D(90), dwells=(OverlayDwell(0.0, "exterior"),
                                                    OverlayDwell(D(240), "interior")))
    out = synthesize_overlay(problem)[0]
    d = out.result.dimensions
    for name in ("d3", "a", "b"):
        # the table's reconstruction is printed to 6 decimals (in)
        assert d[name] / IN == pytest.approx(expect[name], abs=2e-6)
    _check_reanalysis(out, problem)


# --- Examples 8 and 9 from their spec files --------------------------------------------------
def test_example8_four_mechanisms_reanalysed() -> None:
    problem, _ = overlay_problem_from_spec(load_spec(EXAMPLES / "bagci_example8_overlay.toml"))
    assert problem.d1 / IN == pytest.approx(10 / 1.224745, rel=1e-6)
    outcomes = synthesize_overlay(problem)
    # the seed's A, B (counter-clockwise) and C, D (clockwise): two of each sense
    assert sorted(o.output_direction for o in outcomes) == [-1, -1, 1, 1]
    rmses = [_check_reanalysis(o, problem) for o in outcomes]
    assert rmses == sorted(rmses)
    assert math.degrees(rmses[0]) < 0.2
    for o in outcomes:
        assert o.result.range_check.min_transmission > 0.5
        # the translation is the sine d1 sin(lambda0) sin(theta0), not fitted: E_S is the same
        # for every mechanism and its RMS is ~0.14 in against the straight helix
        assert o.result.rmse_S / IN == pytest.approx(outcomes[0].result.rmse_S / IN, rel=1e-9)
    assert 0.1 < outcomes[0].result.rmse_S / IN < 0.2


def test_example9_dwell_and_refined_d2() -> None:
    problem, _ = overlay_problem_from_spec(load_spec(EXAMPLES / "bagci_example9_overlay.toml"))
    assert problem.refine_d2 and problem.d2 == pytest.approx(1.96 * IN)
    out = synthesize_overlay(problem)[0]
    _check_reanalysis(out, problem)
    d2 = out.result.dimensions["d2"] / IN
    assert d2 != pytest.approx(1.96, abs=1e-3)  # refined
    assert out.dwell_curvature_radii[0] / IN == pytest.approx(1.73627, abs=1e-5)
    assert math.degrees(out.result.rmse_phi) < 2.5
    # the dwell: psi'(0) = 0 on the analysed mechanism
    d = out.result.dimensions
    dims = RSRCDimensions(*(d[k] for k in ("d1", "d2", "d3", "a", "b", "e", "delta0",
                                           "lambda0")))
    h = 1e-4
    phi = _phi_near(dims, d["theta01"] + np.array([-h, h]), out.result.rows[0]["phi_g"])
    slope = (phi[1] - phi[0]) / (2 * h)
    assert abs(slope) < 1e-6  # central difference, truncation ~h^2 |psi'''| ~ 1e-8


def test_cli_overlay_json_and_plot(tmp_path: Path) -> None:
    png = tmp_path / "ex9.png"
    r = runner.invoke(app, ["synthesize", str(EXAMPLES / "bagci_example9_overlay.toml"), "--json",
                            "--plot", str(png)])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)  # the document alone on stdout ("wrote …" goes to stderr)
    for key in ("dimensions", "mode", "E_phi", "E_S", "rmse", "rmse_phi", "rows", "status",
                "range_check", "alternatives"):
        assert key in doc
    assert doc["method"] == "overlay"
    ov = doc["overlay"]
    assert ov["d2_refined"] is True and ov["d2_chosen"] == pytest.approx(1.96 * IN)
    assert ov["output_direction"] == "ccw" and len(ov["circle_residual"]) == 9
    assert doc["rows"][0]["S_d"] is None
    assert png.stat().st_size > 1000
    r = runner.invoke(app, ["synthesize", str(EXAMPLES / "bagci_example8_overlay.toml")])
    assert r.exit_code == 0, r.output
    assert "overlay 4: " in r.output and "desired vs generated" in r.output


# --- bad input and limits --------------------------------------------------------------------
def _spec_with(tmp_path: Path, example: int, old: str, new: str) -> Path:
    text = (EXAMPLES / f"bagci_example{example}_overlay.toml").read_text()
    assert old in text
    path = tmp_path / "case.toml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize(("example", "old", "new", "message"), [
    (9, "delta0 = 0.0", "delta0 = 5.0", "needs delta0 = 0"),
    (9, 'unknowns = ["d2", "d3", "a", "b"]', 'unknowns = ["d1", "d3"]',
     "unknowns of the overlay"),
    (9, "dwells = [{ theta = 0, tangency = \"interior\" }]",
     "dwells = [{ theta = 0 }, { theta = 15 }, { theta = 30 }]", "at most two dwells"),
    (9, "dwells = [{ theta = 0, tangency = \"interior\" }]", "dwells = [{ theta = 7 }]",
     "not one of the rotation design points"),
    (9, "dwells = [{ theta = 0, tangency = \"interior\" }]",
     "dwells = [{ theta = 0, tangency = \"sideways\" }]", "interior"),
    (8, 'output_direction = "both"\n', 'output_direction = "both"\ninversion = 2\n',
     "not used by method"),
    (8, '[synthesis.rotation]\nfunction = "power"\nparameters = { amplitude = 45, span = 90, '
        'power = 1 }\ndesign_points = { start = 0, stop = 90, step = 15 }\n', "",
     "fits the output rotation"),
])
def test_overlay_spec_errors(tmp_path: Path, example: int, old: str, new: str,
                             message: str) -> None:
    path = _spec_with(tmp_path, example, old, new)
    with pytest.raises((SynthesisConfigError, SynthesisError)) as info:
        problem, _ = overlay_problem_from_spec(load_spec(path))
        synthesize_overlay(problem)
    assert message in str(info.value), str(info.value)
    r = runner.invoke(app, ["synthesize", str(path)])
    assert r.exit_code == 2
    assert message.split()[0] in r.output


def test_least_squares_route_rejects_overlay_only_keys(tmp_path: Path) -> None:
    text = (EXAMPLES / "bagci_example4_synthesis.toml").read_text()
    path = tmp_path / "both.toml"
    path.write_text(text.replace("[synthesis]\n", "[synthesis]\noutput_direction = \"both\"\n", 1))
    with pytest.raises(SynthesisConfigError, match="is for method = \"overlay\""):
        problem_from_spec(load_spec(path))


def test_contradictory_dwells() -> None:
    theta = np.radians(np.arange(0.0, 91.0, 15.0))
    flat = ScrewTarget(library_function("zero"), theta)  # same output angle at both dwells
    problem = OverlayProblem(flat, d1=1.0, d2=2.0, lambda0=D(60), theta01=D(30),
                             dwells=(OverlayDwell(0.0), OverlayDwell(D(90))), length_scale=1.0)
    with pytest.raises(SynthesisError, match="contradictory constraints"):
        synthesize_overlay(problem)


def test_target_no_mechanism_can_follow() -> None:
    # 300 deg of output over 30 deg of input with a coupler of 0.2 d1: every overlay circle
    # leaves design points out of the output crank's reach
    theta = np.radians(np.arange(0.0, 31.0, 5.0))
    target = ScrewTarget(library_function("power", amplitude=D(300), span=D(30), power=1), theta)
    problem = OverlayProblem(target, d1=1.0, d2=0.2, lambda0=D(60), theta01=D(20),
                             output_directions=(1, -1), length_scale=1.0)
    with pytest.raises(SynthesisError, match="no RSRC with these d1, d2, lambda0, theta01 "
                                             "follows the target"):
        synthesize_overlay(problem)


def test_poor_overlay_is_said_to_miss_the_target() -> None:
    # 720 deg of output over 30 deg of input: the overlay finds mechanisms that run, but the
    # message says the target is not followed
    theta = np.radians(np.arange(0.0, 31.0, 5.0))
    target = ScrewTarget(library_function("power", amplitude=D(720), span=D(30), power=1), theta)
    problem = OverlayProblem(target, d1=1.0, d2=0.5, lambda0=D(60), theta01=D(20),
                             length_scale=1.0)
    result = synthesize_overlay(problem)[0].result
    assert "the target rotation is not followed" in result.message


def test_time_and_iteration_limits_are_reported(tmp_path: Path) -> None:
    problem, _ = overlay_problem_from_spec(load_spec(EXAMPLES / "bagci_example8_overlay.toml"))
    out = synthesize_overlay(dataclasses.replace(problem, time_limit=1e-9))
    assert out[0].result.status == "time limit"
    assert "time limit" in out[0].result.message
    out = synthesize_overlay(dataclasses.replace(problem, max_iterations=1))
    assert out[0].result.status == "iteration limit"
    path = _spec_with(tmp_path, 8, "[synthesis]\n", "[synthesis]\ntime_limit = 1e-9\n")
    r = runner.invoke(app, ["synthesize", str(path), "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["status"] == "time limit"
