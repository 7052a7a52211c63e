"""The point formulation of spatial R/S/U graphs (modes/spatial_points.py, issue 27), checked
against second methods: the closed forms (RSSR roots, the double wishbone's dyads), the Delta
robot's Study-coordinate formulation and, for a platform no closed form takes (the five-link
suspension), the Stewart–Gough elimination template on the same six rods. Every kept mode also
closes every loop of the graph tracker's own closure (exact SE(3) logarithm), independent of the
polynomials."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

import screwkit as sk
from screwkit.algebraic.solve import solve_all
from screwkit.errors import CapabilityError
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation
from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation
from screwkit.kinematics.modes.stewart import pose_from_study, stewart_parameters
from screwkit.kinematics.modes.stewart_solve import solve_stewart
from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

MECHANISMS = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


def joint(name: str, kind: str, a: str, b: str, at: object,
          axis: object = (0.0, 0.0, 1.0), axis2: object = None) -> MechanismJoint:
    return MechanismJoint(name, kind, (a, b), np.asarray(at, float), np.asarray(axis, float),
                          None if axis2 is None else np.asarray(axis2, float))


def _random_rssr(rng: np.random.Generator) -> Mechanism:
    """A spatial RSSR: random axes and ball centres, a short crank (every drawing closes)."""
    O, A, B, D = (rng.uniform(-1.0, 1.0, 3) for _ in range(4))
    A = O + 0.3 * (A - O) / np.linalg.norm(A - O)
    return Mechanism("random RSSR", (Body("crank"), Body("rod"), Body("rocker")),
                     (joint("O", "R", "ground", "crank", O, rng.normal(size=3)),
                      joint("A", "S", "crank", "rod", A),
                      joint("B", "S", "rod", "rocker", B),
                      joint("D", "R", "rocker", "ground", D, rng.normal(size=3))), ("O.theta",))


def _centres(mech: Mechanism, conf: object) -> np.ndarray:
    return graph_forward(mech, graph_layout(mech), conf).centres  # type: ignore[arg-type]


def _matched(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Every row of a (M, ...) is within tol of a row of b, and the counts are equal."""
    if len(a) != len(b):
        return False
    return all(np.abs(b - x).reshape(len(b), -1).max(1).min() <= tol for x in a)


def test_200_random_rssrs_point_modes_are_the_closed_form_modes() -> None:
    """Issue 27's check "RSSR: 2" on 200 seeded random RSSRs, by the point formulation in one
    batched parameter homotopy, each instance's real modes the closed form's (the rod-loop
    formulation: the RSSR's quadratic), joint centres to 1e-9 of the length scale."""
    rng = np.random.default_rng(2031)
    mechs = [_random_rssr(rng) for _ in range(200)]
    forms = [spatial_point_formulation(m) for m in mechs]
    assert len({f.system.n for f in forms}) == 1 and forms[0].system.n == 3
    theta = rng.uniform(-np.pi, np.pi, 200)
    P = np.vstack([f.parameters([[t]]) for f, t in zip(forms, theta, strict=True)])
    start = forms[0].start()
    assert start.generic_count == 2
    sol = solve_all(forms[0].system, P, start)
    complete = int(np.count_nonzero(sol.found == 2))
    assert complete >= 198, f"{200 - complete} of 200 instances short of 2 solutions"
    agree = 0
    for b, (m, f) in enumerate(zip(mechs, forms, strict=True)):
        rows = np.flatnonzero((sol.instance == b) & sol.real)
        closed = every_mode(m, [[theta[b]]])  # the RSSR's own (rod-loop) formulation
        assert closure_formulation(m).__class__ is not SpatialPointFormulation
        ours = np.zeros((0, 4, 3)) if rows.size == 0 else \
            _centres(m, f.configuration(sol.x[rows], [theta[b]])[0])
        theirs = np.zeros((0, 4, 3)) if closed.configurations[0].size == 0 else \
            _centres(m, closed.configurations[0])
        agree += _matched(ours, theirs, 1e-9 * m.length_scale)
    assert agree >= 198


