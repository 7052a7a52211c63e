"""One assembly mode's full motion from its closed configurations: link frames, joint centres and
axes, and the velocities and accelerations of every freedom and link.

Velocities solve the loop-closure rate equation J_p q̇_p = −J_in q̇_in (Bagci eqs. 3.27–3.48
differentiated; Rahman §1.4 done with the true axes); accelerations J_p q̈_p = −J_in q̈_in − J̇q̇
with J̇q̇ = Σ_{j<k} [S_j, S_k] q̇_j q̇_k (Lie brackets of the freedom screws). Passive freedoms
take the minimum-norm rates, except the spin of a link between two spherical joints (an S–S
rod), which is zero (ω·u = 0, Rahman 1996 §1.2). Where J_p loses rank beyond its passive
freedoms the configuration is singular: it is flagged, not divided through.

Every solver ends here — the generic loop solver and the closed forms alike — so every
:class:`~screwkit.kinematics.motion.ModeMotion` has the same fields and conventions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.loop import (
    Array,
    Configuration,
    Layout,
    LoopFrames,
    closure_twist,
    forward,
    lie_bracket,
)
from screwkit.kinematics.motion import ModeMotion
from screwkit.model.linkage import Linkage

#: relative singular-value threshold of the passive Jacobian below which a sample is singular
SINGULAR_RTOL = 1e-7


def _unit(d: Array) -> Array:
    return np.asarray(d / np.linalg.norm(d, axis=-1, keepdims=True))


@dataclass(frozen=True)
class _RateEquations:
    """The scaled rate equations of one mode: passive Jacobian (plus the zero-spin rows of S–S
    rods), its pseudo-inverse, and where it loses rank."""

    screws: Array  # (N, 6, m) unit freedom screws, ground frame
    spin: Array  # (N, r, m) zero-spin rows of the S–S rods
    spin_links: list[int]
    rows: Array
    cols: Array
    in_idx: list[int]
    p_idx: list[int]
    pinv: Array
    singular: NDArray[np.bool_]

    def solve(self, input_values: Array, bias: Array, spin_bias: Array) -> Array:
        """Passive rates (or accelerations) from the input ones and the bias terms."""
        S, C = self.screws, self.spin
        rhs = np.concatenate(
            [(-np.einsum("nij,nj->ni", S[:, :, self.in_idx], input_values) - bias) * self.rows,
             -np.einsum("nij,nj->ni", C[:, :, self.in_idx], input_values) - spin_bias], axis=1)
        return np.einsum("nij,nj->ni", self.pinv, rhs) * self.cols[self.p_idx]


def _rate_equations(linkage: Linkage, lay: Layout, fr: LoopFrames,
                    mask: NDArray[np.bool_]) -> _RateEquations:
    N, _, m = fr.screws.shape
    L = linkage.length_scale
    names = list(lay.names)
    in_idx = [names.index(n) for n in linkage.inputs]
    p_idx = [k for k in range(m) if k not in in_idx]
    rows = np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    S = fr.screws
    # Passive spin of a link between two spherical joints (an S–S rod): the rule is zero
    # absolute spin, ω_link·u = 0 with u the line of the two ball centres (Rahman 1996 §1.2).
    # Then α_link·u = −ω·u̇ = 0 too, and an axisymmetric rod's axial inertia does no work.
    spin_links = [i for i in range(len(linkage.joints) - 1)
                  if linkage.joints[i].kind == "S" and linkage.joints[i + 1].kind == "S"]
    C = np.zeros((N, len(spin_links), m))
    for r, i in enumerate(spin_links):
        u = _unit(fr.centres[:, i + 1] - fr.centres[:, i])
        upto = [f for f in range(m) if lay.joint_of[f] <= i]
        C[:, r, upto] = np.einsum("ni,nif->nf", u, S[:, :3, upto])
    Jp = np.concatenate([S[:, :, p_idx] * rows[None, :, None], C[:, :, p_idx]], axis=1)
    Jp = Jp * cols[p_idx][None, None, :]
    sv = np.linalg.svd(Jp, compute_uv=False)
    rank = np.sum(sv > SINGULAR_RTOL * sv[:, :1], axis=-1)
    generic_rank = int(np.max(rank[mask])) if mask.any() else 0
    singular = mask & (rank < generic_rank)
    pinv = np.linalg.pinv(Jp, rcond=1e-10)
    return _RateEquations(S, C, spin_links, rows, cols, in_idx, p_idx, pinv, singular)


def _link_twists(linkage: Linkage, lay: Layout, S: Array, qd: Array) -> tuple[Array, Array]:
    """Twist of the frame after each joint and the bias J̇q̇ accumulated up to it:
    J̇q̇ = Σ_k [V_before(k), S_k] q̇_k, V_before(k) the motion of the loop before freedom k."""
    N, _, m = S.shape
    bracket = np.zeros((N, 6))
    V = np.zeros((N, 6))
    link_V = np.zeros((N, len(linkage.joints), 6))
    link_bias = np.zeros((N, len(linkage.joints), 6))
    for i, j in enumerate(linkage.joints):
        ks = [f for f in range(m) if lay.joint_of[f] == i]
        Vj = V.copy()
        for f in ks:
            bracket = bracket + lie_bracket(Vj, S[:, :, f]) * qd[:, f:f + 1]
            if j.kind == "U":
                Vj = Vj + S[:, :, f] * qd[:, f:f + 1]
        for f in ks:
            V = V + S[:, :, f] * qd[:, f:f + 1]
        link_V[:, i] = V
        link_bias[:, i] = bracket
    return link_V, link_bias


def _link_accelerations(linkage: Linkage, lay: Layout, S: Array, qdd: Array,
                        link_bias: Array) -> Array:
    N, _, m = S.shape
    link_A = np.zeros_like(link_bias)
    acc = np.zeros((N, 6))
    for i in range(len(linkage.joints)):
        for f in (f for f in range(m) if lay.joint_of[f] == i):
            acc = acc + S[:, :, f] * qdd[:, f:f + 1]
        link_A[:, i] = acc + link_bias[:, i]
    return link_A


def _variable_tables(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
                     X: Array, qd: Array, qdd: Array) -> tuple[dict[str, Array], ...]:
    variables: dict[str, Array] = {}
    velocities: dict[str, Array] = {}
    accelerations: dict[str, Array] = {}
    for f, name in enumerate(lay.names):
        c = lay.scalar_col[f]
        if c >= 0:
            values = conf.scalars[:, c].copy()
            if name in linkage.inputs:
                values = X[:, linkage.inputs.index(name)].copy()  # exactly as given
            elif not lay.is_translation[f] and mask.any():
                # continuous along the branch, starting in (−π, π] (as the closed forms do)
                run = np.unwrap(values[mask])
                values[mask] = run - 2 * np.pi * np.round(run[0] / (2 * np.pi))
            variables[name] = values
        velocities[name] = qd[:, f]
        accelerations[name] = qdd[:, f]
    from scipy.spatial.transform import Rotation  # on first use (start-up time)

    for i, sidx in lay.spherical_of_joint.items():
        rv = Rotation.from_matrix(conf.spherical[:, sidx]).as_rotvec()
        jn = linkage.joints[i].name
        for a, ax in enumerate("xyz"):
            variables[f"{jn}.r{ax}"] = rv[:, a]
    return variables, velocities, accelerations


def mode_from_configuration(linkage: Linkage, lay: Layout, conf: Configuration,
                            mask: NDArray[np.bool_], X: Array, Xd: Array, Xdd: Array,
                            events: list[str]) -> ModeMotion:
    """Everything about one assembly mode from its closed configurations ``conf`` (N samples,
    ``mask`` where they hold): link frames, joint centres and axes, and the rates and
    accelerations of every freedom and link from the loop's rate equations (module docstring).
    ``X``, ``Xd``, ``Xdd`` (N, n_in) are the inputs and their first two time derivatives."""
    N = conf.size
    fr = forward(linkage, conf, lay)
    eq = _rate_equations(linkage, lay, fr, mask)
    S, m = fr.screws, len(lay.names)
    qd = np.zeros((N, m))
    qd[:, eq.in_idx] = Xd
    qd[:, eq.p_idx] = eq.solve(Xd, np.zeros((N, 6)), np.zeros((N, len(eq.spin_links))))
    link_V, link_bias = _link_twists(linkage, lay, S, qd)
    qdd = np.zeros((N, m))
    qdd[:, eq.in_idx] = Xdd
    spin_bias = np.stack(
        [np.einsum("ni,ni->n", _unit(fr.centres[:, i + 1] - fr.centres[:, i]),
                   link_bias[:, i, :3]) for i in eq.spin_links], axis=1,
    ) if eq.spin_links else np.zeros((N, 0))
    qdd[:, eq.p_idx] = eq.solve(Xdd, link_bias[:, -1], spin_bias)
    link_A = _link_accelerations(linkage, lay, S, qdd, link_bias)
    # link frames and their motion in the world, per moving link i < n
    nl = len(linkage.joints) - 1
    bR, bp = linkage.base.real, linkage.base.translation
    w, v0 = link_V[:, :nl, :3], link_V[:, :nl, 3:]
    al, a0 = link_A[:, :nl, :3], link_A[:, :nl, 3:]
    p_g = fr.after_p[:, :nl]
    v_o = v0 + np.cross(w, p_g)
    a_o = a0 + np.cross(al, p_g) + np.cross(w, v_o)

    def world(x: Array) -> Array:
        return np.einsum("ij,n...j->n...i", bR, x)

    frames = [np.einsum("ij,nljk->nlik", bR, fr.after_R[:, :nl]), world(p_g) + bp]
    rates = [world(w), world(v_o), world(al), world(a_o)]
    cen = world(fr.centres) + bp
    axs = world(fr.axes)
    variables, velocities, accelerations = _variable_tables(linkage, lay, conf, mask, X, qd, qdd)
    xi_res = np.max(np.abs(closure_twist(fr.closure_R, fr.closure_p) * eq.rows), axis=-1)
    bad, singular = ~mask, eq.singular
    for table in (variables, velocities, accelerations):
        for values in table.values():
            values[bad] = np.nan
    for table in (velocities, accelerations):
        for values in table.values():
            values[singular] = np.nan
    for arr in frames + rates + [cen, axs]:
        arr[bad] = np.nan
    for arr in rates:
        arr[singular] = np.nan
    xi_res[bad] = np.nan
    if singular.any():
        events.append(f"singular (velocities undefined) at {int(singular.sum())} sample(s)")
    return ModeMotion(mask, singular, conf, variables, velocities, accelerations,
                      link_rotation=frames[0], link_origin=frames[1],
                      link_angular_velocity=rates[0], link_origin_velocity=rates[1],
                      link_angular_acceleration=rates[2], link_origin_acceleration=rates[3],
                      joint_centres=cen, joint_axes=axs, closure_residual=xi_res, events=events)
