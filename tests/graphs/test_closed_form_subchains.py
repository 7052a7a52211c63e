"""Closed-form sub-chains (issue 27; kinematics/graph/subchains.py, dyads.py, closed_modes.py)
checked against independent routes: the stacked loop closure (every mode closes), the graph
tracker (the drawn mode equals its motion; the tracker started from each closed-form mode stays
on it), the mode count of a Watt six-bar, and a four-bar's fold against brentq on the
distance law."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism
from screwkit.kinematics.graph.closed_modes import every_mode
from screwkit.kinematics.graph.closure import graph_forward, graph_layout, loop_residuals
from screwkit.kinematics.graph.follow import follow_drawn_mode, reach
from screwkit.kinematics.graph.from_loop import mechanism_from_loop
from screwkit.kinematics.graph.idle import rods
from screwkit.kinematics.graph.motion import build_mode
from screwkit.kinematics.graph.subchains import decompose
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import Body, BodyPoint, Mechanism, MechanismJoint

MECHANISMS = Path(__file__).parents[2] / "examples" / "mechanisms"
Z = np.array([0.0, 0.0, 1.0])


def joint(name: str, kind: str, a: str, b: str, at: object, axis: object = Z) -> MechanismJoint:
    return MechanismJoint(name, kind, (a, b), np.asarray(at, float), np.asarray(axis, float))


def _residual(mech: Mechanism, conf: Configuration) -> float:
    """The largest loop closure twist (rad, and length over the length scale)."""
    lay = graph_layout(mech)
    fr = graph_forward(mech, lay, conf)
    res = loop_residuals(mech, lay, conf, fr.R, fr.p)
    scale = np.array([1, 1, 1, *(3 * [1 / mech.length_scale])])
    return float(np.max(np.abs(res * scale))) if res.size else 0.0


def test_bundled_examples_decompose_or_say_what_needs_the_homotopy() -> None:
    expect = {"fourbar_graph": 2, "watt_sixbar": 4, "watt_sixbar_balance": 4,
              "watt_sixbar_simulate": 4, "jansen_leg": 8,
              "double_wishbone": 4, "double_wishbone_synthesis": 4}
    for path in sorted(MECHANISMS.glob("*.toml")):
        mech = sk.load_spec(path).mechanism
        dec = decompose(mech)
        if path.stem in expect:
            assert dec.complete and dec.mode_count == expect[path.stem], path.stem
            kinds = {"double_wishbone": ["RSS", "SS"], "double_wishbone_synthesis": ["RSS", "SS"]
                     }.get(path.stem, ["RRR"] * len(dec.dyads))
            assert [d.kind for d in dec.dyads] == kinds
        else:
            assert not dec.complete, path.stem
            assert "needs the homotopy" in dec.describe(mech)[-1]
    st = decompose(sk.load_spec(MECHANISMS / "stephenson3_sixbar.toml").mechanism)
    assert set(st.unplaced) == {"rod", "coupler", "link_k", "link_r"}  # the triad


@pytest.mark.parametrize("name", ["fourbar_graph", "watt_sixbar", "jansen_leg",
                                  "double_wishbone"])
def test_drawn_mode_equals_the_tracker_and_every_mode_closes(name: str) -> None:
    spec = sk.load_spec(MECHANISMS / f"{name}.toml")
    mech = spec.mechanism
    X = spec.inputs
    motion = solve_mechanism(mech, X, rates=spec.speed, every_mode=True)
    # a single loop is the loop engine's (graph/loop_subchain.py), the others the dyads'
    assert motion.method == ("graph (loop, closed)" if name == "fourbar_graph"
                             else "graph (closed forms)")
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, X)
    ones, zeros = np.full_like(X, spec.speed), np.zeros_like(X)
    tracked = build_mode(mech, lay, followed.conf, followed.mask, X, ones, zeros)
    drawn = motion.modes[0]
    assert np.array_equal(drawn.assembles, tracked.assembles)
    ok = tracked.assembles
    assert np.max(np.abs(drawn.conf.scalars - followed.conf.scalars)[ok]) <= 1e-10
    # a rod between two balls spins idly: its pose about its own axis, and so its balls'
    # relative rotations, are a convention (docs/kinematics.md); everything else must agree
    spinning = {b for b, _, _ in rods(mech)}
    balls = {j.name for j in mech.joints if j.kind == "S" and set(j.bodies) & spinning}
    for table in ("variables", "velocities", "accelerations", "points", "outputs"):
        for key, value in getattr(tracked, table).items():
            if key.split(".")[0] in balls:
                continue
            got = getattr(drawn, table)[key]
            assert np.max(np.abs(got - value)[ok]) <= 1e-9 * max(1.0, np.max(np.abs(value))), key
    held = [k for k, b in enumerate(mech.bodies) if b.name not in spinning]
    assert np.max(np.abs(drawn.link_origin - tracked.link_origin)[ok][:, held]) \
        <= 1e-10 * mech.length_scale
    assert np.max(np.abs(drawn.link_rotation - tracked.link_rotation)[ok][:, held]) <= 1e-10
    for md in motion.modes:
        idx = np.nonzero(md.assembles)[0]
        assert idx.size and _residual(mech, md.conf.take(idx)) <= 1e-10
        assert np.all(np.isnan(md.link_origin[~md.assembles]))
    # the modes are told apart: no two coincide at a sample where both assemble
    for a in range(len(motion.modes)):
        for b in range(a):
            both = motion.modes[a].assembles & motion.modes[b].assembles
            d = np.abs(motion.modes[a].link_origin - motion.modes[b].link_origin)[both]
            assert np.all(np.max(d.reshape(both.sum(), -1), axis=1) > 1e-6 * mech.length_scale)


def test_watt_sixbar_has_four_modes_and_the_folds_of_the_second_dyad() -> None:
    spec = sk.load_spec(MECHANISMS / "watt_sixbar.toml")
    mech = spec.mechanism
    theta = np.radians(np.arange(0.0, 360.0, 0.5))
    motion = solve_mechanism(mech, theta, every_mode=True)
    labels = [md.label for md in motion.modes]
    assert labels == ["drawn", "branches A–B–OB +, E–G–F −", "branches A–B–OB −, E–G–F +",
                      "branches A–B–OB −, E–G–F −"]
    assert [int(md.assembles.sum()) for md in motion.modes[:2]] == [720, 720]
    # the four-bar's other branch folds the E–G–F dyad: modes 2 and 3 die and are born there,
    # at the same inputs (the two branches of that dyad meet at its fold)
    e2, e3 = motion.modes[2].events, motion.modes[3].events
    assert len(e2) == 2 and [e.split(":")[0] for e in e2] == [e.split(":")[0] for e in e3]
    assert e2[0].startswith("dies at OA.theta = ") and "E–G–F folds" in e2[0]
    assert e2[1].startswith("is born at OA.theta = ")
    # modes 2 and 3 meet at those folds: one circuit; the others are circuits of their own
    assert motion.notes[1].endswith(": {0}, {1}, {2, 3}")
    # the batched every-mode poses agree on where each mode assembles
    lay = graph_layout(mech)
    em = every_mode(mech, lay, decompose(mech), theta[:, None])
    assert em.count == 4 and em.assembles(theta.size).sum(axis=1).tolist()[:2] == [720, 720]


def _fourbar(a: float, b: float, c: float, d: float) -> Mechanism:
    """A four-bar (crank a at O, coupler b, rocker c pivoted at (d, 0)) drawn at crank 90°."""
    A = np.array([0.0, a, 0.0])
    D = np.array([d, 0.0, 0.0])
    e = D - A
    f = np.linalg.norm(e)
    along = (f ** 2 + b ** 2 - c ** 2) / (2 * f)
    B = A + along * e / f + np.sqrt(b ** 2 - along ** 2) * np.array([-e[1], e[0], 0.0]) / f
    return Mechanism("4R", (Body("crank"), Body("coupler"), Body("rocker")),
                     (joint("O", "R", "ground", "crank", [0, 0, 0]),
                      joint("A", "R", "crank", "coupler", A),
                      joint("B", "R", "coupler", "rocker", B),
                      joint("D", "R", "rocker", "ground", D)), ("O.theta",),
                     (BodyPoint("P", "coupler", B),))


def test_a_fold_is_reported_where_brentq_finds_the_distance_law_root() -> None:
    a, b, c, d = 2.0, 2.5, 1.5, 3.0  # non-Grashof: the crank stops where |A − D| = b + c
    mech = _fourbar(a, b, c, d)
    theta = np.radians(np.arange(-90.0, 181.0, 1.0))  # from the drawing (crank at 90°)
    motion = solve_mechanism(mech, theta, every_mode=True)

    def reach_gap(t: float) -> float:  # crank angle t measured from the drawing
        phi = np.pi / 2 + t
        return float(np.hypot(a * np.cos(phi) - d, a * np.sin(phi))) - (b + c)

    drawn = motion.modes[0]
    stop = int(np.argmin(drawn.assembles))
    assert stop > 0 and not drawn.assembles[stop:].any()
    root = brentq(reach_gap, theta[stop - 1], theta[stop], xtol=1e-14)
    assert drawn.events[0].startswith(f"stops assembling after input O.theta = "
                                      f"{np.degrees(theta[stop - 1]):.6g} deg")
    fold = next(e for e in drawn.events if e.startswith("dies at"))
    assert f"O.theta = {np.degrees(root):.6g} deg" in fold, (fold, np.degrees(root))
    # the same fold to 1e-12 rad from the library's bisection
    from screwkit.kinematics.graph.closed_modes import branch_combinations, fold_inputs

    lay = graph_layout(mech)
    dec = decompose(mech)
    x, dyad = fold_inputs(mech, lay, dec, theta[:, None], branch_combinations(dec)[:1],
                          np.array([stop - 1]))
    assert abs(x[0, 0] - root) <= 1e-12 and dyad[0] == 0
    # the other branch meets it there: it dies at the same input, one circuit with it
    other = motion.modes[1]
    assert any(f"O.theta = {np.degrees(root):.6g} deg" in e for e in other.events)
    # the drawn branches assemble again later in the sweep: a mode of their own, born at a fold
    again = motion.modes[2]
    assert len(motion.modes) == 3 and "drawn branches again" in again.label
    assert not (again.assembles & drawn.assembles).any()
    assert motion.notes[1].endswith(": {0, 1, 2}")


def _random_dyad_graph(rng: np.random.Generator, kind: str) -> Mechanism:
    """A crank and one random dyad of ``kind`` on it and the ground, then an RRR dyad on the
    dyad's bodies and the ground: every drawing closes (all freedoms 0)."""
    pt = lambda: np.append(rng.uniform(-1.0, 1.0, 2), 0.0)  # noqa: E731
    u = lambda: np.append(np.array([np.cos(t := rng.uniform(0, np.pi)), np.sin(t)]), 0.0)  # noqa: E731
    A, B, C, E, F, G = (pt() for _ in range(6))
    A = 0.3 * A / max(np.linalg.norm(A), 1e-3)  # a short crank: the dyads assemble often
    j = [joint("O", "R", "ground", "crank", [0, 0, 0])]
    if kind == "RRR":
        j += [joint("A", "R", "crank", "b1", A), joint("B", "R", "b1", "b2", B),
              joint("C", "R", "b2", "ground", C)]
    elif kind == "RRP":
        j += [joint("A", "R", "crank", "b1", A), joint("B", "R", "b1", "b2", B),
              joint("C", "P", "b2", "ground", C, u())]
    elif kind == "RPR":
        j += [joint("A", "R", "crank", "b1", A), joint("B", "P", "b1", "b2", B, u()),
              joint("C", "R", "b2", "ground", C)]
    else:  # PRP: a slot in the crank, a slider on the ground
        j += [joint("A", "P", "crank", "b1", A, u()), joint("B", "R", "b1", "b2", B),
              joint("C", "P", "b2", "ground", C, u())]
    j += [joint("E", "R", "b1", "b3", E), joint("G", "R", "b3", "b4", G),
          joint("F", "R", "b4", "ground", F)]
    bodies = tuple(Body(n) for n in ("crank", "b1", "b2", "b3", "b4"))
    return Mechanism(f"random {kind}", bodies, tuple(j), ("O.theta",))


