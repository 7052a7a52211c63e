"""Mechanism graphs (issues 26, 27): a Watt six-bar over 3 600 crank angles, both loops together,
against pylinkage on the same six-bar in the same run; every assembly mode of it from the
closed-form dyads; a single loop through the graph path against the joint-list path.

screwkit: ``solve_mechanism`` on examples/mechanisms/watt_sixbar.toml — every body's pose, every
freedom with exact rates and accelerations, every joint centre and the coupler point's path. The
six-bar decomposes into a driven crank and two RRR dyads, so its positions come from the closed
forms (kinematics/graph/dyads.py); the continuation the other graphs use (the loop engine's
Tracker on the stacked closure, graph/follow.py) is timed beside it on the same six-bar, and on
the bundled several-loop examples (six-bars, Jansen's leg, Delta robot, 3-UPU, Stewart platform). Every mode: the body poses of all 4 branch combinations at every
sample (``closed_modes.every_mode``, target ≤ 10 ms, issue 27), and the whole motion of every mode
with rates and accelerations (``every_mode=True``); every mode of the 3-UPU along its motion
(the homotopy at anchors, tracking, fold searches: wall, the homotopy's compiled tracks on the
cores against one thread); the fold search on the gapped six-bar (probes against bisection),
and on a step with no fold (heading for the step's end against halvings).
pylinkage: ``Linkage.step_fast`` (numba-compiled when numba is installed) on the same six-bar
built from a crank, two RRR dyads and two fixed points (one mode, joint positions only). Both
are checked to give the same path of joint G to 1e-9 of the length scale. Targets: ≤ 20 µs per
sample; the graph path within 1.5× the joint-list path on the same loop (a 4R, an RSRC, an RSSR
and an RCCC: both paths run the family's closed form, graph/loop_subchain.py; the two paths are
timed alternately, best of 5 each).
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

import screwkit as sk
from screwkit.kinematics.graph import small_linalg, solve_mechanism
from screwkit.kinematics.graph.closed_modes import every_mode
from screwkit.kinematics.graph.closure import graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode
from screwkit.kinematics.graph.motion import build_mode
from screwkit.kinematics.graph.subchains import decompose

ROOT = Path(__file__).resolve().parents[1]
WATT = ROOT / "examples" / "mechanisms" / "watt_sixbar.toml"
SAMPLES = 3600
REPEATS = 5


def _best(fn: Any, repeats: int = REPEATS) -> float:
    """Best CPU time of ``repeats`` calls (single-threaded work: CPU time is steadier than wall
    time on a shared machine)."""
    best = math.inf
    for _ in range(repeats):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    return math.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])


def _pylinkage(mech: Any, theta: np.ndarray) -> tuple[float | None, np.ndarray | None, str]:
    """CPU seconds of pylinkage's step_fast over ``theta`` and its path of G, or the reason."""
    try:
        from pylinkage.actuators import Crank
        from pylinkage.components import Ground
        from pylinkage.dyads import FixedDyad, RRRDyad
        from pylinkage.simulation import Linkage
    except ImportError:
        return None, None, "pylinkage not installed (make bench installs it)"
    at = {j.name: j.at[:2] for j in mech.joints}
    OA, A, B, OB, E, G, F = (at[n] for n in ("OA", "A", "B", "OB", "E", "G", "F"))
    d = np.linalg.norm
    g1, g2 = Ground(*OA, name="OA"), Ground(*OB, name="OB")
    crank = Crank(anchor=g1, radius=d(A - OA), angular_velocity=float(theta[1] - theta[0]),
                  initial_angle=math.atan2(A[1] - OA[1], A[0] - OA[0]))
    b = RRRDyad(anchor1=crank.output, anchor2=g2, distance1=d(B - A), distance2=d(B - OB),
                x=B[0], y=B[1], name="B")
    e = FixedDyad(anchor1=g2, anchor2=b, distance=d(E - OB), angle=_angle(B - OB, E - OB),
                  name="E")
    f = FixedDyad(anchor1=crank.output, anchor2=b, distance=d(F - A),
                  angle=_angle(B - A, F - A), name="F")
    g = RRRDyad(anchor1=e, anchor2=f, distance1=d(G - E), distance2=d(G - F), x=G[0], y=G[1],
                name="G")
    linkage = Linkage([g1, g2, crank, b, e, f, g], name="Watt I")
    init = linkage.get_coords()
    linkage.step_fast(iterations=10)  # compile / warm up
    linkage.set_coords(init)
    path = np.asarray(linkage.step_fast(iterations=len(theta)))
    t = _best(lambda: (linkage.set_coords(init), linkage.step_fast(iterations=len(theta))))
    return t, path, "pylinkage step_fast"


