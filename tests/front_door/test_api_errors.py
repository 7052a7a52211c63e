"""Misusing the Python API raises a screwkit exception that names the argument — never a
generic error from deep inside (issue: 10 of 17 misuse calls raised KeyError or reshape errors)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.dual import Dual
from screwkit.errors import InputError, InputTypeError, UnknownNameError
from screwkit.io.units import to_si

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def fig7():
    spec = sk.load_spec(EXAMPLES / "rsrc_fig7_dynamics.toml")
    return spec, sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)


def _lk():
    return sk.rsrc(d1=0.05, d2=0.11, d3=0.08, a=0.08, b=0.03, e=0.02, delta0=0.3, lambda0=1.0)


CASES = [
    ("string as a dual number", lambda f: Dual("a", "b"), InputTypeError, "real part"),
    ("not a linkage", lambda f: sk.solve_motion("RSRC", [0.0, 0.1]), InputTypeError, "Linkage"),
    ("no samples", lambda f: sk.solve_motion(_lk(), []), InputError, "at least one sample"),
    ("text inputs", lambda f: sk.solve_motion(_lk(), "abc"), InputTypeError, "inputs"),
    ("NaN input", lambda f: sk.solve_motion(_lk(), [0.0, np.nan]), InputError, "finite"),
    ("two columns for one input", lambda f: sk.solve_motion(_lk(), np.zeros((3, 2))),
     InputError, "1 value(s) per sample"),
    ("rates of the wrong length", lambda f: sk.solve_motion(_lk(), [0.0, 0.1, 0.2],
                                                           rates=[1.0, 2.0]),
     InputError, "one value for every sample or one per sample (3 samples); got 2"),
    ("joints: accelerations of the wrong length", lambda f: sk.solve_joints(
        _lk(), [0.0, 0.1, 0.2], accelerations=[1.0, 2.0]), InputError,
     "accelerations: give one value for every sample"),
    ("joints: text inputs", lambda f: sk.solve_joints(_lk(), "abc"), InputTypeError, "inputs"),
    ("unknown method", lambda f: sk.solve_motion(_lk(), [0.0, 0.1], method="fast"),
     InputError, "method must be"),
    ("closed form of a LOOP", lambda f: sk.solve_motion(
        sk.Linkage.from_hartenberg_denavit("L", [sk.Joint("a", "R"), sk.Joint("b", "R"),
                                                  sk.Joint("c", "R"), sk.Joint("d", "R")],
                                           [1, 3, 2.5, 3], [0, 0, 0, 0], ["a.theta"]),
        [0.0, 0.1], method="closed"), InputError, "no closed form"),
    ("mode out of range", lambda f: f[1].mode(7), sk.AssemblyError, "assembly mode 7"),
    ("mode not an integer", lambda f: f[1].mode("0"), InputTypeError, "integer index"),
    ("unknown variable", lambda f: f[1].variable("lenght"), UnknownNameError, "no variable"),
    ("bad derivative order", lambda f: f[1].variable("phi0", derivative=3), InputError,
     "derivative must be"),
    ("negative length", lambda f: sk.rsrc(d1=-1, d2=1, d3=1, a=1, b=0, e=0, delta0=0,
                                           lambda0=0), InputError, "d1 must be a positive"),
    ("unknown family", lambda f: sk.family("fivebar"), InputError, "unknown family"),
    ("closed-form limits of a CSSP", lambda f: sk.limit_positions(
        sk.load_spec(EXAMPLES / "rahman_cssp.toml").linkage, method="closed"), InputError,
     "no closed-form limits of s4 for a CSSP"),
    ("dynamics with a mode object for a Motion", lambda f: sk.inverse_dynamics(f[1], "x"),
     InputError, "assembly mode as an index"),
    ("dynamics without masses", lambda f: sk.inverse_dynamics(
        sk.solve_motion(_lk(), np.radians(np.arange(0, 360, 30.0))), 0), InputError, "mass"),
    ("balancing without weights", lambda f: sk.balance(
        f[1], 0, [sk.point_mass_variables(f[0].linkage, "coupler")]), InputError,
     "give the weights"),
    ("unknown joint kind", lambda f: sk.Joint("j", "Q"), InputError, "unknown kind"),
    ("coupler point of 2 coordinates", lambda f: sk.coupler_point_path(f[1].mode(0), [1, 2]),
     InputError, "3 finite coordinates"),
    ("missing spec file", lambda f: sk.load_spec(EXAMPLES / "no_such.toml"), InputError,
     "no_such.toml"),
    # issue 30: the calls that raised TypeError, KeyError or AttributeError from inside
    ("spec path None", lambda f: sk.load_spec(None), InputTypeError, "path must be a file name"),
    ("spec path an int", lambda f: sk.load_spec(123), InputTypeError, "got int"),
    ("spec path bytes", lambda f: sk.load_spec(b"examples/x.toml"), InputTypeError, "got bytes"),
    ("misspelt quantity kind", lambda f: to_si("2 in", "lenght"), UnknownNameError,
     "unknown quantity kind 'lenght'; did you mean 'length'?"),
    ("None as a length", lambda f: to_si(None, "length"), InputError, "got None (NoneType)"),
    ("text dwell tolerance", lambda f: sk.limit_positions(f[1], dwell_tolerance="x"),
     InputTypeError, "dwell_tolerance must be a number"),
    ("negative dwell tolerance", lambda f: sk.limit_positions(f[1], dwell_tolerance=-1.0),
     InputError, "dwell_tolerance must be positive"),
    ("text max order", lambda f: sk.limit_positions(f[1], max_order="3"), InputTypeError,
     "max_order must be an integer"),
    ("limits of a string", lambda f: sk.limit_positions("m"), InputTypeError,
     "limit_positions: source"),
    ("text starts", lambda f: sk.solve_motion(_lk(), [0.0, 0.1], starts="x"), InputTypeError,
     "starts must be an integer"),
    ("None inputs", lambda f: sk.solve_motion(_lk(), None), InputTypeError, "got NoneType"),
    ("dynamics of a string", lambda f: sk.inverse_dynamics("m", 0), InputTypeError,
     "linkage must be a solved Motion"),
    ("regressor of a string", lambda f: sk.regressor("m", 0), InputTypeError,
     "linkage must be a solved Motion"),
    ("text gravity", lambda f: sk.inverse_dynamics(f[1], 0, gravity="down"), InputError,
     "gravity must be a finite 3-vector"),
    ("external loads not a mapping", lambda f: sk.inverse_dynamics(f[1], 0, external_loads="a"),
     InputError, "external_loads must be a mapping"),
    ("mobility of a string", lambda f: sk.mobility("x"), InputTypeError, "mobility: linkage"),
    ("mobility at text inputs", lambda f: sk.mobility(f[0].linkage, "x"), InputTypeError,
     "mobility: inputs"),
    ("transmission of a string", lambda f: sk.transmission("x"), InputTypeError,
     "transmission: motion"),
    ("joints of a string", lambda f: sk.solve_joints("x", [0.0]), InputTypeError, "Linkage"),
    ("synthesis of a string", lambda f: sk.synthesize("x"), InputTypeError,
     "synthesize: config"),
    ("pipeline of a string", lambda f: sk.Pipeline("x"), InputTypeError, "Pipeline: spec"),
    ("coupler path of a string", lambda f: sk.coupler_point_path("m", [0, 0, 0]),
     InputTypeError, "coupler_point_path: mode"),
    ("coupler path, text link", lambda f: sk.coupler_point_path(f[1].mode(0), [0, 0, 0], "a"),
     InputError, "link must be a moving link's index"),
    ("balance, text mode", lambda f: sk.balance(
        f[1], "a", [sk.point_mass_variables(f[0].linkage, "coupler")], {"F": 1}), InputError,
     "assembly mode as an index"),
    ("balance, text blocks", lambda f: sk.balance(f[1], 0, "coupler", {"F": 1}), InputError,
     "blocks must be a list of design variables"),
    ("balance, text weights", lambda f: sk.balance(
        f[1], 0, [sk.point_mass_variables(f[0].linkage, "coupler")], "F"), InputError,
     "weights must be a mapping"),
    ("balance, a text weight", lambda f: sk.balance(
        f[1], 0, [sk.point_mass_variables(f[0].linkage, "coupler")], {"F": "a"}), InputError,
     "weights must be numbers"),
    ("balance, text speed", lambda f: sk.balance(
        f[0].linkage, f[1].mode(0), [sk.point_mass_variables(f[0].linkage, "coupler")],
        {"F": 1}, speed="x"), InputTypeError, "balance: speed must be a number"),
    ("point masses of a string", lambda f: sk.point_mass_variables("x", "coupler"),
     InputTypeError, "linkage must be a screwkit Linkage"),
    ("table in unknown units", lambda f: f[1].table().headers("mm"), InputTypeError,
     "units must be display units"),
    ("joint name not a string", lambda f: sk.Joint(3, "R"), InputTypeError, "both are strings"),
    ("text mass", lambda f: sk.MassProperties("a", [0, 0, 0], np.eye(3)), InputTypeError,
     "mass must be numbers"),
    ("text dimension", lambda f: sk.rsrc(d1="a", d2=1, d3=1, a=1, b=0, e=0, delta0=0,
                                         lambda0=0), InputError, "d1 must be a number"),
    ("joints as a string", lambda f: sk.Linkage.from_hartenberg_denavit(
        "L", "abcd", [1, 3, 2.5, 3], [0, 0, 0, 0], ["a.theta"]), InputError,
     "joints must be Joint objects"),
    ("links of numbers", lambda f: f[0].linkage.with_links([1, 2, 3]), InputError,
     "links must be Link objects"),
    ("text synthesis starts", lambda f: sk.synthesize(
        sk.load_spec(EXAMPLES / "bagci_example1_synthesis.toml").synthesis, starts="x"),
     InputTypeError, "synthesize: starts must be an integer"),
    ("text coupler points", lambda f: f[1].table(coupler_points="x"), InputTypeError,
     "coupler_points must be CouplerPoint objects"),
    ("dynamics inputs of text", lambda f: sk.inverse_dynamics(f[1], 0, inputs="x"), InputError,
     "inputs must have one column per input"),
    ("text counterweight bound", lambda f: sk.counterweight_variables(
        f[0].linkage, "coupler", "cw", mass_max="x"), InputTypeError,
     "mass_max must be a number"),
    ("misspelt unit override", lambda f: f[0].display_units(overrides={"lenght": "mm"}),
     InputError, "did you mean 'length'?"),
]


@pytest.mark.parametrize(("name", "call", "kind", "fragment"), CASES, ids=[c[0] for c in CASES])
def test_misuse_raises_a_screwkit_error_naming_the_problem(fig7, name, call, kind, fragment):
    with pytest.raises(kind) as info:
        call(fig7)
    assert isinstance(info.value, sk.ScrewkitError), type(info.value).__mro__
    assert fragment in str(info.value)