@pytest.mark.parametrize("kind", ["RRR", "RRP", "RPR", "PRP"])
def test_random_dyad_graphs_every_mode_closes_and_the_tracker_stays_on_it(kind: str) -> None:
    rng = np.random.default_rng(27 + "RRR RRP RPR PRP".split().index(kind))
    theta = np.radians(np.arange(0.0, 360.0, 2.0))
    checked = 0
    for _ in range(6):
        mech = _random_dyad_graph(rng, kind)
        dec = decompose(mech)
        assert dec.complete and [d.kind for d in dec.dyads] == [kind, "RRR"]
        assert dec.mode_count == (2 if kind == "PRP" else 4)
        motion = solve_mechanism(mech, theta, every_mode=True)
        lay = graph_layout(mech)
        em = every_mode(mech, lay, dec, theta[:, None])
        margin = np.min(em.placement.discriminant, axis=1).reshape(em.count, theta.size)
        for md in motion.modes:
            idx = np.nonzero(md.assembles)[0]
            assert _residual(mech, md.conf.take(idx)) <= 1e-10
            # the tracker started on this mode, where it is furthest from a fold, follows it
            # over the next samples of its run
            nb = len(mech.bodies)
            origins = em.placement.p.reshape(em.count, theta.size, -1, 3)[:, idx, :nb]
            m = int(np.argmin(np.max(np.abs(origins - md.link_origin[idx]), axis=(1, 2, 3))))
            k = int(idx[np.argmax(margin[m, idx])])
            for step in range(1, 6):
                if k + step >= theta.size or not md.assembles[k + step]:
                    break
                got = reach(mech, lay, md.conf.take(slice(k + step - 1, k + step)),
                            theta[k + step - 1:k + step], theta[k + step:k + step + 1])
                assert got is not None
                diff = np.abs(got.scalars[0] - md.conf.scalars[k + step])
                assert np.max(diff) <= 1e-8, (kind, md.label, step, diff)
                checked += 1
    assert checked >= 20


