"""Spec-file values and units: a unit written in a value beats the [units] default, unit and
spec mistakes are named (exit 2, no traceback), strict types, gravity > 0, principal axes typed
to six decimals are accepted."""

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
