"""Telescopic legs (model/spin_groups.py): bodies slid along the line between two balls spin
idly about it, as one rod. Checked on the 6-SPS platform (tests/graphs/six_sps.py) against the
6-UPS example it is made from: the six leg lengths alone decide the platform's pose, so both
have the same platform poses, modes and platform twists; the legs' spins are idle and held at
zero; and the 6-SPS's loads obey the energy and momentum laws (test_graph_dynamics.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from six_sps import six_sps_spec, six_sps_text

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.topology import mechanism_topology
from screwkit.model.spin_groups import spin_groups

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"


@pytest.fixture(scope="module")
def specs(tmp_path_factory: pytest.TempPathFactory) -> tuple[sk.Spec, sk.Spec]:
    folder = tmp_path_factory.mktemp("sps")
    return (sk.load_spec(EXAMPLES / "stewart_platform.toml"),
            sk.load_spec(six_sps_spec(folder)))


def test_single_body_groups_are_the_rods_of_two_balls() -> None:
    """On every bundled example, the groups of one body are exactly the bodies held by two
    balls and nothing else (the rule before legs), and no example has a leg."""
    for path in sorted(EXAMPLES.glob("*.toml")):
        spec = sk.load_spec(path)
        mech = getattr(spec, "mechanism", None)
        if mech is None:
            continue
        rods = [b for b in mech.body_names
                if [j.kind for j in mech.joints if b in j.bodies] == ["S", "S"]]
        groups = spin_groups(mech)
        assert [g.bodies for g in groups] == [(b,) for b in rods], path.name
        assert not any(g.slides for g in groups)


def test_the_legs_are_found_and_their_spins_are_idle(specs: tuple[sk.Spec, sk.Spec],
                                                     tmp_path: Path) -> None:
    _, sps = specs
    mech = sps.mechanism
    groups = spin_groups(mech)
    assert [g.bodies for g in groups] == [(f"cylinder{i}", f"piston{i}") for i in range(1, 7)]
    for i, g in enumerate(groups, start=1):
        assert [mech.joints[k].name for k in g.balls] == [f"U{i}", f"S{i}"]  # (U: the name kept)
        assert [mech.joints[k].name for k in g.slides] == [f"P{i}"]
    top = mechanism_topology(mech)
    assert top.mobility == 12 and len(top.idle) == 6 and not top.free
    assert top.idle[0] == "cylinder1+piston1 spin (about the line U1–S1)"
    assert "mobility 6 + 6 idle, 6 input(s)" in top.verdict
    # a P joint has no centre: its 'at' off the leg's line changes nothing
    text = six_sps_text().replace("at = [172.45324556864009, -81.72482326302449, 200.0]",
                                  "at = [172.45324556864009, -61.72482326302449, 200.0]")
    path = tmp_path / "off.toml"
    path.write_text(text)
    off = mechanism_topology(sk.load_spec(path).mechanism)
    assert (off.mobility, off.idle, off.free) == (top.mobility, top.idle, top.free)


def test_a_leg_slid_at_a_slant_still_spins_idly(specs: tuple[sk.Spec, sk.Spec],
                                               tmp_path: Path) -> None:
    """A P joint at a slant to its leg's line (its slide changes the leg's direction in its
    bodies as well as its length): the leg still turns as one body about the line through its
    balls, an idle spin; the point formulation's distance ‖d0 + s e‖ and the Stewart route's
    (the same leg vector) give the same platform poses at a slide of 10 mm, and each mode's
    slide reads back as the input."""
    from screwkit.kinematics.modes.every_mode import every_mode, solve_formulation
    from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation

    text = six_sps_text().replace(
        "axis = [-0.33579650605959055, -0.13857379078588428, 0.9316855751944436]",
        "axis = [0, 0, 1]")
    path = tmp_path / "slant.toml"
    path.write_text(text)
    mech = sk.load_spec(path).mechanism
    assert [g.bodies for g in spin_groups(mech)][0] == ("cylinder1", "piston1")
    top = mechanism_topology(mech)
    assert len(top.idle) == 6 and "mobility 6 + 6 idle" in top.verdict
    form = spatial_point_formulation(mech)
    X = np.array([[0.010, 0.0, 0.0, 0.0, 0.0, 0.0]])
    sol = solve_formulation(form, form.parameters(X))
    conf, lay = form.configuration(sol.x[sol.real], X[0])
    stewart = every_mode(mech, X).configurations[0]
    k = lay.body_of["platform"]
    a, b = graph_forward(mech, lay, conf), graph_forward(mech, lay, stewart)
    ours = np.concatenate([a.R[:, k].reshape(-1, 9), a.p[:, k] / mech.length_scale], 1)
    theirs = np.concatenate([b.R[:, k].reshape(-1, 9), b.p[:, k] / mech.length_scale], 1)
    assert len(ours) == len(theirs) >= 2
    assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)
    np.testing.assert_allclose(conf.scalars[:, lay.scalar_col[lay.names.index("P1.s")]], 0.010,
                               atol=1e-12)
    assert np.abs(a.residual).max() <= 1e-10 * mech.length_scale


def test_the_platform_moves_as_on_the_ups_legs(specs: tuple[sk.Spec, sk.Spec]) -> None:
    """The drawn mode over the motion: the platform's pose, twist and acceleration are the
    6-UPS's (to the tracker's closure), and each leg's bodies turn together with no spin
    about the leg's line."""
    ups, sps = specs
    X = sps.inputs[::7]
    a = solve_mechanism(ups.mechanism, X, rates=1.0, accelerations=0.5).modes[0]
    b = solve_mechanism(sps.mechanism, X, rates=1.0, accelerations=0.5).modes[0]
    assert a.assembles.all() and b.assembles.all()
    k = sps.mechanism.body_index("platform")
    scale = sps.mechanism.length_scale
    np.testing.assert_allclose(b.link_rotation[:, k], a.link_rotation[:, k], atol=1e-9)
    np.testing.assert_allclose(b.link_origin[:, k], a.link_origin[:, k], atol=1e-9 * scale)
    np.testing.assert_allclose(b.link_angular_velocity[:, k], a.link_angular_velocity[:, k],
                               atol=1e-9)
    np.testing.assert_allclose(b.link_origin_velocity[:, k], a.link_origin_velocity[:, k],
                               atol=1e-9 * scale)
    mech = sps.mechanism
    for g in spin_groups(mech):
        i, j = (mech.body_index(x) for x in g.bodies)
        np.testing.assert_allclose(b.link_rotation[:, i], b.link_rotation[:, j], atol=1e-12)
        np.testing.assert_allclose(b.link_angular_velocity[:, i],
                                   b.link_angular_velocity[:, j], atol=1e-12)
        c0, c1 = (mech.joints[m].at for m in g.balls)
        u = np.einsum("nij,j->ni", b.link_rotation[:, i], (c1 - c0) / np.linalg.norm(c1 - c0))
        spin = np.einsum("ni,ni->n", b.link_angular_velocity[:, i], u)
        assert np.abs(spin).max() <= 1e-10 * np.abs(b.link_angular_velocity[:, i]).max()


