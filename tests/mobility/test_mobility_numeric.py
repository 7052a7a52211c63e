"""Numeric (instantaneous) mobility from hand-built screw Jacobians (mobility_screws.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mobility_screws import (
    bennett,
    cssp,
    cylinder,
    helical,
    parallelogram_chain,
    plane_4r,
    prism,
    random_direction,
    rccc,
    revolute,
    rsrc,
    rssr,
    spherical,
    spherical_4r,
    spherical_centre,
    unit,
)
from scipy.spatial.transform import Rotation

from screwkit.mobility import (
    MobilityInputError,
    characteristic_length,
    formula_mobility,
    jacobian_rank,
    mobility_from_jacobian,
)

PROFILE = settings(derandomize=True, max_examples=25, deadline=None)
MECHANISMS = {"rssr": rssr, "rsrc": rsrc, "plane_4r": plane_4r, "spherical_4r": spherical_4r,
              "cssp": cssp}


def test_rssr_coupler_spin() -> None:
    # Bagci, Appendix B "Redundant Freedoms": two S pairs in one loop add a freedom that does
    # not affect input–output transmission.
    jac, names = rssr(np.random.default_rng(1))
    r = mobility_from_jacobian(jac, names, inputs="A0.rz", outputs="B0.rz")
    assert (r.rank, r.mobility, r.redundant_constraints) == (6, 2, 0)
    assert r.undetermined_motions == 1 and r.inputs_determine_motion is False
    assert r.redundant_freedoms == 1 and r.inputs_determine_outputs is True
    assert set(r.undetermined_involves or ()) == set(names[1:7])
    assert r.redundant_involves == r.undetermined_involves
    # The spin, built by hand: rotate S1 by +u and S2 by −u about the line through both centres.
    u = unit(spherical_centre(jac[:, 4:7]) - spherical_centre(jac[:, 1:4]))
    spin = np.concatenate([[0.0], u, -u, [0.0]])
    assert np.abs(jac @ spin).max() < 1e-12
    # it lies in the reported null space (rates of rotations need no rescaling)
    residual = spin - r.null_space @ (r.null_space.T @ spin)
    assert np.abs(residual).max() < 1e-10


def test_plane_4r_as_spatial_loop() -> None:
    jac, names = plane_4r(np.random.default_rng(2))
    r = mobility_from_jacobian(jac, names, inputs="A0.rz")
    assert (r.rank, r.mobility, r.redundant_constraints) == (3, 1, 3)
    assert r.loop_constraints[0].general.same_type("m(110,001)")  # Bagci's plane, L2740
    assert r.inputs_determine_motion is True
    assert (r.malytcheff, r.total_general_constraints, r.overclosing_constraints) == (-2, 3, 0)


@pytest.mark.parametrize("theta1_deg", [10.0, 50.0, 120.0, -80.0])
def test_bennett(theta1_deg: float) -> None:
    jac, names, closure = bennett(theta1=np.radians(theta1_deg))
    assert np.abs(closure - np.eye(4)).max() < 1e-12  # the geometry really closes
    r = mobility_from_jacobian(jac, names, inputs="J1.rz")
    # 4 joints, rank 3: mobility 1 with 3 redundant constraints (overconstrained)
    assert (r.rank, r.mobility, r.redundant_constraints) == (3, 1, 3)
    # L2749: "three translational general constraints in its motion, m(000,111) = 3"
    assert r.loop_constraints[0].general.notation == "m(000,111)"
    assert r.inputs_determine_motion is True
    kept, dropped = r.rank_gap
    assert kept > 0.1 and dropped < 1e-14


def test_bennett_conditions_matter_and_tolerance() -> None:
    jac, names, _ = bennett()
    for angle, rank in ((1e-11, 3), (1e-10, 3), (1e-6, 4), (1e-3, 4)):
        # Tilt the last axis about a perpendicular direction through its own point.
        w, v = jac[:3, 3], jac[3:, 3]
        point = np.cross(w, v)  # foot of the axis: r = w × v for a unit w
        tilt = Rotation.from_rotvec(angle * unit(np.cross(w, [0.3, 0.1, 0.9]))).apply(w)
        bent = jac.copy()
        bent[:, 3] = revolute(point, tilt)[:, 0]
        # Tilts up to 1e-10 rad are below rtol = 1e-8 (they read as the Bennett), 1e-6 is not
        # (a generic 4R loop is rigid).
        assert mobility_from_jacobian(bent, names).rank == rank


def test_rsrc_generic() -> None:
    jac, names = rsrc(np.random.default_rng(3))
    r = mobility_from_jacobian(jac, names, inputs="R1.rz", outputs="C")
    assert (r.rank, r.mobility, r.redundant_constraints) == (6, 1, 0)
    assert r.loop_constraints[0].count == 0
    assert r.inputs_determine_motion is True and r.inputs_determine_outputs is True
    assert r.locked_freedoms == ()


def test_rsrc_delta0_zero_and_rs_src() -> None:
    rng = np.random.default_rng(4)
    jac, names = rsrc(rng, delta0_zero=True)
    r = mobility_from_jacobian(jac, names, inputs="R1.rz")
    # With the S pair, the passive rotation is not visible at one configuration: rank 6,
    # M = 0. Bagci's reading is M = 1, F_p = 1; F is the same.
    assert (r.mobility, r.total_general_constraints) == (1, 0)
    assert formula_mobility(4, "RSRC", general_constraints=1, passive_freedoms=1).mobility == 1
    # Fig. 31: replace S by the slotted sphere S_s whose two rotations are about the input and
    # output directions (the passive one, about their common normal, is removed).
    u_in, u_out = jac[:3, 0], jac[:3, 5]
    centre = spherical_centre(jac[:, 1:4])
    s_s = np.hstack([revolute(centre, u_in), revolute(centre, u_out)])
    jac_s = np.hstack([jac[:, :1], s_s, jac[:, 4:]])
    names_s = ["R1.rz", "Ss.rx", "Ss.rz", "R2.rz", "C.rz", "C.tz"]
    r_s = mobility_from_jacobian(jac_s, names_s, inputs="R1.rz")
    assert (r_s.rank, r_s.mobility, r_s.redundant_constraints) == (5, 1, 1)
    assert r_s.loop_constraints[0].general.notation == "m(100,000)"  # Fig. 31: m = 1
    assert r_s.inputs_determine_motion is True


def test_spherical_4r() -> None:
    jac, names = spherical_4r(np.random.default_rng(5))
    r = mobility_from_jacobian(jac, names, inputs="A0.rz")
    assert (r.rank, r.mobility, r.redundant_constraints) == (3, 1, 3)
    assert r.loop_constraints[0].general.notation == "m(000,111)"


def test_cssp_inputs_by_pair() -> None:
    jac, names = cssp(np.random.default_rng(6))
    r = mobility_from_jacobian(jac, names, inputs="C", outputs="P")
    assert r.input_names == ("C.rz", "C.tz")
    assert (r.mobility, r.undetermined_motions, r.redundant_freedoms) == (3, 1, 1)
    assert r.independent_inputs == 2
    assert set(r.redundant_involves or ()) == set(names[2:8])


def test_rccc_parallel_cylinders_function_as_prism() -> None:
    # Bagci, Appendix B: "when the skew angle δ0 is zero the [RCCC] mechanism functions as a
    # prism pair"; the two parallel C's give a redundant translation.
    jac, names = rccc(np.random.default_rng(7), parallel_outputs=True)
    r = mobility_from_jacobian(jac, names, inputs="R.rz", outputs="C3")
    assert r.mobility == 1
    assert set(r.locked_freedoms) == {"R.rz", "C1.rz", "C1.tz", "C2.rz", "C3.rz"}
    assert r.independent_inputs == 0  # the input crank cannot turn
    assert set(r.undetermined_involves or ()) == {"C2.tz", "C3.tz"}


def test_rccr_constrained_inversion() -> None:
    # "A constrained inversion of the RCCC mechanism, the RCRC or RCCR mechanism, is formed when
    # δ0 = α0 = 0": R ∥ C1 and C2 ∥ C3. As RCCC it keeps a redundant translation along the
    # parallel C2, C3; with the last C replaced by an R it is constrained.
    rng = np.random.default_rng(8)
    p = rng.normal(size=(4, 3))
    u0, u2 = random_direction(rng), random_direction(rng)
    rccc_jac = np.hstack([revolute(p[0], u0), cylinder(p[1], u0), cylinder(p[2], u2),
                          cylinder(p[3], u2)])
    names = ["R.rz", "C1.rz", "C1.tz", "C2.rz", "C2.tz", "C3.rz", "C3.tz"]
    r = mobility_from_jacobian(rccc_jac, names, inputs="R", outputs="C3")
    assert (r.mobility, r.undetermined_motions) == (2, 1)
    assert set(r.undetermined_involves or ()) == {"C2.tz", "C3.tz"}
    rccr = mobility_from_jacobian(rccc_jac[:, :6], names[:6], inputs="R", outputs="C3")
    assert (rccr.mobility, rccr.inputs_determine_motion) == (1, True)


Fig29Case = tuple[np.ndarray, list[str], str, int, str]


def _fig29() -> dict[str, Fig29Case]:
    """Constrained RCCC family of Fig. 29 as instantaneous screw systems:
    (Jacobian, names, pairs, links n, Bagci's printed m(...))."""
    rng = np.random.default_rng(9)
    p = rng.normal(size=(4, 3))
    u, w = random_direction(rng), random_direction(rng)
    v = unit(np.cross(u, w))
    w_perp = unit(w - (w @ u) * u)
    out: dict[str, Fig29Case] = {}
    # RS_sPC: rotations only about two directions (R, C and the S_s axes), P generic.
    out["RS_sPC"] = (
        np.hstack([revolute(p[0], u), revolute(p[1], u), revolute(p[1], w),
                   prism(random_direction(rng)), cylinder(p[2], w)]),
        ["R.rz", "Ss.rx", "Ss.rz", "P.tz", "C.rz", "C.tz"], "RS_sPC", 4, "m(100,000)")
    # RCPP: R ∥ C (α0 = 0), two prisms.
    out["RCPP"] = (
        np.hstack([revolute(p[0], u), cylinder(p[1], u), prism(w), prism(v)]),
        ["R.rz", "C.rz", "C.tz", "P1.tz", "P2.tz"], "RCPP", 4, "m(011,000)")
    out["4P"] = (
        np.hstack([prism(random_direction(rng)) for _ in range(4)]),
        ["P1.tz", "P2.tz", "P3.tz", "P4.tz"], "4P", 4, "m(111,000)")
    # RHP: R and H coaxial, P along the axis (three links).
    out["RHP"] = (
        np.hstack([revolute(p[0], u), helical(p[0], u, 0.2), prism(u)]),
        ["R.rz", "H.hz", "P.tz"], "RHP", 3, "m(011,011)")
    # RH_sP: spiral pair coaxial with R, translating 0.2 per radian along w ⊥ u; P along w.
    spiral = revolute(p[0], u) + 0.2 * prism(w_perp)
    out["RH_sP"] = (
        np.hstack([revolute(p[0], u), spiral, prism(w_perp)]),
        ["R.rz", "Hs.sz", "P.tz"], "RH_sP", 3, "m(101,110)")
    return out


@pytest.mark.parametrize("name", ["RS_sPC", "RCPP", "4P", "RHP", "RH_sP"])
def test_fig29_general_constraints(name: str) -> None:
    jac, names, pairs, n_links, printed = _fig29()[name]
    r = mobility_from_jacobian(jac, names, inputs=names[0])
    assert r.mobility == 1
    assert r.inputs_determine_motion is True
    # the Jacobian's constraints are Bagci's printed ones, up to relabelling the axes
    assert r.loop_constraints[0].general.same_type(printed)
    f = formula_mobility(n_links, pairs, general_constraints=printed)
    assert (r.malytcheff, r.total_general_constraints, r.mobility) == (
        f.malytcheff, f.total_general_constraints, f.mobility)


def test_fig32_parallelogram_chain() -> None:
    jac, names = parallelogram_chain()
    r = mobility_from_jacobian(jac, names, inputs="G0.rz")
    assert (r.loops, r.rank, r.mobility) == (3, 7, 1)
    f = formula_mobility(6, "8R", general_constraints="m(110,001)", overclosing_constraints=2)
    assert (r.malytcheff, r.total_general_constraints, r.overclosing_constraints) == (
        f.malytcheff, f.total_general_constraints, f.overclosing_constraints)  # −10, 9, 2
    assert all(lc.general.notation == "m(110,001)" for lc in r.loop_constraints)
    assert r.loop_constraints[0].freedoms == ("G0.rz", "G1.rz", "K0.rz", "K1.rz")
    # One crank not parallel to the others: the chain locks (Grübler's −1 is then a rigid
    # structure with 2 instantaneous overclosing constraints fewer).
    bent, _ = parallelogram_chain(last_pin_shift=[0.05, -0.02, 0.0])
    r_bent = mobility_from_jacobian(bent, names)
    assert (r_bent.mobility, r_bent.overclosing_constraints) == (0, 1)


def _transform(jac: np.ndarray, rot: Rotation, shift: np.ndarray) -> np.ndarray:
    """Screws (ω; v) seen from a moved frame: ω' = R ω, v' = R v + p × R ω."""
    out = jac.copy()
    for j in range(jac.shape[0] // 6):
        w = rot.apply(jac[6 * j: 6 * j + 3].T).T
        v = rot.apply(jac[6 * j + 3: 6 * j + 6].T).T + np.cross(shift, w.T).T
        out[6 * j: 6 * j + 3], out[6 * j + 3: 6 * j + 6] = w, v
    return out


@PROFILE
@given(st.sampled_from(sorted(MECHANISMS)), st.integers(0, 2**32 - 1),
       st.floats(1e-3, 1e3))
def test_invariant_under_frame_sign_and_units(name: str, seed: int, unit_factor: float
                                              ) -> None:
    rng = np.random.default_rng(seed)
    jac, names = MECHANISMS[name](rng)
    ref = mobility_from_jacobian(jac, names, inputs=names[0])
    moved = _transform(jac, Rotation.random(random_state=seed), rng.normal(size=3) * 5.0)
    moved *= rng.choice([-1.0, 1.0], size=jac.shape[1])  # joint axis sense is a convention
    moved[3:] *= unit_factor  # new length unit (prism columns rescaled back to unit below)
    prisms = np.linalg.norm(moved[:3], axis=0) < 1e-9
    moved[3:, prisms] /= unit_factor
    r = mobility_from_jacobian(moved, names, inputs=names[0])
    assert (r.rank, r.mobility, r.undetermined_motions) == (
        ref.rank, ref.mobility, ref.undetermined_motions)
    assert r.loop_constraints[0].general == ref.loop_constraints[0].general


def test_characteristic_length_and_units() -> None:
    jac, names, _ = bennett(a=0.25)
    mm = jac.copy()
    mm[3:] *= 1000.0
    assert characteristic_length(mm) == pytest.approx(1000.0 * characteristic_length(jac))
    r_m = mobility_from_jacobian(jac, names)
    r_mm = mobility_from_jacobian(mm, names)
    assert r_mm.length_scale == pytest.approx(1000.0 * r_m.length_scale)
    assert np.allclose(r_mm.singular_values, r_m.singular_values, atol=1e-12)
    # all axes through the origin: no length to take, L = 1
    sph = np.hstack([revolute([0.0, 0.0, 0.0], random_direction(np.random.default_rng(0)))
                     for _ in range(4)])
    assert characteristic_length(sph) == 1.0


def test_jacobian_rank_batch() -> None:
    batch = np.stack([bennett(theta1=np.radians(t))[0] for t in (10.0, 50.0, 120.0)])
    assert jacobian_rank(batch).tolist() == [3, 3, 3]
    rng = np.random.default_rng(10)
    mixed = np.stack([rssr(rng)[0], rssr(rng)[0]])
    assert jacobian_rank(mixed, length_scale=1.0).tolist() == [6, 6]


def test_results_are_json_ready() -> None:
    jac, names = rssr(np.random.default_rng(11))
    r = mobility_from_jacobian(jac, names, inputs="A0.rz", outputs="B0.rz")
    d = json.loads(json.dumps(r.as_dict()))
    assert d["mobility"] == 2 and d["redundant_freedoms"] == 1
    assert np.asarray(d["null_space"]).shape == (8, 2)
    text = r.describe()
    assert "F = 2" in text and "1 redundant freedom(s)" in text


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda j, n: (j[:5], n), r"shape \(6k, m\)"),
        (lambda j, n: (np.where(np.eye(6, 4, dtype=bool), np.nan, j), n), "NaN"),
        (lambda j, n: (j * 2.0, n), "not a unit screw"),
        (lambda j, n: (np.hstack([j, np.zeros((6, 1))]), [*n, "X.rz"]), "zero in every loop"),
        (lambda j, n: (j, n[:3]), "one non-empty name per Jacobian column"),
        (lambda j, n: (j, ["a", "a", "b", "c"]), "repeated: a"),
        (lambda j, n: (np.stack([j, j]), n), "one configuration"),
    ],
)
def test_bad_jacobian(build: object, message: str) -> None:
    jac, names = plane_4r(np.random.default_rng(12))
    bad_jac, bad_names = build(jac, names)  # type: ignore[operator]
    with pytest.raises(MobilityInputError, match=message):
        mobility_from_jacobian(bad_jac, bad_names)