def test_a_planar_mechanism_drawn_tilted_in_space_is_still_planar() -> None:
    mech = sk.load_spec(MECHANISMS / "watt_sixbar.toml").mechanism
    rot = Rotation.from_rotvec([0.4, -0.7, 0.2]).as_matrix()
    tilted = Mechanism("tilted Watt", mech.bodies,
                       tuple(joint(j.name, j.kind, *j.bodies, rot @ j.at + [0.01, 0.02, 0.03],
                                   rot @ j.axis) for j in mech.joints), mech.inputs)
    dec = decompose(tilted)
    assert dec.complete and np.allclose(np.abs(dec.dyads[0].normal), np.abs(rot @ Z))
    theta = np.radians(np.arange(0.0, 360.0, 3.0))
    a = solve_mechanism(mech, theta, every_mode=True)
    b = solve_mechanism(tilted, theta, every_mode=True)
    assert len(a.modes) == len(b.modes) == 4
    for ma, mb in zip(a.modes, b.modes, strict=True):
        assert np.array_equal(ma.assembles, mb.assembles)
        ok = ma.assembles
        assert np.max(np.abs(ma.conf.scalars - mb.conf.scalars)[ok]) <= 1e-10


def test_an_axis_tilted_off_parallel_falls_back_to_the_tracker() -> None:
    mech = sk.load_spec(MECHANISMS / "fourbar_graph.toml").mechanism
    joints = list(mech.joints)
    j = joints[2]
    joints[2] = joint(j.name, j.kind, *j.bodies, j.at, j.axis + [1e-6, 0.0, 0.0])
    bent = Mechanism("bent", mech.bodies, tuple(joints), mech.inputs)
    assert not decompose(bent).complete
    motion = solve_mechanism(bent, [0.0], every_mode=True)
    assert motion.method == "graph" and len(motion.modes) == 1
    assert motion.notes and "only the drawn mode" in motion.notes[0]


