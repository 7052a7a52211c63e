"""First-order sensitivity of a mode's joint variables to a parameter of the linkage (a
dimension), from the loop's screw Jacobian (docs/sweeps.md, "Tolerance analysis").

With the inputs held, differentiating the loop closure G(q, p) = Π J_i(q_i) L_i(p) = I with
respect to a parameter p gives (Bagci 1969 eqs. 3.19–3.26, the closure's differential as a sum
of screws carried to the ground frame)

    J_p ∂q_p/∂p = −Σ_i Ad(P_i) ξ_i(p),      ξ_i = (∂L_i/∂p · L_i⁻¹)^∨

where J_p holds the passive freedom screws (the columns of :func:`~screwkit.kinematics.tracker.loop.
forward`), P_i is the frame after joint i and ξ_i the twist by which the constant link transform
L_i moves when p changes (joint offsets and pitches contribute screws at the frame before their
joint the same way). The Jacobian part is exact; ∂L_i/∂p follows from the family's constructor
by Richardson-extrapolated central differences of the constant transforms alone (truncation
O(h⁶); the transforms are polynomials in the lengths and trigonometric in the angles, so this
is exact to rounding, ~1e-12 relative), never by re-solving the motion.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.motion import ModeMotion
from screwkit.kinematics.tracker.loop import Array, forward, layout
from screwkit.model.linkage import Linkage


class SensitivityError(InputError):
    """A parameter whose sensitivity cannot be computed (the message says why)."""


@dataclass(frozen=True)
class LoopConstants:
    """The constants of a loop that a parameter can move: link transforms (rotation (n, 3, 3),
    translation (n, 3)), joint offsets (n,) and pitches (n,)."""

    rotation: Array
    translation: Array
    offset: Array
    pitch: Array

    @classmethod
    def of(cls, linkage: Linkage) -> LoopConstants:
        return cls(np.stack([t.real for t in linkage.link_transforms]),
                   np.stack([t.translation for t in linkage.link_transforms]),
                   np.array([j.offset for j in linkage.joints], dtype=float),
                   np.array([j.pitch for j in linkage.joints], dtype=float))

    def vector(self) -> Array:
        return np.concatenate([self.rotation.ravel(), self.translation.ravel(), self.offset,
                               self.pitch])

    def from_vector(self, v: Array) -> LoopConstants:
        n = self.offset.size
        return LoopConstants(v[:9 * n].reshape(n, 3, 3), v[9 * n:12 * n].reshape(n, 3),
                             v[12 * n:13 * n], v[13 * n:])


def richardson_derivative(f: Callable[[float], Array], x: float, h: float,
                          levels: int = 3) -> Array:
    """df/dx by central differences at h, h/2, h/4 … combined by Richardson extrapolation
    (each level removes the next even power of h)."""
    table = [(f(x + h / 2**k) - f(x - h / 2**k)) / (2 * h / 2**k) for k in range(levels)]
    for m in range(1, levels):
        factor = 4.0**m
        table = [(factor * table[k + 1] - table[k]) / (factor - 1) for k in range(len(table) - 1)]
    return table[0]


def constants_derivative(rebuild: Callable[[float], Linkage], value: float, step: float
                         ) -> LoopConstants:
    """∂(link transforms, offsets, pitches)/∂p of the linkage ``rebuild(p)`` at ``value``."""
    nominal = rebuild(value)
    shape = (len(nominal.joints), tuple(j.kind for j in nominal.joints))

    def constants(p: float) -> Array:
        lk = rebuild(p)
        if (len(lk.joints), tuple(j.kind for j in lk.joints)) != shape:
            raise SensitivityError("the loop's joints change with the parameter")
        return LoopConstants.of(lk).vector()

    return LoopConstants.of(nominal).from_vector(richardson_derivative(constants, value, step))


def _vee(w: Array) -> Array:
    return 0.5 * np.array([w[2, 1] - w[1, 2], w[0, 2] - w[2, 0], w[1, 0] - w[0, 1]])


def closure_twists(linkage: Linkage, mode: ModeMotion, d: LoopConstants) -> Array:
    """Σ_i Ad(P_i) ξ_i: the twist (N, 6) by which the loop closure opens per unit parameter,
    in the ground frame (module docstring)."""
    lay = layout(linkage)
    fr = forward(linkage, mode.conf, lay)
    k = LoopConstants.of(linkage)
    N = mode.conf.size
    total = np.zeros((N, 6))
    ez = np.array([0.0, 0.0, 1.0])
    for i, joint in enumerate(linkage.joints):
        R, t = k.rotation[i], k.translation[i]
        w = _vee(d.rotation[i] @ R.T)
        v = d.translation[i] - np.cross(w, t)
        ws = fr.after_R[:, i] @ w
        total += np.concatenate([ws, fr.after_R[:, i] @ v + np.cross(fr.after_p[:, i], ws)], -1)
        if d.offset[i] == 0.0 and d.pitch[i] == 0.0:
            continue
        axis = fr.before_R[:, i] @ ez
        if joint.kind == "P":  # a constant rotation about the slide axis
            total += d.offset[i] * np.concatenate([axis, np.cross(fr.before_p[:, i], axis)], -1)
            continue
        # a constant translation along the joint axis (for H: offset + pitch·θ)
        amount = np.full(N, d.offset[i])
        if joint.kind == "H":
            col = lay.scalar_col[lay.names.index(f"{joint.name}.theta")]
            amount = amount + d.pitch[i] * mode.conf.scalars[:, col]
        total += amount[:, None] * np.concatenate([np.zeros_like(axis), axis], -1)
    return total


def joint_sensitivities(linkage: Linkage, mode: ModeMotion, d: LoopConstants
                        ) -> dict[str, NDArray[np.float64]]:
    """∂q/∂p (N,) of every scalar joint freedom ``"<joint>.<freedom>"`` (rad or m per unit
    parameter), inputs held: zero for the inputs, NaN where the mode does not assemble or is
    singular."""
    lay = layout(linkage)
    fr = forward(linkage, mode.conf, lay)
    L = linkage.length_scale
    rows = np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])
    names = list(lay.names)
    p_idx = [f for f, n in enumerate(names) if n not in linkage.inputs]
    cols = np.array([L if lay.is_translation[f] else 1.0 for f in p_idx])
    Jp = fr.screws[:, :, p_idx] * rows[None, :, None] * cols[None, None, :]
    rhs = -closure_twists(linkage, mode, d) * rows
    dq = np.einsum("nij,nj->ni", np.linalg.pinv(Jp, rcond=1e-10), rhs) * cols
    bad = ~np.asarray(mode.assembles) | np.asarray(mode.singular)
    out: dict[str, NDArray[np.float64]] = {}
    for f, name in enumerate(names):
        if lay.scalar_col[f] < 0:
            continue  # spherical joints: orientation, not a scalar variable
        values = np.zeros(mode.conf.size) if name in linkage.inputs else dq[:, p_idx.index(f)]
        values = np.array(values, dtype=float)
        values[bad] = np.nan
        out[name] = values
    return out


def seed_aliases(mode: ModeMotion) -> dict[str, tuple[str, float]]:
    """Seed names that are a joint freedom or its negative (φ0 = −output_C.theta …): name →
    (freedom, sign), so their sensitivities follow from the freedom's."""
    out: dict[str, tuple[str, float]] = {}
    ok = np.asarray(mode.assembles)
    freedoms = {n: v for n, v in mode.variables.items() if "." in n}
    for name, values in mode.variables.items():
        if "." in name or not ok.any():
            continue
        for fname, fv in freedoms.items():
            for sign in (1.0, -1.0):
                if np.array_equal(values[ok], sign * fv[ok]):
                    out[name] = (fname, sign)
                    break
            if name in out:
                break
    return out