def _every_mode_rows(mech: Any, theta: np.ndarray, t_drawn: float) -> list[dict[str, Any]]:
    """The continuation path on the same six-bar, and every mode from the closed forms."""
    lay = graph_layout(mech)
    X = theta[:, None]
    ones, zeros = np.ones_like(X), np.zeros_like(X)

    def tracked() -> Any:
        f = follow_drawn_mode(mech, lay, X)
        return build_mode(mech, lay, f.conf, f.mask, X, ones, zeros, f.frames)

    t_track = _best(tracked, 3)
    drawn = solve_mechanism(mech, theta).modes[0]
    miss = float(np.max(np.abs(drawn.conf.scalars - tracked().conf.scalars)))
    dec = decompose(mech)
    t_poses = _best(lambda: every_mode(mech, lay, dec, X))
    modes = solve_mechanism(mech, theta, every_mode=True)
    t_all = _best(lambda: solve_mechanism(mech, theta, every_mode=True), 3)
    return [
        {"name": "Watt six-bar, 3 600 samples, drawn mode (graph continuation)",
         "value": t_track / SAMPLES * 1e6, "unit": "µs/sample", "target": None,
         "note": f"the tracker other graphs use; {t_track / t_drawn:.2g}x the closed forms' "
                 f"time; joint variables agree to {miss:.1e} rad"},
        {"name": "Watt six-bar: every mode's body poses over 3 600 samples (closed forms)",
         "value": t_poses * 1e3, "unit": "ms", "target": 10.0,
         "note": f"{dec.mode_count} branch combinations, every body's pose at every sample "
                 f"({t_poses / (dec.mode_count * SAMPLES) * 1e6:.2g} µs per sample and mode); "
                 "pylinkage gives one mode"},
        {"name": "Watt six-bar: every mode's motion over 3 600 samples",
         "value": t_all * 1e3, "unit": "ms", "target": None,
         "note": f"{len(modes.modes)} modes with exact rates and accelerations and their "
                 "folds located"},
    ]


def _best_pair(fn_a: Any, fn_b: Any, repeats: int = REPEATS) -> tuple[float, float]:
    """Best CPU times of ``fn_a`` and ``fn_b`` called alternately ``repeats`` times each (a
    load that comes and goes then falls on both)."""
    best_a = best_b = math.inf
    for _ in range(repeats):
        best_a = min(best_a, _best(fn_a, 1))
        best_b = min(best_b, _best(fn_b, 1))
    return best_a, best_b


def _single_loop_rows(theta: np.ndarray) -> list[dict[str, Any]]:
    """A single loop drawn as a graph against the same loop as a family (issue 26): the graph
    path hands it to the loop engine (graph/loop_subchain.py), so both run the family's closed
    form, the graph path for the drawn mode only (the closed form's branches, then the drawn
    one's positions; graph/loop_motion.py ``drawn_branch``), the joint-list path for every mode;
    the graph path adds the stacked-closure rates, singularity classes and body frames."""
    from screwkit.kinematics.graph.from_loop import mechanism_from_loop

    rows: list[dict[str, Any]] = []
    for name, lk in (("4R", sk.fourbar(a=4.0, d1=1.0, d2=3.5, d3=3.0)),
                     ("RSRC", sk.rsrc(1.0, 3.5, 2.0, 3.0, 0.5, 0.2, 0.3, 0.4)),
                     ("RSSR", sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3)),
                     ("RCCC", sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6)))):
        ok = sk.solve_motion(lk, theta).modes[0].assembles
        k0 = int(np.argmax(ok))  # the samples from the first where mode 0 assembles on
        run = theta[k0:k0 + (int(np.argmin(ok[k0:])) or ok.size - k0)]
        graph = mechanism_from_loop(sk.solve_motion(lk, run[:2]), 0, 0)
        x = run - run[0]
        assert solve_mechanism(graph, x[:50]).method == "graph (loop, closed)"
        t_graph, t_loop = _best_pair(lambda g=graph, x=x: solve_mechanism(g, x),
                                     lambda k=lk, r=run: sk.solve_motion(k, r))
        rows.append({"name": f"{name}, {run.size} samples: graph path / joint-list path",
                     "value": t_graph / t_loop, "unit": "x", "target": 1.5,
                     "note": f"both the closed form: graph {t_graph / run.size * 1e6:.3g} "
                             f"µs/sample (the drawn mode), loop {t_loop / run.size * 1e6:.3g} "
                             "µs/sample (every mode)"})
    rows += _loop_engine_rows(theta)
    return rows


