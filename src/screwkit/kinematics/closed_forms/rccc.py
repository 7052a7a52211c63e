"""Closed-form kinematics of the R–C–C–C loop in Hartenberg–Denavit form
(:func:`screwkit.model.families.rccc`, or a joint list R C C C with the R joint the input).

Derivation (the principle of transference: the spherical four-bar's equation with dual
angles, Bagci 1969 App. A; Yang & Freudenstein's dual input-output equation). The loop is
Z(θ̂1) X(α̂1) Z(θ̂2) X(α̂2) Z(θ̂3) X(α̂3) Z(θ̂4) X(α̂4) = I with θ̂1 = θ1 + ε s1 (s1 the input
joint's constant offset), θ̂i = θi + ε si the cylinder joints' dual angles and α̂i = αi + ε ai.
Then Z(θ̂2) X(α̂2) Z(θ̂3) = X(−α̂1) Z(−θ̂1) X(−α̂4) Z(−θ̂4) X(−α̂3), and since Z(·) leaves e_z
fixed, e_zᵀ(·)e_z of both sides gives

    Â cos θ̂4 + B̂ sin θ̂4 = Ĉ,   Â = −sin α̂3 (sin α̂1 cos α̂4 cos θ̂1 + cos α̂1 sin α̂4),
                                 B̂ = sin α̂1 sin α̂3 sin θ̂1,
                                 Ĉ = cos α̂2 + sin α̂1 sin α̂4 cos α̂3 cos θ̂1 − cos α̂1 cos α̂4 cos α̂3.

Its real part is the spherical four-bar's input-output equation, A cos θ4 + B sin θ4 = C: two
roots θ4 = atan2(B, A) ± acos(C/√(A² + B²)), the two assembly modes. Its dual part is linear in
the slide s4: s4 (B cos θ4 − A sin θ4) = C′ − A′ cos θ4 − B′ sin θ4 (primes: dual parts).
Joints 2 and 3 follow from M = Z(θ̂2) X(α̂2) Z(θ̂3), now known: M e_z = sin α̂2 (sin θ̂2,
−cos θ̂2, ·) and e_zᵀ M = sin α̂2 (sin θ̂3, cos θ̂3, ·), so θ̂2 = atan2(M₁₃, −M₂₃) and
θ̂3 = atan2(M₃₁, M₃₂) (turned by π where sin α2 < 0), each a dual atan2 giving the angle and
the slide at once. The closed form needs sin α2 ≠ 0 and the input-output equation not to vanish
identically (A = B = C = 0); :func:`rccc_applies` says when.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual import number as dn
from screwkit.dual.number import Dual
from screwkit.kinematics.closed_forms.rssr import trig_roots
from screwkit.kinematics.tracker.loop import Array
from screwkit.model.linkage import Linkage

#: sin α2 (and the input-output equation's coefficients) below this make the closed form
#: inapplicable: parallel cylinder axes leave a slide undetermined
PARALLEL_TOL = 1e-9
DEAD_CENTRE_TOL = 1e-9  # |∂/∂θ4| below this fraction of √(A² + B²): no rates there


@dataclass(frozen=True)
class RCCCDimensions:
    """Link lengths a1…a4 and twists α1…α4 (Hartenberg–Denavit) and the input's offset s1."""

    lengths: tuple[float, float, float, float]
    twists: tuple[float, float, float, float]
    input_offset: float = 0.0


def rccc_dimensions(linkage: Linkage) -> RCCCDimensions | None:
    """The RCCC dimensions of a loop R C C C in Hartenberg–Denavit form whose R joint is the
    only input (link transforms X(α + εa)), or None if the loop is not one."""
    kinds = tuple(j.kind for j in linkage.joints)
    if kinds != ("R", "C", "C", "C") or linkage.inputs != (f"{linkage.joints[0].name}.theta",):
        return None
    lengths, twists = [], []
    for L in linkage.link_transforms:
        R, t = np.asarray(L.real), np.asarray(L.translation)
        if not (np.allclose(R[0], [1, 0, 0], atol=1e-12) and np.allclose(R[:, 0], [1, 0, 0],
                                                                         atol=1e-12)
                and abs(t[1]) < 1e-12 and abs(t[2]) < 1e-12):
            return None
        twists.append(float(np.arctan2(R[2, 1], R[1, 1])))
        lengths.append(float(t[0]))
    return RCCCDimensions(tuple(lengths), tuple(twists),  # type: ignore[arg-type]
                          float(linkage.joints[0].offset))


def rccc_applies(linkage: Linkage) -> bool:
    """Whether the RCCC closed form solves this loop (module docstring)."""
    dims = rccc_dimensions(linkage)
    return dims is not None and abs(np.sin(dims.twists[1])) > PARALLEL_TOL \
        and abs(np.sin(dims.twists[2])) > PARALLEL_TOL


