"""Singularities classified along a graph's motion (graph/singular.py): dead centres of a
four-bar at the closed-form limits of its input, a Stewart platform's output singularity where
the six leg lines become dependent (an independent determinant), a Delta robot's input
singularity with an arm and its rods in line, and the condition numbers against an SVD of a
finite-difference Jacobian of the loop residuals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.motion import build_mode
from screwkit.kinematics.graph.newton import column_scale, row_scale
from screwkit.kinematics.modes.stewart_decode import decode_poses, stewart_formulation
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
Z = np.array([0.0, 0.0, 1.0])
# a non-Grashof four-bar (s + l = 3.5 < p + q = 3.7): the crank turns between two limits
A_, B_, C_, D_ = 2.2, 1.0, 1.5, 2.5
DRAWN = np.radians(35.0)


def _fourbar() -> Mechanism:
    Bp = A_ * np.array([np.cos(DRAWN), np.sin(DRAWN), 0.0])
    Dp = np.array([D_, 0.0, 0.0])
    e = np.linalg.norm(Dp - Bp)
    along = (e**2 + B_**2 - C_**2) / (2 * e)  # C from B along BD, then across it
    u = (Dp - Bp) / e
    Cp = Bp + along * u + np.sqrt(B_**2 - along**2) * np.cross(Z, u)

    def j(name: str, a: str, b: str, at: np.ndarray) -> MechanismJoint:
        return MechanismJoint(name, "R", (a, b), np.asarray(at, dtype=float), Z)

    return Mechanism("non-Grashof four-bar", (Body("crank"), Body("coupler"), Body("rocker")),
                     (j("A", "ground", "crank", np.zeros(3)), j("B", "crank", "coupler", Bp),
                      j("C", "coupler", "rocker", Cp), j("D", "rocker", "ground", Dp)),
                     ("A.theta",))


def _limits() -> list[float]:
    """The crank angles where coupler and rocker fall in line (|BD| = b + c or |b − c|), by
    the law of cosines."""
    return [float(np.arccos((A_**2 + D_**2 - r**2) / (2 * A_ * D_))) for r in (B_ + C_, C_ - B_)]


def _fd_condition(mech: Mechanism, conf: Configuration, passive_only: bool) -> np.ndarray:
    """σ₁/σ_r of the scaled finite-difference Jacobian of the loop residuals (central
    differences over every scalar freedom; r = 3 for a planar loop's three rotations)."""
    lay = graph_layout(mech)
    h = 1e-6
    cols = []
    for f in range(lay.m):
        plus, minus = conf.scalars.copy(), conf.scalars.copy()
        plus[:, f] += h
        minus[:, f] -= h
        rp = graph_forward(mech, lay, Configuration(plus, conf.spherical)).residual
        rm = graph_forward(mech, lay, Configuration(minus, conf.spherical)).residual
        cols.append(((rp - rm) / (2 * h)).reshape(conf.size, -1))
    J = np.stack(cols, axis=2) * row_scale(lay, 1)[None, :, None] * column_scale(lay)
    if passive_only:
        J = J[:, :, list(lay.passive)]
    s = np.linalg.svd(J, compute_uv=False)
    return s[:, 0] / s[:, 2]


def _about(q: np.ndarray, phi: float) -> tuple[np.ndarray, np.ndarray]:
    """The pose turning the plane by φ about the point q (R, q − R q), one sample."""
    c, s = np.cos(phi), np.sin(phi)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return R[None], (q - R @ q)[None]


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arctan2(np.cross(a, b)[2], a @ b))


def _at_limit(mech: Mechanism, theta: float, stretched: bool) -> Configuration:
    """The four-bar at crank angle θ (from the x axis) with coupler and rocker in line, from
    the geometry alone (C on the line BD, |BC| = b), decoded into joint variables."""
    from screwkit.kinematics.modes.stewart_decode import joint_values

    A0, B0, C0, D0 = (j.at for j in mech.joints)
    B = A_ * np.array([np.cos(theta), np.sin(theta), 0.0])
    u = (D0 - B) / np.linalg.norm(D0 - B)
    C = B + B_ * u if stretched else B - B_ * u
    crank = _about(A0, theta - DRAWN)
    Rk, pk = crank
    coupler_R = _about(np.zeros(3), _angle(C0 - B0, C - B))[0]
    coupler = (coupler_R, (B - coupler_R[0] @ B0)[None])
    rocker = _about(D0, _angle(C0 - D0, C - D0))
    return joint_values(mech, graph_layout(mech), {"crank": (Rk, pk), "coupler": coupler,
                                                   "rocker": rocker})


