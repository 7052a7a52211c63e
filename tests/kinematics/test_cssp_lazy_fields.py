"""The CSSP's optional per-sample fields through ``solve_motion`` are computed on first access
(issue 30): the ball joints' rotations, rates and rotation vectors and Rahman's angles are not
computed by the solve nor by inverse dynamics, and when read they equal, bit for bit, the fields
the eager pass computes (same keys in the same order, NaN where a mode does not assemble)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from screwkit.dynamics import inverse_dynamics
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.kinematics.lazy_fields import LazyConfiguration, LazyTable, derived_table
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.mode_frames import unwrap_runs
from screwkit.model.families import cssp
from screwkit.model.linkage import Link
from screwkit.model.mass import MassProperties

INCH = 0.0254
ANGLES = ("theta2", "eta2", "theta3", "eta3")


def _massed(a2: float) -> object:
    lk = cssp(2 * INCH, a2 * INCH, 1 * INCH, np.radians(250.0), 0.4 * INCH)
    return lk.with_links([
        Link("crank", MassProperties(0.861, [0.0254, 0.002, -0.001],
                                     np.diag([2.3e-5, 1.97e-4, 1.97e-4]))),
        Link("rod", MassProperties(3.44, [0.1016, 0.0, 0.0], np.diag([9.3e-5, 1.19e-2, 1.19e-2]))),
        Link("slider", MassProperties(2.72, [0.001, 0.0, 0.002],
                                      np.diag([4.8e-4, 4.8e-4, 8.8e-4]))),
    ])


#: a CSSP that assembles over the whole turn, and one (short rod) that assembles over part of it
CASES = {"full turn": 8.0, "part of the turn": 2.5}
THETA = np.linspace(0.0, 2 * np.pi, 1500, endpoint=False)


def _eager_tables(lk: object, root: int, rate: float, accel: float
                  ) -> tuple[list[dict[str, np.ndarray]], np.ndarray, np.ndarray]:
    """The tables of a solve_motion mode built from the eager pass (the seed's names first, the
    angles unwrapped along each run, then the joints'), its spherical rotations and mask."""
    md = cssp_mode_motion(lk, THETA, rate, accel, root=root, allow_partial=True,  # type: ignore[arg-type]
                          seed_angles=True)
    ok = md.assembles
    slider = lk.joints[3].name  # type: ignore[attr-defined]
    tables = []
    for k, (table, first) in enumerate(zip((md.variables, md.velocities, md.accelerations),
                                           (THETA, np.full(THETA.size, rate),
                                            np.full(THETA.size, accel)), strict=True)):
        assert not isinstance(table, LazyTable)
        out = {"theta1": np.where(ok, first, np.nan), "s4": table[f"{slider}.s"]}
        for key in ANGLES:
            out[key] = unwrap_runs(table[key], ok) if k == 0 else table[key]
        out.update((key, v) for key, v in table.items() if key not in ANGLES)
        tables.append(out)
    return tables, md.conf.spherical, ok


@pytest.mark.parametrize("case", CASES)
def test_solve_motion_computes_the_optional_fields_on_first_access(case: str) -> None:
    lk = _massed(CASES[case])
    motion = solve_motion(lk, THETA, rates=3.0, accelerations=0.5)
    assert motion.modes
    for md in motion.modes:
        tables = (md.variables, md.velocities, md.accelerations)
        assert all(isinstance(t, LazyTable) and not t.loaded for t in tables)
        assert isinstance(md.conf, LazyConfiguration) and "spherical" not in vars(md.conf)
        # what inverse dynamics reads is there without them
        inverse_dynamics(lk, md, [0.0, 0.0, -9.81], allow_partial=True)  # type: ignore[arg-type]
        assert not any(t.loaded for t in tables) and "spherical" not in vars(md.conf)
        root = 1 if md.label.startswith("s4 = -b + ") else -1
        expected, spherical, ok = _eager_tables(lk, root, 3.0, 0.5)
        assert np.array_equal(md.assembles, ok)
        assert len(md.variables) == len(expected[0]) and "pin.rx" in md.variables
        for got, want in zip(tables, expected, strict=True):
            assert list(got) == list(want)  # same keys, same order
            for key, values in want.items():
                assert np.array_equal(got[key], values, equal_nan=True), key
        assert np.array_equal(md.conf.spherical, spherical, equal_nan=True)
        assert np.isnan(md.conf.spherical[~ok]).all()


def test_loads_are_unchanged_by_lazy_fields() -> None:
    lk = _massed(8.0)
    lazy = cssp_mode_motion(lk, THETA, 3.0, 0.5, seed_angles=True, lazy=True)  # type: ignore[arg-type]
    eager = cssp_mode_motion(lk, THETA, 3.0, 0.5, seed_angles=True)  # type: ignore[arg-type]
    a = inverse_dynamics(lk, lazy, [0.0, 0.0, -9.81])  # type: ignore[arg-type]
    b = inverse_dynamics(lk, eager, [0.0, 0.0, -9.81])  # type: ignore[arg-type]
    assert np.array_equal(a.shaking_force, b.shaking_force)
    assert np.array_equal(a.shaking_moment, b.shaking_moment)
    for key, values in b.efforts.items():
        assert np.array_equal(a.efforts[key], values)
    for joint, reaction in b.reactions.items():
        assert np.array_equal(a.reactions[joint]["force"], reaction["force"])


def _table() -> tuple[LazyTable, list[int]]:
    calls: list[int] = []

    def source() -> dict[str, np.ndarray]:
        calls.append(1)
        return {"b": np.arange(3.0) + 10, "d": np.arange(3.0) + 30}

    eager = {"a": np.arange(3.0), "c": np.arange(3.0) + 20}
    return LazyTable(["a", "b", "c", "d"], eager, ["b", "d"], source), calls


def test_a_lazy_table_reads_as_the_dict_it_stands_for() -> None:
    table, calls = _table()
    assert len(table) == 4 and "b" in table and "z" not in table and not calls
    assert table["a"][0] == 0.0 and table.get("c")[0] == 20.0 and not calls
    assert table["d"][1] == 31.0 and calls == [1] and table.loaded
    assert list(table) == ["a", "b", "c", "d"]  # the order of the eager table
    again, calls = _table()
    copied = dict(again)  # dict() loads it
    assert calls == [1] and list(copied) == list(table)
    assert all(np.array_equal(copied[k], table[k]) for k in table)
    plain = pickle.loads(pickle.dumps(_table()[0]))
    assert type(plain) is dict and list(plain) == ["a", "b", "c", "d"]
    written, calls = _table()
    written["e"] = np.zeros(3)  # a write loads it first
    assert calls == [1] and list(written) == ["a", "b", "c", "d", "e"]
    assert {**_table()[0]}.keys() == {"a", "b", "c", "d"}
    with pytest.raises(ValueError, match="each once"):
        LazyTable(["a"], {"a": np.zeros(1)}, ["a"], dict)


def test_derived_and_mapped_tables_stay_lazy() -> None:
    table, calls = _table()
    derived = derived_table(table, ["x", "d", "a"], {"x": np.ones(3)}, {"d": lambda v: -v})
    halves = table.mapped(lambda v: v[:2])
    assert isinstance(derived, LazyTable) and not calls
    assert list(derived) == ["x", "d", "a"] and calls == [1]
    assert derived["d"].tolist() == [-30.0, -31.0, -32.0] and derived["x"].tolist() == [1.0] * 3
    assert {k: v.tolist() for k, v in halves.items()} == {
        "a": [0.0, 1.0], "b": [10.0, 11.0], "c": [20.0, 21.0], "d": [30.0, 31.0]}
    assert calls == [1]  # one computation for the table and everything derived from it
