"""Misusing the Python API raises a screwkit exception that names the argument — never a
generic error from deep inside (issue: 10 of 17 misuse calls raised KeyError or reshape errors)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import screwkit as sk
from screwkit.dual import Dual
from screwkit.errors import InputError, InputTypeError, UnknownNameError

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
]


@pytest.mark.parametrize(("name", "call", "kind", "fragment"), CASES, ids=[c[0] for c in CASES])
def test_misuse_raises_a_screwkit_error_naming_the_problem(fig7, name, call, kind, fragment):
    with pytest.raises(kind) as info:
        call(fig7)
    assert isinstance(info.value, sk.ScrewkitError), type(info.value).__mro__
    assert fragment in str(info.value)
