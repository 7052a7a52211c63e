"""Every fold of one input of a planar R mechanism, found at once as the critical points of the
configuration curve's projection onto that input (issue 27, "births and deaths at folds").

With the other inputs fixed, the mechanism's configurations x (its unknown joints' plane
coordinates, modes/planar.py) over the input θ form a curve F(x; θ) = 0. A fold, where modes
are born or die, is a point of the curve where the input cannot move to first order: ∂F/∂x is
singular there. The input is made an unknown on its circle, (c, s) = (cos Δ, sin Δ) with
Δ = θ − θ_ref: each placed joint that moves with the input is on a circle about its pivot,
z₀ + r e^{±iΔ}, so its (x, y) is (x₀ + r_x c − r_y s, y₀ + r_y c + r_x s) (centre and arm read
off the formulation's own parameters at three angles, a discrete Fourier fit, checked at a
fourth; lengths divided by the length scale). Written with that structure, the topology's
generic count is the mechanism's and no path diverges at it (with every coordinate a free
linear function of (c, s), most paths failed on the Stephenson III six-bar). The square system

    F(x; c, s) = 0,   c² + s² = 1,   ∂F/∂x(x; c, s) v = 0,   h·v = 1

(v the kernel vector, h a fixed random real vector that picks its scale; Sommese & Wampler
2005, §13.4 and ch. 15, critical points of a projection by this "kernel" system) has the folds
as its real solutions in (x, c, s). With real h a real fold is a real solution in every
unknown, so the α-test (algebraic/certify.py) certifies it real. It is solved once per
mechanism by the package's homotopy: start solutions of its topology (modes/starts.py: the
total-degree homotopy, 512 paths for a four-bar with a dyad or a Stephenson III six-bar, after
the two-group multi-homogeneous one, {x, c, s} and {v}, has failed paths), then a parameter
homotopy to the mechanism (docs/kinematics.md, "Every mode along the motion", for the counts
and how the start sets' completeness was checked).

Not taken: more than one varying input at once (a path in several inputs is a curve in their
space; its folds need the path's own parametrisation), and a fold where the kernel is more
than a line (two sub-chains folding at one input: a positive-dimensional set of v, reported
as singular end points, not as folds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic.multi_homogeneous import Grouping
from screwkit.algebraic.polynomial import Poly, PolynomialSystem, compile_system
from screwkit.algebraic.solve import solve_all
from screwkit.algebraic.track import PathStatus
from screwkit.errors import CapabilityError
from screwkit.kinematics.modes.planar import PlanarFormulation, closure_equations
from screwkit.kinematics.modes.starts import start_solutions

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

#: seed of the random real vector h fixing the kernel vector's scale (h·v = 1)
KERNEL_SEED = 27
#: a solution is a real fold where its (x, c, s) imaginary parts are within this (relative)
REAL = 1e-8
#: the placed joints' Fourier fit in the input must reproduce a fourth angle to this (relative)
FIT = 1e-12


@dataclass(frozen=True)
class InputFolds:
    """The folds of input ``which`` with the other inputs at ``reference``: ``inputs`` (F,)
    the fold inputs (rad, within π of the reference's), ``points`` (F, 2u) the configuration
    there (formulation unknowns), ``certified`` (F,) whether Smale's α-test certified each
    real; ``found`` the distinct complex critical points, ``singular`` the singular end
    points (not isolated folds), ``generic_count`` and ``how_found`` from the start
    solutions."""

    which: int
    reference: Array
    inputs: Array
    points: Array
    certified: NDArray[np.bool_]
    found: int
    singular: int
    failed: int
    at_infinity: int
    generic_count: int
    how_found: str


def _derivative(poly: Poly, index: int) -> Poly:
    """∂poly/∂(symbol ``index``)."""
    out: dict[tuple[tuple[int, int], ...], complex] = {}
    for mono, c in poly.terms.items():
        for f, (i, power) in enumerate(mono):
            if i == index:
                rest = mono[:f] + (((i, power - 1),) if power > 1 else ()) + mono[f + 1:]
                out[rest] = out.get(rest, 0.0) + c * power
    return Poly(out)


@dataclass(frozen=True)
class PlacedCircles:
    """How the placed joints move with one input Δ: joint i at z₀ᵢ + rᵢ e^{iσΔ} (complex plane
    coordinates; rᵢ = 0 for a joint that does not move with it), lengths divided by ``scale``
    about ``origin``."""

    centre: Complex
    arm: Complex
    sigma: float
    moving: tuple[bool, ...]
    origin: complex
    scale: float


def placed_circles(form: PlanarFormulation, reference: ArrayLike, which: int) -> PlacedCircles:
    """The placed joints' circles in input ``which`` about the input row ``reference``, read
    off the formulation's parameters at three angles (a discrete Fourier fit) and checked at a
    fourth; a CapabilityError where they are not circles of that input."""
    ref = np.asarray(reference, dtype=float).reshape(-1)
    angles = 2 * np.pi * np.arange(4) / 3 + np.array([0.0, 0.0, 0.0, 0.7])
    rows = np.tile(ref, (4, 1))
    rows[:, which] += angles
    nk = 2 * len(form.known_joints)
    z = form.parameters(rows)[:, :nk]
    z = z[:, 0::2] + 1j * z[:, 1::2]
    a0 = z[:3].mean(axis=0)
    ac = (2 / 3) * np.cos(angles[:3]) @ z[:3]
    as_ = (2 / 3) * np.sin(angles[:3]) @ z[:3]
    size = max(1.0, float(np.abs(z).max()))
    moving = np.abs(ac) > FIT * size
    sigma = 1.0
    if moving.any():
        sigma = float(np.real(as_[moving][0] / (1j * ac[moving][0])))
    fit = a0 + ac * np.cos(angles[3]) + as_ * np.sin(angles[3])
    circle = np.abs(as_ - 1j * sigma * ac).max(initial=0.0) <= FIT * size
    if np.abs(fit - z[3]).max() > FIT * size or not circle or abs(abs(sigma) - 1) > FIT:
        raise CapabilityError(f"{form.mechanism.name}: the joints placed by input "
                              f"{form.mechanism.inputs[which]} do not move on circles of it "
                              "alone, so its folds are not found as critical points")
    origin = complex(a0.mean())
    scale = float(form.mechanism.length_scale)
    return PlacedCircles((a0 - origin) / scale, ac / scale, float(np.sign(sigma)),
                         tuple(bool(m) for m in moving), origin, scale)


def fold_system(form: PlanarFormulation, moving: tuple[bool, ...]) -> PolynomialSystem:
    """The kernel system (module docstring) of ``form``'s topology with the placed joints
    ``moving`` with the input: unknowns x (2u), c, s, v (2u); parameters each placed joint's
    centre (x₀, y₀) and, where it moves, its arm (r_x, r_y) (x = x₀ + r_x c − r_y s,
    y = y₀ + r_y c + r_x s), the rigid bodies' (as in modes/planar.py), then h (2u)."""
    known, unknown, rigid = form.known_joints, form.unknown_joints, form.rigid
    n = 2 * len(unknown)
    n_body = sum(2 * len(js) - 3 for _, js in rigid)
    n_placed = 2 * len(known) + 2 * sum(moving)
    sym = [Poly.variable(i) for i in range(2 * n + 2 + n_placed + n_body + n)]
    c, s = sym[n], sym[n + 1]
    v = sym[n + 2:2 * n + 2]
    par = 2 * n + 2
    point = {k: (sym[2 * i], sym[2 * i + 1]) for i, k in enumerate(unknown)}
    params = []
    for k, move in zip(known, moving, strict=True):
        x0, y0 = sym[par], sym[par + 1]
        params += [f"x0_{k}", f"y0_{k}"]
        par += 2
        if move:
            rx, ry = sym[par], sym[par + 1]
            params += [f"rx_{k}", f"ry_{k}"]
            par += 2
            point[k] = (x0 + rx * c - ry * s, y0 + ry * c + rx * s)
        else:
            point[k] = (x0, y0)
    eqs = closure_equations(point, rigid, sym[par:par + n_body])
    h = sym[par + n_body:]
    kernel = []
    for f in eqs:
        row = Poly()
        for j in range(n):
            row = row + _derivative(f, j) * v[j]
        kernel.append(row)
    unit = Poly()
    for j in range(n):
        unit = unit + h[j] * v[j]
    names = [f"{w}{k}" for k in unknown for w in "xy"] + ["c", "s"] + \
        [f"v{w}{k}" for k in unknown for w in "xy"]
    params += [f"{w}{b}" for b, js in rigid for w in (["L2_"] + [f"M{m}{q}_" for m in js[2:]
                                                                  for q in "ri"])]
    params += [f"h{j}" for j in range(n)]
    return compile_system([*eqs, c * c + s * s - 1.0, *kernel, unit - 1.0], names, params)


def fold_parameters(form: PlanarFormulation, circles: PlacedCircles,
                    seed: int = KERNEL_SEED) -> Array:
    """The kernel system's parameters for ``form`` with the placed joints on ``circles``."""
    cols: list[float] = []
    for z0, r, move in zip(circles.centre, circles.arm, circles.moving, strict=True):
        cols += [z0.real, z0.imag] + ([r.real, r.imag] if move else [])
    drawn = np.zeros((1, len(form.mechanism.inputs)))  # (the bodies' part is the same at any)
    body = form.parameters(drawn)[0, 2 * len(form.known_joints):]
    scaled, i = body.copy(), 0
    for _, js in form.rigid:  # L² in the scaled lengths; the ratios M keep
        scaled[i] /= circles.scale ** 2
        i += 2 * len(js) - 3
    h = np.random.default_rng(seed).standard_normal(2 * len(form.unknown_joints))
    return np.concatenate([np.array(cols), scaled, h])


def input_folds(form: PlanarFormulation, reference: ArrayLike, which: int = 0,
                seed: int = KERNEL_SEED) -> InputFolds:
    """Every fold of input ``which`` of ``form``'s mechanism, the other inputs at the row
    ``reference`` (module docstring); ``seed`` picks h."""
    ref = np.asarray(reference, dtype=float).reshape(-1)
    circles = placed_circles(form, ref, which)
    system = fold_system(form, circles.moving)
    n = 2 * len(form.unknown_joints)
    groups = (tuple(range(n + 2)), tuple(range(n + 2, 2 * n + 2)))
    start = start_solutions(system, grouping=Grouping(groups))
    sol = solve_all(system, fold_parameters(form, circles, seed), start)
    xcs = sol.x[:, :n + 2]
    real = np.abs(xcs.imag).max(axis=1, initial=0.0) <= REAL * (
        1.0 + np.abs(xcs).max(axis=1, initial=0.0))
    regular = sol.status == PathStatus.REGULAR
    keep = real & regular
    cs = xcs[keep, n:].real
    at = ref[which] + circles.sigma * np.arctan2(cs[:, 1], cs[:, 0])
    order = np.argsort(at, kind="stable")
    xy = xcs[keep, :n].real * circles.scale
    xy[:, 0::2] += circles.origin.real
    xy[:, 1::2] += circles.origin.imag
    return InputFolds(which, ref, at[order], xy[order], sol.certified_real[keep][order],
                      int(sol.found[0]), int(np.count_nonzero(real & ~regular)),
                      int(sol.failed[0]), int(sol.at_infinity[0]), sol.generic_count,
                      sol.how_found)
