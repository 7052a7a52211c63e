"""The continuation's fill (samples between corrected ones by quintic Hermite interpolation), the
rates found on the way, and the generic solver's bare route (joint variables, rates and
accelerations without link frames): each checked against an independent computation."""

import numpy as np
import pytest

import screwkit.kinematics.tracker.continuation as continuation
from screwkit.io.spec import load_spec
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.branch_fill import quintic_hermite, spherical_end_conditions
from screwkit.kinematics.tracker.branch_merge import same_samples
from screwkit.kinematics.tracker.generic_motion import all_branches, generic_motion
from screwkit.kinematics.tracker.joint_motion import solve_joints
from screwkit.kinematics.tracker.loop import closure_twist, forward, layout
from screwkit.kinematics.tracker.rates import joint_rates, rate_equations, solve_rates
from screwkit.kinematics.tracker.tracks import Track
from screwkit.model import Joint, Linkage
from screwkit.model.families import fourbar, rssr

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
deg = np.radians


def _fig7():
    return load_spec(ROOT / "examples" / "bagci_fig7_rsrc.toml").linkage


def _skew(v):
    z = 0 * v[0]
    return np.array([[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]])


def _right_jacobian(d):
    th = np.sqrt(np.sum(d * d))
    K = _skew(d)
    return np.eye(3) - (1 - np.cos(th)) / th**2 * K + (th - np.sin(th)) / th**3 * (K @ K)


@pytest.mark.parametrize("scale", [1e-6, 1e-4, 1e-2, 0.3, 1.5, 2.5])
def test_ball_joint_end_conditions_invert_the_body_rates(scale):
    # a path δ(t) of R = exp([δ]): body rates ω = J_r(δ) δ' (J_r checked against the rotation
    # matrices' finite differences below) and α = dω/dt by complex step; the end conditions
    # must give back δ' and δ'' exactly
    rng = np.random.default_rng(int(1e6 * scale))
    c0, c1, c2 = rng.normal(size=(3, 3)) * scale

    def delta(t):
        return c0 * t + c1 * t**2 + c2 * np.sin(t)

    def omega(t):
        return _right_jacobian(delta(t)) @ (c0 + 2 * c1 * t + c2 * np.cos(t))

    h = 1e-30
    alpha = np.imag(omega(1.0 + 1j * h)) / h
    v, a = spherical_end_conditions(delta(1.0)[None], np.real(omega(1.0))[None], alpha[None])
    np.testing.assert_allclose(v[0], c0 + 2 * c1 + c2 * np.cos(1.0), atol=1e-14 * max(1, scale))
    np.testing.assert_allclose(a[0], 2 * c1 - c2 * np.sin(1.0), atol=1e-13 * max(1, scale))


def test_right_jacobian_is_the_body_rate_of_the_exponential():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    for _ in range(20):
        d, dd = rng.normal(size=3), rng.normal(size=3)
        h = 1e-6
        R = Rotation.from_rotvec(d).as_matrix()
        Rd = (Rotation.from_rotvec(d + h * dd).as_matrix()
              - Rotation.from_rotvec(d - h * dd).as_matrix()) / (2 * h)
        W = R.T @ Rd
        np.testing.assert_allclose([W[2, 1], W[0, 2], W[1, 0]], _right_jacobian(d) @ dd,
                                   atol=1e-8)


