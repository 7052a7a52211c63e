"""The generic loop solver: every assembly mode of any single loop over an input sweep.

Assembly modes are continuous branches (``../shared/DESIGN.md``): every closed configuration at
every sample is found by :func:`~screwkit.kinematics.solve.find_assemblies`, then consecutive
samples are linked by path following: each branch is continued from one sample to the next in
small sub-steps with Newton correction and must land on a root found there. A branch that cannot
be continued stops: the message says at which input it last assembled (a limit position or dead
centre lies between that sample and the next). Rates and accelerations follow from the loop's
rate equations (:mod:`screwkit.kinematics.mode_frames`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics.loop import (
    Array,
    Configuration,
    Layout,
    layout,
)
from screwkit.kinematics.mode_frames import mode_from_configuration
from screwkit.kinematics.motion import (
    AssemblyError,
    Motion,
    as_input_array,
    format_inputs,
)
from screwkit.kinematics.solve import Assemblies, find_assemblies, newton, signature
from screwkit.model.linkage import Linkage

MAX_GENERIC_SAMPLES = 20_000


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


def generic_motion(
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
    X = as_input_array(linkage, input_values, "input values")
    N = X.shape[0]
    Xd = np.broadcast_to(as_input_array(linkage, input_rates, "input rates"), X.shape)
    Xdd = np.broadcast_to(as_input_array(linkage, input_accelerations, "input accelerations"), X.shape)
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
        modes.append(mode_from_configuration(linkage, lay, conf, mask, X, Xd, Xdd, events))
    modes = [replace(md, index=k, label=f"branch {k}") for k, md in enumerate(modes)]
    return Motion(linkage, X, np.array(Xd), np.array(Xdd), tuple(modes), method="generic",
                  solver="generic loop solver: Newton on the loop closure from many starts, "
                         "branches linked by path following (docs/kinematics.md)")


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


