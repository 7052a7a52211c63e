"""The [balancing] table: validation messages for bad input."""

from __future__ import annotations

import pytest

from conftest import EXAMPLE
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
