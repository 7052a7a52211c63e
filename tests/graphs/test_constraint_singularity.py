"""A constraint singularity on a real mechanism: the translational 3-UPU
(examples/mechanisms/three_upu.toml; geometry and an independent model in
tests/graphs/three_upu.py). Driven along x until its platform is 2|R − r| = 200 mm off centre,
where the legs' constraint couples become dependent (det[c_1 c_2 c_3] = 0, Zlatanov, Bonev &
Gosselin 2002), graph/singular.py must call that sample — and only that one — a "constraint"
singularity, and its closure condition number must equal σ₁/σ₁₂ of a central-difference
Jacobian of the legs' own product-of-exponentials kinematics.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.graphs import three_upu as T

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_layout

#: 0, 20, …, 260 mm along x: the sample at 200 mm is the singularity
XS = np.arange(0.0, 261.0, 20.0)
OFFSETS = np.stack([XS, np.zeros_like(XS), np.zeros_like(XS)], axis=1)
AT = int(np.flatnonzero(XS == T.SINGULAR_OFFSET)[0])


@pytest.fixture(scope="module")
def upu() -> tuple[sk.Mechanism, sk.MechanismMotion]:
    mech = sk.load_spec(T.PATH).mechanism
    return mech, solve_mechanism(mech, T.slides(OFFSETS) / 1000.0)  # mm → m


def test_the_bundled_example_is_the_model_here(tmp_path) -> None:
    assert T.write_spec(tmp_path / "three_upu.toml") == T.PATH.read_text(encoding="utf-8")


def test_the_couples_are_dependent_at_one_sample_only() -> None:
    det = T.couple_det(OFFSETS)
    assert abs(det[AT]) < 1e-12
    assert np.all(np.abs(np.delete(det, AT)) > 0.03)
    assert det[AT - 1] * det[AT + 1] < 0  # a crossing, not a touch


def test_the_platform_only_translates_through_it(upu) -> None:
    mech, motion = upu
    md = motion.modes[0]
    assert md.assembles.all()
    centre = md.points["centre"] * 1000.0
    err = np.abs(centre - (OFFSETS + [0.0, 0.0, T.HEIGHT])).max(axis=1)
    assert np.delete(err, AT).max() < 1e-9 and err[AT] < 1e-6  # mm (Newton is slow at it)
    plat = [b.name for b in mech.bodies].index("platform")
    assert np.abs(md.link_rotation[:, plat] - np.eye(3)).max() < 1e-9


def test_constraint_class_at_the_singular_sample_only(upu) -> None:
    mech, motion = upu
    md = motion.modes[0]
    expect = np.where(np.arange(XS.size) == AT, "constraint", "")
    assert list(md.singular_class) == list(expect)
    (event,) = [e for e in md.events if e.startswith("singular")]
    assert "a constraint singularity" in event
    # the regular example never comes near it
    spec = sk.load_spec(T.PATH)
    own = solve_mechanism(mech, spec.inputs).modes[0]
    assert own.assembles.all() and not own.singular_class.any()
    assert np.max(own.jacobian_condition["closure"]) < 100


def test_condition_number_equals_a_finite_difference_svd(upu) -> None:
    mech, motion = upu
    md = motion.modes[0]
    lay = graph_layout(mech)
    leg_of = {}
    for i in range(3):  # joints per leg: the base U, the P, the platform U
        leg_of.update({3 * i: (i, 0), 3 * i + 1: (i, 2), 3 * i + 2: (i, 3)})
    assert [mech.joints[k].name for k in range(3)] == ["Ub1", "P1", "Up1"]
    freedoms = [len(j.freedoms) for j in mech.joints]
    loops = [list(loop) for loop in mech.topology.loops]
    for k in range(XS.size):
        J = T.fd_closure_jacobian(OFFSETS[k], loops, leg_of, freedoms, lay.length * 1000.0)
        s = np.linalg.svd(J, compute_uv=False)
        assert J.shape == (12, 15)
        if k == AT:  # rank 11: the constraints are dependent
            assert s[11] / s[0] < 1e-9
            assert md.jacobian_condition["closure"][k] > 1e9
        else:
            assert s[11] / s[0] > 1e-2
            assert md.jacobian_condition["closure"][k] == pytest.approx(s[0] / s[11],
                                                                         rel=1e-7)
