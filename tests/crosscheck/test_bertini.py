"""Every assembly mode against Bertini 2 (validation/bertini/bertini_crosscheck.py): the same closure
polynomials solved by screwkit's parameter homotopy and by Bertini's own total-degree homotopy
with adaptive precision give the same finite solutions one to one, and the same real ones.

Bertini 2 is GPL-3: it is only in the optional ``crosscheck`` extra, which ``make test``
installs, never a dependency of screwkit."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("bertini", reason="the crosscheck extra (Bertini 2) is not installed")

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "validation" / "bertini"))

from bertini_crosscheck import FAMILIES, compare  # noqa: E402


def test_every_stewart_pose_equals_bertini():
    """Three random 6-6 platforms (40 complex poses each; Bertini tracks 128 paths per instance
    in adaptive precision). The 6R loop is in the validation script only: Bertini's 1,024
    total-degree paths take minutes in adaptive precision."""
    family = "Stewart–Gough 6-6"
    make, start, draw = FAMILIES[family]
    system, s = make(), start()
    p, known = draw(np.random.default_rng(7), 3)
    for i in range(3):
        r = compare(family, system, s, p[i].real.astype(complex))
        assert r.ours == r.theirs == s.generic_count, r
        assert r.ours_real == r.theirs_real >= 1, r  # each instance assembles where drawn
        assert r.mismatch < 1e-7, r


def test_a_wrong_system_is_told_apart():
    """The comparison can fail: a Stewart instance against Bertini's solutions of a different
    instance (other leg lengths) matches nothing."""
    make, start, draw = FAMILIES["Stewart–Gough 6-6"]
    system, s = make(), start()
    p, _ = draw(np.random.default_rng(8), 2)
    from bertini_crosscheck import _mismatch, bertini_solutions

    from screwkit.algebraic.solve import solve_all

    ours = solve_all(system, p[0].real.astype(complex), s).of(0)
    other = bertini_solutions(system, p[1].real.astype(complex))
    assert _mismatch(ours, other) > 1e-3


def test_the_bundled_stewart_platform_equals_bertini():
    """The bundled platform is not generic (its legs meet the plates in symmetric pairs): 28 of
    the 40 generic poses stay finite. Bertini finds the same 28 at its first row, with the same
    16 real ones, as screwkit's formulation of the spec (every_mode's parameters)."""
    from bertini_crosscheck import _real_count, bertini_solutions

    import screwkit as sk
    from screwkit.algebraic.solve import solve_all
    from screwkit.kinematics.modes.every_mode import closure_formulation, formulation_start

    spec = sk.load_spec(ROOT / "examples" / "mechanisms" / "stewart_platform.toml")
    form = closure_formulation(spec.mechanism)
    p = form.parameters(np.asarray(spec.inputs)[:1])[0]
    ours = solve_all(form.system, p, formulation_start(form)).of(0)
    theirs = bertini_solutions(form.system, p)
    assert len(ours) == len(theirs) == 28
    assert _real_count(ours) == _real_count(theirs) == 16
    from bertini_crosscheck import _mismatch

    assert _mismatch(ours, theirs) < 1e-7
