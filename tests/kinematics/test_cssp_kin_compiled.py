"""The CSSP's closed-form kinematics compiled by numba (kinematics/closed_forms/cssp_compiled.py,
issue 30) gives the numpy route's motion: the lean pass (link frames and rates, joint centres
and axes, s4, the closure gap) and the rod's zero-spin turn φ, on random CSSPs, both roots,
constant and per-sample rates, a driven crank offset, a placed base (the numpy route places
the rows; the turn compiled), sweeps that assemble over part of the samples only (NaN and the
validity masks as the numpy route's) and coarse steps.

Everything that does not go through a trigonometric function is compared bit for bit; the rod
frame's rows (link rotation, the pin's axis) and φ go through cos, sin and atan2, which numba
takes from the C library and numpy from its own SIMD routines on some CPUs (a few ulp apart),
so there the bound is 2e-15 on unit vectors (equal on the machine these were written on)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from screwkit.dual import ScrewMatrix
from screwkit.kinematics.closed_forms import cssp_compiled
from screwkit.kinematics.closed_forms.cssp_inputs import cssp_sweep
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import cssp
from screwkit.model.linkage import Linkage

EXACT = ("link_origin", "link_origin_velocity", "link_origin_acceleration",
         "link_angular_velocity", "link_angular_acceleration", "joint_centres",
         "closure_residual", "assembles")
TRIG = ("link_rotation", "joint_axes")


def _random_cssp(seed: int, *, a2: float = 0.23, driven: bool = False,
                 placed: bool = False) -> Linkage:
    rng = np.random.default_rng(seed)
    lk = cssp(rng.uniform(0.04, 0.06), a2, rng.uniform(0.0, 0.03),
              np.radians(rng.uniform(230.0, 270.0)), rng.uniform(0.0, 0.02),
              s1_is_input=driven)
    if placed:
        axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        axes *= np.sign(np.linalg.det(axes))
        lk = replace(lk, base=ScrewMatrix.from_rotation_translation(axes, rng.normal(size=3)))
    return lk


def _route(monkeypatch: pytest.MonkeyPatch, compiled: bool) -> None:
    monkeypatch.setattr(cssp_compiled, "AVAILABLE", compiled)
    monkeypatch.setattr(cssp_compiled, "MIN_SAMPLES", 0)  # small sweeps, compiled too


def _same(a: ModeMotion, b: ModeMotion) -> None:
    for name in EXACT:
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name
    for table in ("variables", "velocities", "accelerations"):
        ta, tb = getattr(a, table), getattr(b, table)
        assert list(ta) == list(tb)
        for key in tb:
            assert np.array_equal(ta[key], tb[key], equal_nan=True), (table, key)
    for name in TRIG:
        x, y = getattr(a, name), getattr(b, name)
        assert np.array_equal(np.isnan(x), np.isnan(y)), name
        np.testing.assert_allclose(x, y, rtol=0, atol=2e-15, err_msg=name)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("root", [1, -1])
def test_lean_motion_is_the_numpy_routes(monkeypatch: pytest.MonkeyPatch, seed: int,
                                         root: int) -> None:
    rng = np.random.default_rng(100 + seed)
    driven = seed % 2 == 1
    lk = _random_cssp(seed, driven=driven, placed=seed == 3)
    n = 3001
    theta = np.sort(rng.uniform(-7.0, 7.0, n))
    kwargs: dict[str, object] = {}
    if driven:
        kwargs = {"s1": 0.01 * np.sin(theta), "s1_dot": rng.normal(size=n),
                  "s1_ddot": 0.0 if seed == 1 else rng.normal(size=n)}
    w = 7.0 if seed < 2 else rng.normal(size=n)
    wd = rng.normal(size=n) if seed else 0.0
    motions = []
    for compiled in (True, False):
        _route(monkeypatch, compiled)
        copies = {k: np.copy(v) for k, v in kwargs.items()}
        motions.append(cssp_mode_motion(lk, theta.copy(), np.copy(w), np.copy(wd), root,
                                        ball_joints=False, **copies))  # type: ignore[arg-type]
    _same(*motions)
    assert np.isfinite(motions[0].link_rotation).all()


@pytest.mark.parametrize("root", [1, -1])
def test_partial_assembly_keeps_the_masks(monkeypatch: pytest.MonkeyPatch, root: int) -> None:
    lk = _random_cssp(7, a2=0.045)  # a short rod: assembles over part of the turn only
    theta = np.linspace(0.0, 4 * np.pi, 4000)
    motions = []
    for compiled in (True, False):
        _route(monkeypatch, compiled)
        motions.append(cssp_mode_motion(lk, theta, 3.0, -1.0, root, ball_joints=False,
                                        allow_partial=True))
    ok = motions[1].assembles
    assert ok.any() and not ok.all()  # the case this test is for
    _same(*motions)
    fast = motions[0]
    assert np.isfinite(fast.link_rotation[ok]).all() and np.isnan(fast.link_rotation[~ok]).all()


def test_rod_turn_is_the_numpy_routes(monkeypatch: pytest.MonkeyPatch) -> None:
    # coarse steps and partial assembly (several runs, each started by the numpy functions)
    lk = _random_cssp(11, a2=0.05)
    theta = np.concatenate([np.linspace(0.0, 2 * np.pi, 7), np.linspace(1.0, 9.0, 5000)])
    turns = []
    for compiled in (True, False):
        _route(monkeypatch, compiled)
        for root in (1, -1):
            turns.append(cssp_sweep(lk, theta, 2.0, 0.0, root, allow_partial=True).rod_turn)
    for fast, slow in zip(turns[:2], turns[2:], strict=True):
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-15 * np.abs(slow).max() + 1e-15)


def test_solve_motion_both_modes(monkeypatch: pytest.MonkeyPatch) -> None:
    lk = _random_cssp(5)
    theta = np.linspace(0.0, 2 * np.pi, 2500, endpoint=False)
    runs = []
    for compiled in (True, False):
        _route(monkeypatch, compiled)
        runs.append(solve_motion(lk, theta, rates=4.0))
    assert len(runs[0].modes) == len(runs[1].modes) == 2
    for fast, slow in zip(runs[0].modes, runs[1].modes, strict=True):
        _same(fast, slow)
        # the lazy fields (second pass, numpy) read the same rod frame
        np.testing.assert_allclose(fast.conf.spherical, slow.conf.spherical, rtol=0,
                                   atol=2e-15)


def test_switch_rule(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cssp_compiled, "AVAILABLE", True)
    assert cssp_compiled.use_compiled(cssp_compiled.MIN_SAMPLES)
    assert not cssp_compiled.use_compiled(cssp_compiled.MIN_SAMPLES - 1)
    monkeypatch.setattr(cssp_compiled, "AVAILABLE", False)
    assert not cssp_compiled.use_compiled(10**7)


def test_lean_pass_reads_and_writes_rows_contiguously(monkeypatch: pytest.MonkeyPatch) -> None:
    """The lean pass's tile loops load and store the rows with contiguous vector moves: no
    masked gathers or scatters, which LLVM emitted for its inputs and stores (lean pass 1.5×
    slower) while the tiles were stepped with ``range(0, n, TILE)`` — numba wraps negative
    indices and LLVM could not prove ``t0 + j`` non-negative. Checked on the optimised LLVM IR
    of a fresh compile for the signature the route uses (the cached kernel cannot be
    inspected); a target without gathers (no AVX2) emits none either way, one with them
    (AVX2, AVX-512) caught the bug. The sample loop is vectorised."""
    import re
    from typing import Any

    import numba

    from screwkit.kinematics.closed_forms import cssp_kin_kernels

    _route(monkeypatch, True)
    cssp_mode_motion(_random_cssp(3), np.linspace(0.0, 1.0, 50), 5.0, 0.0, ball_joints=False)
    kernel = cssp_kin_kernels.lean_rows
    fresh: Any = numba.njit(nogil=True, error_model="numpy")(kernel.py_func)
    signature = kernel.signatures[0]
    fresh.compile(signature)
    ir = fresh.inspect_llvm(signature)
    assert not re.findall(r"llvm\.masked\.(gather|scatter)", ir)
    assert len(re.findall(r"fmul <\d+ x double>", ir)) > 50
