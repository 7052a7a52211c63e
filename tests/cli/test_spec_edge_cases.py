"""Spec-file and CLI edge cases found in review: units, strict types, gravity, output paths."""

import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from screwkit.cli.main import app
from screwkit.io.spec import load_spec
from screwkit.io.units import UnitError, to_si

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FOURBAR = '[mechanism]\nfamily = "4R"\n[dimensions]\na = 3\nd1 = 1\nd2 = 3\nd3 = 2.5\n'


@pytest.mark.parametrize("text, kind, default, expected", [
    ("1.2 rad", "angle", "deg", 1.2),           # a written unit beats the [units] default
    ("18 deg", "angle", "rad", np.radians(18)),
    ("0.5 turn", "angle", "deg", np.pi),
    ("2", "length", "in", 0.0508),              # a bare number takes the default
    (2, "length", "in", 0.0508),
    ("3000 rpm", "angular_velocity", None, 100 * np.pi),
])
def test_units_written_in_a_value_are_kept(text, kind, default, expected):
    assert to_si(text, kind, default) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("args, fragment", [
    (("50 Hz", "angular_velocity", None), "ambiguous"),
    (("1 deg", "length", "in"), "not a length"),
    (("2", "length", "inch_typo"), "unknown unit"),
])
def test_unit_mistakes_are_named(args, fragment):
    with pytest.raises(UnitError, match=fragment):
        to_si(*args)


def _spec(tmp_path, text):
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("text, fragment", [
    (FOURBAR.replace("[dimensions]", "[units]\nlenght = \"in\"\n[dimensions]"), "unknown kind 'lenght'"),
    (FOURBAR.replace("[dimensions]", "[units]\nlength = \"inch_typo\"\n[dimensions]"), "unknown unit"),
    (FOURBAR.replace("d1 = 1", "d1 = true"), "d1"),
    ("gravity = \"0 m/s^2\"\n" + FOURBAR, "gravity must be a positive"),
    ("gravity = \"-9.8 m/s^2\"\n" + FOURBAR, "gravity must be a positive"),
    ('[mechanism]\nfamily = "LOOP"\n[[joints]]\nname = "a"\nkind = "P"\ninput = true\nlength = 1\n'
     '[[joints]]\nname = "b"\nkind = "R"\nlength = 1\n[[joints]]\nname = "c"\nkind = "R"\nlength = 1\n', "translation"),
    ('[mechanism]\nfamily = "LOOP"\n[[joints]]\nname = "a"\nkind = "R"\ninput = true\n'
     '[[joints]]\nname = "b"\nkind = "C"\noffset = 1\n', "no constant offset"),
])
def test_spec_mistakes_give_exit_2_and_name_the_key(tmp_path, text, fragment):
    r = runner.invoke(app, ["validate", str(_spec(tmp_path, text))])
    assert r.exit_code == 2, r.output
    assert fragment in r.output.replace("\n", " ")
    assert "Traceback" not in r.output


def test_principal_axes_typed_to_six_decimals_are_accepted(tmp_path):
    text = (EXAMPLES / "rahman_cssp.toml").read_text().replace(
        "inertia = [8.195304e-4, 0.105310, 0.105310]",
        "inertia = [8.195304e-4, 0.105310, 0.105310]\n"
        "principal_axes = [[0.707107, -0.707107, 0], [0.707107, 0.707107, 0], [0, 0, 1]]")
    spec = load_spec(_spec(tmp_path, text))
    axes = np.linalg.eigh(spec.linkage.links[1].mass.inertia)[1]
    assert abs(abs(axes[0, 0]) - np.sqrt(0.5)) < 1e-6 or abs(abs(axes[0, 2]) - np.sqrt(0.5)) < 1e-6


def test_output_to_a_folder_or_a_missing_folder_is_a_clear_error(tmp_path):
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(tmp_path)])
    assert r.exit_code == 2 and "it is a folder" in r.output.replace("\n", " ")
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(tmp_path / "no" / "x.json")])
    assert r.exit_code == 2 and "does not exist" in r.output


def test_result_files_are_ordinary_readable_files(tmp_path):
    out = tmp_path / "r.json"
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-o", str(out)])
    assert r.exit_code == 0
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask


def test_limits_of_the_cssp_slider_are_the_stroke_ends():
    r = runner.invoke(app, ["limits", str(EXAMPLES / "rahman_cssp.toml"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["method"] == "generic" and {lim["kind"] for lim in doc["limits"]} == {"translation"}
    import screwkit as sk
    from screwkit.io.spec import load_spec

    s = load_spec(EXAMPLES / "rahman_cssp.toml")
    for lim in doc["limits"]:  # the closed form just around each limit: s4 is extreme there
        x = lim["input"] + np.radians(np.linspace(-0.5, 0.5, 1001))
        md = sk.solve_motion(s.linkage, x, method="closed").modes[lim["mode"]]
        s4 = md.variables["s4"]
        k = int(np.argmax(s4) if lim["second_derivative"] < 0 else np.argmin(s4))
        assert abs(x[k] - lim["input"]) < np.radians(1e-3)
        assert abs(s4[k] - lim["value"]) < 1e-12


def test_generic_modes_do_not_depend_on_the_step_and_match_analyze():
    from analysis_helpers import analyze, mode_motion
    from screwkit.kinematics.registry import seed_variables

    spec = load_spec(EXAMPLES / "rsrc_fig7_dynamics.toml")
    first = []
    for step in (5.0, 20.0, 45.0):
        x = np.radians(np.arange(0.0, 360.0, step))
        v, _, _ = seed_variables(spec.linkage, mode_motion(spec.linkage, x, 1.0, 0.0, 0))
        _, doc = analyze(spec.linkage, x, method="closed")
        assert v["S"][0] == pytest.approx(doc["modes"][0]["variables"]["S"][0], abs=1e-12)
        first.append(v["S"][0])
    assert np.ptp(first) < 1e-12


def test_generic_input_values_are_reported_exactly_even_for_big_steps():
    r = runner.invoke(app, ["analyze", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "--method", "generic", "--json"])
    doc = json.loads(r.stdout)
    for m in doc["modes"]:
        np.testing.assert_allclose(m["variables"]["input.theta"], doc["input"], atol=0)
        first_phi = m["variables"]["phi0"][0]
        assert -np.pi < first_phi <= np.pi  # starts where the closed form starts
