"""Random mechanisms of every family with random, physically valid mass properties.

Dimensions are drawn (fixed seeds) from ranges in which the input crank turns fully, so one
assembly mode covers the whole 0–360° sweep; the S–S rods (RSSR coupler, CSSP rod) get
axisymmetric line-mass inertia about their own axis (zero axial moment, CoM on the axis) — the
rule under which their idle spin carries no load (docs/dynamics.md).  `assert_same_dynamics`
compares two ``Dynamics`` field by field.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from screwkit.dynamics import Dynamics
from screwkit.kinematics.motion import ModeMotion, Motion
from screwkit.kinematics.tracker.generic_motion import generic_motion as motion
from screwkit.model.families import cssp, fourbar, rccc, rsrc, rssr
from screwkit.model.linkage import Link, Linkage
from screwkit.model.mass import MassProperties

FAMILIES = ("rsrc", "rssr", "cssp", "fourbar", "rccc")

# link index of the S–S rod (x axis of its body frame runs from ball to ball) and its length key
ROD = {"rssr": (1, "d2"), "cssp": (1, "a2")}


def _u(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def random_geometry(family: str, rng: np.random.Generator) -> Linkage:
    if family == "fourbar":
        return fourbar(1.0, _u(rng, 0.2, 0.35), _u(rng, 0.9, 1.2), _u(rng, 0.8, 1.1))
    if family == "cssp":
        return cssp(_u(rng, 0.04, 0.06), _u(rng, 0.2, 0.26), _u(rng, 0.0, 0.03),
                    np.radians(_u(rng, 230.0, 270.0)), _u(rng, 0.0, 0.02))
    if family == "rssr":
        return rssr(_u(rng, 0.15, 0.25), _u(rng, 1.0, 1.2), _u(rng, 0.7, 0.9),
                    _u(rng, 0.9, 1.1), _u(rng, 0.1, 0.3), _u(rng, 0.2, 0.5),
                    _u(rng, -0.05, 0.05))
    if family == "rsrc":
        return rsrc(_u(rng, 0.15, 0.25), _u(rng, 1.0, 1.2), _u(rng, 0.7, 0.9),
                    _u(rng, 0.9, 1.1), _u(rng, 0.1, 0.3), _u(rng, -0.05, 0.05),
                    _u(rng, 0.2, 0.5), _u(rng, 0.2, 0.5))
    if family == "rccc":
        lengths = (_u(rng, 0.1, 0.2), _u(rng, 0.8, 1.0), _u(rng, 0.6, 0.9), _u(rng, 0.8, 1.0))
        twists = tuple(float(t) for t in np.radians(rng.uniform(20.0, 70.0, 4)))
        return rccc(lengths, twists, _u(rng, -0.1, 0.1))  # type: ignore[arg-type]
    raise ValueError(family)


def random_mass(rng: np.random.Generator, size: float) -> MassProperties:
    """A random rigid body: mass 0.5–3 kg, CoM within ``size``, principal moments satisfying the
    triangle inequalities, random principal axes."""
    mass = _u(rng, 0.5, 3.0)
    com = rng.uniform(-size, size, 3)
    k = rng.uniform(0.1, 0.5, 3) * size
    second = mass * k**2  # second moments along the principal axes (always realisable)
    moments = second.sum() - second
    axes = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
    return MassProperties.from_principal(mass, com, moments, axes)


def rod_mass(rng: np.random.Generator, length: float) -> MassProperties:
    """A line mass along the body x axis between 0 and ``length``: zero axial moment."""
    mass = _u(rng, 0.5, 2.0)
    x = _u(rng, 0.2 * length, 0.8 * length)
    transverse = mass * length**2 * _u(rng, 0.02, 0.1)
    return MassProperties(mass, [x, 0.0, 0.0], np.diag([0.0, transverse, transverse]))


def with_random_masses(linkage: Linkage, rng: np.random.Generator) -> Linkage:
    size = 0.3 * linkage.length_scale / len(linkage.joints)
    links = []
    rod = ROD.get((linkage.family or "").lower())
    for k, link in enumerate(linkage.links):
        if rod is not None and k == rod[0]:
            mp = rod_mass(rng, linkage.parameters[rod[1]])
        else:
            mp = random_mass(rng, size)
        links.append(Link(link.name, mp))
    return linkage.with_links(links)


def with_world_rotations(linkage: Linkage, mode: ModeMotion) -> ModeMotion:
    """The mode with ``link_rotation`` recomputed as base · (ground-frame rotation).

    motion.py (as of this writing) builds it with ``einsum("ij,nljk->nljk", …)``, which sums the
    base rotation's columns instead of multiplying by it: right for the 4R's diagonal base, wrong
    for the RSRC/RSSR permutation base. inverse_dynamics detects the inconsistency; this repair
    is a no-op once motion.py uses "ij,nljk->nlik".
    """
    from dataclasses import replace

    from screwkit.kinematics.tracker.loop import forward

    fr = forward(linkage, mode.conf)
    L = len(linkage.links)
    R = np.einsum("ij,nljk->nlik", linkage.base.real, fr.after_R[:, :L])
    R[~mode.assembles] = np.nan
    return replace(mode, link_rotation=R)


@cache
def full_cycle(family: str, seed: int, samples: int = 24, rate: float = 7.0,
               acceleration: float = 0.0) -> tuple[Linkage, Motion, ModeMotion]:
    """A random mechanism with masses and one mode that assembles over the full input turn."""
    rng = np.random.default_rng([seed, FAMILIES.index(family)])
    for _ in range(20):
        lk = with_random_masses(random_geometry(family, rng), rng)
        theta = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
        mo = motion(lk, theta, rate, acceleration, starts=16)
        for mode in mo.modes:
            if mode.assembles.all() and not mode.singular.any():
                return lk, mo, with_world_rotations(lk, mode)
    raise RuntimeError(f"no fully rotating {family} found for seed {seed}")


def fine_sweep(linkage: Linkage, mode: ModeMotion, refine: int) -> tuple[np.ndarray, np.ndarray]:
    """World rotation (Nf, L, 3, 3) and origin (Nf, L, 3) of every moving link on a sweep
    ``refine`` times finer than the mode's (full turn, uniform; fine sample i·refine is coarse
    sample i). Positions only: each fine sample is closed by Newton from the nearest coarse one."""
    from screwkit.kinematics.tracker.loop import Configuration, forward, layout
    from screwkit.kinematics.tracker.solve import newton, set_inputs

    lay = layout(linkage)
    n_coarse = mode.assembles.size
    n_fine = n_coarse * refine
    theta = np.linspace(0.0, 2 * np.pi, n_fine, endpoint=False)
    nearest = (np.round(np.arange(n_fine) / refine).astype(int)) % n_coarse
    start = Configuration(mode.conf.scalars[nearest].copy(), mode.conf.spherical[nearest].copy())
    start = set_inputs(start, lay, linkage.inputs, theta[:, None])
    res = newton(linkage, start, lay=lay, tol=1e-13, max_iter=80)
    assert res.converged.all(), "fine sweep did not close"
    fr = forward(linkage, res.conf, lay)
    L = len(linkage.links)
    bR, bp = linkage.base.real, linkage.base.translation
    R = np.einsum("ij,nljk->nlik", bR, fr.after_R[:, :L])
    p = np.einsum("ij,nlj->nli", bR, fr.after_p[:, :L]) + bp
    return R, p


AGREE = 1e-12  # of the largest joint load: both paths are exact, this is round-off


def assert_same_dynamics(a: Dynamics, b: Dynamics, ell: float, tol: float = AGREE) -> None:
    """Every field of two Dynamics equal, loads to ``tol`` of the largest joint load."""
    scale = b.residual_scale
    assert a.residual_scale == pytest.approx(scale, rel=tol)
    force, moment = tol * scale, tol * scale * ell
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_array_equal(a.inputs, b.inputs)
    assert a.input_names == b.input_names
    np.testing.assert_array_equal(a.moment_point, b.moment_point)
    np.testing.assert_array_equal(a.gravity, b.gravity)
    np.testing.assert_array_equal(a.joint_centres, b.joint_centres)
    np.testing.assert_allclose(a.shaking_force, b.shaking_force, rtol=0, atol=force)
    np.testing.assert_allclose(a.shaking_moment, b.shaking_moment, rtol=0, atol=moment)
    assert a.reactions.keys() == b.reactions.keys()
    for joint in a.reactions:
        np.testing.assert_allclose(a.reactions[joint]["force"], b.reactions[joint]["force"],
                                   rtol=0, atol=force, err_msg=joint)
        np.testing.assert_allclose(a.reactions[joint]["moment"], b.reactions[joint]["moment"],
                                   rtol=0, atol=moment, err_msg=joint)
    assert a.efforts.keys() == b.efforts.keys()
    for name in a.efforts:
        unit = moment if name.endswith(".theta") else force
        np.testing.assert_allclose(a.efforts[name], b.efforts[name], rtol=0, atol=unit,
                                   err_msg=name)
    np.testing.assert_allclose(a.residual, b.residual, rtol=0, atol=force)
    assert a.indeterminacy.count == b.indeterminacy.count
    assert a.indeterminacy.idle_freedoms == b.indeterminacy.idle_freedoms
    np.testing.assert_array_equal(a.indeterminacy.directions, b.indeterminacy.directions)