def test_four_bar_dead_centres_at_the_closed_form_limits_of_the_crank() -> None:
    mech = _fourbar()
    lay = graph_layout(mech)
    hi, lo = _limits()
    # the crank's two limits by the law of cosines: the configurations there from geometry
    limits = [_at_limit(mech, hi, True), _at_limit(mech, lo, False)]
    conf = Configuration(np.concatenate([c.scalars for c in limits]),
                         np.concatenate([c.spherical for c in limits]))
    assert np.abs(graph_forward(mech, lay, conf).residual).max() < 1e-12
    X = np.array([[hi - DRAWN], [lo - DRAWN]])
    np.testing.assert_allclose(conf.scalars[:, lay.scalar_col[lay.inputs[0]]], X[:, 0],
                               atol=1e-12)
    md = build_mode(mech, lay, conf, np.ones(2, dtype=bool), X, np.ones_like(X),
                    np.zeros_like(X))
    # dead centres: the rocker and coupler in line, the whole Jacobian keeps its rank
    assert md.singular_class.tolist() == ["dead centre", "dead centre"]
    assert md.singular.all()
    assert np.all(md.jacobian_condition["passive"] > 1e7)
    assert np.all(md.jacobian_condition["closure"] < 1e3)
    assert any(e.startswith("singular at A.theta") and "dead centre of loop 1" in e
               for e in md.events)
    # in between, along both modes of the closed form: regular, the condition numbers those
    # of an independent SVD of a finite-difference Jacobian, growing towards the limits
    m = solve_mechanism(mech, np.linspace(lo + 1e-3, hi - 1e-3, 41) - DRAWN, every_mode=True)
    assert len(m.modes) == 2
    for md in m.modes:
        assert md.assembles.all() and set(md.singular_class) == {""}
        assert not md.singular.any()
        np.testing.assert_allclose(md.jacobian_condition["passive"],
                                   _fd_condition(mech, md.conf, True), rtol=1e-5)
        np.testing.assert_allclose(md.jacobian_condition["closure"],
                                   _fd_condition(mech, md.conf, False), rtol=1e-5)
        c = md.jacobian_condition["passive"]
        assert min(c[0], c[-1]) > 10 * c.min()


