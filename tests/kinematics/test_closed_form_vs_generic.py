"""Second method: the family closed forms equal the generic single-loop solver on every mode."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from screwkit.kinematics.closed_forms.cssp import CSSPDimensions, cssp_motion
from screwkit.kinematics.registry import seed_variables
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model.families import cssp

deg = np.radians


@settings(max_examples=6, deadline=None, derandomize=True)
@given(a1=st.floats(0.03, 0.06), a2=st.floats(0.18, 0.25), a4=st.floats(-0.03, 0.03),
       alpha4=st.floats(deg(200), deg(290)), s1=st.floats(-0.02, 0.02))
def test_cssp_closed_form_equals_generic_solver(a1, a2, a4, alpha4, s1):
    theta = deg(np.arange(0.0, 360.0, 20.0))
    omega, omega_dot = 314.159, 25.0
    lk = cssp(a1, a2, a4, alpha4, s1)
    m = motion(lk, theta, omega, omega_dot)
    dims = CSSPDimensions(a1, a2, a4, alpha4, s1)
    matched = 0
    for mode in (1, -1):
        cf = cssp_motion(dims, theta, omega, omega_dot, root=mode)
        for md in m.modes:
            v, vd, vdd = seed_variables(lk, md)
            if not md.assembles.all() or abs(v["s4"][0] - cf.s4[0]) > 1e-9:
                continue
            matched += 1
            # exact formulas on both sides: agreement to round-off (1e-9 of the natural scale)
            np.testing.assert_allclose(v["s4"], cf.s4, atol=1e-12)
            np.testing.assert_allclose(vd["s4"], cf.s4_dot, atol=1e-9 * omega * a2)
            np.testing.assert_allclose(vdd["s4"], cf.s4_ddot, atol=1e-9 * omega**2 * a2)
            np.testing.assert_allclose(np.cos(v["theta2"]), np.cos(cf.theta2), atol=1e-10)
            np.testing.assert_allclose(v["eta2"], cf.eta2, atol=1e-10)
            np.testing.assert_allclose(vd["eta2"], cf.eta2_dot, atol=1e-9 * omega)
            np.testing.assert_allclose(vdd["theta2"], cf.theta2_ddot, atol=1e-9 * omega**2)
            # the rod's zero-spin angular velocity of the closed form = generic rod angular
            # velocity less its (passive, minimum-norm) spin component along the rod
            u = cf.rod_direction
            w = md.link_angular_velocity[:, 1]
            w_perp = w - np.sum(w * u, axis=-1, keepdims=True) * u
            np.testing.assert_allclose(w_perp, cf.rod_angular_velocity, atol=1e-9 * omega)
    assert matched == 2


def test_rahman_example_range():
    # Rahman example: exact stroke 6.10 … 9.96 in (reference spec §1.2) on the seed's branch
    lk = cssp(2 * 0.0254, 8 * 0.0254, 0.0254, deg(250), 0.4 * 0.0254)
    m = motion(lk, deg(np.arange(0, 360, 2.0)), 314.159, 0.0)
    s4 = max((seed_variables(lk, md)[0]["s4"] for md in m.modes), key=lambda s: np.nanmean(s))
    assert s4.min() / 0.0254 == pytest.approx(6.10, abs=0.01)
    assert s4.max() / 0.0254 == pytest.approx(9.96, abs=0.01)



@settings(max_examples=12, deadline=None, derandomize=True)
@given(d1=st.floats(0.5, 1.5), d2=st.floats(3.0, 5.0), d3=st.floats(1.5, 3.5), a=st.floats(2.0, 4.0),
       b=st.floats(-1.0, 3.0), e=st.floats(-1.0, 1.0), delta0=st.floats(-0.6, 0.6),
       lambda0=st.floats(0.2, 1.3), theta=st.floats(0.0, 6.28))
def test_rsrc_quartic_roots_equal_generic_solver_roots(d1, d2, d3, a, b, e, delta0, lambda0, theta):
    from screwkit.kinematics.closed_forms.rsrc import RSRCDimensions, rsrc_positions
    from screwkit.kinematics.tracker.solve import find_assemblies
    from screwkit.model.families import rsrc, rsrc_seed_variables

    cf = rsrc_positions(RSRCDimensions(d1, d2, d3, a, b, e, delta0, lambda0), np.array([theta]))
    ok = cf.assembles[0]
    closed = np.stack([np.mod(cf.phi0[0][ok], 2 * np.pi), cf.S[0][ok]], -1)
    lk = rsrc(d1, d2, d3, a, b, e, delta0, lambda0)
    asm = find_assemblies(lk, np.array([[theta]]))
    names = ["input.theta", "coupler_R.theta", "output_C.theta", "output_C.s"]
    generic = []
    for k in np.nonzero(asm.found[0])[0]:
        sv = rsrc_seed_variables({n: asm.conf.scalars[k, i] for i, n in enumerate(names)})
        generic.append((np.mod(sv["phi0"], 2 * np.pi), sv["S"]))

    def dist(p, q):
        return max(abs(np.angle(np.exp(1j * (p[0] - q[0])))), abs(p[1] - q[1]))

    # a double root (limit position) is one configuration: the generic solver returns it once,
    # and only to ~√(closure tolerance) because the closure is quadratic there
    double = [any(dist(c, o) < 1e-6 for j, o in enumerate(closed) if j != i) for i, c in enumerate(closed)]
    for i, c in enumerate(closed):
        tol = 1e-4 if double[i] else 1e-8
        assert any(dist(c, g) < tol for g in generic), (c, generic)
    for g in generic:
        assert any(dist(g, c) < 1e-4 for c in closed), (g, closed)