def test_every_mode_is_the_ups_platforms(specs: tuple[sk.Spec, sk.Spec]) -> None:
    """Every assembly mode at a few inputs: as many as the 6-UPS's, with the same platform
    poses (the legs' spins left out of the mode matching, else each anchor would start new
    modes)."""
    ups, sps = specs
    X = sps.inputs[[0, 12, 24]]
    a = solve_mechanism(ups.mechanism, X, every_mode=True)
    b = solve_mechanism(sps.mechanism, X, every_mode=True)
    assert len(b.modes) == len(a.modes) >= 2
    k = sps.mechanism.body_index("platform")
    scale = sps.mechanism.length_scale

    def poses(m: object, n: int) -> np.ndarray:
        rows = [np.concatenate([md.link_rotation[n, k].ravel(), md.link_origin[n, k] / scale])
                for md in m.modes if md.assembles[n]]  # type: ignore[attr-defined]
        return np.array(sorted(rows, key=lambda r: tuple(np.round(r, 6))))

    for n in range(len(X)):
        pa, pb = poses(a, n), poses(b, n)
        assert pa.shape == pb.shape and len(pa) >= 2
        np.testing.assert_allclose(pb, pa, atol=1e-8)


def test_a_point_off_a_legs_line_is_refused(tmp_path: Path) -> None:
    text = six_sps_text() + ('\n[[points]]\nname = "flag"\nbody = "piston1"\n'
                             'at = [150.0, -90.0, 300.0]\n')
    path = tmp_path / "flag.toml"
    path.write_text(text)
    with pytest.raises(sk.ScrewkitError, match="in the leg cylinder1\\+piston1 between the "
                                               "balls 'U1' and 'S1'"):
        sk.load_spec(path)


