"""The generic single-loop solver: closure, every assembly mode, derivatives, and agreement with
the worked values of Bagci's Fig. 7/8 mechanism (reference spec §3.6)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.kinematics.motion import AssemblyError
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.kinematics.tracker.solve import find_assemblies
from screwkit.model.families import cssp, fourbar, rccc, rsrc, rsrc_seed_variables, rssr

deg = np.radians


def test_rsrc_fig7_worked_values_both_modes():
    # Bagci 1969 Fig. 7/8 mechanism; values at θ0 = 100°, θ̇0 = 1 (reference spec §3.6,
    # recomputed there from the closed form and finite differences, 6 decimals).
    lk = rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60))
    m = motion(lk, deg(np.array([100.0, 100.5])), 1.0, 0.0)
    got = []
    for md in m.modes:
        v = rsrc_seed_variables(md.variables)
        w = rsrc_seed_variables(md.velocities)
        a = rsrc_seed_variables(md.accelerations)
        got.append(
            (
                np.degrees(v["phi0"][0]),
                np.degrees(v["chi0"][0]),
                v["S"][0],
                w["phi0"][0],
                w["S"][0],
                a["phi0"][0],
                a["S"][0],
            )
        )
    got.sort()
    expected = sorted(
        [
            (119.797172, 52.545308, 3.052906, 0.402247, -0.849736, 0.310773, -1.328912),
            (-81.030575, -64.626507, 5.413226, -0.759859, 0.075582, 0.629419, -2.148684),
        ]
    )
    for g, e in zip(got, expected, strict=True):
        # print precision of the reference: 6 decimals
        np.testing.assert_allclose(g, e, atol=6e-6)
    # the second-to-last chi0 velocity of root A (reference: 0.649163)
    ra = [md for md in m.modes if rsrc_seed_variables(md.variables)["phi0"][0] > 0][0]
    assert abs(rsrc_seed_variables(ra.velocities)["chi0"][0] - 0.649163) < 6e-7


FAMILIES = {
    "rsrc": lambda: rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60)),
    "rssr": lambda: rssr(1.0, 4.0, 3.0, 3.0, 2.0, deg(50), 0.5),
    "cssp": lambda: cssp(0.0508, 0.2032, 0.0254, deg(250), 0.01016),
    "fourbar": lambda: fourbar(3.0, 1.0, 3.0, 2.5),
}


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_velocity_and_acceleration_are_derivatives_of_position(family):
    lk = FAMILIES[family]()
    h = 1e-3
    t0 = deg(37.0)
    th = t0 + h * np.arange(-2, 3)
    m = motion(lk, th, 1.0, 0.0)
    assert m.modes
    for md in m.modes:
        assert md.assembles.all()
        # joint centres are invariant to passive spin: differentiate them (5-point stencil)
        c = md.joint_centres
        vel_fd = (c[0] - 8 * c[1] + 8 * c[3] - c[4]) / (12 * h)
        # velocity of each joint centre from link twists: centre of joint i+1 moves with link i
        L = md.link_origin.shape[1]
        for i in range(L):
            p = c[2, i + 1]
            v = md.link_origin_velocity[2, i] + np.cross(
                md.link_angular_velocity[2, i], p - md.link_origin[2, i]
            )
            # O(h^4) stencil error on O(1) quantities: 1e-8 is ~100x the truncation error
            np.testing.assert_allclose(v, vel_fd[i + 1], atol=1e-8 * lk.length_scale / 0.05)
        # link angular velocity vs rotation matrix derivative for links without passive spin
        om = md.link_origin_velocity
        acc_fd = (-om[0] + 16 * om[1] - 30 * om[2] + 16 * om[3] - om[4]) / (12 * h * h)
        del acc_fd
        # origin velocity/acceleration consistency: a = d v / dt along the sweep
        v_o = md.link_origin_velocity
        a_fd = (v_o[0] - 8 * v_o[1] + 8 * v_o[3] - v_o[4]) / (12 * h)
        scale = max(1.0, float(np.abs(md.link_origin_acceleration[2]).max()))
        spin_free = [
            i
            for i, j in enumerate(lk.joints[:-1])
            if not (j.kind == "S" and lk.joints[i + 1].kind == "S")
        ]
        np.testing.assert_allclose(
            md.link_origin_acceleration[2, spin_free], a_fd[spin_free], atol=1e-6 * scale
        )
        assert np.nanmax(md.closure_residual) < 1e-10


def test_every_assembly_mode_of_a_fourbar_is_found_and_tracked():
    m = motion(fourbar(3.0, 1.0, 3.0, 2.5), deg(np.arange(0, 360, 5.0)))
    assert len(m.modes) == 2  # crank-rocker: two assembly modes, full rotation each
    for md in m.modes:
        assert md.assembles.all() and not md.events
        # continuity: the unwrapped output angle moves by less than 10° per 5° step
        assert np.max(np.abs(np.diff(md.variables["output.theta"]))) < deg(10)


def test_non_grashof_fourbar_reports_where_it_stops():
    # triple rocker: crank cannot turn fully; branches stop at limit positions
    m = motion(fourbar(2.0, 1.8, 2.2, 1.5), deg(np.arange(0, 360, 6.0)))
    assert any(any("stops assembling" in e for e in md.events) for md in m.modes)
    covered = np.any([md.assembles for md in m.modes], axis=0)
    assert covered.any() and not covered.all()


def test_never_assembles_gives_clear_error():
    with pytest.raises(AssemblyError, match="does not close"):
        motion(fourbar(10.0, 1.0, 1.0, 1.0), deg(np.arange(0, 360, 30.0)))


@settings(max_examples=12, deadline=None, derandomize=True)
@given(
    d1=st.floats(0.5, 1.5),
    d2=st.floats(3.0, 5.0),
    d3=st.floats(1.5, 3.5),
    a=st.floats(2.0, 4.0),
    b=st.floats(-1.0, 3.0),
    e=st.floats(-1.0, 1.0),
    delta0=st.floats(-0.6, 0.6),
    lambda0=st.floats(0.2, 1.3),
    theta=st.floats(0.0, 6.28),
)
def test_random_rsrc_closes_in_every_mode(d1, d2, d3, a, b, e, delta0, lambda0, theta):
    lk = rsrc(d1, d2, d3, a, b, e, delta0, lambda0)
    asm = find_assemblies(lk, np.array([[theta]]))
    for k in np.nonzero(asm.found[0])[0]:
        from screwkit.kinematics.tracker.loop import closure_twist, forward

        fr = forward(lk, asm.conf.take(np.array([k])))
        assert np.abs(closure_twist(fr.closure_R, fr.closure_p)).max() < 1e-10 * max(
            1.0, lk.length_scale
        )
        # the master position loop of Bagci (reference spec §3.1) closes with the seed variables
        v = {
            n: asm.conf.scalars[k, i]
            for i, n in enumerate(
                ["input.theta", "coupler_R.theta", "output_C.theta", "output_C.s"]
            )
        }
        sv = rsrc_seed_variables(v)
        _master_loop_closes(d1, d2, d3, a, b, e, delta0, lambda0, sv)
    assert asm.found.sum() <= 4


def _master_loop_closes(d1, d2, d3, a, b, e, delta0, lambda0, sv):
    def Ry(t):
        return np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])

    def Rx(t):
        return np.array([[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])

    e1, e2 = np.eye(3)[0], np.eye(3)[1]
    th, phi, S, chi = sv["theta0"], sv["phi0"], sv["S"], sv["chi0"]
    lhs = np.array([0.0, d1 * np.cos(th), d1 * np.sin(th)])
    rhs = np.array([b, a, 0.0]) + Ry(lambda0) @ (
        -S * e1 + Rx(phi) @ (d3 * e2 + Ry(-delta0) @ (e * e1 - d2 * Rx(-chi) @ e2))
    )
    np.testing.assert_allclose(lhs, rhs, atol=1e-9)


def test_rccc_modes_close():
    lk = rccc((1.0, 3.0, 2.5, 3.0), (0.3, 0.2, -0.4, 0.5))
    m = motion(lk, deg(np.arange(90, 180, 10.0)))
    for md in m.modes:
        assert np.nanmax(md.closure_residual[md.assembles]) < 1e-10


def test_bad_input_shapes():
    lk = fourbar(3.0, 1.0, 3.0, 2.5)
    with pytest.raises(ValueError, match="finite"):
        motion(lk, [0.0, np.nan])


def test_long_sweeps_are_accepted_and_report_progress():
    # the old solver refused more than 20 000 samples; continuation costs ~tens of µs a sample
    calls = []
    n = 20_001
    m = motion(fourbar(3.0, 1.0, 3.0, 2.5), np.linspace(0.0, 2 * np.pi, n),
               progress=lambda done, total: calls.append((done, total)))
    assert len(m.modes) == 2 and all(md.assembles.all() for md in m.modes)
    done, total = calls[-1]
    # every sample of both modes followed (counted once), then both modes built
    assert done == total == 2 * n + 2 * n
    assert any(c == (2 * n, 2 * n) for c in calls)  # the end of the following
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:], strict=False))


@pytest.mark.parametrize("family", ["RSRC", "RSSR"])
def test_a_closed_form_reports_its_build_as_it_goes(family, monkeypatch):
    # a closed form's Motion is nearly all build (frames, rates, idle spin): each mode reports
    # its stages, so a 10⁶-sample run's bar moves instead of jumping to the end
    from screwkit.kinematics.solve_motion import solve_motion

    lk = (rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60)) if family == "RSRC"
          else rssr(1.0, 4.0, 2.5, 3.0, 1.0, 0.6, 0.2))
    n = 500
    calls = []
    m = solve_motion(lk, np.linspace(0.0, 2 * np.pi, n), method="closed",
                     progress=lambda done, total: calls.append((done, total)))
    k = len(m.modes)
    assert k >= 2 and calls[-1] == (k * n, k * n)
    assert len(calls) >= 5 * k  # stages of every mode, not one call at the end
    assert all(a[0] <= b[0] and a[1] <= b[1] for a, b in zip(calls, calls[1:], strict=False))
    assert all(0 <= d <= t for d, t in calls)
    # on a terminal, with no callback, a long sweep shows the bar (rich, on stderr)
    import screwkit.kinematics.tracker.generic_motion as gm

    monkeypatch.setattr(gm, "PROGRESS_SAMPLES", 100)
    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    shown = []
    from rich.progress import Progress as Bar

    monkeypatch.setattr(Bar, "update", lambda self, task, **kw: shown.append(kw["completed"]))
    solve_motion(lk, np.linspace(0.0, 2 * np.pi, n), method="closed")
    assert len(shown) >= 5 * k and shown[-1] == k * n


def test_build_progress_counts_only_modes_built():
    from screwkit.kinematics.tracker.mode_frames import _built, build_progress, expect_modes

    calls = []
    with build_progress(lambda d, t: calls.append((d, t)), 10):
        expect_modes(0)  # a closed form with nothing to build says so, and is not a mode
        assert calls == []
        expect_modes(2)
        _built(0.0)
        _built(1.0)
        _built(0.0)
        _built(0.5)
    assert calls == [(0, 20), (10, 20), (10, 20), (15, 20)]
    _built(0.0)  # outside the context nothing is reported
    assert len(calls) == 4


def test_a_layout_reused_for_other_dimensions_reads_their_link_transforms():
    # a layout caches its linkage's link transforms for the hot paths; reused for a loop with
    # the same joints and other dimensions (a synthesis trial), it must not apply the old ones
    from screwkit.kinematics.tracker.loop import Configuration, forward, layout

    a = rsrc(2, 4.5, 3, 3, 3, 1, deg(18), deg(60))
    b = rsrc(2.5, 4.0, 3, 3.5, 3, 1, deg(18), deg(60))
    lay = layout(a)
    rng = np.random.default_rng(0)
    conf = Configuration(rng.uniform(-3, 3, (5, lay.n_scalar)),
                         np.tile(np.eye(3), (5, lay.n_spherical, 1, 1)))
    reused, fresh = forward(b, conf, lay), forward(b, conf, layout(b))
    np.testing.assert_allclose(reused.closure_p, fresh.closure_p, atol=1e-15)
    np.testing.assert_allclose(reused.centres, fresh.centres, atol=1e-15)
    assert not np.allclose(forward(a, conf, lay).centres, fresh.centres)