def test_a_slider_driven_slider_crank_matches_the_tracker() -> None:
    """A driven P joint places its body; the RRR dyad on it gives both modes."""
    mech = Mechanism("slider-driven", (Body("slider"), Body("rod"), Body("crank")),
                     (joint("S", "P", "ground", "slider", [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                      joint("B", "R", "slider", "rod", [2.0, 0.0, 0.0]),
                      joint("A", "R", "rod", "crank", [0.6, 0.8, 0.0]),
                      joint("O", "R", "crank", "ground", [0.0, 0.0, 0.0])), ("S.s",))
    dec = decompose(mech)
    assert dec.complete and [d.kind for d in dec.dyads] == ["RRR"]
    s = np.linspace(-0.6, 0.9, 61)
    motion = solve_mechanism(mech, s, every_mode=True)
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, s[:, None])
    ok = followed.mask
    assert np.array_equal(motion.modes[0].assembles, ok)
    assert np.max(np.abs(motion.modes[0].conf.scalars - followed.conf.scalars)[ok]) <= 1e-10
    # the crank angle by the cosine rule in the triangle O–A–B (OA = 1, AB = √2.6, OB = 2 + s)
    crank = motion.variable("O.theta", 0)[ok]
    B = 2.0 + s[ok]
    phi = np.arccos((1.0 + B ** 2 - 2.6) / (2.0 * B))  # A above the x axis, as drawn
    drawn = np.arctan2(0.8, 0.6)
    assert np.max(np.abs(-crank - (phi - drawn))) <= 1e-10  # O turns the ground on the crank
    for md in motion.modes:
        assert _residual(mech, md.conf.take(np.nonzero(md.assembles)[0])) <= 1e-10


def test_an_rssr_as_a_graph_is_an_rss_leg_with_both_modes_of_the_closed_form() -> None:
    """The RSSR family's closed form (both assembly modes) against the graph's RSS leg."""
    lk = sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3)
    x = np.radians(np.arange(0.0, 360.0, 3.0))
    loop = sk.solve_motion(lk, x)
    assert len(loop.modes) == 2
    mech = mechanism_from_loop(loop, 0, 0)
    dec = decompose(mech)
    assert dec.complete and [d.kind for d in dec.dyads] == ["RSS"]
    graph = solve_mechanism(mech, x - x[0], every_mode=True)
    assert len(graph.modes) == 2
    L = mech.length_scale
    for gm in graph.modes:
        # the loop mode with the same joint centres where both assemble
        misses = []
        for md in loop.modes:
            both = gm.assembles & md.assembles
            misses.append(np.max(np.abs(gm.joint_centres[both] - md.joint_centres[both]))
                          if both.any() else np.inf)
        assert min(misses) <= 1e-10 * L, misses
        best = loop.modes[int(np.argmin(misses))]
        assert np.array_equal(gm.assembles, best.assembles)
        assert _residual(mech, gm.conf.take(np.nonzero(gm.assembles)[0])) <= 1e-10
    centres = [gm.joint_centres for gm in graph.modes]
    both = graph.modes[0].assembles & graph.modes[1].assembles
    assert np.max(np.abs(centres[0] - centres[1])[both]) > 1e-3 * L  # two distinct modes


