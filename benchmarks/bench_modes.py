"""Every assembly mode by the homotopy (issue 27), on the closures of kinematics/modes/:

- Stewart–Gough forward kinematics, every one of the 40 complex poses, one instance alone and a
  batch (``SCREWKIT_BENCH_MODES_BATCH``, default 1,000: the issue's batch), by the default
  route (modes/stewart_solve.py: the elimination template, a 526 × 526 block-triangular solve
  (313 × 313 for 40 right-hand sides, 206 × 206 for one) and a 40 × 40 eigenproblem per instance, the homotopy where it falls short) and, side by
  side (alternating runs, medians), by the parameter homotopy (every instance's 40 paths in
  one call); the peer, martyushev/fkSGP (MIT; Martyushev's elimination-template solver,
  numpy/scipy), side by side on the same instances when its ``python/`` folder is found
  (``SCREWKIT_FKSGP``, or the fetched mirror under /work/.mirror), its real poses compared with
  ours;
- 6R inverse kinematics (a 6R loop), all 16 solutions, alone and in a batch of 100: by
  elimination (modes/loop6r_solve.py: a 24 × 24 eigenproblem, Raghavan & Roth 1993) and, side
  by side on the same instances (alternating runs, medians), by the parameter homotopy.

Checked: the count per instance (40, 16); for Stewart, the leg lengths of every real pose
(≤ 1e-9) and the largest distance from a homotopy pose to the template route's; for 6R, the
largest distance between the two routes' solutions. Times are CPU seconds (best of 3 alone, one run for a batch), start solutions
excluded; the Stewart batch also in elapsed (wall-clock) time, since the template spreads a
batch's chunks over the cores in threads (found once per process: their time is its own row).

The template route's Newton polish and fast α-test evaluate the Stewart system from its 9 × 9
quadric matrices (modes/stewart_solve.py's ``dense_quadrics``), not the 489-term table.

Targets (issue 27): Stewart ≤ 5 ms alone, ≤ 0.5 ms per instance in the batch of 1,000 (fkSGP
12–14 ms per instance); 6R ≤ 1 ms per instance.

Both systems are quadrics, so the tracker evaluates them densely (algebraic/quadrics.py) and,
with numba installed (the ``fast`` extra), runs its step loop compiled (algebraic/compiled.py;
its first-call compile time is a row of its own, excluded elsewhere). The rows "numpy route"
run the same solves with ``TrackOptions(compiled=False)`` (the vectorised numpy tracker, the
same algorithm) on the same instances, side by side; the rows "sparse evaluation" with
``TrackOptions(dense=False, compiled=False)`` (the term-table evaluation used before that). BLAS runs on one thread
(OPENBLAS_NUM_THREADS=1, set before numpy loads unless already set): the products here are
small, and extra BLAS threads only add spinning CPU time to the measured process time.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import importlib.util
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from screwkit.algebraic import compiled  # noqa: E402
from screwkit.algebraic.path import TrackOptions  # noqa: E402
from screwkit.algebraic.solve import solve_all  # noqa: E402
from screwkit.algebraic.track import track_parameter_homotopy  # noqa: E402
from screwkit.kinematics.modes import stewart_sparse  # noqa: E402
from screwkit.kinematics.modes.loop6r import (  # noqa: E402
    loop6r_start,
    loop6r_system,
    random_loop6r,
)
from screwkit.kinematics.modes.loop6r_solve import ELIMINATION, solve_loop6r  # noqa: E402
from screwkit.kinematics.modes.stewart import (  # noqa: E402
    leg_lengths,
    pose_from_study,
    random_stewart,
    stewart_start,
    stewart_system,
)
from screwkit.kinematics.modes.stewart_solve import TEMPLATE, solve_stewart  # noqa: E402
from screwkit.kinematics.modes.stewart_template import THREADS as TEMPLATE_THREADS  # noqa: E402

BATCH = int(os.environ.get("SCREWKIT_BENCH_MODES_BATCH", "1000"))
BATCH_6R = 100
#: the single-instance calls behind one 6R 'alone' time (the mean per call)
ALONE_6R = 10
#: and behind one Stewart 'alone' time
ALONE_STEWART = 5
#: instances of the side-by-side run with the sparse evaluation
SPARSE_BATCH = 20
SPARSE = TrackOptions(dense=False, compiled=False)
NUMPY = TrackOptions(compiled=False)
#: instances of the side-by-side batch run on the numpy route
NUMPY_BATCH = 100
MIRROR = Path("/work/.mirror/martyushev+fkSGP/repo")


def _best(fn: Any, repeats: int = 3) -> float:
    best = math.inf
    for _ in range(repeats):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def _fksgp() -> Any | None:
    """fkSGP's solver66 module, or None when its code is not on this machine. Its package
    __init__ imports a test script that needs Python 3.12, so the package is made by hand."""
    folder = os.environ.get("SCREWKIT_FKSGP")
    if folder is None and MIRROR.exists():
        out = Path(tempfile.mkdtemp(prefix="fksgp"))
        archive = subprocess.run(["git", "-C", str(MIRROR), "archive", "HEAD", "python"],
                                 capture_output=True, check=False)
        if archive.returncode != 0:
            return None
        subprocess.run(["tar", "-x", "-C", str(out)], input=archive.stdout, check=True)
        folder = str(out / "python")
    if folder is None or not (Path(folder) / "solver66.py").exists():
        return None
    spec = importlib.machinery.ModuleSpec("fksgp", None, is_package=True)
    package = importlib.util.module_from_spec(spec)
    package.__path__ = [folder]
    sys.modules["fksgp"] = package
    return importlib.import_module("fksgp.solver66")


def _stewart_rows() -> list[dict[str, Any]]:
    system = stewart_system()
    t0 = time.process_time()
    start = stewart_start()
    t_start = time.process_time() - t0
    rng = np.random.default_rng(0)
    p, _ = random_stewart(rng, BATCH)
    p = p.real
    t0 = time.process_time()
    solve_all(system, p[0], start)  # the first call compiles the step loop (numba)
    t_compile = time.process_time() - t0
    solve_stewart(p[:2])  # the template's layout and block order, once per process
    # the default route (the elimination template, the homotopy where it falls short) and the
    # homotopy alone, alternating (medians: the load moves); one instance per call
    alone = _median_of_alternating(
        {"template": lambda: [solve_stewart(p[i]) for i in range(ALONE_STEWART)],
         "hom": lambda: [solve_all(system, p[i], start) for i in range(ALONE_STEWART)]}, 5)
    t_alone, h_alone = alone["template"] / ALONE_STEWART, alone["hom"] / ALONE_STEWART
    paths = np.repeat(p[:1], start.generic_count, axis=0)
    # tracking alone against the whole solve, in alternating pairs (medians: the load moves)
    pairs = [(_best(lambda: track_parameter_homotopy(system, start.p, paths, start.x), 1),
              _best(lambda: solve_all(system, p[0], start), 1)) for _ in range(5)]
    t_track = float(np.median([a for a, _ in pairs]))
    t_rest = float(np.median([b - a for a, b in pairs]))
    steps = track_parameter_homotopy(system, start.p, paths, start.x).steps
    t_numpy_alone = _best(lambda: solve_all(system, p[0], start, NUMPY))
    nb = min(NUMPY_BATCH, BATCH)
    t0 = time.process_time()
    solve_all(system, p[:nb], start, NUMPY)
    t_numpy_batch = (time.process_time() - t0) / nb
    side = _median_of_alternating({"template": lambda: solve_stewart(p[:nb]),
                                   "hom": lambda: solve_all(system, p[:nb], start)}, 3)
    t_fast_batch, t_tmpl_nb = side["hom"] / nb, side["template"] / nb
    hom = solve_all(system, p[:nb], start)
    t0, w0 = time.process_time(), time.perf_counter()
    sol = solve_stewart(p)
    t_batch = (time.process_time() - t0) / BATCH
    w_batch = (time.perf_counter() - w0) / BATCH
    complete = int((sol.found == 40).sum())
    by_template = sum(r == TEMPLATE for r in sol.route)
    # the batch with the sparse elimination off (every instance by the LAPACK route) and on,
    # alternating (CPU time; medians of 3: the load moves)
    routes: dict[bool, list[float]] = {}
    for on in (False, True) * 3:
        stewart_sparse.AVAILABLE = on and compiled.AVAILABLE
        t0 = time.process_time()
        solve_stewart(p)
        routes.setdefault(on, []).append((time.process_time() - t0) / BATCH)
    stewart_sparse.AVAILABLE = compiled.AVAILABLE
    t_lapack, t_sparse_route = (float(np.median(routes[k])) for k in (False, True))
    gap = 0.0
    for b in range(nb):  # every homotopy solution within reach of one of the template route's
        a, h = sol.of(b), hom.of(b)
        d = np.abs(h[:, None] - a[None]).max(axis=2) / (1.0 + np.abs(h).max(axis=1)[:, None])
        gap = max(gap, float(d.min(axis=1).max(initial=0.0)))
    R, t = pose_from_study(sol.x[sol.real].real)
    inst = sol.instance[sol.real]
    L = leg_lengths(R, t, p[inst, :18].reshape(-1, 6, 3), p[inst, 18:36].reshape(-1, 6, 3))
    legs = float(np.abs(L - np.sqrt(p[inst, 36:])).max(initial=0.0))
    t_sparse_alone = _best(lambda: solve_all(system, p[0], start, SPARSE), repeats=1)
    t0 = time.process_time()
    solve_all(system, p[:SPARSE_BATCH], start, SPARSE)
    t_sparse = (time.process_time() - t0) / SPARSE_BATCH
    t0 = time.process_time()
    solve_all(system, p[:SPARSE_BATCH], start, NUMPY)
    t_dense = (time.process_time() - t0) / SPARSE_BATCH
    route = "compiled (numba)" if compiled.AVAILABLE else "numpy (numba absent)"
    rows = [
        {"name": "Stewart start: monodromy to 40", "value": t_start * 1e3, "unit": "ms",
         "target": "", "note": start.how_found + " (the homotopy's; the template needs none)"},
        {"name": "first solve (numba compiles or loads the step loop)",
         "value": t_compile * 1e3, "unit": "ms", "target": "", "note": route},
        {"name": "Stewart FK, 40 poses, alone", "value": t_alone * 1e3, "unit": "ms",
         "target": "≤ 5", "note": ("PASS" if t_alone <= 5e-3 else "MISS")
         + f"; elimination template (homotopy fallback); one instance per call, mean of "
           f"{ALONE_STEWART} calls, median of 5 alternating with the homotopy"},
        {"name": "Stewart FK by the homotopy, alone", "value": h_alone * 1e3, "unit": "ms",
         "target": "", "note": f"{h_alone / t_alone:.1f}× the template route alone; {route}"},
        {"name": "Stewart FK alone, tracking only (track_parameter_homotopy)",
         "value": t_track * 1e3, "unit": "ms", "target": "",
         "note": f"{steps.mean():.1f} steps per path; the rest of the solve (α-test, "
                 f"duplicates, residuals) {t_rest * 1e3:.1f} ms (medians of 5 pairs)"},
        {"name": f"Stewart FK, 40 poses, batch of {BATCH}", "value": t_batch * 1e3,
         "unit": "ms/instance", "target": "≤ 0.5",
         "note": ("PASS" if t_batch <= 5e-4 else "MISS")
         + f"; {by_template}/{BATCH} by the template, {complete}/{BATCH} with 40; real "
           f"poses' legs within {legs:.1e}"},
        {"name": f"Stewart FK, 40 poses, batch of {BATCH}, wall clock", "value": w_batch * 1e3,
         "unit": "ms/instance", "target": "≤ 0.5",
         "note": ("PASS" if w_batch <= 5e-4 else "MISS")
         + f"; the same run's elapsed time: the template's chunks on {TEMPLATE_THREADS} "
           f"thread(s) (modes/stewart_template.py THREADS; the CPU row above sums them); "
           f"a shared machine's load inflates it"},
        {"name": f"Stewart FK, batch of {BATCH}, LAPACK route only", "value": t_lapack * 1e3,
         "unit": "ms/instance", "target": "",
         "note": f"every instance by the block-triangular LAPACK solve (the sparse elimination "
                 f"off): {t_lapack / t_sparse_route:.1f}× the default route's "
                 f"{t_sparse_route * 1e3:.2f} ms (CPU, medians of 3, alternating)"},
        {"name": f"Stewart FK by the homotopy, batch of {nb}", "value": t_fast_batch * 1e3,
         "unit": "ms/instance", "target": "",
         "note": f"the template route on the same {nb}: {t_tmpl_nb * 1e3:.1f} ms/instance "
                 f"({t_fast_batch / t_tmpl_nb:.1f}× faster; median of 3, alternating); every "
                 f"homotopy pose within {gap:.0e} (relative) of one of its "
                 f"({int((hom.found == 40).sum())}/{nb} with 40)"},
        {"name": "Stewart FK alone, numpy route", "value": t_numpy_alone * 1e3, "unit": "ms",
         "target": "", "note": f"the homotopy: {t_numpy_alone / h_alone:.1f}× its compiled "
                               "route"},
        {"name": f"Stewart FK batch of {nb}, numpy route", "value": t_numpy_batch * 1e3,
         "unit": "ms/instance", "target": "",
         "note": f"the homotopy: {t_numpy_batch / t_fast_batch:.1f}× its compiled route"},
        {"name": "Stewart FK alone, sparse evaluation", "value": t_sparse_alone * 1e3,
         "unit": "ms", "target": "",
         "note": f"{t_sparse_alone / t_numpy_alone:.1f}× the dense numpy route"},
        {"name": f"Stewart FK batch of {SPARSE_BATCH}, sparse vs dense (numpy)",
         "value": t_sparse * 1e3, "unit": "ms/instance", "target": "",
         "note": f"dense {t_dense * 1e3:.1f} ms/instance: {t_sparse / t_dense:.1f}× faster"},
    ]
    peer = _fksgp()
    if peer is None:
        rows.append({"name": "fkSGP (peer)", "value": None, "unit": "", "target": "",
                     "note": "not available: set SCREWKIT_FKSGP to its python/ folder"})
        return rows
    n = min(BATCH, 100)
    # fkSGP wants the first base and platform points at the origin: shift both frames
    A = p[:n, :18].real.reshape(n, 6, 3)
    B = p[:n, 18:36].real.reshape(n, 6, 3)
    L2 = p[:n, 36:].real
    t0 = time.process_time()
    peer_real = [peer.solver66(A[b] - A[b, 0], B[b] - B[b, 0], L2[b], 1)[0] for b in range(n)]
    t_peer = (time.process_time() - t0) / n
    agree = sum(len(peer_real[b]) == int(sol.real_count[b]) for b in range(n))
    rows.append({"name": "fkSGP (peer), real poses", "value": t_peer * 1e3,
                 "unit": "ms/instance", "target": "",
                 "note": f"real-pose counts equal to ours on {agree}/{n} instances"})
    return rows


def _median_of_alternating(fns: dict[str, Any], rounds: int = 3) -> dict[str, float]:
    """CPU seconds of each function, run alternately ``rounds`` times: the median per name."""
    times: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(rounds):
        for name, fn in fns.items():
            t0 = time.process_time()
            fn()
            times[name].append(time.process_time() - t0)
    return {name: float(np.median(v)) for name, v in times.items()}


def _loop6r_rows() -> list[dict[str, Any]]:
    system = loop6r_system()
    p, _ = random_loop6r(np.random.default_rng(1), BATCH_6R)
    p = p.real
    solve_loop6r(p[:2])  # the eigen route's fixed bases, once per process
    t0 = time.process_time()
    start = loop6r_start()
    t_start = time.process_time() - t0
    solve_all(system, p[0], start)  # compile (or load) the step loop for this layout
    # alone: one instance per call, ALONE_6R calls on as many instances, the mean per call
    # (a single call right after the other route's is the cold-cache worst case, not the
    # per-call cost of a caller solving instances one at a time)
    alone = _median_of_alternating(
        {"elim": lambda: [solve_loop6r(p[i]) for i in range(ALONE_6R)],
         "hom": lambda: [solve_all(system, p[i], start) for i in range(ALONE_6R)]}, 5)
    alone = {name: t / ALONE_6R for name, t in alone.items()}
    batch = _median_of_alternating({"elim": lambda: solve_loop6r(p),
                                    "hom": lambda: solve_all(system, p, start)}, 3)
    t_alone, t_batch = alone["elim"], batch["elim"] / BATCH_6R
    h_alone, h_batch = alone["hom"], batch["hom"] / BATCH_6R
    sol, hom = solve_loop6r(p), solve_all(system, p, start)
    by_elim = sum(r == ELIMINATION for r in sol.route)
    complete = int((sol.found == 16).sum())
    gap = 0.0
    for b in range(BATCH_6R):  # every solution of either route within reach of the other's
        a, h = sol.of(b), hom.of(b)
        d = np.abs(a[:, None] - h[None]).max(axis=2) / (1.0 + np.abs(a).max(axis=1)[:, None])
        gap = max(gap, float(d.min(axis=1).max()), float(d.min(axis=0).max()))
    t_numpy_alone = _best(lambda: solve_all(system, p[0], start, NUMPY))
    t0 = time.process_time()
    solve_all(system, p, start, NUMPY)
    t_numpy_batch = (time.process_time() - t0) / BATCH_6R
    t_sparse_alone = _best(lambda: solve_all(system, p[0], start, SPARSE), repeats=1)
    t0 = time.process_time()
    solve_all(system, p[:SPARSE_BATCH], start, SPARSE)
    t_sparse = (time.process_time() - t0) / SPARSE_BATCH
    return [
        {"name": "6R IK by elimination, 16 solutions, alone", "value": t_alone * 1e3,
         "unit": "ms", "target": "≤ 1", "note": ("PASS" if t_alone <= 1e-3 else "MISS")
         + f"; one instance per call, mean of {ALONE_6R} calls; median of 5, alternating "
         "with the homotopy"},
        {"name": f"6R IK by elimination, 16 solutions, batch of {BATCH_6R}",
         "value": t_batch * 1e3, "unit": "ms/instance", "target": "≤ 1",
         "note": ("PASS" if t_batch <= 1e-3 else "MISS")
         + f"; {by_elim}/{BATCH_6R} by elimination, {complete}/{BATCH_6R} with 16, all within "
         f"{gap:.0e} (relative) of the homotopy's; median of 3, alternating"},
        {"name": "6R start: monodromy to 16 (the homotopy's)", "value": t_start * 1e3,
         "unit": "ms", "target": "", "note": start.how_found},
        {"name": "6R IK by the homotopy, alone", "value": h_alone * 1e3, "unit": "ms",
         "target": "", "note": f"{h_alone / t_alone:.1f}× the elimination alone"},
        {"name": f"6R IK by the homotopy, batch of {BATCH_6R}", "value": h_batch * 1e3,
         "unit": "ms/instance", "target": "",
         "note": f"{h_batch / t_batch:.1f}× the elimination batch; "
         f"{int((hom.found == 16).sum())}/{BATCH_6R} with 16"},
        {"name": "6R IK alone, homotopy, numpy route", "value": t_numpy_alone * 1e3,
         "unit": "ms", "target": "", "note": f"{t_numpy_alone / h_alone:.1f}× the compiled"},
        {"name": f"6R IK batch of {BATCH_6R}, homotopy, numpy route",
         "value": t_numpy_batch * 1e3, "unit": "ms/instance", "target": "",
         "note": f"{t_numpy_batch / h_batch:.1f}× the compiled batch"},
        {"name": "6R IK alone, homotopy, sparse evaluation", "value": t_sparse_alone * 1e3,
         "unit": "ms", "target": "",
         "note": f"{t_sparse_alone / t_numpy_alone:.1f}× the dense numpy route"},
        {"name": f"6R IK batch of {SPARSE_BATCH}, homotopy, sparse evaluation",
         "value": t_sparse * 1e3, "unit": "ms/instance", "target": "", "note": ""},
    ]


def run() -> list[dict[str, Any]]:
    return _stewart_rows() + _loop6r_rows()


if __name__ == "__main__":
    for row in run():
        print(row)
