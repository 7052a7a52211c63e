"""Bagci's general-constraint notation m(M_R1 M_R2 M_R3, M_T1 M_T2 M_T3), Appendix B."""

from __future__ import annotations

import itertools

import pytest

from screwkit.mobility import GeneralConstraints, general_constraint_types, general_constraints
from screwkit.mobility.errors import MobilityInputError
from screwkit.mobility.general_constraints import general_constraints_from_counts


@pytest.mark.parametrize(
    ("text", "count", "rot", "tra"),
    [
        ("m(110,001)", 3, (1, 1, 0), (0, 0, 1)),  # plane (L2740)
        ("m(000,111)", 3, (0, 0, 0), (1, 1, 1)),  # spherical
        ("m(111,000)", 3, (1, 1, 1), (0, 0, 0)),  # all prisms
        ("(011,011)", 4, (0, 1, 1), (0, 1, 1)),  # RHP, Fig. 29f
        ("101,110", 4, (1, 0, 1), (1, 1, 0)),  # RH_sP, Fig. 29g
        ("M(100, 000) = 1", 1, (1, 0, 0), (0, 0, 0)),
        ("m(000 000)", 0, (0, 0, 0), (0, 0, 0)),
    ],
)
def test_parse(text: str, count: int, rot: tuple[int, ...], tra: tuple[int, ...]) -> None:
    gc = general_constraints(text)
    assert (gc.count, gc.rotation, gc.translation) == (count, rot, tra)
    assert general_constraints(gc.notation) == gc
    assert gc.on_rotation + gc.on_translation == count


@pytest.mark.parametrize("bad", ["m(112,000)", "m(11,000)", "plane", "m(110,001) = 2", ""])
def test_parse_errors(bad: str) -> None:
    with pytest.raises(MobilityInputError):
        general_constraints(bad)


def test_flags_must_be_bits() -> None:
    with pytest.raises(MobilityInputError, match="0/1 flags"):
        GeneralConstraints((2, 0, 0), (0, 0, 0))  # type: ignore[arg-type]
    with pytest.raises(MobilityInputError):
        general_constraints(3)  # type: ignore[arg-type]


def test_nineteen_types() -> None:
    # L2738: "There are 19 possible types of general constraint combinations" (m ≤ 5).
    types = general_constraint_types()
    assert len(types) == 19
    assert all(t.count <= 5 and t.canonical() == t for t in types)
    # Brute force over all 2^6 flag sets up to relabelling of the axes gives the same set.
    brute = {
        GeneralConstraints(r, t).canonical()  # type: ignore[arg-type]
        for r in itertools.product((0, 1), repeat=3)
        for t in itertools.product((0, 1), repeat=3)
        if sum(r) + sum(t) <= 5
    }
    assert brute == set(types)


def test_same_type_is_axis_relabelling() -> None:
    assert general_constraints("m(011,011)").same_type("m(110,110)")
    assert general_constraints("m(101,110)").same_type("m(110,101)")
    assert general_constraints("m(011,000)").same_type("m(100,100)") is False
    # canonical order: axes constrained in both, rotation only, translation only, free
    assert general_constraints("m(001,110)").canonical().notation == "m(100,011)"
    assert general_constraints("m(011,010)").canonical().notation == "m(110,100)"


def test_from_counts() -> None:
    assert general_constraints_from_counts(2, 1, 0).notation == "m(110,001)"
    assert general_constraints_from_counts(2, 2, 2).notation == "m(110,110)"
    with pytest.raises(MobilityInputError):
        general_constraints_from_counts(3, 2, 1)  # needs 4 axes
    with pytest.raises(MobilityInputError):
        general_constraints_from_counts(1, 1, 2)