def _perturbed_wishbone(rng: np.random.Generator) -> Mechanism:
    """The bundled double wishbone, every hardpoint moved by up to 5 % of its size."""
    mech = sk.load_spec(MECHANISMS / "double_wishbone.toml").mechanism
    L = mech.length_scale
    joints = tuple(MechanismJoint(j.name, j.kind, j.bodies,
                                  j.at + rng.uniform(-0.05, 0.05, 3) * L, j.axis)
                   for j in mech.joints)
    return Mechanism("random wishbone", mech.bodies, joints, mech.inputs)


def test_double_wishbones_point_modes_are_the_closed_form_dyads_modes() -> None:
    """Twelve perturbed double wishbones at five lower-arm angles each: the homotopy on the
    point formulation finds 4 complex solutions (2 upper-ball circles × 2 tie-rod ends), its
    real modes certified, closing to 1e-10, and they are exactly the closed-form modes of the
    graph's dyads (RSS and SS, graph/subchains.py)."""
    rng = np.random.default_rng(2032)
    x = np.radians(np.linspace(-10.0, 10.0, 5))
    for _ in range(12):
        mech = _perturbed_wishbone(rng)
        form = closure_formulation(mech)
        assert isinstance(form, SpatialPointFormulation)
        found = every_mode(mech, x[:, None])
        assert found.generic_count == 4 and (found.found == 4).all()
        assert found.worst_closure <= 1e-10 * mech.length_scale
        closed = solve_mechanism(mech, x, every_mode=True)
        assert closed.method == "graph (closed forms)"
        for n in range(x.size):
            assert found.certified[n].all()
            theirs = np.array([md.joint_centres[n] for md in closed.modes if md.assembles[n]])
            ours = _centres(mech, found.configurations[n])
            assert _matched(ours, theirs.reshape(len(theirs), -1, 3), 1e-9 * mech.length_scale)


def test_the_delta_robot_by_points_has_the_modes_of_its_study_formulation() -> None:
    """The Delta robot read as points (its plate held by six S–S rods: a 6-6 platform, 40
    complex solutions by monodromy) against its own formulation (modes/delta.py: the Study
    system with the elbow balls as base points): the same 16 plate poses at two inputs."""
    mech = sk.load_spec(MECHANISMS / "delta_robot.toml").mechanism
    form = spatial_point_formulation(mech)
    assert form.system.n == 18 and form.start().generic_count == 40
    X = np.array([[0.0, 0.0, 0.0], [0.2, -0.1, 0.05]])
    own = every_mode(mech, X)
    sol = solve_all(form.system, form.parameters(X), form.start())
    for b in range(2):
        rows = np.flatnonzero((sol.instance == b) & sol.real)
        conf, lay = form.configuration(sol.x[rows], X[b])
        assert np.abs(graph_forward(mech, lay, conf).residual).max() <= 1e-10
        plate = lay.body_of["plate"]
        ours = graph_forward(mech, lay, conf).p[:, plate]
        theirs = graph_forward(mech, lay, own.configurations[b]).p[:, plate]
        assert len(ours) == len(theirs) == own.configurations[b].size
        assert _matched(ours, theirs, 1e-9 * mech.length_scale)


@pytest.fixture(scope="module")
def five_link() -> tuple[Mechanism, SpatialPointFormulation]:
    mech = sk.load_spec(MECHANISMS / "five_link_suspension.toml").mechanism
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation)
    return mech, form


def test_the_five_link_uprights_are_the_stewart_platform_poses(
        five_link: tuple[Mechanism, SpatialPointFormulation]) -> None:
    """The five-link suspension's upright is a platform on six rods (five links and the
    pushrod from the rocker): at three rocker angles its modes by the point formulation are
    the real poses of the Stewart–Gough forward kinematics (Study coordinates, elimination
    template, modes/stewart_solve.py) with the chassis balls and the turned rocker ball as base
    points and the rods' drawn lengths as legs: the same count and the same upright poses."""
    mech, form = five_link
    assert form.start().generic_count == 40  # a general 6-6 platform's count
    lay = graph_layout(mech)
    up = lay.body_of["upright"]
    pivot = mech.joint("rocker_pivot")
    rods = [("pushrod_top", "pushrod_foot")] + [(f"{n}_in", f"{n}_out") for n in (
        "upper_front", "upper_rear", "lower_front", "lower_rear", "toe_link")]
    inner = np.array([mech.joint(a).at for a, _ in rods])
    outer = np.array([mech.joint(b).at for _, b in rods])
    lengths = np.linalg.norm(outer - inner, axis=1)
    for theta in np.radians([-12.0, 0.0, 9.0]):
        u, c = pivot.axis, pivot.at
        K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
        Rr = np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K
        base = inner.copy()
        base[0] = c + Rr @ (inner[0] - c)
        st = solve_stewart(stewart_parameters(base, outer, lengths)[None, :])
        real = st.x[st.real]
        R, t = pose_from_study(real)
        theirs = np.real(np.concatenate([R.reshape(-1, 9), t], 1))
        found = every_mode(mech, [[theta]])
        fr = graph_forward(mech, lay, found.configurations[0])
        ours = np.concatenate([fr.R[:, up].reshape(-1, 9), fr.p[:, up]], 1)
        assert found.certified[0].all() and found.worst_closure <= 1e-10 * mech.length_scale
        assert _matched(ours, theirs, 1e-8), (len(ours), len(theirs))


