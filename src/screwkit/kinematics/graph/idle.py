"""Idle rod spins held still: a body joined by exactly two ball joints (or a telescopic leg of
bodies slid by P joints between two balls, model/spin_groups.py) can spin about the line
through their centres without moving anything else. The minimum-norm rates leave some of that
spin in (the norm is the joints', not the rod's); here the idle part of the rates is chosen so
that every such rod's angular velocity and acceleration have no component along its axis
(ω·u = 0 and then α·u = 0, since u̇ = ω × u), as single loops hold theirs
(kinematics/tracker/idle_spin.py). Loads that do no work along a spin (a centre of mass on the axis, an
inertia symmetric about it) are then carried exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout, body_accelerations, body_twists
from screwkit.kinematics.graph.newton import RANK_CUTOFF, Linearised, column_scale
from screwkit.model.mechanism import Mechanism
from screwkit.model.spin_groups import spin_groups

Array = NDArray[np.float64]


def rods(mech: Mechanism) -> list[tuple[str, int, int]]:
    """(body, first ball joint, second ball joint) of every rod: a body held by exactly two
    balls, or a telescopic leg of bodies slid by P joints between its two balls
    (model/spin_groups.py; its first body, whose spin the leg's bodies share)."""
    return [(g.bodies[0], g.balls[0], g.balls[1]) for g in spin_groups(mech)]


def spin_lines(mech: Mechanism) -> list[tuple[str, Array, Array]]:
    """(body, a point on its line, the line's unit direction) of every body that can spin
    about one line without moving any other body: its joints are S joints centred on the line
    and R or C joints whose axes are the line (a rod between two balls; a strut held by a C
    joint and a ball on its axis). The drawn positions decide; the tolerance is 1e-9 of the
    length scale."""
    out = []
    tol = 1e-9 * mech.length_scale
    for b in mech.body_names:
        joints = [j for j in mech.joints if b in j.bodies]
        if len(joints) < 2 or any(j.kind not in ("S", "R", "C") for j in joints):
            continue
        axial = [j for j in joints if j.kind != "S"]
        if axial:
            c, u = axial[0].at, axial[0].axis
        else:
            far = max(joints[1:], key=lambda j: float(np.linalg.norm(j.at - joints[0].at)))
            c, u = joints[0].at, far.at - joints[0].at
            if np.linalg.norm(u) <= tol:
                continue
            u = u / np.linalg.norm(u)

        def on_line(x: Array, c: Array = c, u: Array = u) -> bool:
            w = x - c
            return bool(np.linalg.norm(w - (w @ u) * u) <= tol)

        if all(on_line(j.at) for j in joints) and all(
                np.linalg.norm(np.cross(j.axis, u)) <= 1e-9 for j in axial):
            out.append((b, np.asarray(c, float), np.asarray(u, float)))
    # and every body of a telescopic leg (bodies slid by P joints between two balls)
    for g in spin_groups(mech):
        if len(g.bodies) > 1:
            near, end = (np.asarray(mech.joints[k].at, float) for k in g.balls)
            line = (end - near) / np.linalg.norm(end - near)
            out += [(b, near, line) for b in g.bodies]
    return out


def _spin_of(mech: Mechanism, lay: GraphLayout, lin: Linearised, q: Array,
             found: list[tuple[str, int, int]], bias: Array | None = None) -> Array:
    """Each rod's spin ω·u (N, r) under freedom rates ``q`` (N, m); with the joints'
    velocity-product terms ``bias``, ``q`` are accelerations and this is α·u."""
    if bias is None:
        V, _ = body_twists(mech, lay, lin.frames.screws, q)
    else:
        V = body_accelerations(mech, lay, lin.frames.screws, q, bias)
    out = np.empty((q.shape[0], len(found)))
    for k, (body, j1, j2) in enumerate(found):
        u = lin.frames.centres[:, j2] - lin.frames.centres[:, j1]
        size = np.linalg.norm(u, axis=1, keepdims=True)
        u = np.where(size > 0.0, u / np.where(size > 0.0, size, 1.0), 0.0)  # 0: not reached
        out[:, k] = np.einsum("ni,ni->n", V[:, lay.body_of[body], :3], u)
    return out


@dataclass(frozen=True)
class IdleBasis:
    """What :func:`hold_rod_spin` needs of a linearisation, the same for rates and
    accelerations: the rods, the scaled idle directions ``null`` (N, d, m_p) of the passive
    block (its right singular vectors past its rank) and each rod's spin ``C`` (N, r, d) under
    each of them."""

    found: list[tuple[str, int, int]]
    null: Array
    C: Array


def idle_basis(mech: Mechanism, lay: GraphLayout, lin: Linearised) -> IdleBasis | None:
    """The idle directions and the rods' spins under them (:class:`IdleBasis`; None: no rod, no
    passive freedom or no idle direction). Made once per linearisation and shared by the rates
    and the accelerations (one SVD instead of two)."""
    found = rods(mech)
    passive = list(lay.passive)
    if not found or not passive:
        return None
    Jp = lin.J[:, :, passive]
    _, s, Vt = np.linalg.svd(Jp)
    keep = s > RANK_CUTOFF * np.maximum(s[:, :1], 1e-300)
    rank = int(np.median(keep.sum(axis=1)))
    null = Vt[:, rank:]  # (N, d, m_p): scaled idle directions
    d = null.shape[1]
    if d == 0:
        return None
    cs = column_scale(lay)[passive]
    C = np.empty((Jp.shape[0], len(found), d))
    for k in range(d):
        z = np.zeros((Jp.shape[0], lay.m))
        z[:, passive] = null[:, k] * cs
        C[:, :, k] = _spin_of(mech, lay, lin, z, found)
    return IdleBasis(found, null, C)


def hold_rod_spin(mech: Mechanism, lay: GraphLayout, lin: Linearised, q: Array,
                  bias: Array | None = None, basis: IdleBasis | None = None) -> Array:
    """Rates ``q`` (N, m) with the idle part chosen so no rod spins; with the joints'
    velocity-product terms ``bias`` (closure.body_twists), accelerations with no spin
    acceleration. ``basis``: :func:`idle_basis` of ``lin`` when already made, else made here
    (``q`` is returned as it is where there is none)."""
    if basis is None:
        basis = idle_basis(mech, lay, lin)
    if basis is None:
        return q
    passive = list(lay.passive)
    cs = column_scale(lay)[passive]
    spin = _spin_of(mech, lay, lin, q, basis.found, bias)
    coef = -np.einsum("nij,nj->ni", np.linalg.pinv(basis.C), spin)
    out = q.copy()
    out[:, passive] += np.einsum("ndi,nd->ni", basis.null, coef) * cs
    return out
