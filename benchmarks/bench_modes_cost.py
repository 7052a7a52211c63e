"""The cost of every mode on the bundled Stewart example (issue 27, "cost of every mode"): the
every-mode motion of examples/mechanisms/stewart_platform.toml (the homotopy at 8 anchors,
tracking between them; what ``analyze``, ``report`` and ``export`` run by default) against its
drawn mode alone (``--modes drawn``), and the anchors' homotopy batch with equal rows solved
once (every_mode) against every row solved (the closed motion's first and last rows are
equal). CPU seconds, one run each, the start solutions (monodromy, once per topology) found
before the timings; OPENBLAS_NUM_THREADS=1 as in bench_modes.py.

Measured at the change (a shared 2-core machine, two runs): start 2.6–2.8 s; anchors 4.7–5.6 s
with every row solved → 4.3 s with the equal rows once; the every-mode motion 14.8–15.1 s; the
drawn mode 0.03 s.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

SPEC = Path(__file__).resolve().parents[1] / "examples" / "mechanisms" / "stewart_platform.toml"


def _cpu(fn: Any) -> tuple[float, Any]:
    t = time.process_time()
    out = fn()
    return time.process_time() - t, out


def run() -> list[dict[str, Any]]:
    import screwkit as sk
    from screwkit.kinematics.graph import solve_mechanism
    from screwkit.kinematics.modes.along import ANCHOR_SPACING
    from screwkit.kinematics.modes.every_mode import _every_mode_rows, every_mode

    spec = sk.load_spec(SPEC)
    mech, X = spec.mechanism, np.asarray(spec.inputs, dtype=float)
    t_start, _ = _cpu(lambda: every_mode(mech, X[:1]))
    anchors = np.unique(np.r_[np.arange(0, len(X), ANCHOR_SPACING), len(X) - 1])
    t_rows, rows = _cpu(lambda: _every_mode_rows(mech, X[anchors]))
    t_once, once = _cpu(lambda: every_mode(mech, X[anchors]))
    same = [a.size for a in rows.configurations] == [b.size for b in once.configurations]
    t_every, every = _cpu(lambda: solve_mechanism(mech, X, rates=spec.speed, every_mode=True))
    t_drawn, drawn = _cpu(lambda: solve_mechanism(mech, X, rates=spec.speed))
    note = f"{len(anchors)} anchors, {len(every.modes)} modes"
    return [
        {"name": "Stewart example: start solutions (monodromy, once)", "value": t_start,
         "unit": "s", "target": None, "note": "found before the rows below"},
        {"name": "Stewart example: anchor homotopy, every row solved", "value": t_rows,
         "unit": "s", "target": None, "note": f"{len(anchors)} rows, first = last"},
        {"name": "Stewart example: anchor homotopy, equal rows once", "value": t_once,
         "unit": "s", "target": None,
         "note": "same real modes per anchor" if same else "real modes per anchor DIFFER"},
        {"name": "Stewart example: every mode along the motion", "value": t_every,
         "unit": "s", "target": None, "note": note},
        {"name": "Stewart example: drawn mode only (--modes drawn)", "value": t_drawn,
         "unit": "s", "target": None, "note": f"{len(drawn.modes)} mode"},
    ]