def test_the_five_link_every_mode_motion_keeps_the_drawn_mode(
        five_link: tuple[Mechanism, SpatialPointFormulation]) -> None:
    """Along the rocker's travel the homotopy route (anchors, tracking between) gives every
    mode; mode 0 is the drawn one and equals the tracker's own continuation from the drawing;
    every mode closes to 1e-10 wherever it assembles."""
    mech, _ = five_link
    x = np.radians(np.linspace(-12.0, 12.0, 25))
    motion = solve_mechanism(mech, x, every_mode=True)
    assert motion.method.startswith("graph (homotopy")
    assert len(motion.modes) >= 2
    followed = follow_drawn_mode(mech, graph_layout(mech), x[:, None])
    assert followed.mask.all() and motion.modes[0].assembles.all()
    assert np.abs(motion.modes[0].conf.scalars - followed.conf.scalars).max() <= 1e-8
    for md in motion.modes:
        assert float(np.nanmax(md.closure_residual[md.assembles])) <= 1e-10


def _with_joint(mech: Mechanism, extra: MechanismJoint, body: str | None = None) -> Mechanism:
    bodies = mech.bodies + ((Body(body),) if body else ())
    return Mechanism(mech.name, bodies, mech.joints + (extra,), mech.inputs)


def test_what_the_point_formulation_does_not_take_is_said() -> None:
    """A body driven at its freedom; a body hanging from one ball; a mechanism locked at fixed inputs (the RSSR's
    crank tied to the ground by a second ball); freedoms left (the rocker's hinge made a
    ball); an H joint: each a CapabilityError that names the body or joint and says what to
    do."""
    rssr = _random_rssr(np.random.default_rng(5))
    travel = sk.load_spec(MECHANISMS / "double_wishbone_travel.toml").mechanism
    with pytest.raises(CapabilityError, match="driven at a body's freedom"):
        spatial_point_formulation(travel)
    # (over 48 unknowns: a 3-UPU with its U axes not square, tests/graphs/test_gimbal_legs.py)
    hanging = _with_joint(rssr, joint("H", "S", "rod", "pendulum", [2.0, 2.0, 2.0]),
                          "pendulum")
    with pytest.raises(CapabilityError, match="'pendulum' has a single joint"):
        spatial_point_formulation(hanging)
    locked = _with_joint(rssr, joint("T", "S", "crank", "ground", rssr.joints[1].at))
    with pytest.raises(CapabilityError, match="locked"):
        spatial_point_formulation(locked)
    loose = Mechanism("RSSR without its rocker hinge", rssr.bodies[:2] + (Body("rocker"),),
                      rssr.joints[:3] + (joint("D", "S", "rocker", "ground",
                                                rssr.joints[3].at),), ("O.theta",))
    with pytest.raises(CapabilityError, match=r"2 equations in 3 unknowns; 1 freedom"):
        spatial_point_formulation(loose)
    d = rssr.joints[3]
    helix = Mechanism("RSSH", rssr.bodies, rssr.joints[:3] + (
        MechanismJoint("D", "H", d.bodies, d.at, d.axis, pitch=0.01),), ("O.theta",))
    with pytest.raises(CapabilityError, match="H joints"):
        spatial_point_formulation(helix)