def _leg_lines(sm, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The six leg lines (u, p × u) as rows: the classic Stewart Jacobian (Merlet)."""
    p = sm.top @ R.T + t
    u = p - sm.base
    u /= np.linalg.norm(u, axis=1)[:, None]
    return np.concatenate([u, np.cross(p, u)], axis=1)


def _turned(psi: float, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(psi), np.sin(psi)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return R, centre - R @ centre


def test_stewart_output_singularity_where_the_leg_lines_are_dependent() -> None:
    spec = sk.load_spec(EXAMPLES / "stewart_platform.toml")
    mech = spec.mechanism
    sm = stewart_formulation(mech).stewart
    lay = graph_layout(mech)
    centre = np.array([0.0, 0.0, 0.4])

    def det(psi: float) -> float:
        return float(np.linalg.det(_leg_lines(sm, *_turned(psi, centre))))

    grid = np.radians(np.arange(0.0, 180.0, 1.0))
    values = np.array([det(x) for x in grid])
    k = int(np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0])
    star = brentq(det, grid[k], grid[k + 1], xtol=1e-15)
    psis = np.array([star - 0.05, star, star + 0.05])
    confs, X = [], []
    for psi in psis:
        R, t = _turned(psi, centre)
        L = np.linalg.norm(sm.top @ R.T + t - sm.base, axis=1)
        x = np.zeros(6)
        x[list(sm.input_columns)] = L - np.linalg.norm(sm.top - sm.base, axis=1)
        confs.append(decode_poses(sm, R[None], t[None], x))
        X.append(x)
    conf = Configuration(np.concatenate([c.scalars for c in confs]),
                         np.concatenate([c.spherical for c in confs]))
    assert np.abs(graph_forward(mech, lay, conf).residual).max() < 1e-12
    X = np.array(X)
    md = build_mode(mech, lay, conf, np.ones(3, dtype=bool), X, np.zeros_like(X),
                    np.zeros_like(X))
    assert md.singular_class.tolist() == ["", "output", ""]
    assert md.singular.tolist() == [False, True, False]
    cond = md.jacobian_condition
    assert cond["passive"][1] > 1e7 and max(cond["passive"][[0, 2]]) < 1e4
    assert cond["closure"][1] < 1e4  # the constraints keep their rank: not a constraint one
    assert any("output singularity (parallel, type II)" in e for e in md.events)
    # away from it, the passive block is as ill-conditioned as the leg lines are
    # (the same singularity, two different matrices: both finite, both blow up at ψ*)
    lines = [np.linalg.cond(_leg_lines(sm, *_turned(p, centre))) for p in psis]
    assert lines[1] > 1e10 and max(lines[0], lines[2]) < 1e4


def test_stewart_conditions_hold_along_the_bundled_motion() -> None:
    spec = sk.load_spec(EXAMPLES / "stewart_platform.toml")
    md = solve_mechanism(spec.mechanism, spec.inputs[:12]).modes[0]
    for name in ("passive", "closure", "platform_held"):
        c = md.jacobian_condition[name]
        assert c.shape == (12,) and np.all(np.isfinite(c)) and np.all(c >= 1.0)
    assert set(md.singular_class) == {""}


def _rot(a: np.ndarray, th: float) -> np.ndarray:
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


def _delta_at(mech: Mechanism, thetas: list[float], t: np.ndarray) -> Configuration:
    """The Delta robot with arm k turned by θ_k and the plate translated by t, decoded into
    joint variables (each rod turned by the least rotation onto its new direction)."""
    from screwkit.kinematics.modes.rod_loops import least_rotation
    from screwkit.kinematics.modes.stewart_decode import joint_values

    J = {j.name: j for j in mech.joints}
    poses = {"plate": (np.eye(3)[None], t[None])}
    for k, th in enumerate(thetas, start=1):
        sh = J[f"R{k}"]
        R = _rot(sh.axis, th)
        poses[f"arm{k}"] = (R[None], (sh.at - R @ sh.at)[None])
        for side in "ab":
            E0, P0 = J[f"E{k}{side}"].at, J[f"P{k}{side}"].at
            E = sh.at + R @ (E0 - sh.at)
            Rr = least_rotation(P0 - E0, (P0 + t - E)[None])
            poses[f"rod{k}{side}"] = (Rr, (E - Rr[0] @ E0)[None])
    return joint_values(mech, graph_layout(mech), poses)


def _arm_angle(mech: Mechanism, k: int, t: np.ndarray) -> float | None:
    """Arm k's angle (nearer the drawing) that reaches the plate at t: |E(θ) − P| = ℓ is
    A cos θ + B sin θ = C."""
    J = {j.name: j for j in mech.joints}
    sh, E0, P0 = J[f"R{k}"], J[f"E{k}a"].at, J[f"P{k}a"].at
    a, ell = sh.axis, np.linalg.norm(E0 - P0)
    v = E0 - sh.at
    c, r = (v @ a) * a, v - (v @ a) * a
    q = P0 + t - sh.at
    A, B = 2 * r @ (c - q), 2 * np.cross(a, r) @ (c - q)
    C = ell**2 - (c - q) @ (c - q) - r @ r
    rho = np.hypot(A, B)
    if abs(C) > rho:
        return None
    roots = np.arctan2(B, A) + np.array([1, -1]) * np.arccos(C / rho)
    roots = np.angle(np.exp(1j * roots))
    return float(roots[np.argmin(np.abs(roots))])


def test_delta_input_singularity_with_an_arm_and_its_rods_in_line() -> None:
    spec = sk.load_spec(EXAMPLES / "delta_robot.toml")
    mech = spec.mechanism
    lay = graph_layout(mech)
    J = {j.name: j for j in mech.joints}
    sh, E0, P0 = J["R1"], J["E1a"].at, J["P1a"].at
    a, ell = sh.axis, np.linalg.norm(E0 - P0)
    r0 = (E0 - sh.at) - ((E0 - sh.at) @ a) * a
    best = None
    for th in np.radians(np.arange(-180.0, 180.0, 0.5)):  # arm 1 straight along its rods
        E = sh.at + _rot(a, th) @ (E0 - sh.at)
        t = E + ell * (_rot(a, th) @ r0) / np.linalg.norm(r0) - P0
        others = [_arm_angle(mech, k, t) for k in (2, 3)]
        if all(o is not None for o in others):
            best = (th, others, t)
            break
    assert best is not None
    th, (t2, t3), t = best
    straight = _delta_at(mech, [th, t2, t3], t)
    # a regular pose nearby: arm 1 bent back 0.1 rad, the plate where all three arms reach
    t_in = t + 0.05 * (sh.at - t - P0) / np.linalg.norm(sh.at - t - P0)
    bent = [_arm_angle(mech, k, t_in) for k in (1, 2, 3)]
    assert all(b is not None for b in bent)
    regular = _delta_at(mech, bent, t_in)  # type: ignore[arg-type]
    conf = Configuration(np.concatenate([straight.scalars, regular.scalars]),
                         np.concatenate([straight.spherical, regular.spherical]))
    assert np.abs(graph_forward(mech, lay, conf).residual).max() < 1e-12
    X = conf.scalars[:, [lay.scalar_col[f] for f in lay.inputs]]
    md = build_mode(mech, lay, conf, np.ones(2, dtype=bool), X, np.zeros_like(X),
                    np.zeros_like(X))
    assert md.singular_class.tolist() == ["input", ""]
    assert not md.singular.any()  # the forward rates exist at an input singularity
    cond = md.jacobian_condition
    assert cond["platform_held"][0] > 1e7 > 1e3 > cond["platform_held"][1]
    assert max(cond["passive"]) < 1e4
    assert any("input singularity (serial, type I): R1.theta" in e for e in md.events)
    # along the bundled motion: regular throughout
    m = solve_mechanism(mech, spec.inputs[:10]).modes[0]
    assert set(m.singular_class) == {""} and np.all(m.jacobian_condition["platform_held"] < 1e4)
