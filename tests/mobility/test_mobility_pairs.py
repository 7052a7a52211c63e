"""Pair catalogue: classes, freedoms, lookup and compact pair lists."""

from __future__ import annotations

import pytest

from screwkit.mobility import (
    PAIR_KINDS,
    MobilityInputError,
    freedom_names,
    pair_kind,
    pair_kind_names,
    parse_pairs,
)
from screwkit.mobility.pairs import FREEDOM_MEANINGS, count_pairs_by_class

EXPECTED_CLASS = {
    "R": 1,
    "P": 1,
    "H": 1,
    "H_s": 1,
    "C": 2,
    "U": 2,
    "S_s": 2,
    "S": 3,
    "E": 3,
    "S_c": 4,
    "C_e": 4,
    "S_e": 5,
}


def test_catalogue_classes() -> None:
    assert {k.symbol: k.pair_class for k in PAIR_KINDS} == EXPECTED_CLASS


def test_freedoms_are_known_and_distinct() -> None:
    for kind in PAIR_KINDS:
        assert set(kind.freedoms) <= set(FREEDOM_MEANINGS)
        assert len(set(kind.freedoms)) == len(kind.freedoms)
        assert (
            kind.rotary_freedoms + kind.translatory_freedoms + kind.screw_freedoms
            == kind.pair_class
        )


def test_freedom_types() -> None:
    assert (pair_kind("C").rotary_freedoms, pair_kind("C").translatory_freedoms) == (1, 1)
    assert pair_kind("H").screw_freedoms == 1
    assert pair_kind("E").translatory_freedoms == 2
    assert pair_kind("sphere on plane").rotary_freedoms == 3


@pytest.mark.parametrize(
    ("name", "symbol"),
    [
        ("R", "R"),
        ("r", "R"),
        ("Revolute", "R"),
        ("revolute pair", "R"),
        ("hinge", "R"),
        ("prismatic", "P"),
        ("Prism pair", "P"),
        ("slider", "P"),
        ("screw", "H"),
        ("axial screw pair", "H"),
        ("S_a", "H"),
        ("axial-screw-pair", "H"),
        ("spiral", "H_s"),
        ("planar-screw-pair", "H_s"),
        ("S_p", "H_s"),
        ("h_s", "H_s"),
        ("cylindrical", "C"),
        ("Hooke's joint", "U"),
        ("universal joint", "U"),
        ("slotted-sphere pair", "S_s"),
        ("S_S", "S_s"),
        ("ball joint", "S"),
        ("spherical", "S"),
        ("planar", "E"),
        ("sphere-in-cylinder", "S_c"),
        ("cylinder on plane", "C_e"),
        ("point contact", "S_e"),
        ("Sphere-on-plane", "S_e"),
    ],
)
def test_lookup_by_alias(name: str, symbol: str) -> None:
    assert pair_kind(name).symbol == symbol


def test_unknown_pair_lists_valid_names() -> None:
    with pytest.raises(ValueError, match="unknown pair kind 'gear'") as info:
        pair_kind("gear")
    for listed in pair_kind_names():
        assert listed in str(info.value)
    with pytest.raises(MobilityInputError):
        pair_kind("ss")  # neither the symbol S_s nor a name: no silent guess
    with pytest.raises(MobilityInputError, match="string"):
        pair_kind(3)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "symbols"),
    [
        ("RSRC", ["R", "S", "R", "C"]),
        ("rsrc", ["R", "S", "R", "C"]),
        ("RS_sRC", ["R", "S_s", "R", "C"]),
        ("RH_sP", ["R", "H_s", "P"]),
        ("R-S-S-R", ["R", "S", "S", "R"]),
        ("4P", ["P"] * 4),
        ("2RS_s", ["R", "R", "S_s"]),
        ("SC", ["S", "C"]),  # not the sphere-in-cylinder S_c
        ("S_c", ["S_c"]),
        ("R S_s R C", ["R", "S_s", "R", "C"]),
        ("revolute, spherical, revolute, cylinder", ["R", "S", "R", "C"]),
        ("sphere in cylinder, R", ["S_c", "R"]),
    ],
)
def test_parse_pairs(text: str, symbols: list[str]) -> None:
    assert [k.symbol for k in parse_pairs(text)] == symbols


def test_parse_pairs_errors() -> None:
    with pytest.raises(MobilityInputError, match="cannot read the pair list 'RXR'"):
        parse_pairs("RXR")
    with pytest.raises(MobilityInputError, match="names no pair"):
        parse_pairs(" , ")
    with pytest.raises(MobilityInputError, match="must be ≥ 1"):
        parse_pairs("0P")


def test_count_by_class() -> None:
    assert count_pairs_by_class("RS_sRC") == ((2, 2, 0, 0, 0), {"R": 2, "S_s": 1, "C": 1})
    assert count_pairs_by_class({"revolute": 2, "R": 1, "ball": 1})[0] == (3, 0, 1, 0, 0)
    with pytest.raises(MobilityInputError, match="whole number"):
        count_pairs_by_class({"R": 1.5})
    with pytest.raises(MobilityInputError, match="≥ 0"):
        count_pairs_by_class({"R": -1})


def test_freedom_names() -> None:
    assert freedom_names([("A", "R"), ("B", "spherical"), ("D", "C")]) == (
        "A.rz",
        "B.rx",
        "B.ry",
        "B.rz",
        "D.rz",
        "D.tz",
    )


def test_as_dict() -> None:
    d = pair_kind("S_s").as_dict()
    assert d["class"] == 2 and d["symbol"] == "S_s" and d["freedoms"] == ["rx", "rz"]