def _loop_engine_rows(theta: np.ndarray) -> list[dict[str, Any]]:
    """The drawn mode of a single loop without a closed form: followed by the loop engine's
    continuation on the loop in frame form (graph/loop_track.py, the route solve_mechanism takes)
    against the same engine on the graph's stacked closure (graph/follow.py), both with the
    graph's build (rates, accelerations, singular classes), alternated 5 times, median CPU time:
    an RCCC driven at a cylinder over 28° and an RSSR in frame form over a turn (the frame form
    also holds its rod's idle spin, which minimum-norm steps on the stacked closure let drift)."""
    from dataclasses import replace

    from screwkit.kinematics.graph.from_loop import mechanism_from_loop
    from screwkit.kinematics.graph.loop_subchain import loop_chain
    from screwkit.kinematics.graph.loop_track import follow_drawn_loop

    rccc = replace(sk.rccc((1.0, 1.5, 1.2, 1.4), (0.3, 0.5, -0.4, 0.6)), inputs=("C2.theta",),
                   family=None)
    cases = (("RCCC driven at a cylinder", mechanism_from_loop(sk.solve_motion(
                 rccc, np.radians([0.0, 2.0]))), np.linspace(0.0, np.radians(28.0), SAMPLES)),
             ("RSSR in frame form", mechanism_from_loop(sk.solve_motion(
                 sk.rssr(1.0, 3.0, 2.0, 2.5, 1.0, 0.3), theta[:2])), theta))
    rows: list[dict[str, Any]] = []
    for name, graph, x in cases:
        lay = graph_layout(graph)
        chain = loop_chain(graph, generic=True)
        assert chain is not None
        X = x[:, None]
        ones, zeros = np.ones_like(X), np.zeros_like(X)

        def engine(g: Any = graph, lay: Any = lay, c: Any = chain, X: Any = X,
                   o: Any = ones, z: Any = zeros) -> Any:
            f = follow_drawn_loop(g, lay, c, X)
            return build_mode(g, lay, f.conf, f.mask, X, o, z, f.frames)

        def tracker(g: Any = graph, lay: Any = lay, X: Any = X, o: Any = ones,
                    z: Any = zeros) -> Any:
            f = follow_drawn_mode(g, lay, X)
            return build_mode(g, lay, f.conf, f.mask, X, o, z, f.frames)

        a, b = engine(), tracker()
        ok = a.assembles & b.assembles
        miss = float(np.max(np.abs(a.conf.scalars - b.conf.scalars)[ok]))
        times: dict[str, list[float]] = {"engine": [], "tracker": []}
        for _ in range(5):
            times["engine"].append(_best(engine, 1))
            times["tracker"].append(_best(tracker, 1))
        t_e, t_t = (float(np.median(times[k])) for k in ("engine", "tracker"))
        rows.append({"name": f"{name}, drawn, {x.size} samples: frame form / stacked closure",
                     "value": t_e / t_t, "unit": "x", "target": 1.0,
                     "note": f"frame form {t_e / x.size * 1e6:.3g} µs/sample, stacked closure "
                             f"{t_t / x.size * 1e6:.3g} µs/sample (each with the graph's build; "
                             f"median of 5 alternated); joint variables agree to {miss:.1e}"})
    return rows


