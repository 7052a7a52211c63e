"""Motion of a single loop over an input sweep, in every assembly mode, with velocities and
accelerations — for any :class:`~screwkit.model.Linkage`.

Assembly modes are continuous branches (``../shared/DESIGN.md``): every closed configuration at
every sample is found by :func:`~screwkit.kinematics.solve.find_assemblies`, then consecutive
samples are linked by path following: each branch is continued from one sample to the next
in small sub-steps with Newton correction and must land on a root found there. A branch that cannot be continued
successor stops: the message says at which input it last assembled (a limit position or dead
centre lies between that sample and the next).

Velocities solve the loop-closure rate equation J_p q̇_p = −J_in q̇_in (Bagci eqs. 3.27–3.48
differentiated; Rahman §1.4 done with the true axes); accelerations J_p q̈_p = −J_in q̈_in − J̇q̇
with J̇q̇ = Σ_{j<k} [S_j, S_k] q̇_j q̇_k (Lie brackets of the freedom screws). Passive freedoms
take the minimum-norm rates, except the spin of a link between two spherical joints (an S–S
rod), which is zero (ω·u = 0, Rahman 1996 §1.2). Where J_p loses rank
beyond its passive freedoms the configuration is singular: it is flagged, not divided through.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from screwkit.kinematics.loop import (
    Array,
    Configuration,
    Layout,
    closure_twist,
    forward,
    layout,
    lie_bracket,
)
from screwkit.kinematics.solve import Assemblies, find_assemblies, newton, signature
from screwkit.model.linkage import Linkage

SINGULAR_RTOL = 1e-7
MAX_GENERIC_SAMPLES = 20_000


class AssemblyError(ValueError):
    """The mechanism does not assemble where it was asked to."""


@dataclass(frozen=True)
class ModeMotion:
    """One assembly mode over the sweep. Arrays are batch-first over the N input samples;
    entries where ``assembles`` is False are NaN and must be read through the mask."""

    assembles: NDArray[np.bool_]
    singular: NDArray[np.bool_]
    conf: Configuration
    variables: dict[str, Array]
    velocities: dict[str, Array]
    accelerations: dict[str, Array]
    link_rotation: Array  # (N, L, 3, 3) world
    link_origin: Array  # (N, L, 3)
    link_angular_velocity: Array
    link_origin_velocity: Array
    link_angular_acceleration: Array
    link_origin_acceleration: Array
    joint_centres: Array  # (N, n, 3) world
    joint_axes: Array  # (N, n, 3) world
    closure_residual: Array  # (N,)
    events: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Motion:
    """Result of :func:`motion`: the inputs and one :class:`ModeMotion` per assembly mode."""

    linkage: Linkage
    inputs: Array  # (N, n_in)
    input_rates: Array
    input_accelerations: Array
    modes: list[ModeMotion]

    @property
    def input_names(self) -> tuple[str, ...]:
        return self.linkage.inputs


def _as_inputs(linkage: Linkage, values: Array | list[float] | float, name: str) -> Array:
    a = np.asarray(values, dtype=float)
    n_in = len(linkage.inputs)
    if a.ndim == 0:
        a = a[None, None]
    if a.ndim == 1:
        a = a[:, None] if n_in == 1 else a[None, :]
    if a.shape[-1] != n_in:
        raise ValueError(f"{name}: expected {n_in} value(s) per sample for inputs {list(linkage.inputs)}; got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: values must be finite")
    return a


def _continue(linkage: Linkage, lay: Layout, conf: Configuration, x_from: Array, x_to: Array,
              max_sub: Array) -> tuple[Configuration, NDArray[np.bool_]]:
    """Path-follow a batch of closed configurations from inputs ``x_from`` to ``x_to`` in
    sub-steps no larger than ``max_sub`` per input, Newton-correcting at each (Bagci's eq. 3.64
    idea applied to the loop); returns the end configurations and which ones got there."""
    n_sub = int(max(1, np.ceil(np.max(np.abs(x_to - x_from) / max_sub))))
    ok = np.ones(conf.size, dtype=bool)
    in_cols = [lay.scalar_col[lay.names.index(n)] for n in linkage.inputs]
    for k in range(1, n_sub + 1):
        x = x_from + (x_to - x_from) * (k / n_sub)
        q = conf.scalars.copy()
        q[:, in_cols] = x
        res = newton(linkage, Configuration(q, conf.spherical), max_iter=30, lay=lay)
        conf = res.conf
        ok &= res.converged
    return conf, ok


def _track(linkage: Linkage, lay: Layout, X: Array, asm: Assemblies) -> list[tuple[Configuration, NDArray[np.bool_], list[int]]]:
    """Link the roots of consecutive samples into continuous branches by path following."""
    N, K = asm.found.shape
    sig = asm.signature
    max_sub = np.array([np.radians(2.0) if not lay.is_translation[lay.names.index(n)]
                        else linkage.length_scale / 50 for n in linkage.inputs])
    branches: list[dict[str, Any]] = []
    active: list[int] = []
    for i in range(N):  # sequential by nature: each step continues from the previous one
        roots = np.nonzero(asm.found[i])[0]
        claimed: dict[int, tuple[int, float]] = {}
        still: list[int] = []
        if active:
            start = Configuration(
                np.stack([branches[b]["q"][i - 1] for b in active]),
                np.stack([branches[b]["r"][i - 1] for b in active]),
            )
            end, ok = _continue(linkage, lay, start, X[i - 1], X[i], max_sub)
            sig_end = signature(linkage, end, lay)
            for r, b in enumerate(active):
                if not ok[r]:
                    continue
                d = np.max(np.abs(sig[i, roots] - sig_end[r]), axis=-1) if roots.size else np.array([])
                moved = float(np.max(np.abs(sig_end[r] - branches[b]["sig"])))
                if d.size and d.min() < 1e-6:
                    root = int(roots[np.argmin(d)])
                    if root in claimed and claimed[root][1] <= moved:
                        continue
                    if root in claimed:
                        still.remove(claimed[root][0])
                    claimed[root] = (b, moved)
                branches[b]["q"][i] = end.scalars[r]
                branches[b]["r"][i] = end.spherical[r]
                branches[b]["sig"] = sig_end[r]
                still.append(b)
            for b in active:
                if b not in still:
                    branches[b]["stops"].append(i)
                    branches[b]["mask"][i:] = False
            for b in still:
                branches[b]["mask"][i] = True
        taken = set(claimed)
        for root in roots.tolist():
            if int(root) in taken:
                continue
            j = i * K + int(root)
            q_new = np.full((N, lay.n_scalar), np.nan)
            r_new = np.tile(np.eye(3), (N, lay.n_spherical, 1, 1))
            q_new[i] = asm.conf.scalars[j]
            r_new[i] = asm.conf.spherical[j]
            m_new = np.zeros(N, dtype=bool)
            m_new[i] = True
            branches.append({"q": q_new, "r": r_new, "mask": m_new, "stops": [], "sig": sig[i, root]})
            still.append(len(branches) - 1)
        active = still
    out = []
    for br in branches:
        q = np.where(np.isnan(br["q"]), 0.0, br["q"])
        out.append((Configuration(q, br["r"]), br["mask"], br["stops"]))
    return out


def motion(
    linkage: Linkage,
    input_values: Array | list[float],
    input_rates: Array | list[float] | float = 1.0,
    input_accelerations: Array | list[float] | float = 0.0,
    starts: int = 48,
    seed: int = 0,
) -> Motion:
    """Positions, velocities and accelerations of every freedom and link over an input sweep,
    in every assembly mode (generic solver; works for any single loop)."""
    lay = layout(linkage)
    X = _as_inputs(linkage, input_values, "input values")
    N = X.shape[0]
    Xd = np.broadcast_to(_as_inputs(linkage, input_rates, "input rates"), X.shape)
    Xdd = np.broadcast_to(_as_inputs(linkage, input_accelerations, "input accelerations"), X.shape)
    if N > MAX_GENERIC_SAMPLES:
        raise ValueError(
            f"{linkage.name}: {N} input samples is too many for the generic solver, which follows "
            f"every branch sample by sample (~10 ms a sample): use at most {MAX_GENERIC_SAMPLES} "
            "(a larger step), or a family with a closed form (RSRC, 4R, CSSP)"
        )
    asm = _find_all(linkage, X, starts, seed)
    if not asm.found.any():
        raise AssemblyError(
            f"{linkage.name}: the loop does not close at any of the {N} inputs "
            f"(from {format_inputs(linkage, X[0])} to {format_inputs(linkage, X[-1])}); "
            "check the dimensions"
        )
    tracks = _track(linkage, lay, X, asm)
    # a documented, deterministic mode order: by the first sample where the mode assembles,
    # then by its configuration there (joint centres and axes), not by the random starts
    def key(track: tuple[Configuration, NDArray[np.bool_], list[int]]) -> tuple[float, ...]:
        conf, mask, _ = track
        first = int(np.argmax(mask))
        sig = signature(linkage, conf.take(np.array([first])), lay)[0]
        return (float(first), *np.round(sig, 9).tolist())

    modes = []
    for conf, mask, stops in sorted(tracks, key=key):
        events = [
            f"stops assembling after input {format_inputs(linkage, X[s - 1])} (limit position "
            f"or dead centre before {format_inputs(linkage, X[s])})"
            for s in stops
        ]
        first = int(np.argmax(mask))
        if first > 0:
            events.insert(0, f"starts assembling at input {format_inputs(linkage, X[first])}")
        modes.append(_mode_motion(linkage, lay, conf, mask, X, Xd, Xdd, events))
    return Motion(linkage, X, np.array(Xd), np.array(Xdd), modes)


def format_inputs(linkage: Linkage, x: Array) -> str:
    """Input values for a message: degrees for rotations, metres for translations."""
    parts = []
    for name, v in zip(linkage.inputs, np.atleast_1d(x), strict=True):
        if name.endswith(".s"):
            parts.append(f"{name} = {float(v):.6g} m")
        else:
            parts.append(f"{name} = {float(np.degrees(v)):.6g} deg")
    return ", ".join(parts)


def _find_all(linkage: Linkage, X: Array, starts: int, seed: int) -> Assemblies:
    """Every assembly at every sample. Random starts can miss a root, most often where the
    number of roots changes (a branch is born or dies): samples whose count differs from a
    neighbour's are searched again with four times the starts, keeping the richer answer."""
    asm = find_assemblies(linkage, X, starts=starts, seed=seed)
    count = asm.found.sum(axis=1)
    if len(count) < 2:
        return asm
    differs = np.zeros(len(count), dtype=bool)
    differs[1:] |= count[1:] != count[:-1]
    differs[:-1] |= count[:-1] != count[1:]
    idx = np.nonzero(differs)[0]
    if idx.size == 0:
        return asm
    again = find_assemblies(linkage, X[idx], starts=4 * starts, seed=seed + 1)
    K = asm.found.shape[1]
    better = again.found.sum(axis=1) > count[idx]
    for r, i in zip(np.nonzero(better)[0], idx[better], strict=True):
        asm.found[i] = again.found[r]
        asm.signature[i] = again.signature[r]
        asm.conf.scalars[i * K:(i + 1) * K] = again.conf.scalars[r * K:(r + 1) * K]
        asm.conf.spherical[i * K:(i + 1) * K] = again.conf.spherical[r * K:(r + 1) * K]
    return asm