CRANK_STRUT = """
[mechanism]
name = "crank and telescopic strut"
[units]
length = "mm"
angle = "deg"
[[bodies]]
name = "crank"
[[bodies]]
name = "cylinder"
[[bodies]]
name = "piston"
[[joints]]
name = "R1"
kind = "R"
between = ["ground", "crank"]
at = [0, 0, 0]
axis = [0, 0, 1]
[[joints]]
name = "S1"
kind = "S"
between = ["crank", "cylinder"]
at = [{cx}, {cy}, 0]
[[joints]]
name = "P1"
kind = "P"
between = ["{first}", "{second}"]
at = [{px}, {py}, {pz}]
axis = [{ax}, {ay}, {az}]
input = true
[[joints]]
name = "S2"
kind = "S"
between = ["piston", "ground"]
at = [{gx}, {gy}, {gz}]
[motion]
start = -20
stop = 20
step = 5
"""


def _crank_strut(rng: np.random.Generator, folder: Path, k: int) -> tuple[sk.Spec, dict]:
    """A crank (R on the ground about z) driven by a telescopic strut (S–P–S) from a ball on
    the ground, at random: the P joint drawn either way, its point anywhere on the strut's
    line."""
    crank = rng.uniform(50.0, 150.0) * np.array([*(lambda a: (np.cos(a), np.sin(a)))(
        rng.uniform(0, 2 * np.pi)), 0.0])
    g = rng.uniform(-200.0, 200.0, 3) + np.array([0.0, 0.0, 60.0])
    u = (g - crank) / np.linalg.norm(g - crank)
    first, second, axis = ("cylinder", "piston", u) if rng.random() < 0.5 else \
        ("piston", "cylinder", -u)
    at = crank + rng.uniform(-0.5, 1.5) * (g - crank)
    text = CRANK_STRUT.format(cx=crank[0], cy=crank[1], gx=g[0], gy=g[1], gz=g[2],
                              px=at[0], py=at[1], pz=at[2], ax=axis[0], ay=axis[1],
                              az=axis[2], first=first, second=second)
    path = folder / f"strut{k}.toml"
    path.write_text(text)
    spec = sk.load_spec(path)  # (SI: the balls' centres read back from the mechanism)
    return spec, {"crank": spec.mechanism.joint("S1").at, "ground_ball": spec.mechanism.joint("S2").at}


def _crank_angles(crank: np.ndarray, g: np.ndarray, length: np.ndarray) -> np.ndarray:
    """The crank turns θ (from the drawing) at which the crank's ball is ``length`` from the
    ground ball: |R(θ) c − g|² = ℓ², cos(θ + φ_c − φ_g) = (|c|² + |g|² − ℓ²) / (2 |c| ρ_g)
    (ρ_g the ground ball's distance from the axis); both roots, NaN where none."""
    r, rho = np.linalg.norm(crank[:2]), np.linalg.norm(g[:2])
    cosine = (r**2 + g @ g - length**2) / (2 * r * rho)
    phi = np.arctan2(g[1], g[0]) - np.arctan2(crank[1], crank[0])
    with np.errstate(invalid="ignore"):
        half = np.arccos(np.where(np.abs(cosine) <= 1, cosine, np.nan))
    return np.stack([phi + half, phi - half], axis=-1)