def _ups_rocker(s0: np.ndarray, flipped: bool = False) -> Mechanism:
    """A rocker on an R joint driven by a U–P–S leg whose slide is the input (a cylinder
    driving an arm): the input P joint lies between two moving bodies. Flipped: the leg's
    ball on the ground and its U joint on the rocker (the same points: U0 the fixed end, s0
    the rocker's)."""
    U0, D, rocker_axis = np.zeros(3), np.array([1.0, -0.2, 0.1]), np.array([0.3, 1.0, 0.2])
    leg = (s0 - U0) / np.linalg.norm(s0 - U0)
    e1 = np.array([0.0, 0.0, 1.0]) - leg[2] * leg
    e1 /= np.linalg.norm(e1)
    ends = ((joint("S", "S", "ground", "cylinder", U0),
             joint("U", "U", "piston", "rocker", s0, e1, np.cross(leg, e1))) if flipped else
            (joint("U", "U", "ground", "cylinder", U0, e1, np.cross(leg, e1)),
             joint("S", "S", "piston", "rocker", s0)))
    return Mechanism("UPS-driven rocker", (Body("cylinder"), Body("piston"), Body("rocker")),
                     (ends[0], joint("P", "P", "cylinder", "piston", (U0 + s0) / 2, leg),
                      ends[1], joint("R", "R", "rocker", "ground", D, rocker_axis)), ("P.s",))