def test_bad_options() -> None:
    jac, names = plane_4r(np.random.default_rng(13))
    with pytest.raises(MobilityInputError, match="neither a freedom nor a pair"):
        mobility_from_jacobian(jac, names, inputs="Z.rz")
    with pytest.raises(MobilityInputError, match="given twice"):
        mobility_from_jacobian(jac, names, inputs=["A0.rz", "A0"])
    with pytest.raises(MobilityInputError, match="give the inputs too"):
        mobility_from_jacobian(jac, names, outputs="B0.rz")
    with pytest.raises(MobilityInputError, match="empty"):
        mobility_from_jacobian(jac, names, inputs=[])
    with pytest.raises(MobilityInputError, match="length_scale"):
        mobility_from_jacobian(jac, names, length_scale=0.0)
    with pytest.raises(MobilityInputError, match="rtol"):
        mobility_from_jacobian(jac, names, rtol=2.0)
    with pytest.raises(MobilityInputError, match="rtol"):
        jacobian_rank(jac, rtol=0.0)


def test_spherical_helper_is_three_rotations() -> None:
    s = spherical([1.0, 2.0, 3.0])
    assert s.shape == (6, 3) and np.allclose(s[:3], np.eye(3))


def test_singular_plane_4r_configurations() -> None:
    ez = [0.0, 0.0, 1.0]
    names = ["A0.rz", "A.rz", "B.rz", "B0.rz"]

    def loop(*points: list[float]) -> np.ndarray:
        return np.hstack([revolute(p, ez) for p in points])

    generic = loop([0, 0, 0], [0.3, 0.4, 0], [1.2, 0.9, 0], [1.0, 0, 0])
    # All four pivots in line (a flattened, change-point configuration): the instantaneous
    # mobility is 2 although the linkage has one freedom.
    flat = loop([0, 0, 0], [0.5, 0, 0], [1.7, 0, 0], [1.0, 0, 0])
    assert jacobian_rank(np.stack([generic, flat])).tolist() == [3, 2]
    r_flat = mobility_from_jacobian(flat, names, inputs="A0.rz")
    assert r_flat.mobility == 2 and r_flat.inputs_determine_motion is False
    # Coupler and rocker in line (A, B, B0 collinear): still one freedom, but the crank cannot
    # drive it — the input is locked at this instant (a transmission dead centre).
    dead = loop([0, 0, 0], [0.3, 0.4, 0], [1.7, -0.4, 0], [1.0, 0, 0])
    r_dead = mobility_from_jacobian(dead, names, inputs="A0.rz")
    assert r_dead.mobility == 1
    assert r_dead.locked_freedoms == ("A0.rz",) and r_dead.independent_inputs == 0
    assert r_dead.inputs_determine_motion is False