def test_a_crank_on_a_telescopic_strut_has_the_closed_form_modes(tmp_path: Path) -> None:
    """The point formulation writes a driven S–P–S strut as one distance, ‖b − a‖ = ℓ0 ± s:
    on 12 random crank-and-strut mechanisms, every mode at five strut lengths is one of the
    two crank angles of the closed form (circle ∩ sphere), none missing, each closing to
    1e-10, the strut's slide the input and its two bodies turned alike."""
    from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
    from screwkit.kinematics.modes.spatial_points import SpatialPointFormulation

    rng = np.random.default_rng(11)
    total = 0
    for k in range(12):
        spec, geo = _crank_strut(rng, tmp_path, k)
        mech = spec.mechanism
        assert isinstance(closure_formulation(mech), SpatialPointFormulation)
        length0 = np.linalg.norm(geo["ground_ball"] - geo["crank"])
        s = np.linspace(-0.3, 0.3, 5) * length0
        found = every_mode(mech, s[:, None])
        assert found.generic_count == 2
        lay = graph_layout(mech)
        theta, slide = (lay.scalar_col[lay.names.index(f)] for f in ("R1.theta", "P1.s"))
        theirs = _crank_angles(geo["crank"], geo["ground_ball"], length0 + s)
        for n in range(len(s)):
            conf = found.configurations[n]
            total += conf.size
            ours = np.sort(conf.scalars[:, theta]) if conf.size else []
            want = np.sort(np.angle(np.exp(1j * theirs[n][np.isfinite(theirs[n])])))
            ours = np.sort(np.angle(np.exp(1j * np.asarray(ours))))
            np.testing.assert_allclose(ours, want, atol=1e-9)
            if conf.size:
                np.testing.assert_allclose(conf.scalars[:, slide], s[n],
                                           atol=1e-9 * mech.length_scale)
                fr = graph_forward(mech, lay, conf)
                np.testing.assert_allclose(fr.R[:, lay.body_of["cylinder"]],
                                           fr.R[:, lay.body_of["piston"]], atol=1e-12)
        assert found.worst_closure <= 1e-10 * mech.length_scale
    assert total >= 60  # most of the 12 × 5 × 2 closed-form modes are real


def test_the_six_sps_by_points_is_the_stewart_template(specs: tuple[sk.Spec, sk.Spec]) -> None:
    """Two formulations of one platform: the 6-SPS by the point formulation (its legs as
    distances between ball centres, 18 unknowns, start solutions by monodromy) finds the
    general 6-6 platform's 40, and at two inputs the same real platform poses as the Stewart
    route (Study coordinates, elimination template) that every_mode picks for it."""
    from screwkit.algebraic.solve import Solutions
    from screwkit.kinematics.modes.every_mode import every_mode, solve_formulation
    from screwkit.kinematics.modes.spatial_points_build import spatial_point_formulation

    _, sps = specs
    mech = sps.mechanism
    form = spatial_point_formulation(mech)
    assert len(form.legs) == 6 and form.system.n == 18
    assert form.start().generic_count == 40
    X = sps.inputs[[0, 20]]
    sol: Solutions = solve_formulation(form, form.parameters(X))
    lay = graph_layout(mech)
    k = lay.body_of["platform"]
    stewart = every_mode(mech, X)
    for n in range(len(X)):
        rows = np.flatnonzero((sol.instance == n) & sol.real)
        conf, _ = form.configuration(sol.x[rows], X[n])
        a, b = graph_forward(mech, lay, conf), graph_forward(mech, lay, stewart.configurations[n])
        ours = np.concatenate([a.R[:, k].reshape(-1, 9), a.p[:, k] / mech.length_scale], 1)
        theirs = np.concatenate([b.R[:, k].reshape(-1, 9), b.p[:, k] / mech.length_scale], 1)
        assert len(ours) == len(theirs) >= 2
        assert all(np.abs(theirs - x).max(1).min() <= 1e-8 for x in ours)


