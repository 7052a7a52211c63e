"""The CSSP's inverse dynamics compiled by numba (dynamics/cssp_compiled.py, issue 30) gives the
numpy route's loads bit for bit: every array of the result (shaking loads, reactions, efforts,
residual) and the largest joint load, on random CSSPs with random mass properties (the rod's
idle spin loaded), a placed base, a driven crank offset (a second effort), gravity and a
moment point; from the closed form (component-major storage, read in place) and from the
generic solver (other layouts); where the mode assembles over part of the sweep only; with
small blocks (the largest joint load is the numpy route's block by block). A motion that is
not finite is named by both routes alike, and external loads keep the numpy route."""

from __future__ import annotations

import importlib.util
import os
from dataclasses import replace

import numpy as np
import pytest
from mechanisms import random_mass

from screwkit.dual import ScrewMatrix
from screwkit.dynamics import ExternalLoad, cssp_compiled, inverse_dynamics
from screwkit.dynamics.result import Dynamics
from screwkit.kinematics.closed_forms.cssp_motion import cssp_mode_motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.model.families import cssp
from screwkit.model.linkage import Link, Linkage


def _random_cssp(seed: int, *, a2: float = 0.23, driven: bool = False) -> Linkage:
    rng = np.random.default_rng(seed)
    lk = cssp(rng.uniform(0.04, 0.06), a2, rng.uniform(0.0, 0.03),
              np.radians(rng.uniform(230.0, 270.0)), rng.uniform(0.0, 0.02),
              s1_is_input=driven)
    lk = lk.with_links([Link(name, random_mass(rng, 0.08))
                        for name in ("crank", "rod", "slider")])
    if seed % 2:
        axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        axes *= np.sign(np.linalg.det(axes))
        lk = replace(lk, base=ScrewMatrix.from_rotation_translation(axes, rng.normal(size=3)))
    return lk


def _both(monkeypatch: pytest.MonkeyPatch, *args: object, **kwargs: object
          ) -> tuple[Dynamics, Dynamics]:
    monkeypatch.setattr(cssp_compiled, "AVAILABLE", True)
    monkeypatch.setattr(cssp_compiled, "MIN_SAMPLES", 0)  # small sweeps, compiled too
    fast = inverse_dynamics(*args, **kwargs)  # type: ignore[arg-type]
    monkeypatch.setattr(cssp_compiled, "AVAILABLE", False)
    slow = inverse_dynamics(*args, **kwargs)  # type: ignore[arg-type]
    return fast, slow


def _identical(a: Dynamics, b: Dynamics) -> None:
    def same(x: np.ndarray, y: np.ndarray, name: str) -> None:
        assert np.array_equal(x, y, equal_nan=True), name

    same(a.shaking_force, b.shaking_force, "shaking_force")
    same(a.shaking_moment, b.shaking_moment, "shaking_moment")
    same(a.residual, b.residual, "residual")
    same(a.valid, b.valid, "valid")
    assert list(a.efforts) == list(b.efforts)
    for name, effort in b.efforts.items():
        same(a.efforts[name], effort, name)
    for joint, reaction in b.reactions.items():
        same(a.reactions[joint]["force"], reaction["force"], joint)
        same(a.reactions[joint]["moment"], reaction["moment"], joint)
    assert a.residual_scale == b.residual_scale


def test_numba_is_there_and_used_for_long_sweeps() -> None:
    """The dev extra installs numba (both routes are tested, the compiled one switched on by
    hand where SCREWKIT_NO_NUMBA turns it off); it runs for long sweeps unless turned off."""
    assert importlib.util.find_spec("numba") is not None
    on = not os.environ.get("SCREWKIT_NO_NUMBA")
    assert cssp_compiled.AVAILABLE == on
    assert cssp_compiled.use_compiled(10**6) == on and not cssp_compiled.use_compiled(1000)


