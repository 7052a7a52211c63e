"""Closed-form statics of the CSSP (Rahman 1996 §2.2) for a block of samples.

The CSSP — crank on an R (or driven C) joint, rod between two ball joints, slider on a P joint —
is statically determinate apart from the rod's idle spin about its own axis
(docs/dynamics.md). With W_j the wrench through joint j (proximal on distal; moment about the
reference point r), B_l the applied inertia + weight (+ external) wrench on link l, the link
balances give W_1 = W_0 + B_0, W_2 = W_1 + B_1, W_3 = W_2 + B_2 (:mod:`loop_statics`). Write the
crank-on-rod wrench W_1 as a force f at the pin centre D and a moment m_D about it; u the unit
vector from D to the ball centre P, d = |P − D|, k4 the slider axis, and M_P the rod load's
moment about P, μ = u·M_P. The passive freedoms ask

    m_D = 0                      (pin: no moment about its centre)
    m_D − d u × f + M_P = 0      (ball: W_2 has no moment about P)
    k4 · (f + F_1 + F_2) = 0     (slider: no force along its axis)

Seven equations, six unknowns, rank six: the component of the ball equation along u,
u·m_D + μ = 0, contradicts the pin's unless μ = 0 — the rod's spin is idle. The generic solver
takes the least-squares solution in the scaled units of :mod:`loop_statics` (rows of moment
divided by the length scale ℓ), which is, in closed form,

    m_D = −(μ/2) u,    f = (M_P × u)/d + λ u,    λ = −k4·((M_P × u)/d + F_1 + F_2) / (k4·u),

with the unbalanced generalised force (the residual) of norm |μ| / (√2 ℓ). The prototype kernel
of benchmarks/bench_dynamics.py is this solution for μ = 0 (an axisymmetric rod).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from screwkit.dynamics import component_arrays as soa
from screwkit.dynamics.component_arrays import Array, Vec
from screwkit.kinematics.closed_forms.cssp_motion import NotACSSPError, cssp_dimensions
from screwkit.model.linkage import Linkage

_KINDS = (("R", "C"), ("S",), ("S",), ("P",))


@dataclass(frozen=True)
class CSSPStatics:
    """What the closed form needs to know of the linkage: the input freedoms of the crank
    joint (``"theta"`` about its axis, and ``"s"`` along it for a driven C joint)."""

    crank_inputs: tuple[tuple[str, str], ...]  # (freedom name, "theta" | "s")


@dataclass(frozen=True)
class CSSPBlockLoads:
    """Reported reactions per joint (force, moment about the joint centre) as component
    tuples, efforts by freedom name, and the residual norm, for one block."""

    forces: tuple[Vec, Vec, Vec, Vec]
    moments: tuple[Vec, Vec, Vec, Vec]
    efforts: dict[str, Array]
    residual: Array


def cssp_statics_for(linkage: Linkage) -> CSSPStatics | None:
    """The closed form applies to a CSSP built by :func:`screwkit.model.families.cssp` (joints
    R|C, S, S, P; :func:`~screwkit.kinematics.closed_forms.cssp_motion.cssp_dimensions` accepts it) whose
    driven freedoms are exactly the crank joint's; ``None`` otherwise (the generic solve is
    used)."""
    try:
        cssp_dimensions(linkage)
    except NotACSSPError:
        return None
    joints = linkage.joints
    crank = joints[0]
    freedoms = [f"{crank.name}.theta"] + ([f"{crank.name}.s"] if crank.kind == "C" else [])
    if sorted(linkage.inputs) != sorted(freedoms):
        return None
    return CSSPStatics(tuple((f, f.rsplit(".", 1)[1]) for f in freedoms))


def _about(point: Vec, moment_ref: Vec, force: Vec) -> Vec:
    """Moment about ``point`` (relative to the reference) of a wrench given about the reference:
    m_point = m_ref − point × f."""
    return soa.sub(moment_ref, soa.cross(point, force))


def cssp_block_statics(
    plan: CSSPStatics,
    link_wrenches: list[tuple[Vec, Vec]],
    centres: list[Vec],
    axes: list[Vec],
    length_scale: float,
) -> CSSPBlockLoads:
    """Joint wrenches of the CSSP for one block (module docstring).

    ``link_wrenches``: per moving link (force, moment about the reference), component tuples;
    ``centres``: the four joint centres relative to the reference; ``axes``: the crank joint's
    and the slider joint's axes. Returns the reported
    reactions ( reactions: on the distal link, moment about the joint centre; the last joint's
    negated to give the load on the slider by the ground), ``efforts`` by freedom name and the
    ``residual`` norm (n,)."""
    (F0, M0), (F1, M1), (F2, M2) = link_wrenches
    c0, c1, c2, c3 = centres
    axis0, k4 = axes
    span = soa.sub(c2, c1)
    inv_d = 1.0 / np.sqrt(soa.dot(span, span))
    u = soa.scale(inv_d, span)
    M_P = _about(c2, M1, F1)  # the rod load's moment about the ball centre
    mu = soa.dot(u, M_P)
    f_perp = soa.scale(inv_d, soa.cross(M_P, u))
    lam = -soa.dot(k4, soa.add(f_perp, soa.add(F1, F2))) / soa.dot(k4, u)  # type: ignore[operator]
    f1 = soa.add(f_perp, soa.scale(lam, u))
    m1_pin = soa.scale(-0.5 * mu, u)
    # every joint wrench about the reference: W1 from (f, m_D), then the link balances
    m1 = soa.add(m1_pin, soa.cross(c1, f1))
    f0, m0 = soa.sub(f1, F0), soa.sub(m1, M0)
    f2, m2 = soa.add(f1, F1), soa.add(m1, M1)
    f3, m3 = soa.add(f2, F2), soa.add(m2, M2)
    m0_c = _about(c0, m0, f0)
    efforts: dict[str, Array] = {}
    for name, kind in plan.crank_inputs:
        value = soa.dot(axis0, m0_c) if kind == "theta" else soa.dot(axis0, f0)
        efforts[name] = np.asarray(value)
    m3_c = _about(c3, m3, f3)
    return CSSPBlockLoads(
        forces=(f0, f1, f2, soa.scale(-1.0, f3)),
        moments=(m0_c, m1_pin, _about(c2, m2, f2), soa.scale(-1.0, m3_c)),
        efforts=efforts,
        residual=np.abs(np.asarray(mu, dtype=float)) / (math.sqrt(2.0) * length_scale),
    )