def test_a_leg_driven_at_its_slide_between_moving_bodies_has_every_ball_position() -> None:
    """The input is a P joint between the cylinder and the piston, neither placed. With the
    leg's U joint on the rocker (flipped) the point formulation writes the leg as points and
    holds the slide as a parameter; at three slides the rocker's point lies where its circle
    meets the sphere of the leg's length about the ground ball (two points, by hand), each
    twice, the U joint's two roots. With the U joint on the ground the leg is one sphere
    (modes/spatial_point_legs.py ``UniversalLeg``): each point once, the U on its root nearer
    the drawing. Every mode closes, is certified, and holds the drawn mode."""
    s0 = np.array([0.6, 0.3, 0.5])
    X = np.array([[0.0], [0.05], [-0.1]])
    sphere = _ups_rocker(s0)
    form = closure_formulation(sphere)
    assert isinstance(form, SpatialPointFormulation) and len(form.universals) == 1
    once = every_mode(sphere, X)
    assert once.generic_count == 2 and once.worst_closure <= 1e-12
    mech = _ups_rocker(s0, flipped=True)
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation) and len(form.slides) == 1
    found = every_mode(mech, X)
    assert found.generic_count == 4
    D, a = mech.joint("R").at, mech.joint("R").axis
    centre = D + ((s0 - D) @ a) * a  # the ball's circle about the rocker axis
    radius = np.linalg.norm(s0 - centre)
    e1 = np.cross(a, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    for n, (s,) in enumerate(X):
        length = np.linalg.norm(s0) + s
        # |centre + r (cos φ e1 + sin φ e2)|² = length²: A cos φ + B sin φ = C
        A, B = 2 * radius * centre @ e1, 2 * radius * centre @ e2
        C = length ** 2 - centre @ centre - radius ** 2
        phi0, off = np.arctan2(B, A), np.arccos(C / np.hypot(A, B))
        balls = np.array([centre + radius * (np.cos(f) * e1 + np.sin(f) * e2)
                          for f in (phi0 + off, phi0 - off)])
        ours = _centres(mech, found.configurations[n])[:, 2]
        assert found.certified[n].all() and len(ours) == 4
        assert _matched(ours, np.repeat(balls, 2, axis=0), 1e-12)
        ours = _centres(sphere, once.configurations[n])[:, 2]
        assert once.certified[n].all() and _matched(ours, balls, 1e-12)
    for m, every in ((mech, found), (sphere, once)):
        drawn = follow_drawn_mode(m, graph_layout(m), X)
        for n in range(len(X)):
            mine = _centres(m, every.configurations[n])
            assert np.abs(mine - _centres(m, drawn.conf.take(slice(n, n + 1)))).reshape(
                len(mine), -1).max(1).min() <= 1e-12


def _macpherson(kind: str = "P", bodies: tuple[str, str] = ("upright", "strut")) -> Mechanism:
    """A MacPherson strut (mm): the lower arm's hinge is the input, the upright slides on
    the strut (a P joint between moving bodies, or a C joint: the strut then spins idly about
    its own line, which holds its top ball) whose top turns in a ball on the body, an S–S tie
    rod steers."""
    mm = 1e-3
    T, W = np.array([-20.0, 600.0, 700.0]), np.array([10.0, 690.0, 350.0])
    return Mechanism("MacPherson strut", (Body("arm"), Body("upright"), Body("strut"),
                                          Body("tie_rod")),
                     (joint("L", "R", "ground", "arm", mm * np.array([0.0, 350.0, 160.0]),
                            (1.0, 0.02, 0.01)),
                      joint("LB", "S", "arm", "upright", mm * np.array([0.0, 720.0, 150.0])),
                      joint("P", kind, *bodies, mm * W, T - W),
                      joint("T", "S", "strut", "ground", mm * T),
                      joint("TI", "S", "ground", "tie_rod", mm * np.array([-150.0, 380.0, 200.0])),
                      joint("TO", "S", "tie_rod", "upright",
                            mm * np.array([-140.0, 700.0, 210.0]))), ("L.theta",))


def test_a_macpherson_strut_every_upright_pose_and_no_other() -> None:
    """A P joint between moving bodies not driven (the strut): its slide is an unknown. At
    three arm angles the upright poses (turned about the lower ball so that the strut's line
    passes through the top mount and the tie rod keeps its length) are checked against a
    second method: Newton (scipy's least squares) from 200 random rotations of the upright,
    which finds no pose the homotopy misses, and every homotopy pose closes and is
    certified."""
    mech = _macpherson()
    j = {jt.name: jt for jt in mech.joints}
    LB0, T, W, u = j["LB"].at, j["T"].at, j["P"].at, j["P"].axis
    TI, TO0 = j["TI"].at, j["TO"].at
    rod = np.linalg.norm(TO0 - TI)
    lay = graph_layout(mech)
    rng = np.random.default_rng(7)
    for theta in np.radians([0.0, 5.0, -8.0]):
        found = every_mode(mech, [[theta]])
        assert found.certified[0].all() and found.worst_closure <= 1e-10 * mech.length_scale
        fr = graph_forward(mech, lay, found.configurations[0])
        up = lay.body_of["upright"]
        ours = fr.R[:, up].reshape(-1, 9)
        LB = fr.centres[0, 1]

        def residual(r: np.ndarray, LB: np.ndarray = LB) -> np.ndarray:
            R = Rotation.from_rotvec(r).as_matrix()
            w, a = LB + R @ (W - LB0), R @ u
            to = LB + R @ (TO0 - LB0)
            return np.append(np.cross(T - w, a) / mech.length_scale,
                             (np.linalg.norm(to - TI) - rod) / mech.length_scale)

        theirs: list[np.ndarray] = []
        for r0 in rng.normal(size=(200, 3)):
            sol = least_squares(residual, r0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
            if np.abs(residual(sol.x)).max() < 1e-11:
                R = Rotation.from_rotvec(sol.x).as_matrix().reshape(9)
                if not theirs or np.abs(np.array(theirs) - R).max(1).min() > 1e-6:
                    theirs.append(R)
        assert len(theirs) >= 1
        for R in theirs:  # every pose Newton finds is one of ours
            assert np.abs(ours - R).max(1).min() <= 1e-8


def test_an_r_joint_driven_between_moving_bodies_turns_its_point_with_the_input() -> None:
    """A loop R–R–S–S driven at its second R joint (between the crank and the coupler, both
    moving): the point formulation carries a point of the coupler in the crank's frame by the
    input angle. At three knee angles crank and coupler are one rigid body turning about the
    ground hinge, so the ball B lies where its circle meets the rod's sphere about C (two
    points, by hand): the modes are exactly those two, and the drawn one is among them."""
    O, K, B, C = (np.array(v) for v in ([0.0, 0.0, 0.0], [0.4, 0.1, 0.2], [0.7, 0.5, 0.1],
                                        [0.3, 1.2, 0.5]))
    axis_o, axis_k = np.array([0.1, 0.2, 1.0]), np.array([1.0, 0.3, 0.2])
    mech = Mechanism("RRSS driven at its knee", (Body("crank"), Body("coupler"), Body("rod")),
                     (joint("O", "R", "ground", "crank", O, axis_o),
                      joint("K", "R", "crank", "coupler", K, axis_k),
                      joint("B", "S", "coupler", "rod", B),
                      joint("C", "S", "rod", "ground", C)), ("K.theta",))
    form = closure_formulation(mech)
    assert isinstance(form, SpatialPointFormulation) and len(form.turns) == 1
    X = np.radians([[0.0], [10.0], [-20.0]])
    found = every_mode(mech, X)
    assert found.generic_count == 2
    a = axis_o / np.linalg.norm(axis_o)
    ka = axis_k / np.linalg.norm(axis_k)
    drawn = follow_drawn_mode(mech, graph_layout(mech), X)
    for n, (q,) in enumerate(X):
        Kr = np.eye(3) + np.sin(q) * np.cross(np.eye(3), ka) + (1 - np.cos(q)) * (
            np.outer(ka, ka) - np.eye(3))
        b0 = K + Kr @ (B - K)  # the ball with the knee turned, the crank as drawn
        centre = O + ((b0 - O) @ a) * a
        radius = np.linalg.norm(b0 - centre)
        e1 = (b0 - centre) / radius
        e2 = np.cross(a, e1)
        rod = np.linalg.norm(B - C)
        A_, B_ = 2 * radius * (centre - C) @ e1, 2 * radius * (centre - C) @ e2
        C_ = rod ** 2 - (centre - C) @ (centre - C) - radius ** 2
        phi0, off = np.arctan2(B_, A_), np.arccos(C_ / np.hypot(A_, B_))
        balls = np.array([centre + radius * (np.cos(f) * e1 + np.sin(f) * e2)
                          for f in (phi0 + off, phi0 - off)])
        ours = _centres(mech, found.configurations[n])
        assert found.certified[n].all() and _matched(ours[:, 2], balls, 1e-12)
        there = _centres(mech, drawn.conf.take(slice(n, n + 1)))[0]
        assert np.abs(ours - there).reshape(len(ours), -1).max(1).min() <= 1e-12


def _rssp(rng: np.random.Generator, drawn_ground_first: bool) -> Mechanism:
    """A spatial RSSP (a crank drives a slider on a random rail through an S–S rod), its P
    joint drawn ground-first or slider-first."""
    O, A, B = (rng.uniform(-1.0, 1.0, 3) for _ in range(3))
    A = O + 0.3 * (A - O) / np.linalg.norm(A - O)
    rail = rng.normal(size=3)
    bodies = ("ground", "slider") if drawn_ground_first else ("slider", "ground")
    return Mechanism("random RSSP", (Body("crank"), Body("rod"), Body("slider")),
                     (joint("O", "R", "ground", "crank", O, rng.normal(size=3)),
                      joint("A", "S", "crank", "rod", A),
                      joint("B", "S", "rod", "slider", B),
                      joint("P", "P", *bodies, B, rail)), ("O.theta",))


def test_a_passive_slider_drawn_either_way_gives_the_closed_form_modes() -> None:
    """Ten random RSSPs with the P joint drawn ground-first and slider-first (the slide's
    carried points are then turned into the body written later, b = a − s (a1 − a0)): both
    drawings give the closed form's modes (the PSS dyad: the rod's sphere meets the rail)."""
    for seed in range(10):
        for first in (True, False):
            mech = _rssp(np.random.default_rng(seed), first)
            x = np.array([0.0, 0.7])
            found = every_mode(mech, x[:, None])
            closed = solve_mechanism(mech, x, every_mode=True)
            assert "closed" in closed.method  # the loop's or the dyads' closed form
            for n in range(x.size):
                theirs = np.array([md.joint_centres[n] for md in closed.modes
                                   if md.assembles[n]]).reshape(-1, 4, 3)
                ours = _centres(mech, found.configurations[n]) if \
                    found.configurations[n].size else np.zeros((0, 4, 3))
                assert found.certified[n].all()
                assert _matched(ours, theirs, 1e-9), (seed, first, n)


def test_the_knee_loop_drawn_in_any_order_has_the_same_modes() -> None:
    """The knee-driven R–R–S–S loop with its bodies listed in either order and its knee joint
    drawn either way: the same two balls (the builder writes bodies nearest the ground first
    and carries the turned point in the body written later, so the count holds)."""
    O, K, B, C = (np.array(v) for v in ([0.0, 0.0, 0.0], [0.4, 0.1, 0.2], [0.7, 0.5, 0.1],
                                        [0.3, 1.2, 0.5]))
    balls = []
    for names in (("crank", "coupler", "rod"), ("coupler", "crank", "rod")):
        for knee in (("crank", "coupler"), ("coupler", "crank")):
            sign = 1.0 if knee[0] == "crank" else -1.0
            mech = Mechanism("knee", tuple(Body(b) for b in names),
                             (joint("O", "R", "ground", "crank", O, (0.1, 0.2, 1.0)),
                              joint("K", "R", *knee, K, (1.0, 0.3, 0.2)),
                              joint("B", "S", "coupler", "rod", B),
                              joint("C", "S", "rod", "ground", C)), ("K.theta",))
            found = every_mode(mech, [[sign * np.radians(10.0)]])
            assert found.generic_count == 2 and found.certified[0].all()
            ball = _centres(mech, found.configurations[0])[:, 2]
            balls.append(ball[np.lexsort(ball.T)])
    for other in balls[1:]:
        assert np.abs(other - balls[0]).max() <= 1e-12


def test_a_square_closure_that_leaves_a_freedom_is_refused() -> None:
    """Two R hinges and rods that leave the middle body one freedom at a fixed input (its
    ball on a circle): whatever way the equations are counted, the formulation refuses it by
    name rather than report no mode."""
    rng = np.random.default_rng(14)
    P = lambda: rng.uniform(-1.0, 1.0, 3)  # noqa: E731
    O, ao, A, B, D, ad = P(), rng.normal(size=3), P(), P(), P(), rng.normal(size=3)
    O = A + 0.3 * (O - A) / np.linalg.norm(O - A)
    mech = Mechanism("loose", tuple(Body(b) for b in ("A", "r1", "B", "C")),
                     (joint("R1", "R", "ground", "A", O, ao), joint("S1", "S", "A", "r1", A),
                      joint("S2", "S", "r1", "B", B), joint("R2", "R", "B", "C", D, ad),
                      joint("R3", "R", "C", "ground", P(), rng.normal(size=3))), ("R1.theta",))
    with pytest.raises(CapabilityError, match="freedom"):
        spatial_point_formulation(mech)


def test_a_macpherson_strut_with_a_c_joint_has_the_p_joints_upright_poses() -> None:
    """The strut modelled with a C joint, drawn either way: the strut is then a body on a line
    (its top ball on the C axis) whose points a slide carries, and its random instance puts
    them back on the line after the slide. The upright poses are those of the P-joint strut
    (the C joint's extra turn only spins the strut about its line)."""
    lay = graph_layout(_macpherson())
    up = lay.body_of["upright"]
    x = np.radians([[0.0], [5.0]])
    ref = every_mode(_macpherson(), x)
    for bodies in (("upright", "strut"), ("strut", "upright")):
        mech = _macpherson("C", bodies)
        found = every_mode(mech, x)
        assert found.generic_count == ref.generic_count
        for n in range(len(x)):
            ours = graph_forward(mech, graph_layout(mech), found.configurations[n]).R[:, up]
            theirs = graph_forward(_macpherson(), lay, ref.configurations[n]).R[:, up]
            assert found.certified[n].all()
            assert _matched(ours.reshape(-1, 9), theirs.reshape(-1, 9), 1e-9)


def test_a_strut_spinning_idly_about_its_c_axis_keeps_its_modes_along_the_motion() -> None:
    """The C-joint strut spins idly about its own line (a C joint and its top ball on that
    line), and the tracker and the point decoding set that spin differently. Along the arm's
    travel the modes are matched by poses with the spin left out (graph/idle.py
    ``spin_lines``): as many modes as with the P-joint strut, not fragments, and the drawn one
    is the tracker's (it was 19 fragments against 4 before)."""
    x = np.radians(np.linspace(-6.0, 6.0, 13))
    with_p = solve_mechanism(_macpherson(), x, every_mode=True)
    mech = _macpherson("C")
    with_c = solve_mechanism(mech, x, every_mode=True)
    assert len(with_c.modes) == len(with_p.modes)
    assert [int(m.assembles.sum()) for m in with_c.modes] == \
        [int(m.assembles.sum()) for m in with_p.modes]
    assert not any("not among" in n for n in with_c.notes)
    drawn = follow_drawn_mode(mech, graph_layout(mech), x[:, None])
    centres = with_c.modes[0].joint_centres
    assert np.abs(centres - _centres(mech, drawn.conf)).max() <= 1e-9


def _rscr_ssr(order: tuple[str, ...]) -> Mechanism:
    """An RSCR loop (its C joint between the rod and the rocker, both moving) with an S–S dyad
    hung on the rocker: the rocker holds two rigid groups (the C joint's slid points and its
    ground hinge's axis), so the count depends on the order the bodies are written."""
    O, A, B, D, E, F, G = (np.array(v, float) for v in (
        [0, 0, 0], [0.3, 0.1, 0.0], [0.5, 0.9, 0.3], [1.0, 0.8, -0.2], [1.2, 0.3, 0.4],
        [1.6, -0.3, 0.5], [2.0, 0.0, 0.0]))
    return Mechanism("RSCR+SSR", tuple(Body(b) for b in order),
                     (joint("O", "R", "ground", "crank", O, (0.1, 0.2, 1.0)),
                      joint("A", "S", "crank", "rod", A),
                      joint("B", "C", "rod", "rocker", B, (0.3, -0.5, 0.8)),
                      joint("D", "R", "rocker", "ground", D, (0.7, 0.2, 0.4)),
                      joint("E", "S", "rocker", "rod2", E),
                      joint("F", "S", "rod2", "rocker2", F),
                      joint("G", "R", "ground", "rocker2", G, (0.1, 1.0, 0.3))), ("O.theta",))


def test_a_body_with_two_rigid_groups_is_taken_in_either_body_order() -> None:
    """RSCR with an S–S dyad, its bodies listed in two orders: the builder writes the bodies
    nearest the input first with ties in the spec's order and, where that over-counts, in the
    reverse; both orders give the same modes, among them the tracker's drawn one (one order was
    refused as over-constrained before, found by review)."""
    X = np.array([[0.0], [0.1], [-0.1]])
    seen = []
    for order in (("crank", "rod", "rocker", "rod2", "rocker2"),
                  ("crank", "rocker", "rod", "rod2", "rocker2")):
        mech = _rscr_ssr(order)
        found = every_mode(mech, X)
        drawn = follow_drawn_mode(mech, graph_layout(mech), X)
        for n in range(len(X)):
            ours = _centres(mech, found.configurations[n])
            there = _centres(mech, drawn.conf.take(slice(n, n + 1)))[0]
            assert found.certified[n].all() and len(ours) == 2
            assert np.abs(ours - there).reshape(len(ours), -1).max(1).min() <= 1e-9
        seen.append(np.sort(_centres(mech, found.configurations[1])[:, 4], axis=0))
    assert np.abs(seen[0] - seen[1]).max() <= 1e-9


def test_the_five_link_example_is_what_its_generator_writes(tmp_path: Path) -> None:
    """examples/mechanisms/five_link_suspension.toml is tests/graphs/five_link.py's output."""
    from tests.graphs.five_link import write_spec

    text = write_spec(tmp_path / "five_link.toml")
    assert (MECHANISMS / "five_link_suspension.toml").read_text(encoding="utf-8") == text


def test_the_least_rotation_turns_a_reversed_direction_over() -> None:
    """least_rotation (the rods' and legs' poses): every row turns its d0 onto d, d0 given
    once or per row, also where d is exactly d0 reversed (a half turn; it was the identity)."""
    from screwkit.kinematics.modes.rod_loops import least_rotation

    rng = np.random.default_rng(3)
    d0 = rng.standard_normal(3)
    d = np.stack([-d0, d0, *(rng.standard_normal((5, 3)))])
    d *= np.linalg.norm(d0) / np.linalg.norm(d, axis=1)[:, None]
    for first in (d0, np.broadcast_to(d0, d.shape)):
        R = least_rotation(first, d)
        np.testing.assert_allclose(np.einsum("nij,j->ni", R, d0), d, atol=1e-14)
        np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape),
                                   atol=1e-14)
        np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
