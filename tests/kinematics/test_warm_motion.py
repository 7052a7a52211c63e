"""The warm start of a generic loop's motion after a small change of its dimensions
(kinematics/warm_motion.py): it is the generic solver's motion at the new dimensions, to the
accuracy the generic solver's own samples are converged to, and every way it could be wrong —
a mode lost, a branch switch, a mode that does not assemble everywhere, a change too large for
Newton, a closed form — gives None or fails the root-search check."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from screwkit.kinematics.motion import Motion
from screwkit.kinematics.solve_motion import solve_motion
from screwkit.kinematics.tracker.loop import forward, layout
from screwkit.kinematics.tracker.rates import rate_equations
from screwkit.kinematics.tracker.tracks import closure_residual
from screwkit.kinematics.warm_motion import same_modes_as_search, warm_motion
from screwkit.studio.design import Design

EXAMPLES = Path(__file__).parents[2] / "examples"
#: the generic solver's samples are closed to round-off: the fill keeps a sample closed to
#: FILL_TOL = 1e-14 and the corrector polishes to below that; the closure error is evaluated
#: no better than this either
ROUND_OFF = 1e-14


def solved(design: Design, values: dict[str, float]) -> tuple[object, Motion]:
    spec = design.spec_with({**design.initial_values, **values}, 0)
    return spec, solve_motion(spec.linkage, spec.inputs, rates=spec.speed,
                              accelerations=spec.acceleration)


def converged_to(motion: Motion, k: int) -> np.ndarray:
    """Per sample, how far (scaled freedoms: rad, lengths / length scale) mode ``k``'s
    configuration may be from the exact root: its closure error (at least ROUND_OFF) over the
    smallest singular value of the scaled passive Jacobian (Newton's first-order bound)."""
    md, lay = motion.modes[k], layout(motion.linkage)
    fr = forward(motion.linkage, md.conf, lay)
    eq = rate_equations(motion.linkage, lay, fr)
    sigma = np.linalg.svd(eq.passive, compute_uv=False)[:, -1]
    res = closure_residual(motion.linkage, fr.closure_R, fr.closure_p)
    return np.asarray(np.maximum(res, ROUND_OFF) / sigma)


def assert_same_motion(warm: Motion, full: Motion) -> None:
    """Same modes (labels, assembly, singular samples, events) and every joint variable
    within the sum of both solutions' distance bounds to the exact root (times 2 for the
    linearisation); the rates and accelerations within ten times that times their size (they
    follow from the positions through the rate equations, solved with the same J_p)."""
    assert [m.label for m in warm.modes] == [m.label for m in full.modes]
    L = full.linkage.length_scale
    for k, (a, b) in enumerate(zip(warm.modes, full.modes, strict=True)):
        assert np.array_equal(a.assembles, b.assembles) and np.array_equal(a.singular, b.singular)
        assert a.events == b.events
        tol = 2.0 * (converged_to(warm, k) + converged_to(full, k))
        assert tol.max() < 1e-9  # a meaningful bound: the loop is well conditioned here
        assert a.variables.keys() == b.variables.keys()
        for name in b.variables:
            scale = 1.0 / L if name.endswith(".s") else 1.0
            d = np.abs(a.variables[name] - b.variables[name]) * scale
            assert np.all(d <= tol), (name, float(np.max(d / tol)))
        for table_a, table_b in ((a.velocities, b.velocities),
                                 (a.accelerations, b.accelerations)):
            for name in table_b:
                size = 1.0 + np.max(np.abs(table_b[name]))
                assert np.all(np.abs(table_a[name] - table_b[name]) <= 10.0 * tol * size), name


@pytest.fixture(scope="module")
def loop() -> tuple[Design, Motion]:
    design = Design(EXAMPLES / "rrsrr_loop.toml")
    return design, solved(design, {})[1]


@pytest.mark.parametrize("change", [{"joints[1].length": 113.0}, {"joints[1].length": 108.5},
                                    {"joints[3].twist": 44.0}, {"joints[2].length": 62.0},
                                    {"joints[1].offset": 13.0, "joints[4].length": 142.0}])
def test_warm_start_is_the_generic_solvers_motion(loop: tuple[Design, Motion],
                                                  change: dict[str, float]) -> None:
    design, before = loop
    spec, full = solved(design, change)
    warm = warm_motion(spec.linkage, spec.inputs, before, rates=spec.speed,  # type: ignore[attr-defined]
                       accelerations=spec.acceleration)  # type: ignore[attr-defined]
    assert warm is not None and warm.method == "generic"
    assert same_modes_as_search(warm)
    assert_same_motion(warm, full)
    # and the warm start moved the modes: they are not the old ones
    assert np.nanmax(np.abs(warm.modes[0].variables["output.theta"]
                            - before.modes[0].variables["output.theta"])) > 1e-4


def test_what_is_not_warm_started(loop: tuple[Design, Motion]) -> None:
    design, before = loop
    spec, _ = solved(design, {"joints[1].length": 112.0})
    args = (spec.linkage, spec.inputs)  # type: ignore[attr-defined]
    # a mode that does not assemble at every sample (its ends move with the dimensions)
    held = before.modes[1].assembles.copy()
    held[5] = False
    partial = replace(before, modes=(before.modes[0], replace(before.modes[1], assembles=held)))
    assert warm_motion(*args, partial) is None
    # a singular sample
    sing = before.modes[0].singular.copy()
    sing[3] = True
    assert warm_motion(*args, replace(before, modes=(replace(before.modes[0], singular=sing),
                                                     before.modes[1]))) is None
    # a change too large for Newton from the old configurations
    big, _ = solved(design, {"joints[1].length": 140.0})
    assert warm_motion(big.linkage, big.inputs, before) is None  # type: ignore[attr-defined]
    # other inputs, or a closed form
    assert warm_motion(spec.linkage, spec.inputs[:-1], before) is None  # type: ignore[attr-defined]
    rssr = Design(EXAMPLES / "rssr_spatial.toml")
    s0, m0 = solved(rssr, {})
    s1 = rssr.spec_with({**rssr.initial_values, "dimensions.d2": 101.0}, 0)
    assert m0.method != "generic"
    assert warm_motion(s1.linkage, s1.inputs, m0) is None


def test_a_branch_switch_is_refused(loop: tuple[Design, Motion]) -> None:
    """Mode 0 handed mode 1's configurations over a stretch of samples: Newton converges
    there (onto the other branch), and the jump between neighbouring samples refuses it."""
    design, before = loop
    spec, _ = solved(design, {"joints[1].length": 112.0})
    a, b = before.modes
    mixed = a.conf.scalars.copy()
    mixed[10:15] = b.conf.scalars[10:15]
    spherical = a.conf.spherical.copy()
    spherical[10:15] = b.conf.spherical[10:15]
    switched = replace(a, conf=type(a.conf)(mixed, spherical))
    assert warm_motion(spec.linkage, spec.inputs,  # type: ignore[attr-defined]
                       replace(before, modes=(switched, b))) is None
    # both modes handed the same branch: not distinct, refused
    assert warm_motion(spec.linkage, spec.inputs,  # type: ignore[attr-defined]
                       replace(before, modes=(a, replace(b, conf=a.conf)))) is None


def test_a_lost_mode_fails_the_root_search_check(loop: tuple[Design, Motion]) -> None:
    """A warm start that misses a mode (here: the old motion without mode 1) passes the
    Newton checks, and the generic solver's root search finds the mode it lacks."""
    design, before = loop
    spec, _ = solved(design, {"joints[1].length": 112.0})
    warm = warm_motion(spec.linkage, spec.inputs,  # type: ignore[attr-defined]
                       replace(before, modes=before.modes[:1]))
    assert warm is not None and len(warm.modes) == 1
    assert not same_modes_as_search(warm)