def _rsrc_with_leg() -> Any:
    """An RSRC loop driven at its ground R joint whose coupler carries an RSS leg (an arm on an
    R joint, an S–S tie rod to the ground): tests/graphs/test_loop_stage.py's "folding" case."""
    from screwkit.kinematics.graph.from_loop import mechanism_from_loop
    from screwkit.model.mechanism import Body, Mechanism, MechanismJoint

    lk = sk.rsrc(1.0, 3.5, 2.0, 3.0, 0.5, 0.2, 0.3, 0.4)
    loop = mechanism_from_loop(sk.solve_motion(lk, np.radians([0.0, 2.0])), 0, 0)
    z = np.array([0.0, 0.0, 1.0])
    leg = (MechanismJoint("K", "R", ("coupler", "arm"), np.array([-1.797, 4.77, -0.752]),
                          np.array([0.914, -0.02, -1.249])),
           MechanismJoint("T", "S", ("arm", "tie"), np.array([-1.108, 4.03, -0.026]), z),
           MechanismJoint("G", "S", ("tie", "ground"), np.array([-2.96, 1.52, 2.105]), z))
    return Mechanism("RSRC with a leg", (*loop.bodies, Body("arm"), Body("tie")),
                     (*loop.joints, *leg), loop.inputs)


def _loop_stage_poses(mech: Any, lay: Any, X: np.ndarray) -> int:
    """Every branch combination's body poses at every row (graph/loop_stage.py: the loop's
    closed form once, every combination placed in one batched pass); the combination count."""
    from screwkit.kinematics.graph.loop_motion import approach
    from screwkit.kinematics.graph.loop_stage import (
        combinations,
        loop_rows,
        place_rows,
        stage_modes,
    )

    dec = decompose(mech)
    rows = np.vstack([approach(lay, X), X])
    loops = [stage_modes(mech, lay, st, rows) for st in dec.loops]
    combos = combinations(dec, loops)
    signs = np.repeat(combos, rows.shape[0], axis=0)
    place_rows(mech, lay, dec, np.tile(rows, (combos.shape[0], 1)), signs,
               loop_rows(dec, loops, signs, np.tile(np.arange(rows.shape[0]), combos.shape[0])))
    return int(combos.shape[0])


def _loop_stage_rows(theta: np.ndarray) -> list[dict[str, Any]]:
    """A family loop inside a larger graph (issue 27): the RSRC with a leg on its coupler is
    placed by the RSRC's closed form (every loop mode) and the leg's, graph/loop_stage.py;
    before, it fell to the graph tracker (the drawn mode only: no polynomial formulation takes
    the graph, so no every-mode either). Both routes timed side by side, CPU time."""
    mech = _rsrc_with_leg()
    lay = graph_layout(mech)
    X = theta[:, None]
    ones, zeros = np.ones_like(X), np.zeros_like(X)
    assert "LoopStage" in [type(s).__name__ for s in decompose(mech).steps]

    def tracked() -> Any:
        f = follow_drawn_mode(mech, lay, X)
        return build_mode(mech, lay, f.conf, f.mask, X, ones, zeros, f.frames)

    ours = solve_mechanism(mech, theta)
    theirs = tracked()
    ok = theirs.assembles
    assert np.array_equal(ours.modes[0].assembles, ok)
    miss = float(np.max(np.abs(ours.modes[0].link_origin - theirs.link_origin)[ok][:, :4]))
    t_stage = t_track = math.inf
    for _ in range(3):  # alternated: the same load on both
        t_stage = min(t_stage, _best(lambda: solve_mechanism(mech, theta), 1))
        t_track = min(t_track, _best(tracked, 1))
    t_poses = t_follow = math.inf
    for _ in range(3):  # positions alone: every combination's poses against one followed mode
        t_poses = min(t_poses, _best(lambda: _loop_stage_poses(mech, lay, X), 1))
        t_follow = min(t_follow, _best(lambda: follow_drawn_mode(mech, lay, X), 1))
    t_every = _best(lambda: solve_mechanism(mech, theta, every_mode=True), 3)
    every = solve_mechanism(mech, theta, every_mode=True)
    n = int(ok.sum())
    return [
        {"name": f"RSRC + RSS leg, {theta.size} samples: drawn mode, loop stage / graph tracker",
         "value": t_stage / t_track, "unit": "x", "target": None,
         "note": f"loop stage {t_stage / theta.size * 1e6:.3g} µs/sample, tracker "
                 f"{t_track / theta.size * 1e6:.3g} µs/sample (both with rates, accelerations "
                 f"and singularity classes); the drawn mode assembles at {n} samples and the two "
                 f"agree to {miss / mech.length_scale:.1e} of the length"},
        {"name": f"RSRC + RSS leg, {theta.size} samples: every combination's body poses "
                 "(loop stage) / the tracker's drawn positions",
         "value": t_poses / t_follow, "unit": "x", "target": None,
         "note": f"{t_poses * 1e3:.3g} ms for the {_loop_stage_poses(mech, lay, X)} branch "
                 f"combinations at every sample against {t_follow * 1e3:.3g} ms for the drawn "
                 "mode followed (positions only; the rest, rates and singularity classes from "
                 "the stacked Jacobian, is the same on both routes)"},
        {"name": f"RSRC + RSS leg, {theta.size} samples: every mode (loop stage)",
         "value": t_every * 1e3, "unit": "ms", "target": None,
         "note": f"{len(every.modes)} modes (RSRC loop modes × leg branches, folds located), "
                 f"{t_every / t_track:.2g}x the tracker's one drawn mode; before, the drawn mode "
                 "was all (no homotopy formulation takes this graph)"},
    ]