def test_every_mode_of_too_many_dyads_falls_back_to_the_drawn_mode() -> None:
    """2^D modes: a chain of 40 RRR dyads asks for 2^40 of them; the drawn mode alone is
    solved, and the note says why."""
    joints = [joint("O", "R", "ground", "b0", [0, 0, 0])]
    bodies = [Body("b0")]
    for k in range(40):
        a, b, prev = f"a{k}", f"c{k}", f"b{k}" if k == 0 else f"c{k - 1}"
        bodies += [Body(a), Body(b)]
        joints += [joint(f"A{k}", "R", prev, a, [k + 1.0, 0.5, 0]),
                   joint(f"B{k}", "R", a, b, [k + 1.5, 1.0, 0]),
                   joint(f"C{k}", "R", b, "ground", [k + 2.0, 0.0, 0])]
    mech = Mechanism("forty dyads", tuple(bodies), tuple(joints), ("O.theta",))
    assert decompose(mech).mode_count == 2 ** 40
    motion = solve_mechanism(mech, [0.0, 0.01], every_mode=True)
    assert len(motion.modes) == 1 and motion.modes[0].assembles.all()
    assert motion.notes[0].startswith(f"every mode: only the drawn mode is solved; the "
                                      f"{2 ** 40} branch combinations would be over a limit")
    assert "time limit" in motion.notes[0]
    assert _residual(mech, motion.modes[0].conf) <= 1e-10