def _rssr(strut: str | None) -> sk.Mechanism:
    """An RSSR (a crank, a rod, a rocker; the crank driven) with a collar slid along its rod
    (``strut="collar"``: the rod and collar a leg whose balls are both on the rod) or a passive
    strut of free length from a ground ball to the rocker's ball (``strut="damper"``)."""
    from screwkit.model.mechanism import Body, BodyPoint, Mechanism, MechanismJoint

    z = np.array([0.0, 0.0, 1.0])
    c0, c1 = np.zeros(3), np.array([0.05, 0.02, 0.03])
    f0, f1 = np.array([0.2, 0.05, -0.02]), np.array([0.18, 0.1, 0.06])
    joints = [MechanismJoint("A", "R", ("ground", "crank"), c0, np.array([0.0, 0.3, 1.0])),
              MechanismJoint("S1", "S", ("crank", "rod"), c1, z),
              MechanismJoint("S2", "S", ("rod", "rocker"), f1, z),
              MechanismJoint("B", "R", ("ground", "rocker"), f0, np.array([1.0, 0.2, 0.1]))]
    bodies = [Body("crank"), Body("rod"), Body("rocker")]
    inputs: tuple[str, ...] = ("A.theta",)
    points: tuple[BodyPoint, ...] = ()
    if strut == "collar":
        u = (f1 - c1) / np.linalg.norm(f1 - c1)
        joints.append(MechanismJoint("P", "P", ("rod", "collar"), (c1 + f1) / 2, u))
        bodies.append(Body("collar"))
        inputs += ("P.s",)
        points = (BodyPoint("m", "collar", (c1 + f1) / 2),)
    elif strut == "damper":
        g = np.array([0.1, -0.1, 0.0])
        u = (f1 - g) / np.linalg.norm(f1 - g)
        joints += [MechanismJoint("T1", "S", ("ground", "cylinder"), g, z),
                   MechanismJoint("P", "P", ("cylinder", "piston"), (g + f1) / 2, u),
                   MechanismJoint("T2", "S", ("piston", "rocker"), f1, z)]
        bodies += [Body("cylinder"), Body("piston")]
    return Mechanism("RSSR", tuple(bodies), tuple(joints), inputs, points)


def test_struts_and_collars_the_formulation_writes_or_refuses_by_name() -> None:
    """Found by review: a collar slid along a rod (a leg whose two balls are on one body) is
    left to the general point system, which refuses it by name (the collar held by one
    joint), its drawn mode followed (before, a bare StopIteration); a passive
    damper strut from the ground to the rocker of an RSSR carries no equation and reads its
    slide back from its balls (the rocker's ball distance less the drawn one); and a crank
    that only a passive strut joins to the ground is placed by its input alone: refused by
    name (nothing to solve), its drawn mode followed."""
    from screwkit.errors import CapabilityError
    from screwkit.kinematics.modes.every_mode import closure_formulation, every_mode
    from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

    collar = _rssr("collar")
    motion = solve_mechanism(collar, [[0.0, 0.0], [0.1, 0.01]], every_mode=True)
    assert motion.modes[0].assembles.all()
    assert "'collar' has a single joint" in motion.notes[0]
    damper = _rssr("damper")
    form = closure_formulation(damper)
    assert len(form.legs) == 1 and form.legs[0].column is None  # type: ignore[attr-defined]
    found = every_mode(damper, [[0.4]])
    conf = found.configurations[0]
    assert conf.size == 2 and found.worst_closure <= 1e-12
    lay = graph_layout(damper)
    fr = graph_forward(damper, lay, conf)
    f1, g = damper.joint("T2").at, damper.joint("T1").at
    ball = np.einsum("nij,j->ni", fr.R[:, lay.body_of["rocker"]], f1) + \
        fr.p[:, lay.body_of["rocker"]]
    np.testing.assert_allclose(conf.scalars[:, lay.scalar_col[lay.names.index("P.s")]],
                               np.linalg.norm(ball - g, axis=1) - np.linalg.norm(f1 - g),
                               atol=1e-12)
    z = np.array([0.0, 0.0, 1.0])
    b, g = np.array([0.3, 0.1, 0.05]), np.array([0.05, 0.25, 0.0])
    u = (b - g) / np.linalg.norm(b - g)
    placed = Mechanism("rocker and damper", (Body("rocker"), Body("cylinder"), Body("piston")),
                       (MechanismJoint("R", "R", ("ground", "rocker"), np.zeros(3),
                                       np.array([0.0, 0.2, 1.0])),
                        MechanismJoint("S1", "S", ("ground", "cylinder"), g, z),
                        MechanismJoint("P", "P", ("cylinder", "piston"), (b + g) / 2, u),
                        MechanismJoint("S2", "S", ("piston", "rocker"), b, z)), ("R.theta",))
    with pytest.raises(CapabilityError, match="inputs place every body"):
        closure_formulation(placed)
    motion = solve_mechanism(placed, [[0.0], [0.3]], every_mode=True)
    assert len(motion.modes) == 1 and motion.modes[0].assembles.all()
    assert "inputs place every body" in motion.notes[0]
