"""The [balancing] table: validation messages for bad input."""

from __future__ import annotations

import pytest
from balancing_examples import EXAMPLE

from screwkit.balancing import BalancingError
from screwkit.io.balancing_table import balancing_table, blocks_from_table
from screwkit.io.spec import load_spec
from screwkit.pipeline import balance_from_spec

BASE = EXAMPLE.read_text().split("[balancing]")[0]


def _spec(tmp_path, table: str):
    """Load a spec; its [balancing] table is validated at load (BalancingConfigError, which is a
    BalancingError and a SpecError)."""
    p = tmp_path / "s.toml"
    p.write_text(BASE + table)
    return load_spec(p)


def test_link_with_no_variables(tmp_path):
    with pytest.raises(BalancingError, match=r"\[balancing.links.crank\] has no variables"):
        s = _spec(tmp_path, "[balancing.links.crank]\nvariables = []\n")
        blocks_from_table(s, balancing_table(s))


def test_unknown_key_and_unknown_link(tmp_path):
    with pytest.raises(BalancingError, match=r"\[balancing.weigths\] unknown key"):
        s = _spec(tmp_path, "[balancing]\nweigths = { F = 1 }\n")
        balancing_table(s)
    with pytest.raises(BalancingError, match="no moving link named 'crnak'"):
        s = _spec(tmp_path, "[balancing.links.crnak]\nmax_decrease = 0.1\n")
        blocks_from_table(s, balancing_table(s))


def test_all_zero_weights_and_no_table(tmp_path, rahman):
    _, mode = rahman
    with pytest.raises(BalancingError, match="all weights are zero"):
        s = _spec(tmp_path, "[balancing]\nweights = { F = 0, T = 0 }\n[balancing.links.rod]\n")
        balance_from_spec(s, mode_motion=mode)
    s = _spec(tmp_path, "")
    with pytest.raises(BalancingError, match="no \\[balancing\\] table"):
        balance_from_spec(s, mode_motion=mode)


def test_bad_sum_rule(tmp_path):
    with pytest.raises(BalancingError, match="pair_sum"):
        s = _spec(tmp_path, "[balancing.links.rod]\npair_sum = \"less\"\n")
        balancing_table(s)


def test_what_balance_would_refuse_is_refused_at_load(tmp_path):
    """validate reports it: an ellipsoid that does not contain its link, a free-position
    counterweight with a measure other than F weighted (or in a Pareto sweep)."""
    links = "[balancing.links.crank]\nvariables = [\"m1\", \"m2\"]\nmax_decrease = 0.05\n"
    with pytest.raises(BalancingError, match="does not lie inside this ellipsoid"):
        _spec(tmp_path, "[balancing]\nweights = { F = 1 }\n" + links
              + "[balancing.bound.ellipsoids.crank]\ncentre = [0.0254, 0, 0]\n"
                "semi_axes = [0.03, 0.01, 0.01]\n")
    _spec(tmp_path, "[balancing]\nweights = { F = 1 }\n" + links
          + "[balancing.bound.ellipsoids.crank]\ncentre = [1.0, 0, 0]\n"
            "semi_axes = [1.5, 0.5, 0.5]\n")  # docs/balancing.md's: fine
    free = ("[[balancing.counterweights]]\nname = \"cw\"\nlink = \"crank\"\nmass_max = \"0.5 kg\"\n"
            "box_min = [-1, -1, -1]\nbox_max = [1, 1, 1]\n")
    with pytest.raises(BalancingError, match="weight only the shaking force F"):
        _spec(tmp_path, "[balancing]\nweights = { F = 1, T = 1 }\n" + free)
    with pytest.raises(BalancingError, match="weight only the shaking force F"):
        _spec(tmp_path, "[balancing]\nweights = { F = 1 }\n[balancing.pareto]\n"
                        "measures = [\"F\", \"T\"]\ndivisions = 2\n" + free)
    _spec(tmp_path, "[balancing]\nweights = { F = 1 }\n" + free)