def _unit(d: Array) -> Array:
    return np.asarray(d / np.linalg.norm(d, axis=-1, keepdims=True))


def _mode_motion(linkage: Linkage, lay: Layout, conf: Configuration, mask: NDArray[np.bool_],
                 X: Array, Xd: Array, Xdd: Array, events: list[str]) -> ModeMotion:
    N = conf.size
    fr = forward(linkage, conf, lay)
    L = linkage.length_scale
    names = list(lay.names)
    m = len(names)
    in_idx = [names.index(n) for n in linkage.inputs]
    p_idx = [k for k in range(m) if k not in in_idx]
    rows = np.array([1, 1, 1, 1 / L, 1 / L, 1 / L])
    cols = np.array([L if t else 1.0 for t in lay.is_translation])
    S = fr.screws  # (N, 6, m)
    # Passive spin of a link between two spherical joints (an S–S rod): the rule is zero
    # absolute spin, ω_link·u = 0 with u the line of the two ball centres (Rahman 1996 §1.2).
    # Then α_link·u = −ω·u̇ = 0 too, and an axisymmetric rod's axial inertia does no work.
    spin_links = [i for i in range(len(linkage.joints) - 1)
                  if linkage.joints[i].kind == "S" and linkage.joints[i + 1].kind == "S"]
    C = np.zeros((N, len(spin_links), m))
    for r, i in enumerate(spin_links):
        d = fr.centres[:, i + 1] - fr.centres[:, i]
        u = d / np.linalg.norm(d, axis=-1, keepdims=True)
        upto = [f for f in range(m) if lay.joint_of[f] <= i]
        C[:, r, upto] = np.einsum("ni,nif->nf", u, S[:, :3, upto])
    Jp = np.concatenate([S[:, :, p_idx] * rows[None, :, None], C[:, :, p_idx]], axis=1)
    Jp = Jp * cols[p_idx][None, None, :]
    sv = np.linalg.svd(Jp, compute_uv=False)
    tol = SINGULAR_RTOL * sv[:, :1]
    rank = np.sum(sv > tol, axis=-1)
    generic_rank = int(np.max(rank[mask])) if mask.any() else 0
    singular = mask & (rank < generic_rank)
    pinv = np.linalg.pinv(Jp, rcond=1e-10)
    qd = np.zeros((N, m))
    qd[:, in_idx] = Xd
    rhs = np.concatenate([-np.einsum("nij,nj->ni", S[:, :, in_idx], Xd) * rows,
                          -np.einsum("nij,nj->ni", C[:, :, in_idx], Xd)], axis=1)
    qd[:, p_idx] = np.einsum("nij,nj->ni", pinv, rhs) * cols[p_idx]
    # J̇q̇ = Σ_k [V_before(k), S_k] q̇_k, V_before(k) = motion of the loop before freedom k
    bracket = np.zeros((N, 6))
    V = np.zeros((N, 6))
    joint_of = lay.joint_of
    link_V = np.zeros((N, len(linkage.joints), 6))
    link_bias = np.zeros((N, len(linkage.joints), 6))
    k = 0
    for i, j in enumerate(linkage.joints):
        ks = [f for f in range(m) if joint_of[f] == i]
        Vj = V.copy()
        for f in ks:
            term = lie_bracket(Vj, S[:, :, f]) * qd[:, f:f + 1]
            bracket += term
            if j.kind == "U":
                Vj = Vj + S[:, :, f] * qd[:, f:f + 1]
        for f in ks:
            V = V + S[:, :, f] * qd[:, f:f + 1]
        link_V[:, i] = V
        link_bias[:, i] = bracket
        k += len(ks)
    qdd = np.zeros((N, m))
    qdd[:, in_idx] = Xdd
    spin_bias = np.stack(
        [np.einsum("ni,ni->n", _unit(fr.centres[:, i + 1] - fr.centres[:, i]),
                   link_bias[:, i, :3]) for r, i in enumerate(spin_links)], axis=1,
    ) if spin_links else np.zeros((N, 0))
    rhs2 = np.concatenate([(-np.einsum("nij,nj->ni", S[:, :, in_idx], Xdd) - bracket) * rows,
                           -np.einsum("nij,nj->ni", C[:, :, in_idx], Xdd) - spin_bias], axis=1)
    qdd[:, p_idx] = np.einsum("nij,nj->ni", pinv, rhs2) * cols[p_idx]
    # link twists and accelerations (ground frame, spatial form), per moving link i < n
    link_A = np.zeros_like(link_V)
    acc = np.zeros((N, 6))
    for i in range(len(linkage.joints)):
        ks = [f for f in range(m) if joint_of[f] == i]
        for f in ks:
            acc = acc + S[:, :, f] * qdd[:, f:f + 1]
        link_A[:, i] = acc + link_bias[:, i]
    nl = len(linkage.joints) - 1
    bR = linkage.base.real
    bp = linkage.base.translation
    Rw = np.einsum("ij,nljk->nlik", bR, fr.after_R[:, :nl])
    pw = np.einsum("ij,nlj->nli", bR, fr.after_p[:, :nl]) + bp
    w = link_V[:, :nl, :3]
    v0 = link_V[:, :nl, 3:]
    al = link_A[:, :nl, :3]
    a0 = link_A[:, :nl, 3:]
    p_g = fr.after_p[:, :nl]
    v_o = v0 + np.cross(w, p_g)
    a_o = a0 + np.cross(al, p_g) + np.cross(w, v_o)
    rot = lambda x: np.einsum("ij,n...j->n...i", bR, x)  # noqa: E731
    variables: dict[str, Array] = {}
    velocities: dict[str, Array] = {}
    accelerations: dict[str, Array] = {}
    for f, name in enumerate(names):
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
    for i, sidx in lay.spherical_of_joint.items():
        rv = Rotation.from_matrix(conf.spherical[:, sidx]).as_rotvec()
        jn = linkage.joints[i].name
        for a, ax in enumerate("xyz"):
            variables[f"{jn}.r{ax}"] = rv[:, a]
    xi = closure_twist(fr.closure_R, fr.closure_p) * rows
    xi_res = np.max(np.abs(xi), axis=-1)
    bad = ~mask
    for table in (variables, velocities, accelerations):
        for values in table.values():
            values[bad] = np.nan
    for table in (velocities, accelerations):
        for values in table.values():
            values[singular] = np.nan
    arrays = [Rw, pw, rot(w), rot(v_o), rot(al), rot(a_o)]
    cen = np.einsum("ij,nlj->nli", bR, fr.centres) + bp
    axs = np.einsum("ij,nlj->nli", bR, fr.axes)
    for arr in arrays + [cen, axs]:
        arr[bad] = np.nan
    for arr in arrays[2:]:
        arr[singular] = np.nan
    xi_res[bad] = np.nan
    if singular.any():
        events.append(f"singular (velocities undefined) at {int(singular.sum())} sample(s)")
    return ModeMotion(mask, singular, conf, variables, velocities, accelerations,
                      arrays[0], arrays[1], arrays[2], arrays[3], arrays[4], arrays[5],
                      cen, axs, xi_res, events)
