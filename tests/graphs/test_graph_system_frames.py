"""graph/system.py: the poses and screws the corrector and the fill check computed are reused
(GraphSystem.frames) for the fronts' jets, the halving test's signatures and the build's frames:
the same numbers as the forward map's, row for row, whether kept, partly kept or not; and
nothing kept outlives a sweep."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import screwkit as sk
from screwkit.kinematics.graph.closure import graph_forward, graph_layout
from screwkit.kinematics.graph.follow import follow_drawn_mode, graph_system
from screwkit.kinematics.tracker.loop import Configuration

ROOT = Path(__file__).resolve().parents[2]
FIELDS = ("R", "p", "screws", "residual", "centres", "axes")


def _three_upu() -> tuple[object, object, np.ndarray]:
    spec = sk.load_spec(ROOT / "examples" / "mechanisms" / "three_upu.toml")
    Xs = np.asarray(spec.inputs, dtype=float)
    X = Xs[0] + np.linspace(0.0, 1.0, 60)[:, None] * (Xs[-1] - Xs[0])
    return spec.mechanism, graph_layout(spec.mechanism), X


def test_kept_frames_are_the_forward_maps() -> None:
    mech, lay, X = _three_upu()
    f = follow_drawn_mode(mech, lay, X)
    assert f.mask.all()
    system = graph_system(mech, lay)
    assert not system.memo  # the sweep's poses are dropped at its end
    conf = f.conf
    ref = graph_forward(mech, lay, conf, exact=False)
    system.residual(conf.take(np.arange(0, 60, 2)))  # every other row kept
    rng = np.random.default_rng(4)
    moved = Configuration(conf.scalars + 1e-3 * rng.standard_normal(conf.scalars.shape),
                          conf.spherical)
    for c, expect in ((conf, ref), (moved, graph_forward(mech, lay, moved, exact=False))):
        got = system.frames(c)  # partly kept (conf), then not at all (moved)
        for name in FIELDS:
            assert np.array_equal(getattr(got, name), getattr(expect, name)), name
    empty = system.frames(conf.take(np.arange(0)))  # no rows: as the forward map
    assert empty.R.shape[0] == 0 and system.residual(conf.take(np.arange(0)))[0].shape == (0,)
    again = system.frames(conf)  # every row kept now
    for name in FIELDS:
        assert np.array_equal(getattr(again, name), getattr(ref, name)), name
    D = np.ones((conf.size, X.shape[1]))
    kept = system.jets(conf, D)
    system.forget()
    assert not system.memo
    fresh = system.jets(conf, D)
    for a, b in zip(kept, fresh, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
