"""Formula against numeric mobility: the explanation of the difference."""

from __future__ import annotations

import json

import numpy as np
import pytest
from mobility_screws import bennett, parallelogram_chain, rsrc, rssr

from screwkit.mobility import compare_mobility, formula_mobility, mobility_from_jacobian


def test_bennett_malytcheff_only() -> None:
    jac, names, _ = bennett()
    c = compare_mobility(formula_mobility(4, "4R"), mobility_from_jacobian(jac, names),
                         name="Bennett")
    assert c.explanation[0] == (
        "Bennett: formula gives -2, the loop moves with 1: 3 redundant constraints "
        "(overconstrained)"
    )
    assert c.difference == 3 and not c.agree
    assert "loop 1 m(000,111) = 3" in c.describe()
    assert any("instantaneous" in line for line in c.explanation)


def test_bennett_with_bagci_constraints_agrees() -> None:
    jac, names, _ = bennett()
    f = formula_mobility(4, "4R", general_constraints="m(000,111)", name="Bennett")
    c = compare_mobility(f, mobility_from_jacobian(jac, names))
    assert c.agree
    assert c.explanation[0] == "Bennett: formula gives 1, the loop moves with 1 (agree)"
    assert "matched by the formula's H = M − F_p + F_c = 3" in c.explanation[1]


def test_parallelogram_without_overclosing() -> None:
    jac, names = parallelogram_chain()
    f = formula_mobility(6, "8R", general_constraints=3, name="Fig. 32")
    c = compare_mobility(f, mobility_from_jacobian(jac, names, inputs="G0.rz"))
    assert c.difference == 2
    text = c.describe()
    assert "11 redundant constraints (6k − rank) but the formula accounts for H" in text
    assert "F_c 0 / 2" in text


def test_formula_assumes_geometry_the_loop_lacks() -> None:
    # A generic RSRC counted as if δ0 = 0 with an extra general constraint and no passive one.
    jac, names = rsrc(np.random.default_rng(1))
    f = formula_mobility(4, "RSRC", general_constraints=1)
    c = compare_mobility(f, mobility_from_jacobian(jac, names), name="RSRC")
    assert c.difference == -1
    assert "lacks the special geometry" in c.describe()


def test_rssr_redundant_freedom_and_passive_note() -> None:
    jac, names = rssr(np.random.default_rng(2))
    n = mobility_from_jacobian(jac, names, inputs="A0.rz", outputs="B0.rz")
    c = compare_mobility(formula_mobility(4, "RSSR"), n, name="RSSR")
    assert c.agree
    assert any(line.startswith("1 redundant freedom moving neither") for line in c.explanation)
    d = json.loads(json.dumps(c.as_dict()))
    assert d["agree"] is True and d["numeric"]["redundant_freedoms"] == 1
    # Bagci's δ0 = 0 reading of the RSRC: the passive freedom is explained.
    jac0, names0 = rsrc(np.random.default_rng(3), delta0_zero=True)
    f0 = formula_mobility(4, "RSRC", general_constraints=1, passive_freedoms=1)
    c0 = compare_mobility(f0, mobility_from_jacobian(jac0, names0))
    assert c0.agree and any("passive freedom" in line for line in c0.explanation)


def test_different_chains_are_flagged() -> None:
    jac, names = rssr(np.random.default_rng(4))
    c = compare_mobility(formula_mobility(4, "RSRC"), mobility_from_jacobian(jac, names))
    assert "do not describe the same chain" in c.describe()


@pytest.mark.parametrize("example, redundant", [("rssr_spatial", 1), ("rahman_cssp", 1),
                                                 ("bagci_fig7_rsrc", 0), ("rrsrr_loop", 0)])
def test_linkage_mobility_names_the_idle_rod_spin_a_redundant_freedom(example, redundant):
    """sk.mobility passes the output joint's freedoms: the S–S rod's spin leaves the output
    still, so it is a redundant freedom (Bagci's R-S-S-R), not an undetermined output."""
    from pathlib import Path

    import screwkit as sk

    spec = sk.load_spec(Path(__file__).resolve().parents[2] / "examples" / f"{example}.toml")
    m = sk.mobility(spec.linkage)
    assert m.numeric.redundant_freedoms == redundant
    assert m.numeric.output_names is not None