@dataclass(frozen=True)
class RCCCMotion:
    """Both roots (columns + then −): every joint's angle and slide (N, 2, 7) in the layout
    order θ1, θ2, s2, θ3, s3, θ4, s4, where they assemble, and dead centres."""

    scalars: Array
    assembles: NDArray[np.bool_]
    dead_centre: NDArray[np.bool_]


def _hat(angle: float, length: float) -> Dual:
    return Dual(angle, length)


def _m_entries(a1: Dual, a3: Dual, a4: Dual, t1: Dual, t4: Dual) -> dict[str, Dual]:
    """Entries M₁₃, M₂₃, M₃₁, M₃₂ of M = X(−α̂1) Z(−θ̂1) X(−α̂4) Z(−θ̂4) X(−α̂3)."""
    c1, s1, c4, s4 = dn.cos(t1), dn.sin(t1), dn.cos(t4), dn.sin(t4)
    ca1, sa1, ca3, sa3 = dn.cos(a1), dn.sin(a1), dn.cos(a3), dn.sin(a3)
    ca4, sa4 = dn.cos(a4), dn.sin(a4)
    # v = X(−α̂4) Z(−θ̂4) X(−α̂3) e_z and w = e_xᵀ/e_yᵀ/e_zᵀ … : expand the product by columns
    # N = X(−α̂4) Z(−θ̂4) X(−α̂3): its columns
    n1 = (c4, ca4 * -s4, sa4 * s4)  # X(−α4) Z(−θ4) e_x (X(−α3) leaves e_x)
    z2 = (s4 * ca3, c4 * ca3, -sa3)  # Z(−θ4) X(−α3) e_y
    n2 = (z2[0], ca4 * z2[1] + sa4 * z2[2], -sa4 * z2[1] + ca4 * z2[2])
    z3 = (s4 * sa3, c4 * sa3, ca3)  # Z(−θ4) X(−α3) e_z
    n3 = (z3[0], ca4 * z3[1] + sa4 * z3[2], -sa4 * z3[1] + ca4 * z3[2])

    def left(col: tuple[Dual, Dual, Dual]) -> tuple[Dual, Dual, Dual]:
        # X(−α̂1) Z(−θ̂1) col
        x = c1 * col[0] + s1 * col[1]
        y = -s1 * col[0] + c1 * col[1]
        return x, ca1 * y + sa1 * col[2], -sa1 * y + ca1 * col[2]

    m1, m2, m3 = left(n1), left(n2), left(n3)
    return {"13": m3[0], "23": m3[1], "31": m1[2], "32": m2[2]}


def rccc_motion(dims: RCCCDimensions, theta1: Array) -> RCCCMotion:
    """Both assembly modes of the RCCC at every input angle (module docstring)."""
    th = np.asarray(theta1, dtype=float)
    N = th.shape[0]
    (a1, a2, a3, a4), (al1, al2, al3, al4) = dims.lengths, dims.twists
    A1, A2, A3, A4 = (_hat(al, a) for al, a in ((al1, a1), (al2, a2), (al3, a3), (al4, a4)))
    t1 = Dual(th, np.full(N, dims.input_offset))
    c1, s1 = dn.cos(t1), dn.sin(t1)
    A = -dn.sin(A3) * (dn.sin(A1) * dn.cos(A4) * c1 + dn.cos(A1) * dn.sin(A4))
    B = dn.sin(A1) * dn.sin(A3) * s1
    C = dn.cos(A2) + dn.sin(A1) * dn.sin(A4) * dn.cos(A3) * c1 - dn.cos(A1) * dn.cos(A4) * dn.cos(A3)
    roots, slope, ok = trig_roots(A.real, B.real, C.real)
    scale = np.hypot(A.real, B.real)[:, None]
    dead = ok & (np.abs(slope) <= DEAD_CENTRE_TOL * scale)
    out = np.full((N, 2, 7), np.nan)
    sign = 1.0 if np.sin(al2) > 0 else -1.0
    for j in range(2):
        th4 = np.where(ok[:, j], roots[:, j], 0.0)
        c4, s4 = np.cos(th4), np.sin(th4)
        den = np.where(dead[:, j] | ~ok[:, j], 1.0, B.real * c4 - A.real * s4)
        slide4 = (C.dual - A.dual * c4 - B.dual * s4) / den
        t4 = Dual(th4, slide4)
        M = _m_entries(A1, A3, A4, t1, t4)
        t2 = dn.atan2(M["13"] * sign, -M["23"] * sign)
        t3 = dn.atan2(M["31"] * sign, M["32"] * sign)
        out[:, j] = np.stack([th, t2.real, t2.dual, t3.real, t3.dual, th4, slide4], axis=-1)
    out[~ok] = np.nan
    return RCCCMotion(out, ok, dead)