def _stacked_rows() -> list[dict[str, Any]]:
    """The drawn modes of the bundled several-loop examples followed by the continuation on the
    stacked closure (graph/follow.py) over a straight sweep from the spec's first row to its
    farthest: CPU time per sample (best of 3), checked by the largest closure residual of the
    samples held (graph_forward's, scaled) and that the whole sweep assembles."""
    from screwkit.kinematics.graph.closure import graph_forward
    from screwkit.kinematics.graph.newton import scaled_residual

    rows: list[dict[str, Any]] = []
    for name, n in (("watt_sixbar", 3600), ("stephenson3_sixbar", 3600), ("jansen_leg", 3600),
                    ("delta_robot", 400), ("three_upu", 400), ("stewart_platform", 400)):
        spec = sk.load_spec(ROOT / "examples" / "mechanisms" / f"{name}.toml")
        Xs = np.asarray(spec.inputs, dtype=float)
        Xs = Xs[:, None] if Xs.ndim == 1 else Xs
        far = int(np.argmax(np.abs(Xs - Xs[0]).max(axis=1)))
        X = Xs[0] + np.linspace(0.0, 1.0, n)[:, None] * (Xs[far] - Xs[0])
        mech = spec.mechanism
        lay = graph_layout(mech)
        f = follow_drawn_mode(mech, lay, X)
        assert f.mask.all(), name
        res = float(np.max(np.abs(scaled_residual(mech, lay, graph_forward(mech, lay, f.conf)))))
        assert res < 1e-9, (name, res)
        t = _best(lambda m=mech, lay=lay, X=X: follow_drawn_mode(m, lay, X), 3)
        rows.append({"name": f"{name}, drawn mode, {n} samples, {X.shape[1]} input(s): "
                             "continuation on the stacked closure",
                     "value": t / n * 1e6, "unit": "µs/sample", "target": None,
                     "note": f"largest closure residual {res:.1e}"})
    return rows


