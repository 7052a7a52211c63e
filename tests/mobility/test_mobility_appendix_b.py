"""Every worked example of Bagci 1969, Appendix B (seed 001_ddf35f8504d02a01.txt, L2712–L2905;
reference: /work/shared/reference/bagci1969/SPEC.md §8).

"printed" means the number is in the seed text; "inferred" means the reference (or this file)
worked it out from the other printed numbers, and the comment says how.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from screwkit.mobility import (
    BASIC,
    OVERCLOSED,
    OVERCLOSED_WITH_PASSIVE_FREEDOMS,
    WITH_PASSIVE_FREEDOMS,
    formula_mobility,
    kutzbach_mobility,
    planar_mobility,
    spherical_mobility,
)


@dataclass(frozen=True)
class Case:
    n_links: int
    kwargs: dict[str, object]
    malytcheff: int  # F0, eq. (B.1)
    general: int  # M, eq. (B.5)
    mobility: int  # F, eq. (B.8)
    classification: str | None = None  # Bagci's name, where the text gives or implies it
    loops: int = 1
    extra: dict[str, object] = field(default_factory=dict)


CASES = {
    # Fig. 30, L2821–L2823: m1 = 2, m2 = 1, N1 = 4, N2 = 2, N3 = 1, F_p = 1 and
    # "F = 6(6-1) - 5(4) - 4(2) - 3(1) + 2 + 1 - 1 = 1" all printed; k = 2 follows from (B.3);
    # "a mechanism with passive freedom" printed at L2895.
    "fig30_two_loop_six_bar": Case(
        6,
        {
            "pairs_by_class": {1: 4, 2: 2, 3: 1},
            "general_constraints": [2, 1],
            "passive_freedoms": 1,
        },
        malytcheff=-1,
        general=3,
        mobility=1,
        classification=WITH_PASSIVE_FREEDOMS,
        loops=2,
    ),
    # Fig. 5 RSRC, no general constraint: F = 1 (the one-input mechanism of the thesis);
    # F0 = 18 − 10 − 4 − 3 = 1 computed. "basic" inferred (F_p = F_c = 0).
    "rsrc": Case(4, {"pairs": "RSRC"}, malytcheff=1, general=0, mobility=1, classification=BASIC),
    # RSRC with δ0 = 0 counted with its S pair, L2825: "a passive freedom on the spherical pair"
    # (F_p = 1) which "introduces one general constraint on the rotation" (m = 1), printed;
    # F = 1 + 1 − 1 = 1 inferred.
    "rsrc_delta0_zero": Case(
        4,
        {"pairs": "RSRC", "general_constraints": 1, "passive_freedoms": 1},
        malytcheff=1,
        general=1,
        mobility=1,
        classification=WITH_PASSIVE_FREEDOMS,
    ),
    # Fig. 31 RS_sRC, caption L2835: m = 1 printed (the caption's "RSRS" is a misprint for
    # RSRC); S_s is class 2 so F0 = 18 − 10 − 8 = 0; F = 1 inferred; "basic" printed (L2895).
    "fig31_rs_src": Case(
        4,
        {"pairs": "RS_sRC", "general_constraints": "m(100,000)"},
        malytcheff=0,
        general=1,
        mobility=1,
        classification=BASIC,
    ),
    # Fig. 29a–g, L2742–L2751; all "Basic Mechanisms" (printed, L2895). The m(...) notations are
    # printed; the figure itself is missing, so F = 1 is inferred from the F0 + m count (the
    # text calls them mechanisms).
    "fig29a_rspc": Case(
        4, {"pairs": "RSPC"}, malytcheff=1, general=0, mobility=1, classification=BASIC
    ),
    "fig29b_rs_spc": Case(
        4,
        {"pairs": "RS_sPC", "general_constraints": "m(100,000)"},
        malytcheff=0,
        general=1,
        mobility=1,
        classification=BASIC,
    ),
    "fig29c_rccc": Case(
        4, {"pairs": "RCCC"}, malytcheff=1, general=0, mobility=1, classification=BASIC
    ),
    "fig29d_rcpp": Case(
        4,
        {"pairs": "RCPP", "general_constraints": "m(011,000)"},
        malytcheff=-1,
        general=2,
        mobility=1,
        classification=BASIC,
    ),
    "fig29e_4p": Case(
        4,
        {"pairs": "4P", "general_constraints": "m(111,000)"},
        malytcheff=-2,
        general=3,
        mobility=1,
        classification=BASIC,
    ),
    # RHP is a three-link loop (n = 3 inferred: R, H, P close one loop by B.3).
    "fig29f_rhp": Case(
        3,
        {"pairs": "RHP", "general_constraints": "m(011,011)"},
        malytcheff=-3,
        general=4,
        mobility=1,
        classification=BASIC,
    ),
    # H_s is the spiral pair (List of Symbols), class 1; n = 3 inferred as for RHP.
    "fig29g_rh_sp": Case(
        3,
        {"pairs": "RH_sP", "general_constraints": "m(101,110)"},
        malytcheff=-3,
        general=4,
        mobility=1,
        classification=BASIC,
    ),
    # Bennett, L2749: "m(000,111) = 3" printed; four R pairs, F = 1 (a moving linkage).
    "bennett": Case(
        4,
        {"pairs": "RRRR", "general_constraints": "m(000,111)"},
        malytcheff=-2,
        general=3,
        mobility=1,
        classification=BASIC,
    ),
    # Plane and spherical 4R: the m(110,001) and m(000,111) notations are printed (L2740);
    # applying them to the four-bar is inferred.
    "plane_4r": Case(
        4,
        {"pairs": "4R", "general_constraints": "m(110,001)"},
        malytcheff=-2,
        general=3,
        mobility=1,
        classification=BASIC,
    ),
    "spherical_4r": Case(
        4,
        {"pairs": "4R", "general_constraints": "m(000,111)"},
        malytcheff=-2,
        general=3,
        mobility=1,
        classification=BASIC,
    ),
    # Fig. 33a, L2853–L2870: k = 2, n = 6, N1 = 4, N2 = 1, N3 = 2, F_p = 2, F_c = 1, F = 1
    # printed; "each loop ... has one general constraint on rotation" (L2853) gives M = 2;
    # "overclosed mechanism with passive freedoms" printed (L2895).
    "fig33a_two_loop_six_bar": Case(
        6,
        {
            "pairs_by_class": {1: 4, 2: 1, 3: 2},
            "general_constraints": [1, 1],
            "passive_freedoms": 2,
            "overclosing_constraints": 1,
            "loops": 2,
        },
        malytcheff=0,
        general=2,
        mobility=1,
        classification=OVERCLOSED_WITH_PASSIVE_FREEDOMS,
        loops=2,
    ),
    # Fig. 33b, L2874–L2884: k = 3, n = 8, N1 = 6, N2 = 4, F_p = 0, F_c = 2, F = 1 printed;
    # M = 3 from one rotation constraint per loop; "overclosed mechanism" printed.
    "fig33b_three_loop_eight_bar": Case(
        8,
        {
            "pairs_by_class": {1: 6, 2: 4},
            "general_constraints": 1,
            "overclosing_constraints": 2,
            "loops": 3,
        },
        malytcheff=-4,
        general=3,
        mobility=1,
        classification=OVERCLOSED,
        loops=3,
    ),
    # Fig. 32, caption L2840: only F_c = 2 is printed. Inferred: a ground bar and a coupler
    # joined by four equal parallel cranks, n = 6, N1 = 8, k = 3 by (B.3), m = 3 per loop
    # (plane), F = 1 (a parallelogram moves); L2850 gives F_c = k − 1 = 2, consistent.
    "fig32_plane_parallelogram": Case(
        6,
        {"pairs": "8R", "general_constraints": "m(110,001)", "overclosing_constraints": 2},
        malytcheff=-10,
        general=9,
        mobility=1,
        classification=OVERCLOSED,
        loops=3,
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_worked_example(name: str) -> None:
    case = CASES[name]
    r = formula_mobility(case.n_links, name=name, **case.kwargs)  # type: ignore[arg-type]
    assert r.loops == case.loops
    assert r.malytcheff == case.malytcheff
    assert r.total_general_constraints == case.general
    assert r.mobility == case.mobility
    assert r.classification == case.classification
    # Kolchin's form (B.9): F = F0 + H with H = M − F_p + F_c.
    assert r.mobility == r.malytcheff + r.kolchin_parameter


def test_fig30_printed_sum() -> None:
    # The printed line L2823 term by term: 6(6−1) − 5(4) − 4(2) − 3(1) + 2 + 1 − 1 = 1.
    assert 6 * (6 - 1) - 5 * 4 - 4 * 2 - 3 * 1 + 2 + 1 - 1 == 1
    r = formula_mobility(
        6, pairs_by_class=(4, 2, 1), general_constraints=[2, 1], passive_freedoms=1
    )
    assert r.general_constraints == (2, 1)
    assert r.kolchin_group == "unlimited"  # H = 2 < M = 3


@pytest.mark.parametrize("name", [n for n, c in CASES.items() if c.loops == 1])
def test_kutzbach_b2_equals_b4_for_single_loops(name: str) -> None:
    # (B.2) as printed agrees with (B.4) F0 + m k: none of these loops has a pair of class
    # ≥ 6 − m. (B.2) ignores F_p, so compare with F0 + M.
    case = CASES[name]
    r = formula_mobility(case.n_links, **case.kwargs)  # type: ignore[arg-type]
    assert r.kutzbach == r.malytcheff + r.total_general_constraints


def test_kutzbach_b7_with_active_freedoms() -> None:
    # (B.7b) for RSRC with δ0 = 0: b = 6 − 1 = 5; active freedoms R 1, S 3 − 1 = 2, R 1, C 2.
    assert kutzbach_mobility(4, [1, 2, 1, 2], motion_components=5) == 1
    # RS_sRC needs no passive freedom: same numbers with S_s (class 2).
    assert (
        kutzbach_mobility(4, [1, 2, 1, 2], motion_components=5)
        == formula_mobility(4, "RS_sRC", general_constraints=1).mobility
    )
    # plane and spherical four-bars, b = 3 (Grübler).
    assert kutzbach_mobility(4, [1, 1, 1, 1], motion_components=3) == 1


def test_kolchin_groups_follow_fp_against_fc() -> None:
    # L2895: overclosed with passive freedoms splits by F_p vs F_c into H < M, H = M, H > M.
    base = {"pairs_by_class": {1: 8}, "general_constraints": 3}
    groups = [
        formula_mobility(6, passive_freedoms=fp, overclosing_constraints=fc, **base).kolchin_group  # type: ignore[arg-type]
        for fp, fc in ((2, 1), (1, 1), (1, 2))
    ]
    assert groups == ["unlimited", "basic", "special"]


def test_plane_and_spherical_shortcuts() -> None:
    assert planar_mobility(4, "4R").mobility == 1
    assert spherical_mobility(4, "4R").mobility == 1
    assert planar_mobility(6, "8R", overclosing_constraints=2).mobility == 1
    # Without F_c the plane count of Fig. 32 gives −1 (Grübler: 3·5 − 2·8): the parallelogram
    # needs its overclosing constraints.
    assert planar_mobility(6, "8R").mobility == -1
