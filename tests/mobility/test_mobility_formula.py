"""Formula mobility: identities between Bagci's forms, input checks, result objects."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.mobility import (
    MobilityInputError,
    formula_mobility,
    kutzbach_mobility,
    loop_count,
    malytcheff_mobility,
    planar_mobility,
)

PROFILE = settings(derandomize=True, max_examples=60, deadline=None)


@st.composite
def mechanisms(draw: st.DrawFn) -> tuple[int, tuple[int, ...], int]:
    """(n, N_1..N_5, k) with (n − 1) + k = Σ N_i."""
    n = draw(st.integers(2, 12))
    k = draw(st.integers(1, 4))
    total = n - 1 + k
    cuts = sorted(draw(st.lists(st.integers(0, total), min_size=4, max_size=4)))
    bounds = [0, *cuts, total]
    by_class = tuple(bounds[i + 1] - bounds[i] for i in range(5))
    return n, by_class, k


@PROFILE
@given(mechanisms(), st.integers(0, 5))
def test_b4_and_b2_from_b1(mech: tuple[int, tuple[int, ...], int], m: int) -> None:
    n, by_class, k = mech
    r = formula_mobility(n, pairs_by_class=by_class, general_constraints=m)
    assert r.loops == k
    # (B.4b) F_m = F0 + m k
    assert r.mobility == malytcheff_mobility(n, by_class) + m * k
    # (B.2) as printed drops pairs of class ≥ 6 − m; with none of them it equals (B.4).
    if not any(by_class[i - 1] for i in range(6 - m, 6)):
        assert r.kutzbach == r.mobility


@PROFILE
@given(mechanisms(), st.integers(0, 3), st.data())
def test_b7_equals_b6(mech: tuple[int, tuple[int, ...], int], m: int, data: st.DataObject) -> None:
    # (B.7b) with per-pair active freedoms h_i = i − f_i equals (B.6) with F_p = Σ f_i.
    n, by_class, k = mech
    b = 6 - m
    classes = [i for i, c in enumerate(by_class, 1) for _ in range(c)]
    passive = [data.draw(st.integers(max(0, i - b), i)) for i in classes]
    active = [i - f for i, f in zip(classes, passive, strict=True)]
    r = formula_mobility(
        n, pairs_by_class=by_class, general_constraints=m, passive_freedoms=sum(passive)
    )
    assert kutzbach_mobility(n, active, motion_components=b) == r.mobility


def test_plane_cam_mechanism_matches_grubler() -> None:
    # Ground, cam and follower: two R pairs and a cam contact (cylinder on plane, class 4, two
    # passive out-of-plane freedoms). Grübler: 3·2 − 2·2 − 1 = 1.
    r = planar_mobility(3, "R R C_e", passive_freedoms=2)
    assert r.mobility == 1
    assert kutzbach_mobility(3, [1, 1, 2], motion_components=3) == 1


def test_describe_and_as_dict() -> None:
    r = formula_mobility(
        6,
        pairs_by_class={1: 4, 2: 2, 3: 1},
        general_constraints=[2, 1],
        passive_freedoms=1,
        name="Fig. 30",
    )
    text = r.describe()
    assert text.splitlines()[0] == "Fig. 30: F = 1"
    assert "F0 = 6(6−1) − 5·4 − 4·2 − 3·1 = -1" in text
    assert "M = 3 [per loop: 2, 1]" in text
    d = json.loads(json.dumps(r.as_dict()))
    assert d["mobility"] == 1 and d["malytcheff"] == -1 and d["kolchin_parameter"] == 2
    assert d["kutzbach"] is None and d["mechanism_class"] is None
    assert d["classification"] == "with passive freedoms"
    r2 = formula_mobility(4, "RS_sRC", general_constraints="m(100,000)")
    assert r2.general_constraint_notation == ("m(100,000)",)
    assert "m(100,000)" in r2.describe() and "class 1" in r2.describe()


def test_open_chain() -> None:
    r = formula_mobility(3, "RR")
    assert (r.loops, r.mobility) == (0, 2)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"n_links": 4}, "either by kind"),
        ({"n_links": 4, "pairs": "RSRC", "pairs_by_class": {1: 2}}, "not both"),
        ({"n_links": 1, "pairs": "R"}, "number of links n must be ≥ 2"),
        ({"n_links": -3, "pairs": "R"}, "≥ 2"),
        ({"n_links": 6, "pairs": "RRR"}, "cannot connect 6 links"),
        ({"n_links": 4, "pairs": "RSRC", "loops": 2}, r"contradicts Bagci eq\. \(B\.3\)"),
        ({"n_links": 4, "pairs": "RSRC", "general_constraints": 6}, "0…5"),
        ({"n_links": 4, "pairs": "RSRC", "general_constraints": -1}, "≥ 0"),
        ({"n_links": 4, "pairs": "RSRC", "general_constraints": "m(111,111)"}, "0…5"),
        ({"n_links": 4, "pairs": "RSRC", "general_constraints": [1, 1]}, "per-loop general"),
        ({"n_links": 3, "pairs": "RR", "general_constraints": 2}, "no loop"),
        ({"n_links": 4, "pairs": "RSRC", "passive_freedoms": -1}, "F_p must be ≥ 0"),
        ({"n_links": 4, "pairs": "RSRC", "passive_freedoms": 8}, "exceed the 7 freedoms"),
        ({"n_links": 4, "pairs": "RSRC", "overclosing_constraints": 1}, "multi-loop"),
        ({"n_links": 6, "pairs": "8R", "overclosing_constraints": [1, 1]}, "per-loop overclosing"),
        ({"n_links": 6, "pairs": "8R", "overclosing_constraints": [1, -1, 0]}, "q_2"),
        ({"n_links": 4, "pairs_by_class": {6: 1}}, "class i must be 1…5"),
        ({"n_links": 4, "pairs_by_class": [1, 1, 1, 1, 1, 1]}, "at most 5"),
        ({"n_links": 4, "pairs_by_class": {1: -2}}, "N1 must be ≥ 0"),
        ({"n_links": 4, "pairs": {"R": True}}, "whole number"),
        ({"n_links": 2.5, "pairs": "R"}, "whole number"),
        ({"n_links": 4, "pairs": "RQRC"}, "cannot read the pair list"),
    ],
)
def test_bad_input(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message) as info:
        formula_mobility(**kwargs)  # type: ignore[arg-type]
    assert isinstance(info.value, MobilityInputError)


def test_kutzbach_mobility_checks() -> None:
    with pytest.raises(MobilityInputError, match="only b = 3"):
        kutzbach_mobility(4, [1, 1, 1, 4], motion_components=3)
    with pytest.raises(MobilityInputError, match="≤ 6"):
        kutzbach_mobility(4, [1, 1, 1, 1], motion_components=7)
    with pytest.raises(MobilityInputError, match="cannot connect"):
        kutzbach_mobility(5, [1, 1], motion_components=3)


def test_loop_count() -> None:
    assert loop_count(6, 7) == 2
    with pytest.raises(MobilityInputError):
        loop_count(6, 4)
