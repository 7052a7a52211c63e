"""Every fold of one input of a planar R mechanism, found at once as the critical points of the
configuration curve's projection onto that input (issue 27, "births and deaths at folds").

With the other inputs fixed, the mechanism's configurations x (its unknown joints' plane
coordinates, modes/planar.py) over the input θ form a curve F(x; θ) = 0. A fold, where modes
are born or die, is a point of the curve where the input cannot move to first order: ∂F/∂x is
singular there. The input is made an unknown on its circle, (c, s) = (cos Δ, sin Δ) with
Δ = θ − θ_ref: each placed joint moves on a circle about its input pivot, so its (x, y) is
a + b c + d s (a, b, d read off the formulation's own parameters at three angles, a discrete
Fourier fit, checked at a fourth). The square system

    F(x; c, s) = 0,   c² + s² = 1,   ∂F/∂x(x; c, s) v = 0,   h·v = 1

(v the kernel vector, h a fixed random real vector that picks its scale; Sommese & Wampler
2005, §13.4 and ch. 15, critical points of a projection by this "kernel" system) has the folds
as its real solutions in (x, c, s). With real h a real fold is a real solution in every
unknown, so the α-test (algebraic/certify.py) certifies it real. It is solved once per
mechanism by the package's homotopy: start solutions of its topology by the two-group
multi-homogeneous homotopy ({x, c, s} and {v}: the kernel equations are bilinear; 32 paths for
a four-bar with a dyad, total degree 512), then a parameter homotopy to the mechanism.

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


def fold_system(form: PlanarFormulation) -> PolynomialSystem:
    """The kernel system (module docstring) of ``form``'s topology: unknowns x (2u), c, s,
    v (2u); parameters each placed joint's (x₀, x_c, x_s, y₀, y_c, y_s), the rigid bodies'
    (as in modes/planar.py), then h (2u)."""
    known, unknown, rigid = form.known_joints, form.unknown_joints, form.rigid
    n = 2 * len(unknown)
    n_body = sum(2 * len(js) - 3 for _, js in rigid)
    sym = [Poly.variable(i) for i in range(2 * n + 2 + 6 * len(known) + n_body + n)]
    c, s = sym[n], sym[n + 1]
    v = sym[n + 2:2 * n + 2]
    par = 2 * n + 2
    point = {k: (sym[2 * i], sym[2 * i + 1]) for i, k in enumerate(unknown)}
    for i, k in enumerate(known):
        a = sym[par + 6 * i:par + 6 * i + 6]
        point[k] = (a[0] + a[1] * c + a[2] * s, a[3] + a[4] * c + a[5] * s)
    par += 6 * len(known)
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
    params = [f"{w}{k}" for k in known for w in ("x0", "xc", "xs", "y0", "yc", "ys")]
    params += [f"{w}{b}" for b, js in rigid for w in (["L2_"] + [f"M{m}{q}_" for m in js[2:]
                                                                  for q in "ri"])]
    params += [f"h{j}" for j in range(n)]
    return compile_system([*eqs, c * c + s * s - 1.0, *kernel, unit - 1.0], names, params)


def fold_parameters(form: PlanarFormulation, reference: ArrayLike, which: int = 0,
                    seed: int = KERNEL_SEED) -> Array:
    """The kernel system's parameters for ``form`` with input ``which`` varying about the
    input row ``reference`` (the others held there)."""
    ref = np.asarray(reference, dtype=float).reshape(-1)
    angles = 2 * np.pi * np.arange(4) / 3 + np.array([0.0, 0.0, 0.0, 0.7])
    rows = np.tile(ref, (4, 1))
    rows[:, which] += angles
    p = form.parameters(rows)
    nk = 2 * len(form.known_joints)
    placed = p[:3, :nk]
    a0 = placed.mean(axis=0)
    ac = (2 / 3) * np.cos(angles[:3]) @ placed
    as_ = (2 / 3) * np.sin(angles[:3]) @ placed
    fit = a0 + ac * np.cos(angles[3]) + as_ * np.sin(angles[3])
    if np.abs(fit - p[3, :nk]).max() > FIT * max(1.0, float(np.abs(placed).max())):
        raise CapabilityError(f"{form.mechanism.name}: the joints placed by input "
                              f"{form.mechanism.inputs[which]} do not move on circles of it "
                              "alone, so its folds are not found as critical points")
    coef = np.stack([a0[0::2], ac[0::2], as_[0::2], a0[1::2], ac[1::2], as_[1::2]], -1)
    h = np.random.default_rng(seed).standard_normal(2 * len(form.unknown_joints))
    return np.concatenate([coef.reshape(-1), p[0, nk:], h])


def input_folds(form: PlanarFormulation, reference: ArrayLike, which: int = 0,
                seed: int = KERNEL_SEED) -> InputFolds:
    """Every fold of input ``which`` of ``form``'s mechanism, the other inputs at the row
    ``reference`` (module docstring); ``seed`` picks h."""
    ref = np.asarray(reference, dtype=float).reshape(-1)
    system = fold_system(form)
    n = 2 * len(form.unknown_joints)
    groups = (tuple(range(n + 2)), tuple(range(n + 2, 2 * n + 2)))
    start = start_solutions(system, grouping=Grouping(groups))
    sol = solve_all(system, fold_parameters(form, ref, which, seed), start)
    xcs = sol.x[:, :n + 2]
    real = np.abs(xcs.imag).max(axis=1, initial=0.0) <= REAL * (
        1.0 + np.abs(xcs).max(axis=1, initial=0.0))
    regular = sol.status == PathStatus.REGULAR
    keep = real & regular
    cs = xcs[keep, n:].real
    at = ref[which] + np.arctan2(cs[:, 1], cs[:, 0])
    order = np.argsort(at, kind="stable")
    return InputFolds(which, ref, at[order], xcs[keep, :n].real[order],
                      sol.certified_real[keep][order], int(sol.found[0]),
                      int(np.count_nonzero(real & ~regular)), sol.generic_count, sol.how_found)
