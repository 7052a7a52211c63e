"""What a balancing result reports: gravity along the spec's gravity_direction, no percentage
change for a measure that is round-off, and a note when the reactions are statically
indeterminate."""

from __future__ import annotations

import json

from balancing_examples import fourbar_spec

from screwkit.io.spec import load_spec
from screwkit.pipeline import balance_from_spec


def test_gravity_follows_gravity_direction(tmp_path):
    table = "[balancing]\nweights = {F = 1}\ngravity = true\n[balancing.links.crank]\n"
    in_plane = balance_from_spec(load_spec(fourbar_spec(tmp_path, table, "[0, -1, 0]")))
    normal = balance_from_spec(load_spec(fourbar_spec(tmp_path, table, "[0, 0, -1]")))
    # the 4R moves in the x-y plane: in-plane gravity loads no bearing moment (round-off,
    # ~1e-27 against measures of order 1), gravity normal to the plane does (0.23)
    assert in_plane.measures_before["M"] < 1e-12 * in_plane.measures_before["R"]
    assert normal.measures_before["M"] > 0.1


def test_round_off_measure_has_no_percentage(tmp_path):
    table = "[balancing]\nweights = {F = 1}\ngravity = true\n[balancing.links.crank]\n"
    res = balance_from_spec(load_spec(fourbar_spec(tmp_path, table)))
    ch = res.changes()
    assert ch["M"] is None and ch["F"] is not None and ch["F"] < 0
    row = next(r for r in res.summary_table() if r[0].endswith("(M)"))
    assert row[3] == "n/a (round-off)"
    assert json.loads(json.dumps(res.as_dict()))["measures"]["change_percent"]["M"] is None


def test_indeterminate_reactions_are_noted(tmp_path):
    bearing = balance_from_spec(load_spec(fourbar_spec(
        tmp_path, "[balancing]\nweights = {R = 1, M = 1}\n[balancing.links.crank]\n")))
    assert any("statically indeterminate" in n and "minimum-norm" in n for n in bearing.notes)
    assert any("statically indeterminate" in n for n in bearing.as_dict()["notes"])
    shaking = balance_from_spec(load_spec(fourbar_spec(
        tmp_path, "[balancing]\nweights = {F = 1, T = 1}\n[balancing.links.crank]\n")))
    assert not any("statically indeterminate" in n for n in shaking.notes)
