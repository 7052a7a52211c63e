"""Every solution of 6R loops (6R arm inverse kinematics, 7R loops at one input): elimination
first, the parameter homotopy where elimination cannot promise all 16.

:func:`solve_loop6r` runs the eigenvalue solver of :mod:`.sixr_elimination` (Raghavan & Roth
1993; Manocha & Canny 1994) on every instance of a batch, polishes its 16 solutions by Newton's
method on the polynomial system of :mod:`.loop6r` (the axes z2..z5; Sommese & Wampler 2005,
ch. 9) and certifies them by Smale's α-test (algebraic/certify.py). An instance whose 16 are
not all settled and distinct (a special geometry: a singular leading matrix, a double root, a
solution at a shifted half-angle of ∞, fewer than 16 finite solutions; :func:`eigen_route`)
is eliminated again with the loop relabelled cyclically, and what is still unsettled is
solved by the parameter homotopy from the stored start solutions (algebraic/solve.py), which
finds every isolated solution there is. The result is the homotopy's :class:`Solutions`, the
same layout and checks for either route, with ``route`` naming per instance the method that
ran.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.algebraic import compiled
from screwkit.algebraic.certify import Certificate, bombieri_weyl_norm, certify
from screwkit.algebraic.path import TrackOptions
from screwkit.algebraic.polynomial import Complex, PolynomialSystem
from screwkit.algebraic.solve import Solutions, collect_solutions
from screwkit.algebraic.track import PathStatus, track_parameter_homotopy
from screwkit.errors import InputError
from screwkit.kinematics.modes import sixr_compiled
from screwkit.kinematics.modes.loop6r import (
    LOOP6R_GENERIC_COUNT,
    PARAMETER_NAMES,
    loop6r_start,
    loop6r_system,
)
from screwkit.kinematics.modes.sixr_elimination import eliminate

#: Newton steps at most on the eigen route's points before the α-test (each roughly squares the
#: error; the points arrive within ~1e-12..1e-6 relative: one step reaches round-off for most)
NEWTON_STEPS = 3
#: a Newton step this small (relative) leaves the point at round-off: no further step there
SETTLED = 1e-10
#: an uncertified point counts as a solution when its Newton step is this small (relative)
CONVERGED = 1e-8
#: the cyclic relabellings of the loop tried in turn on the instances still unsettled
SHIFTS = (0, 1, 5, 2, 4, 3)
#: and as distinct from another when they are this far apart (relative)
DISTINCT = 1e-6
ELIMINATION = "elimination (Raghavan & Roth; 24 × 24 eigenproblem)"
#: the pairs i < j of an instance's 16 points
_PAIR_I, _PAIR_J = np.triu_indices(LOOP6R_GENERIC_COUNT, 1)
#: the fields of a certificate, in order
_FIELDS = tuple(f.name for f in fields(Certificate))
HOMOTOPY = "parameter homotopy (elimination did not settle 16 distinct solutions)"


def _targets(params: ArrayLike) -> Complex:
    p = np.asarray(params, dtype=complex)
    k = len(PARAMETER_NAMES)
    if p.ndim not in (1, 2) or p.shape[-1] != k:
        raise InputError(f"6R parameters must have shape ({k},) or (B, {k}); got {p.shape}")
    if not np.isfinite(p).all():
        raise InputError("6R parameters must be finite")
    return p.reshape(-1, k)


def _newton(system: PolynomialSystem, x: Complex, p: Complex, steps: int) -> Complex:
    """Up to ``steps`` Newton steps on F(·; p) from x (P, n), each after the first only at the
    points whose last step exceeded :data:`SETTLED` (relative); a point whose Jacobian is
    singular or not finite is left where it is (its certificate will fail). Compiled, one
    point at a time, when numba is there (:func:`.compiled.newton_terms`)."""
    if compiled.AVAILABLE:
        return compiled.newton_terms(system, x, p, steps, SETTLED)
    x = np.array(x, dtype=complex)
    n = x.shape[1]
    active = np.arange(len(x))
    for _ in range(steps):
        if not len(active):
            break
        xa, pa = x[active], p[active]
        with np.errstate(all="ignore"):
            F, J, _ = system.evaluate(xa, pa, want_jp=False)
            ok: NDArray[np.bool_] = np.asarray(np.isfinite(F).all(1) & np.isfinite(J).all((1, 2)),
                                               dtype=bool)
            Js: Complex = np.where(ok[:, None, None], J, np.eye(n))
            Fs: Complex = np.where(ok[:, None], F, 0.0)
            try:
                step: Complex = np.asarray(np.linalg.solve(Js, Fs[..., None])[..., 0], dtype=complex)
            except np.linalg.LinAlgError:  # an exactly singular Jacobian somewhere
                step = np.asarray(np.einsum("pij,pj->pi", np.linalg.pinv(Js), Fs), dtype=complex)
            ok &= np.isfinite(step).all(1)
            x[active[ok]] = xa[ok] - step[ok]
            size = np.abs(step).max(1) / (1.0 + np.abs(xa).max(1))
        active = active[ok & (size > SETTLED)]
    return x


def eigen_route(params: ArrayLike
                ) -> tuple[Complex, NDArray[np.intp], NDArray[np.bool_], Certificate]:
    """The polished eigen-route solutions (P, 12) of the instances (B, 23) it settles, sorted
    by their instance (P,); whether each instance is settled: 16 solutions, all settled and
    pairwise distinct (B,); and the α-test of every point (P).

    A point is settled when certified (α-test; distinct from another when their balls of
    radius 2β are disjoint) or, where the α-test cannot decide (an ill-conditioned solution,
    e.g. one far out near infinity, which the homotopy cannot certify either), when its
    Newton step is below :data:`CONVERGED` (relative; distinct when apart by more than
    :data:`DISTINCT`, the homotopy's own rule in algebraic/solve.py); every pair of an
    instance's 16 is compared. A real instance's
    system is real, so its solutions come in conjugate pairs with equal certificates: only
    the solutions with Im x3 ≥ 0 are polished and certified, and the others are their
    conjugates. An instance left unsettled is eliminated again with the loop relabelled
    cyclically (:data:`SHIFTS`): a geometry that makes the 12 × 12 pencil singular in one
    labelling (two consecutive axes that meet, say) may not make it singular in another."""
    targets = _targets(params)
    B = len(targets)
    todo = np.arange(B)
    ok = np.zeros(B, dtype=bool)
    parts: list[tuple[Complex, NDArray[np.intp], Certificate]] = []
    for shift in SHIFTS:
        xs, inst, good, cert = _eigen_pass(targets[todo], shift)
        keep = np.flatnonzero(good[inst])
        if len(keep) < len(inst):  # (else keep is every row: nothing to take)
            xs, inst, cert = xs[keep], inst[keep], _rows(cert, keep)
        parts.append((xs, todo[inst], cert))
        ok[todo[good]] = True
        todo = todo[~good]
        if not len(todo):
            break
    if len(parts) == 1:  # one labelling settled them all: already sorted by instance
        return parts[0][0], parts[0][1], ok, parts[0][2]
    xs = np.concatenate([x for x, _, _ in parts])
    inst = np.concatenate([i for _, i, _ in parts])
    cert = parts[0][2]
    for _, _, c in parts[1:]:
        cert = _joined(cert, c)
    order = np.argsort(inst, kind="stable")
    return xs[order], inst[order], ok, _rows(cert, order)


def _eigen_pass(targets: Complex, shift: int
                ) -> tuple[Complex, NDArray[np.intp], NDArray[np.bool_], Certificate]:
    """:func:`eigen_route` with one labelling of the loop: every point, settled or not."""
    B, m = len(targets), LOOP6R_GENERIC_COUNT
    system = loop6r_system()
    x, x3, _ = eliminate(targets, shift)
    real = np.all(targets.imag == 0, axis=1)[:, None]
    sel = np.flatnonzero((~real | (x3.imag >= 0)).ravel())
    inst = sel // m
    twin = np.flatnonzero((real & (x3.imag > 0)).ravel()[sel])  # their conjugates solve too
    p = targets[inst]
    xs = _newton(system, x.reshape(B * m, -1)[sel].astype(complex), p, NEWTON_STEPS)
    finite: NDArray[np.bool_] = np.asarray(np.isfinite(xs).all(1), dtype=bool)
    xs = np.where(finite[:, None], xs, 0.0)
    cert = certify(system, xs, p, fast=True, norm_f=bombieri_weyl_norm(system, targets)[inst])
    # every point: the polished ones, then their twins (conjugated), sorted by instance (one
    # instance: already in order), in one take
    rows = np.concatenate([np.arange(len(sel)), twin])
    flip = np.arange(len(rows)) >= len(sel)
    if B > 1:
        order = np.argsort(inst[rows], kind="stable")
        rows, flip = rows[order], flip[order]
    xs, inst, finite = np.where(flip[:, None], xs[rows].conj(), xs[rows]), inst[rows], finite[rows]
    cert = _rows(cert, rows, flip)
    return xs, inst, _settled(xs, inst, finite, cert, B), cert


def _settled(xs: Complex, inst: NDArray[np.intp], finite: NDArray[np.bool_], cert: Certificate,
             B: int) -> NDArray[np.bool_]:
    """Whether each of the B instances is settled by its points xs (sorted by ``inst``):
    16 of them, each certified or converged, pairwise distinct (:func:`eigen_route`);
    compiled when numba is there (:func:`.sixr_compiled.settled`)."""
    if sixr_compiled.AVAILABLE:
        return sixr_compiled.settled(xs, inst, finite, cert.newton, cert.certified, cert.radius,
                                     B, LOOP6R_GENERIC_COUNT, CONVERGED, DISTINCT)
    m = LOOP6R_GENERIC_COUNT
    scale = 1.0 + np.abs(xs).max(axis=1)
    with np.errstate(invalid="ignore"):
        settled = np.abs(xs - cert.newton).max(axis=1) <= CONVERGED * scale
    good = (cert.certified | settled) & finite
    radius = np.where(cert.certified, cert.radius, DISTINCT * scale)
    ok = np.bincount(inst, minlength=B) == m
    full = np.flatnonzero(ok[inst])  # the instances with 16 points: contiguous, sorted
    x16, r16 = xs[full].reshape(-1, m, xs.shape[1]), radius[full].reshape(-1, m)
    # every pair i < j at once (120 per instance): ‖x_i − x_j‖ > r_i + r_j
    gap = np.linalg.norm(x16[:, _PAIR_I] - x16[:, _PAIR_J], axis=-1)
    ok[ok] = good[full].reshape(-1, m).all(axis=1) & (
        gap > r16[:, _PAIR_I] + r16[:, _PAIR_J]).all(axis=1)
    return ok


def _rows(cert: Certificate, rows: NDArray[np.intp],
          flip: NDArray[np.bool_] | None = None) -> Certificate:
    """The certificate of the points ``rows``; where ``flip``, of their conjugates (a real
    system's: the same bounds, the conjugate Newton points and values)."""
    parts: dict[str, Any] = {name: (None if getattr(cert, name) is None
                                    else getattr(cert, name)[rows]) for name in _FIELDS}
    if flip is not None:
        for name in ("newton", "value"):
            if parts[name] is not None:
                parts[name] = np.where(flip[:, None], parts[name].conj(), parts[name])
    return Certificate(**parts)


def _joined(a: Certificate, b: Certificate) -> Certificate:
    parts: dict[str, Any] = {name: np.concatenate([getattr(a, name), getattr(b, name)])
                             for name in _FIELDS}
    return Certificate(**parts)


def solve_loop6r(params: ArrayLike, options: TrackOptions | None = None) -> Solutions:
    """Every isolated solution of 6R instances (23,) or (B, 23) (:mod:`.loop6r`'s parameters):
    the eigen route, the parameter homotopy (``options``) for the instances it does not
    settle (module docstring). ``route`` says which ran for each instance."""
    targets = _targets(params)
    B, m = len(targets), LOOP6R_GENERIC_COUNT
    x_eig, i_eig, ok, cert = eigen_route(targets)
    rows = np.flatnonzero(ok[i_eig])
    if len(rows) < len(i_eig):  # (else every row)
        cert, x_eig, i_eig = _rows(cert, rows), x_eig[rows], i_eig[rows]
    xs, inst = [x_eig], [i_eig]
    status = [np.full(len(inst[0]), int(PathStatus.REGULAR), dtype=np.int8)]
    mult = [np.ones(len(inst[0]), dtype=np.int64)]
    at_infinity, failed = np.zeros(B, dtype=np.int64), np.zeros(B, dtype=np.int64)
    redo = np.flatnonzero(~ok)
    how = f"{ELIMINATION} on {int(ok.sum())} of {B} instances"
    if len(redo):
        start = loop6r_start()  # found once per process, only when needed
        how += f"; the parameter homotopy on the others ({start.how_found})"
        system, r = loop6r_system(), len(start.x)
        instance = np.repeat(redo, r)
        res = track_parameter_homotopy(system, start.p, targets[instance],
                                       np.tile(start.x, (len(redo), 1)), options,
                                       instance=np.repeat(np.arange(len(redo)), r))
        end = (res.status == PathStatus.REGULAR) | (res.status == PathStatus.SINGULAR)
        cert = _joined(cert, certify(system, res.x[end], targets[instance[end]]))
        xs.append(res.x[end])
        inst.append(instance[end])
        status.append(res.status[end])
        mult.append(res.multiplicity[end])
        at_infinity += np.bincount(instance[res.status == PathStatus.AT_INFINITY], minlength=B)
        failed += np.bincount(instance[res.status == PathStatus.FAILED], minlength=B)
    route = tuple(ELIMINATION if good else HOMOTOPY for good in ok)
    return collect_solutions(loop6r_system(), targets, np.concatenate(xs),
                             np.concatenate(inst), np.concatenate(status), np.concatenate(mult),
                             at_infinity, failed, m, how, route, cert,
                             None if len(redo) else np.arange(len(xs[0])))