@pytest.mark.parametrize("seed", range(4))
def test_compiled_loads_equal_the_numpy_routes_bit_for_bit(seed: int,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    lk = _random_cssp(seed)
    rng = np.random.default_rng(100 + seed)
    theta = np.linspace(0.0, 2 * np.pi, 3001) + rng.uniform(0.0, 1.0)
    rate, rate_dot = float(rng.uniform(5.0, 50.0)), float(rng.uniform(-100.0, 100.0))
    gravity, point = rng.normal(size=3) * 5.0, rng.normal(size=3) * 0.1
    motion = solve_motion(lk, theta, rates=rate, accelerations=rate_dot)
    for mode in motion.modes:
        for block in (16384, 700):
            fast, slow = _both(monkeypatch, lk, mode, gravity, point, block_size=block)
            _identical(fast, slow)
            assert np.max(slow.relative_residual) > 1e-8  # the rod's idle spin is loaded
    # a mode of the generic solver: (N, …) arrays, not component-major
    generic = solve_motion(lk, theta[::20], rates=rate, accelerations=rate_dot,
                           method="generic")
    _identical(*_both(monkeypatch, lk, generic.modes[0], gravity, point))


def test_driven_offset_and_partial_assembly(monkeypatch: pytest.MonkeyPatch) -> None:
    lk = _random_cssp(5, driven=True)
    theta = np.linspace(0.0, 2 * np.pi, 2000, endpoint=False)
    s1 = 0.01 * np.sin(3 * theta)
    mode = cssp_mode_motion(lk, theta, 9.0, 1.0, s1=s1, s1_dot=0.03 * np.cos(3 * theta),
                            ball_joints=False)
    fast, slow = _both(monkeypatch, lk, mode, [0.0, 0.0, -9.81])
    assert set(fast.efforts) == {"crank.theta", "crank.s"}
    _identical(fast, slow)
    short = _random_cssp(6, a2=0.05)  # assembles over part of the turn only
    part = cssp_mode_motion(short, theta, 4.0, 0.0, allow_partial=True, ball_joints=False)
    assert 0 < part.assembles.sum() < theta.size
    fast, slow = _both(monkeypatch, short, part, [0.0, -9.81, 0.0], allow_partial=True,
                       block_size=333)
    assert np.isnan(fast.shaking_force[~part.assembles]).all()
    _identical(fast, slow)


def test_non_finite_motion_and_external_loads(monkeypatch: pytest.MonkeyPatch) -> None:
    lk = _random_cssp(7)
    theta = np.linspace(0.0, 2 * np.pi, 500, endpoint=False)
    mode = cssp_mode_motion(lk, theta, 6.0, 0.0, ball_joints=False)
    bad = replace(mode, link_origin_velocity=mode.link_origin_velocity.copy())
    bad.link_origin_velocity[123, 1, 2] = np.inf
    messages = []
    monkeypatch.setattr(cssp_compiled, "MIN_SAMPLES", 0)
    for flag in (True, False):
        monkeypatch.setattr(cssp_compiled, "AVAILABLE", flag)
        with pytest.raises(ValueError, match="#123") as info:
            inverse_dynamics(lk, bad, [0.0, 0.0, -9.81])
        messages.append(str(info.value))
    assert messages[0] == messages[1]
    loads = {"rod": ExternalLoad(force=[1.0, -2.0, 3.0], moment=[0.1, 0.0, 0.0],
                                 point=[0.05, 0.0, 0.0])}
    fast, slow = _both(monkeypatch, lk, mode, [0.0, 0.0, -9.81], external_loads=loads)
    _identical(fast, slow)


def test_kernel_reads_and_writes_rows_contiguously() -> None:
    """The kernel's tile loops load and store the rows with contiguous vector moves: no
    masked gathers or scatters, which LLVM emitted for every row (3× slower kernel) while the
    tiles were stepped with ``range(0, n, TILE)`` — numba wraps negative indices and LLVM could
    not prove ``start + k`` non-negative. Checked on the optimised LLVM IR of a fresh compile
    (the cached kernel cannot be inspected); a target without gathers (no AVX2) emits none
    either way, one with them (AVX2, AVX-512) caught the bug. The sample loop is vectorised."""
    import re
    from typing import Any

    import numba

    from screwkit.dynamics import cssp_kernels

    fresh: Any = numba.njit(nogil=True, error_model="numpy")(cssp_kernels.cssp_loads.py_func)
    n = 5

    def rows(r: int) -> np.ndarray:
        return np.ones((r, n))

    outputs = [np.empty((3, n)), np.empty((3, n)), np.empty((12, n)), np.empty((12, n))]
    fresh(rows(27), rows(9), rows(9), rows(9), rows(9), rows(12), rows(12), rows(9),
          np.ones(n, dtype=bool), 16384, np.ones(3), np.ones((3, 3)), np.ones((3, 3, 3)),
          np.ones(3), np.zeros(3), np.zeros(3), 1.0, 1.0, True, *outputs, np.empty(n),
          np.empty(n), True, True, np.empty(n))
    ir = fresh.inspect_llvm(fresh.signatures[0])
    assert not re.findall(r"llvm\.masked\.(gather|scatter)", ir)
    assert len(re.findall(r"fmul <\d+ x double>", ir)) > 100