def _forward_rows() -> list[dict[str, Any]]:
    """``graph_forward`` (every body pose, screw and closure twist) at one sample, the call the
    tracker, the fold searches and every-mode decoding repeat thousands of times (wall time
    per call, best of 3 runs of 300 calls, at a random configuration); and the fold search
    (modes/along_folds.py) on the gapped six-bar of tests/graphs/test_step_folds.py against
    plain bisection of the same step, side by side (reaches and wall time)."""
    from screwkit.kinematics.graph.closure import graph_forward
    from screwkit.kinematics.tracker.loop import Configuration, rotation_matrix

    rows: list[dict[str, Any]] = []
    rng = np.random.default_rng(0)
    for name in ("watt_sixbar", "jansen_leg", "delta_robot", "three_upu", "stewart_platform"):
        mech = sk.load_spec(ROOT / "examples" / "mechanisms" / f"{name}.toml").mechanism
        lay = graph_layout(mech)
        conf = Configuration(0.1 * rng.normal(size=(1, lay.n_scalar)), rotation_matrix(
            0.1 * rng.normal(size=(lay.n_spherical, 3))).reshape(1, lay.n_spherical, 3, 3))
        graph_forward(mech, lay, conf)
        best = math.inf
        for _ in range(3):
            t0 = time.perf_counter()
            for _ in range(300):
                graph_forward(mech, lay, conf)
            best = min(best, (time.perf_counter() - t0) / 300)
        rows.append({"name": f"{name}: graph_forward at one sample ({len(mech.joints)} joints, "
                             f"{len(mech.topology.chords)} loops)",
                     "value": best * 1e6, "unit": "µs/call", "target": None,
                     "note": "every joint's motion at once, the tree by levels "
                             "(graph/joint_motions.py); the per-joint loop before: ~470 µs "
                             "on the 3-UPU (docs/kinematics.md)"})
    rows.append(_fold_search_row())
    rows.append(_no_fold_row())
    rows.append(_every_mode_along_row())
    return rows


def _fold_search_row() -> dict[str, Any]:
    import sys

    from screwkit.kinematics.graph import follow
    from screwkit.kinematics.graph.closure import zero_configuration
    from screwkit.kinematics.modes import along_folds

    sys.path.insert(0, str(ROOT))
    from tests.graphs.test_step_folds import GAP, GAP_DRAWN, _sixbar

    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    x0, x1 = np.radians([60.0]), np.radians([100.0])
    conf = follow.reach(mech, lay, zero_configuration(lay), np.zeros(1), x0)
    assert conf is not None
    real, count = along_folds.reach, [0]

    def counted(*args: Any, **kwargs: Any) -> Any:
        count[0] += 1
        return real(*args, **kwargs)

    along_folds.reach = counted
    rounds = along_folds.FOLD_ROUNDS
    out: dict[int, tuple[int, float, float]] = {}
    try:
        for r in (rounds, 0, rounds, 0):  # alternating; FOLD_ROUNDS = 0 and halvings
            along_folds.FOLD_ROUNDS = r    # first: plain bisection
            along_folds.HEAD_FOR_END = r != 0
            count[0] = 0
            t0 = time.perf_counter()
            at, _ = along_folds.fold_between(mech, lay, conf, x0, x1)
            dt = time.perf_counter() - t0
            if r not in out or dt < out[r][1]:
                out[r] = (count[0], dt, float(at[0]))
    finally:
        along_folds.reach, along_folds.FOLD_ROUNDS = real, rounds
        along_folds.HEAD_FOR_END = True
    probe, plain = out[rounds], out[0]
    return {"name": "gapped six-bar: the fold between 60° and 100° of input (probes / bisection)",
            "value": probe[1] / plain[1], "unit": "x", "target": None,
            "note": f"{probe[0]} reaches against {plain[0]}, {probe[1] * 1e3:.0f} against "
                    f"{plain[1] * 1e3:.0f} ms (best of 2, wall); the two folds "
                    f"{abs(probe[2] - plain[2]):.1e} rad apart"}


def _no_fold_row() -> dict[str, Any]:
    """A step with no fold (the gapped six-bar from 0° to 20° of input) told from one: the
    first trials heading for the step's end (the gap squared) against halvings."""
    import sys

    from screwkit.kinematics.graph.closure import zero_configuration
    from screwkit.kinematics.modes import along_folds

    sys.path.insert(0, str(ROOT))
    from tests.graphs.test_step_folds import GAP, GAP_DRAWN, _sixbar

    mech = _sixbar(*GAP, GAP_DRAWN)
    lay = graph_layout(mech)
    conf = zero_configuration(lay)
    x0, x1 = np.zeros(1), np.radians([20.0])
    real, count = along_folds.reach, [0]

    def counted(*args: Any, **kwargs: Any) -> Any:
        count[0] += 1
        return real(*args, **kwargs)

    along_folds.reach = counted
    out: dict[bool, tuple[int, float]] = {}
    try:
        for head in (True, False, True, False):  # alternating
            along_folds.HEAD_FOR_END = head
            count[0] = 0
            t0 = time.perf_counter()
            assert along_folds.fold_in_step(mech, lay, conf, x0, x1) is None
            dt = time.perf_counter() - t0
            if head not in out or dt < out[head][1]:
                out[head] = (count[0], dt)
    finally:
        along_folds.reach, along_folds.HEAD_FOR_END = real, True
    new, old = out[True], out[False]
    return {"name": "gapped six-bar: a step with no fold, 0° to 20° (heading for the end / "
                    "halvings)",
            "value": new[1] / old[1], "unit": "x", "target": None,
            "note": f"{new[0]} reaches against {old[0]}, {new[1] * 1e3:.0f} against "
                    f"{old[1] * 1e3:.0f} ms (best of 2, wall); no fold either way"}