def test_a_five_bar_driven_by_two_cranks_by_rows_matches_the_tracker() -> None:
    """Two inputs (rows of values): both cranks driven, one RRR dyad between them."""
    mech = Mechanism("five-bar", tuple(Body(n) for n in ("left", "right", "l2", "r2")),
                     (joint("O1", "R", "ground", "left", [0, 0, 0]),
                      joint("O2", "R", "right", "ground", [2.0, 0, 0]),
                      joint("A", "R", "left", "l2", [0.3, 0.9, 0]),
                      joint("B", "R", "right", "r2", [2.2, 1.0, 0]),
                      joint("C", "R", "l2", "r2", [1.1, 2.2, 0])), ("O1.theta", "O2.theta"),
                     (BodyPoint("tool", "l2", np.array([1.1, 2.2, 0.0])),))
    t = np.linspace(0.0, 1.0, 41)
    rows = np.stack([0.6 * np.sin(2 * np.pi * t), 0.4 * (1 - np.cos(2 * np.pi * t))], axis=1)
    motion = solve_mechanism(mech, rows, every_mode=True)
    assert motion.method == "graph (closed forms)" and len(motion.modes) == 2
    lay = graph_layout(mech)
    followed = follow_drawn_mode(mech, lay, rows)
    assert followed.mask.all() and motion.modes[0].assembles.all()
    assert np.max(np.abs(motion.modes[0].conf.scalars - followed.conf.scalars)) <= 1e-10
    for md in motion.modes:
        assert _residual(mech, md.conf.take(np.nonzero(md.assembles)[0])) <= 1e-10


def _random_rssr(rng: np.random.Generator) -> Mechanism:
    """A spatial RSSR: random axes and ball centres (every drawing closes)."""
    ax = lambda: rng.normal(size=3)  # noqa: E731
    O, Ac, Bc, D = (rng.uniform(-1.0, 1.0, 3) for _ in range(4))
    Ac = O + 0.3 * (Ac - O) / np.linalg.norm(Ac - O)  # a short crank
    return Mechanism("random RSSR", (Body("crank"), Body("rod"), Body("rocker")),
                     (joint("O", "R", "ground", "crank", O, ax()),
                      joint("A", "S", "crank", "rod", Ac),
                      joint("B", "S", "rod", "rocker", Bc),
                      joint("D", "R", "rocker", "ground", D, ax())), ("O.theta",))