def test_quintic_hermite_reproduces_a_quintic():
    rng = np.random.default_rng(0)
    c = rng.normal(size=6)
    p = np.polynomial.Polynomial(c)
    d1, d2 = p.deriv(), p.deriv(2)
    u = np.linspace(0.0, 1.0, 11)
    H = quintic_hermite(u)
    ends = np.array([p(0), d1(0), d2(0), p(1), d1(1), d2(1)])
    np.testing.assert_allclose(H @ ends, p(u), atol=1e-13)
    np.testing.assert_allclose(H[0], [1, 0, 0, 0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(H[-1], [0, 0, 0, 1, 0, 0], atol=1e-15)


def _loops():
    from test_joint_kinds import _loops as joint_kind_loops  # RSHC, RUSR: H and U joints

    kinds = joint_kind_loops()
    return {"RSRC": _fig7(), "RSSR": rssr(0.025, 0.1, 0.075, 0.075, 0.05, deg(50), 0.0125),
            "RCCC": load_spec(ROOT / "examples" / "rccc_loop.toml").linkage,
            "4R": fourbar(0.1, 0.04, 0.12, 0.09), "RSHC": kinds["RSHC"], "RUSR": kinds["RUSR"]}


@pytest.mark.parametrize("name", ["RSRC", "RSSR", "RCCC", "4R", "RSHC", "RUSR"])
def test_joint_rates_equal_the_full_rate_solution(name):
    # loop_bias (one bracket per joint) against link_twists (one per freedom), every joint kind
    lk = _loops()[name]
    lay = layout(lk)
    m = generic_motion(lk, np.linspace(0.3, 1.2, 30), 1.7, -0.4)
    assert m.modes
    for md in m.modes:
        fr = forward(lk, md.conf, lay)
        eq = rate_equations(lk, lay, fr, md.assembles, exact_sigma=False)
        Xd, Xdd = np.full((30, 1), 1.7), np.full((30, 1), -0.4)
        full = solve_rates(lk, lay, eq, Xd, Xdd)
        bare = joint_rates(lk, lay, eq, md.assembles, Xd, Xdd)
        ok = md.assembles & ~bare.singular
        assert ok.any()
        np.testing.assert_array_equal(bare.singular, md.singular)
        scale = np.max(np.abs(full.qdd[ok]))
        np.testing.assert_allclose(bare.qd[ok], full.qd[ok], rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(bare.qdd[ok], full.qdd[ok], rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("name", ["RSRC", "RSSR", "RCCC", "4R", "RUSR"])
def test_bare_route_equals_the_motion(name):
    # same branches, same poses (an S–S rod's idle spin held), same rates and singular samples
    lk = _loops()[name]
    x = np.linspace(0.0, 2 * np.pi, 2000, endpoint=False)
    m = generic_motion(lk, x, 2.0, 0.5)
    j = solve_joints(lk, x, rates=2.0, accelerations=0.5)
    assert j.modes == len(m.modes)
    lay = layout(lk)
    for k, md in enumerate(m.modes):
        np.testing.assert_array_equal(j.assembles[k], md.assembles)
        np.testing.assert_array_equal(j.singular[k], md.singular)
        held = md.assembles
        np.testing.assert_allclose(j.configurations[k].scalars[held], md.conf.scalars[held],
                                   atol=1e-12)
        np.testing.assert_allclose(j.configurations[k].spherical[held],
                                   md.conf.spherical[held], atol=1e-12)
        ok = held & ~md.singular
        for f, name_f in enumerate(lay.names):
            scale = max(1.0, np.nanmax(np.abs(md.accelerations[name_f][ok])))
            np.testing.assert_allclose(j.rates[k][ok, f], md.velocities[name_f][ok],
                                       atol=1e-12 * scale, err_msg=name_f)
            np.testing.assert_allclose(j.accelerations[k][ok, f],
                                       md.accelerations[name_f][ok], atol=1e-11 * scale,
                                       err_msg=name_f)
        assert np.all(np.isnan(j.rates[k][~ok]))


def _closure(lk, conf):
    fr = forward(lk, conf, layout(lk))
    xi = closure_twist(fr.closure_R, fr.closure_p)
    return np.max(np.abs(xi[:, :3]), axis=1), np.max(np.abs(xi[:, 3:]), axis=1) / lk.length_scale


def test_a_long_sweep_is_filled_and_every_sample_closes_and_satisfies_its_rate_equations():
    lk = _fig7()
    lay = layout(lk)
    N = 40_000
    x = np.linspace(0.0, 2 * np.pi, N, endpoint=False)
    calls = []
    fill = continuation.Tracker._fill

    def counting(self, fills):
        out = fill(self, fills)
        calls.append(sum(len(t) for _, t, *_ in out))
        return out

    continuation.Tracker._fill = counting  # type: ignore[method-assign]
    try:
        j = solve_joints(lk, x, rates=3.0, accelerations=0.0)
    finally:
        continuation.Tracker._fill = fill  # type: ignore[method-assign]
    assert sum(calls) > 0.9 * j.assembles.sum()  # nearly every sample came from the fill
    for k in range(j.modes):
        conf = j.configurations[k]
        rot, tra = _closure(lk, conf)
        held = j.assembles[k]
        # every sample — filled, corrected or a root search's seed — polished to round-off
        assert np.max(rot[held]) < 1e-13 and np.max(tra[held]) < 1e-13
        # J q̇ = 0 with the full Jacobian at the very configuration (independent of the solve)
        fr = forward(lk, conf, lay)
        rows = np.array([1, 1, 1, 1 / lk.length_scale, 1 / lk.length_scale,
                         1 / lk.length_scale])
        cols = np.array([lk.length_scale if t else 1.0 for t in lay.is_translation])
        ok = held & ~j.singular[k]
        J = fr.screws[ok] * rows[:, None] * cols
        qd = j.rates[k][ok] / cols
        res = np.linalg.norm(np.einsum("nij,nj->ni", J, qd), axis=1)
        assert np.max(res / np.linalg.norm(qd, axis=1)) < 1e-9


def test_the_bare_route_equals_the_closed_form():
    lk = _fig7()
    x = np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)
    closed = solve_motion(lk, x, rates=2.0, accelerations=1.0, method="closed")
    j = solve_joints(lk, x, rates=2.0, accelerations=1.0)
    lay = layout(lk)
    assert j.modes == len(closed.modes)
    cols = [lay.names.index(n) for n in ("coupler_R.theta", "output_C.theta", "output_C.s")]
    for md in closed.modes:
        # the generic mode that holds this closed mode at its first sample
        s = int(np.argmax(md.assembles))
        k = min(range(j.modes), key=lambda k: np.inf if not j.assembles[k, s] else np.abs(
            np.angle(np.exp(1j * (j.configurations[k].scalars[s, 1:3]
                                  - md.conf.scalars[s, 1:3])))).max())
        np.testing.assert_array_equal(j.assembles[k], md.assembles)
        ok = md.assembles & ~md.singular
        for c, name in zip(cols, ("coupler_R.theta", "output_C.theta", "output_C.s"),
                           strict=True):
            np.testing.assert_allclose(j.rates[k][ok, c], md.velocities[name][ok], atol=1e-9)
            np.testing.assert_allclose(j.accelerations[k][ok, c], md.accelerations[name][ok],
                                       atol=1e-8)


def test_a_fill_that_does_not_close_falls_back_to_newton(monkeypatch):
    # interpolated samples off the branch by 1e-4 must be corrected, not accepted; samples off
    # by far more (a bad interpolation) make the front take shorter chunks: either way every
    # sample is the branch's
    lk = _fig7()
    x = np.linspace(0.0, 2 * np.pi, 6000, endpoint=False)
    reference = solve_joints(lk, x)
    real = continuation.hermite_increments
    for noise in (1e-4, 0.5):
        def off(*args, noise=noise):
            return real(*args) + noise

        monkeypatch.setattr(continuation, "hermite_increments", off)
        j = solve_joints(lk, x)
        monkeypatch.setattr(continuation, "hermite_increments", real)
        assert j.modes == reference.modes
        for k in range(j.modes):
            np.testing.assert_array_equal(j.assembles[k], reference.assembles[k])
            held = j.assembles[k]
            np.testing.assert_allclose(j.configurations[k].scalars[held],
                                       reference.configurations[k].scalars[held], atol=1e-10)
            np.testing.assert_allclose(j.rates[k][held], reference.rates[k][held], atol=1e-8)


def test_overlapping_tracks_are_compared_sample_by_sample_where_they_meet():
    # two distinct branches, one of which ran onto the other for three samples between two of
    # the strided comparison samples: exactly those samples are found the same
    lk = _fig7()
    lay = layout(lk)
    x = np.linspace(0.0, 2 * np.pi, 3000, endpoint=False)[:, None]
    a, b = all_branches(lk, lay, x, 48, 0, None)
    jumped = Track(b.scalars.copy(), b.spherical.copy(), b.mask.copy(), 0)
    jumped.scalars[1001:1004] = a.scalars[1001:1004]
    jumped.spherical[1001:1004] = a.spherical[1001:1004]
    both = np.nonzero(a.mask & jumped.mask)[0]
    same = same_samples(lk, lay, a, jumped, both)
    np.testing.assert_array_equal(both[same], [1001, 1002, 1003])
    assert same_samples(lk, lay, a, a, both).all()
    assert not same_samples(lk, lay, a, b, both).any()


@pytest.mark.parametrize("family", ["RSSR", "RCCC"])
def test_bare_route_on_long_sweeps_of_loops_with_closed_forms(family):
    # against the closed forms' Motions at 20 000 samples: the fill is used on these too
    lk = _loops()[family]
    x = np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)
    closed = solve_motion(lk, x, method="closed")
    j = solve_joints(lk, x)
    assert j.modes == len(closed.modes)
    assert (j.assembles.sum(axis=0) == sum(md.assembles for md in closed.modes)).all()
    # each closed mode's rates are some generic mode's at every sample outside the fold band
    lay = layout(lk)
    names = [n for n in lay.names if lay.scalar_col[lay.names.index(n)] >= 0]
    for md in closed.modes:
        ok = md.assembles & ~md.singular
        qd = np.stack([md.velocities[n] for n in names], axis=1)
        cols = [lay.names.index(n) for n in names]
        gap = np.min([np.where(j.assembles[k][:, None], np.abs(j.rates[k][:, cols] - qd), np.inf)
                      .max(axis=1) for k in range(j.modes)], axis=0)
        scale = np.maximum(1.0, np.abs(qd).max(axis=1))
        assert np.all((gap / scale)[ok] < 1e-8)


@pytest.mark.parametrize("name", ["RSRC", "RSSR", "RCCC", "RSHC", "RUSR"])
def test_signature_moves_bound_how_far_the_signature_moves(name):
    from screwkit.kinematics.tracker.branch_merge import signature_moves
    from screwkit.kinematics.tracker.solve import signature

    lk = _loops()[name]
    lay = layout(lk)
    x = np.linspace(0.0, 2 * np.pi, 400, endpoint=False)[:, None]
    tracks = all_branches(lk, lay, x, 48, 0, None)
    assert tracks
    for tr in tracks:
        held = np.nonzero(tr.mask)[0]
        bound = signature_moves(lk, lay, tr, held)
        sig = signature(lk, tr.configuration().take(held), lay)
        true = np.max(np.abs(np.diff(sig, axis=0)), axis=1)
        near = np.diff(held) == 1
        assert np.all(true[near] <= bound[near] + 1e-12)
        assert np.all(np.isinf(bound[~near]))
        assert np.median(bound[near] / np.maximum(true[near], 1e-300)) < 100  # not vacuous


def test_joint_motion_names_its_freedoms_and_modes():
    import screwkit as sk
    from screwkit.errors import InputError, UnknownNameError

    lk = _fig7()
    x = np.linspace(0.0, 1.0, 30)
    j = sk.solve_joints(lk, x, rates=2.0)
    m = generic_motion(lk, x, 2.0)
    np.testing.assert_allclose(j.variable("output_C.s", 1), m.modes[1].variables["output_C.s"],
                               atol=1e-12)
    np.testing.assert_allclose(j.variable("sphere.wy", 0, derivative=1),
                               m.modes[0].velocities["sphere.wy"], atol=1e-12)
    with pytest.raises(UnknownNameError, match="the freedoms are"):
        j.variable("phi0")
    with pytest.raises(sk.AssemblyError, match="assembly mode 5"):
        j.variable("output_C.s", 5)
    with pytest.raises(InputError, match="ball joint's body rate"):
        j.variable("sphere.wx")


@pytest.mark.parametrize("family", ["RSRC", "4R", "RSSR", "RCCC"])
def test_long_sweeps_of_random_mechanisms_miss_no_mode_and_match_the_closed_forms(family):
    # the never-miss property test at 20 000 samples, where nearly every sample is filled:
    # the same mode count as the closed form away from the band around folds, every sample
    # closed, and each closed mode's rates some bare-route mode's
    from test_never_miss_a_mode import BAND, _counts, _sigma, _solve, random_linkage

    rng = np.random.default_rng({"RSRC": 11, "4R": 12, "RSSR": 13, "RCCC": 14}[family])
    N = 20_000
    x = np.linspace(0.0, 2 * np.pi, N, endpoint=False)
    checked = 0
    for _ in range(5):
        lk = random_linkage(family, rng)
        closed = _solve(solve_motion, lk, x, method="closed")
        joints = _solve(solve_joints, lk, x)
        if closed is None and joints is None:
            continue
        g = np.zeros(N, dtype=int) if joints is None else joints.assembles.sum(axis=0)
        away = _sigma(closed, N) > BAND
        np.testing.assert_array_equal(g[away], _counts(closed, N)[away])
        if closed is None:
            continue
        checked += 1
        lay = layout(lk)
        for k in range(joints.modes):
            rot, tra = _closure(lk, joints.configurations[k])
            held = joints.assembles[k]
            assert np.max(rot[held]) < 1e-10 and np.max(tra[held]) < 1e-10
        names = [n for n in lay.names if lay.scalar_col[lay.names.index(n)] >= 0
                 and n not in lk.inputs]
        cols = [lay.names.index(n) for n in names]
        for md in closed.modes:
            ok = md.assembles & ~md.singular & away
            qd = np.stack([md.velocities[n] for n in names], axis=1)
            gap = np.min([np.where(joints.assembles[k][:, None],
                                   np.abs(joints.rates[k][:, cols] - qd), np.inf).max(axis=1)
                          for k in range(joints.modes)], axis=0)
            scale = np.maximum(1.0, np.abs(qd).max(axis=1))
            assert np.all((gap / scale)[ok] < 1e-7), np.nanmax((gap / scale)[ok])
    assert checked >= 2


def _rpscr():
    # two inputs, one of them a long slide (≈ 4 length scales): points far from earlier axes
    return Linkage.from_hartenberg_denavit(
        "RPSCR", [Joint("in", "R"), Joint("slide", "P"), Joint("ball", "S"), Joint("cyl", "C"),
                  Joint("out", "R")],
        [0.1, 0.1, 0.2, 0.3, 0.5], [np.pi / 2, 0, 0.3, np.pi / 2, 0],
        inputs=["in.theta", "slide.s"])


def test_signature_moves_count_the_slides_of_the_loop():
    from screwkit.kinematics.tracker.branch_merge import signature_moves
    from screwkit.kinematics.tracker.solve import signature

    lk = _rpscr()
    lay = layout(lk)
    X = np.stack([np.linspace(0.0, 0.5, 100), np.full(100, 5.0)], axis=1)
    tracks = all_branches(lk, lay, X, 48, 0, None)
    assert tracks
    for tr in tracks:
        held = np.nonzero(tr.mask)[0]
        bound = signature_moves(lk, lay, tr, held)
        true = np.abs(np.diff(signature(lk, tr.configuration().take(held), lay), axis=0))
        assert np.all(true.max(axis=1) <= bound)
    # a sample the track does not hold (NaN) in the middle does not shrink the bound
    tr = tracks[0]
    tr.mask[50], tr.scalars[50] = False, np.nan
    held = np.nonzero(tr.mask)[0]
    bound = signature_moves(lk, lay, tr, held)
    true = np.abs(np.diff(signature(lk, tr.configuration().take(held), lay), axis=0))
    near = np.diff(held) == 1
    assert np.all(true.max(axis=1)[near] <= bound[near])


def test_a_two_input_loop_takes_one_rate_for_every_input():
    import screwkit as sk

    lk = _rpscr()
    X = np.stack([np.linspace(0.0, 0.5, 40), np.linspace(4.0, 5.0, 40)], axis=1)
    j = sk.solve_joints(lk, X)  # default rates 1 and accelerations 0, for both inputs
    m = sk.solve_motion(lk, X, rates=1.0)
    assert j.modes == len(m.modes) > 0
    for k, md in enumerate(m.modes):
        ok = md.assembles & ~md.singular
        np.testing.assert_allclose(j.rates[k][ok, 1], md.velocities["slide.s"][ok])
        np.testing.assert_allclose(md.velocities["slide.s"][ok], 1.0)


def test_an_unevenly_sampled_sweep_is_filled_too(monkeypatch):
    # ±30 % jitter in the spacing: the interpolation follows the inputs, so chunks stay long
    lk = _fig7()
    N = 20_000
    x = np.linspace(0.0, 2 * np.pi, N, endpoint=False)
    x += 0.3 * (x[1] - x[0]) * np.random.default_rng(0).uniform(-1, 1, N)
    waves = []
    real = continuation.Tracker._wave

    def counted(self, fronts):
        waves.append(len(fronts))
        return real(self, fronts)

    monkeypatch.setattr(continuation.Tracker, "_wave", counted)
    j = solve_joints(lk, x)
    assert len(waves) < 200
    closed = solve_motion(lk, x, method="closed")
    assert j.modes == len(closed.modes) == 2
    np.testing.assert_array_equal(j.assembles.sum(axis=0),
                                  sum(md.assembles for md in closed.modes))
    lay = layout(lk)
    c = lay.names.index("output_C.s")
    for md in closed.modes:
        ok = md.assembles & ~md.singular
        gap = np.min([np.abs(j.rates[k][:, c] - md.velocities["output_C.s"]) for k in range(2)],
                     axis=0)
        assert np.nanmax(gap[ok]) < 1e-9