def _every_mode_along_row() -> dict[str, Any]:
    """Every mode of the bundled 3-UPU along its spec's motion (solve_mechanism, every_mode):
    wall time with the homotopy's compiled tracks on the cores (algebraic/compiled.py THREADS)
    against one thread, one run each (~25 s), the same modes."""
    from screwkit.algebraic import compiled
    from screwkit.algebraic.blas import one_blas_thread

    spec = sk.load_spec(ROOT / "examples" / "mechanisms" / "three_upu.toml")
    threads = compiled.THREADS
    out: dict[int, tuple[float, int]] = {}
    try:
        for n in (threads, 1):
            compiled.THREADS = n
            t0 = time.perf_counter()
            with one_blas_thread():  # BLAS at one thread for both (the threaded run holds it)
                got = solve_mechanism(spec.mechanism, spec.inputs, every_mode=True)
            out[n] = (time.perf_counter() - t0, len(got.modes))
    finally:
        compiled.THREADS = threads
    assert out[threads][1] == out[1][1]
    return {"name": "3-UPU, every mode along its 50 samples (solve_mechanism, every_mode)",
            "value": out[threads][0], "unit": "s", "target": None,
            "note": f"wall, the homotopy's tracks on {threads} thread(s); on one: "
                    f"{out[1][0]:.1f} s; {out[1][1]} modes either way"}


def run() -> list[dict[str, Any]]:
    spec = sk.load_spec(WATT)
    mech = spec.mechanism
    theta = np.radians(np.arange(SAMPLES) * 0.1)
    solve_mechanism(mech, theta[:50])  # warm up
    t_ours = _best(lambda: solve_mechanism(mech, theta))
    motion = solve_mechanism(mech, theta)
    rows: list[dict[str, Any]] = [{
        "name": "Watt six-bar, 3 600 samples, drawn mode (closed-form dyads)",
        "value": t_ours / SAMPLES * 1e6, "unit": "µs/sample", "target": 20.0,
        "note": f"every body, exact rates and accelerations; best of {REPEATS}, CPU time; "
                f"small matrices {'compiled' if small_linalg.AVAILABLE else 'by LAPACK'} "
                "(graph/small_linalg.py)"}]
    rows += _every_mode_rows(mech, theta, t_ours)
    t_py, path, note = _pylinkage(mech, theta)
    if t_py is None or path is None:
        rows.append({"name": "Watt six-bar: screwkit / pylinkage", "value": float("nan"),
                     "unit": "x", "target": None, "note": note})
    else:
        k = [j.name for j in mech.joints].index("G")
        ours_g = motion.modes[0].joint_centres[:, k, :2]
        # pylinkage's coordinates after step n are the crank at theta[n+1]
        theirs_g = path[:, -1, :][: SAMPLES - 1]
        miss = float(np.max(np.abs(ours_g[1:] - theirs_g))) / mech.length_scale
        rows.append({"name": "Watt six-bar: screwkit time / pylinkage time",
                     "value": t_ours / t_py, "unit": "x", "target": None,
                     "note": f"{note}: {t_py / SAMPLES * 1e6:.3g} µs/sample (one mode, "
                             f"positions only); paths of G agree to {miss:.1e} of the length"})
    rows += _single_loop_rows(theta)
    rows += _loop_stage_rows(theta)
    rows += _stacked_rows()
    rows += _forward_rows()
    return rows


if __name__ == "__main__":
    for row in run():
        print(f"{row['name']}: {row['value']:.3g} {row['unit']} (target {row['target']}) "
              f"- {row['note']}")
