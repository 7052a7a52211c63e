"""Messages name lists and numbers as prose, never as Python or numpy reprs (issue 30): a
sample of the less common messages of the model, balancing and kinematics layers, and the
helpers they use (messages.listing, messages.shown_values, messages.given)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from screwkit.errors import ScrewkitError, expect_number
from screwkit.messages import given, message_units, shown_values
from screwkit.model.families import cssp
from screwkit.model.mass import PointMassModel, point_mass_distances

INCH = 0.0254
#: what a repr leaves behind
REPRS = ("np.float64", "np.int64", "array(", "['", "[np.", "(np.")


def _message(fn) -> str:  # type: ignore[no-untyped-def]
    with pytest.raises(ScrewkitError) as info:
        fn()
    text = str(info.value)
    assert not [r for r in REPRS if r in text], text
    return text


@pytest.fixture(scope="module")
def loop():  # type: ignore[no-untyped-def]
    return cssp(2 * INCH, 8 * INCH, 1 * INCH, np.radians(250.0), 0.4 * INCH)


def test_helpers_write_numbers_and_sequences_plainly() -> None:
    assert given(np.float64(-1.5)) == "-1.5"
    assert given(np.int64(3)) == "3"
    assert given(np.array([1.0, np.nan])) == "(1, nan)"
    assert given([np.float64(0.25), "x"]) == "(0.25, 'x')"
    assert given(np.zeros((5, 5))) == "an array of shape 5 × 5"
    assert given(float("inf")) == "inf"
    assert shown_values((2, 3)) == "(2, 3)"
    assert shown_values(np.array([0.0254, -0.0508]), "length") == "(0.0254, -0.0508) m"
    with message_units(_Inches()):
        assert shown_values(np.array([0.0254, -0.0508]), "length") == "(1, -2) in"


class _Inches:
    def unit_of(self, kind: str) -> tuple[str, float]:
        return ("in", INCH) if kind == "length" else ("", 1.0)


def test_linkage_messages_list_the_freedoms(loop) -> None:  # type: ignore[no-untyped-def]
    text = _message(lambda: dataclasses.replace(loop, inputs=("nope.theta",)))
    names = loop.freedom_names
    assert f"freedoms are {', '.join(names[:-1])} and {names[-1]}" in text, text
    twice = loop.inputs[0]
    text = _message(lambda: dataclasses.replace(loop, inputs=(twice, twice)))
    assert f"an input is named twice: {twice} and {twice}" in text, text


def test_mass_messages_write_numbers_in_units() -> None:
    text = _message(lambda: point_mass_distances([1.0, 1.0, 1.0], [1.0, -2.0, np.float64(3)]))
    assert "pair masses must be >= 0, got (1, -2, 3) kg" in text, text
    text = _message(lambda: point_mass_distances([1.0, 1.0, 5.0], [1.0, 1.0, 1.0]))
    assert "principal moments (1, 1, 5) kg*m^2 violate a triangle inequality" in text, text
    text = _message(lambda: PointMassModel(np.zeros((3, 3)), [1.0, -1.0, -2.0]))
    assert "masses (1, 2) (counted from 0) are (-1, -2) kg" in text, text


def test_a_non_finite_number_is_named_without_numpy() -> None:
    text = _message(lambda: expect_number(np.float64(np.inf), "omega"))
    assert text == "omega must be finite; got inf", text


def test_kinematics_messages_list_the_variables(loop) -> None:  # type: ignore[no-untyped-def]
    from screwkit.kinematics.solve_motion import solve_motion

    motion = solve_motion(loop, np.radians([0.0, 10.0]), rates=1.0)
    text = _message(lambda: motion.variable("nope"))
    assert "the variables are " in text and " and " in text, text
    text = _message(lambda: solve_motion(loop, np.zeros((2, 3))))
    assert "got shape (2, 3)" in text, text
    from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion

    text = _message(lambda: cssp_mode_motion(loop, [0.0, np.nan, 1.0, np.inf]))
    assert "NaN/inf at samples 1 and 3, counted from 0" in text, text


def test_balancing_messages_list_the_variables(loop) -> None:  # type: ignore[no-untyped-def]
    from screwkit.balancing.variables import point_mass_variables
    from screwkit.model.linkage import Link
    from screwkit.model.mass import MassProperties

    massed = loop.with_links([Link(link.name, MassProperties(1.0, [0.01, 0.0, 0.0],
                                                             np.diag([1e-4, 1e-3, 1e-3])))
                              for link in loop.links])
    crank = massed.links[0].name
    text = _message(lambda: point_mass_variables(massed, crank, variables=("m1", "q")))
    assert "non-empty subset of m1, m2, m3 and m4; got m1 and q" in text, text
    text = _message(lambda: point_mass_variables(massed, crank,
                                                 split=np.array([0.5, 0.5, 0.5, 0.5])))
    assert "got (0.5, 0.5, 0.5, 0.5)" in text, text