def _random_rssp(rng: np.random.Generator) -> Mechanism:
    """A spatial RSSP: a crank driving a slider on a random rail through an S–S rod."""
    ax = lambda: rng.normal(size=3)  # noqa: E731
    O, Ac, Bc = (rng.uniform(-1.0, 1.0, 3) for _ in range(3))
    Ac = O + 0.3 * (Ac - O) / np.linalg.norm(Ac - O)
    return Mechanism("random RSSP", (Body("crank"), Body("rod"), Body("slider")),
                     (joint("O", "R", "ground", "crank", O, ax()),
                      joint("A", "S", "crank", "rod", Ac),
                      joint("B", "S", "rod", "slider", Bc),
                      joint("P", "P", "slider", "ground", Bc, ax())), ("O.theta",))


def _random_wishbone(rng: np.random.Generator) -> Mechanism:
    """The bundled double wishbone with every hardpoint moved by up to 5 % of its size."""
    mech = sk.load_spec(MECHANISMS / "double_wishbone.toml").mechanism
    L = mech.length_scale
    joints = tuple(joint(j.name, j.kind, *j.bodies, j.at + rng.uniform(-0.05, 0.05, 3) * L,
                         j.axis) for j in mech.joints)
    return Mechanism("random wishbone", mech.bodies, joints, mech.inputs)


@pytest.mark.parametrize("shape", ["RSSR", "RSSP", "wishbone"])
def test_random_spatial_legs_every_mode_closes_and_the_tracker_stays_on_it(shape: str) -> None:
    rng = np.random.default_rng({"RSSR": 2027, "RSSP": 2029, "wishbone": 2028}[shape])
    build, kinds = {"RSSR": (_random_rssr, ["RSS"]), "RSSP": (_random_rssp, ["PSS"]),
                    "wishbone": (_random_wishbone, ["RSS", "SS"])}[shape]
    checked = 0
    for _ in range(8):
        mech = build(rng)
        dec = decompose(mech)
        assert dec.complete and [d.kind for d in dec.dyads] == kinds
        L = mech.length_scale
        x = np.linspace(0.0, 0.04, 41) / L if shape == "wishbone" else np.linspace(0.0, 1.0, 41)
        motion = solve_mechanism(mech, x, every_mode=True)
        lay = graph_layout(mech)
        for md in motion.modes:
            idx = np.nonzero(md.assembles)[0]
            assert _residual(mech, md.conf.take(idx)) <= 1e-10
            k = int(idx[idx.size // 2])
            for step in range(1, 4):
                if k + step >= x.size or not md.assembles[k + step]:
                    break
                got = reach(mech, lay, md.conf.take(slice(k + step - 1, k + step)),
                            x[k + step - 1:k + step], x[k + step:k + step + 1])
                if got is None:
                    continue  # the tracker cannot step here (next to a fold or singular)
                centres = graph_forward(mech, lay, got).centres[0]
                assert np.max(np.abs(centres - md.joint_centres[k + step])) <= 1e-8 * L
                checked += 1
    assert checked >= 20


def _circle_meets(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> list[np.ndarray]:
    """The points (2D) where two circles meet: none, or two (a tangency is not counted)."""
    w = c2 - c1
    f = float(np.hypot(*w))
    if not abs(r1 - r2) < f < r1 + r2:
        return []
    along = (f ** 2 + r1 ** 2 - r2 ** 2) / (2 * f)
    h = np.sqrt(r1 ** 2 - along ** 2)
    mid, across = c1 + along * w / f, np.array([-w[1], w[0]]) / f
    return [mid + h * across, mid - h * across]


def test_a_re_entered_branch_combination_is_a_mode_each_time_it_assembles() -> None:
    """Issue 27's re-entry on a dyad-built graph (two loops: no loop route): a non-Grashof
    four-bar (crank 2, coupler 2.6, rocker 1.4, frame 3: the crank turns only within
    15.6° … 104.5° and its mirror) with an RRR dyad from its coupler to the ground, drawn at
    crank 90° and driven 0° … 380° from there. The drawn branches die 14.48° on, assemble again
    within the mirror interval and again one turn on: with every mode, each sample is held by
    as many modes as circles meet there (the four-bar's B on circles about A and D, then the
    dyad's G on circles about E and F, counted per B), the drawn mode stops at its first fold,
    and the drawn branches' later runs are one mode of their own, born at a fold."""
    a, b, c, d = 2.0, 2.6, 1.4, 3.0
    fb = _fourbar(a, b, c, d)
    A0, B0, D0 = (fb.joints[i].at[:2] for i in (1, 2, 3))
    E0 = 0.5 * (A0 + B0) + np.array([0.0, 0.4])
    G0, F0 = np.array([1.0, 3.2]), np.array([-1.0, 2.0])
    mech = Mechanism("re-entering six-bar", (*fb.bodies, Body("b3"), Body("b4")),
                     (*fb.joints, joint("E", "R", "coupler", "b3", [*E0, 0.0]),
                      joint("G", "R", "b3", "b4", [*G0, 0.0]),
                      joint("F", "R", "b4", "ground", [*F0, 0.0])), ("O.theta",))
    assert [dy.kind for dy in decompose(mech).dyads] == ["RRR", "RRR"]
    t = np.radians(np.arange(0.0, 381.0, 5.0))
    motion = solve_mechanism(mech, t, every_mode=True)
    assert motion.method == "graph (closed forms)"

    u0 = (B0 - A0) / b
    local = np.array([(E0 - A0) @ u0, u0[0] * (E0 - A0)[1] - u0[1] * (E0 - A0)[0]])
    eg, gf = float(np.hypot(*(G0 - E0))), float(np.hypot(*(F0 - G0)))
    expected = []
    for phi in np.pi / 2 + t:
        A = a * np.array([np.cos(phi), np.sin(phi)])
        count = 0
        for B in _circle_meets(A, b, D0, c):
            u = (B - A) / b
            E = A + local[0] * u + local[1] * np.array([-u[1], u[0]])
            count += len(_circle_meets(E, eg, F0, gf))
        expected.append(count)
    held = np.sum([md.assembles for md in motion.modes], axis=0)
    assert held.tolist() == expected
    assert {0, 2, 4} <= set(expected)  # dead, one four-bar branch, both
    assert len(motion.modes) == 5
    drawn, again = motion.modes[0], motion.modes[4]
    stop = int(np.argmin(drawn.assembles))
    assert stop == 3 and not drawn.assembles[stop:].any()  # dies 14.48° on (crank at 104.48°)
    assert "the drawn branches again" in again.label and again.label.startswith(
        "branches A–B–D +, E–G–F +")
    assert again.assembles[stop:].any() and not again.assembles[:stop].any()
    # the fold the drawn mode stops at is the four-bar's (|A − D| = b + c), not the dyad's
    # placed on it
    root = np.degrees(np.arccos((a ** 2 + d ** 2 - (b + c) ** 2) / (2 * a * d))) - 90.0
    assert f"dies at O.theta = {root:.6g} deg: the RRR dyad A–B–D folds" in drawn.events[1]
    assert again.events[0].startswith("is born at")
    # one turn on, the drawn branches' pose is the drawn mode's (the same branch, no switch)
    turn = int(np.flatnonzero(np.isclose(t, t[0] + 2 * np.pi))[0])
    assert again.assembles[turn:turn + stop].all()
    assert np.abs(again.link_origin[turn:turn + stop] - drawn.link_origin[:stop]).max() <= 1e-9
    assert np.abs(again.link_rotation[turn:turn + stop] - drawn.link_rotation[:stop]).max() \
        <= 1e-9
    for md in motion.modes:
        idx = np.nonzero(md.assembles)[0]
        assert _residual(mech, md.conf.take(idx)) <= 1e-10
