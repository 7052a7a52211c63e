"""Blocked evaluation of inverse dynamics: what every block shares, the preallocated outputs the
blocks fill, and their assembly into a :class:`~screwkit.dynamics.result.Dynamics`.

Samples are processed in blocks of :data:`BLOCK_SAMPLES`: the block's temporaries stay in the
CPU caches and the peak memory is the (N, …) outputs plus one block, whatever N. The outputs
are component-major (:func:`screwkit.dynamics.component_arrays.component_major`): each component of a load
is contiguous over the samples, which the structure-of-arrays kernels write without transposing.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.dual.spatial import cross
from screwkit.dynamics import component_arrays as soa
from screwkit.dynamics.loop_statics import StaticsStructure
from screwkit.dynamics.result import Array, Dynamics, Indeterminacy, Reaction
from screwkit.model.linkage import Linkage

BLOCK_SAMPLES = 16384
"""Samples per block of :func:`inverse_dynamics`: the block's temporaries (a few hundred (n,)
arrays in the closed-form kernels, (n, n_joints, 6, 6) matrices in the generic solve) stay in
the CPU caches, and the peak memory is the outputs plus one block, whatever N."""

Selection = slice | NDArray[np.intp]



@dataclass(frozen=True)
class Setup:
    """What every block of one analysis shares: the valid samples, the input values, the
    reference point (moments are taken about it inside, for round-off), the generic statics
    structure, gravity and the shaking-moment point."""

    valid: NDArray[np.bool_]
    inputs: Array
    reference: Array
    structure: StaticsStructure
    gravity: Array
    moment_point: Array



def blocks(valid: NDArray[np.bool_], size: int) -> Iterator[Selection]:
    """The valid samples in blocks of at most ``size``: slices when every sample is valid."""
    if valid.all():
        N = valid.shape[0]
        for start in range(0, N, size):
            yield slice(start, min(start + size, N))
        return
    idx = np.flatnonzero(valid)
    for start in range(0, idx.size, size):
        yield idx[start:start + size]



def joint_scale(forces: Array, moments: Array, length: float) -> float:
    """Largest joint load √(|f|² + |m/ℓ|²) of (…, 3) forces and moments (NaN ignored)."""
    if forces.size == 0:
        return 0.0
    size2 = np.einsum("...i,...i->...", forces, forces) + np.einsum(
        "...i,...i->...", moments, moments) / length**2
    return float(np.sqrt(np.nanmax(size2))) if np.any(np.isfinite(size2)) else 0.0


@dataclass
class Outputs:
    """The (N, …) result arrays of :func:`inverse_dynamics`, filled block by block."""

    shaking_force: Array
    shaking_moment: Array
    reaction_force: Array  # (N, n, 3)
    reaction_moment: Array
    efforts: dict[str, Array]
    residual: Array  # (N,) norm
    scale: float = 0.0

    @classmethod
    def allocate(cls, linkage: Linkage, N: int, fill: bool) -> Outputs:
        """Component-major (N, …) arrays (:func:`screwkit.dynamics.component_arrays.component_major`), NaN
        filled when some samples will not be computed."""
        def new(*shape: int) -> Array:
            out = soa.component_major(*shape)
            if fill:
                out.fill(np.nan)
            return out

        n = len(linkage.joints)
        return cls(new(N, 3), new(N, 3), new(N, n, 3), new(N, n, 3),
                   {name: np.full(N, np.nan) if fill else np.empty(N) for name in linkage.inputs},
                   np.full(N, np.nan) if fill else np.empty(N))

    def block(self, sel: Selection) -> Outputs:
        """Arrays to write one block into: views for a slice, new arrays otherwise (then
        :meth:`scatter`)."""
        if isinstance(sel, slice):
            return Outputs(self.shaking_force[sel], self.shaking_moment[sel],
                            self.reaction_force[sel], self.reaction_moment[sel],
                            {k: v[sel] for k, v in self.efforts.items()}, self.residual[sel])
        nb = sel.shape[0]
        n = self.reaction_force.shape[1]
        return Outputs(np.empty((nb, 3)), np.empty((nb, 3)), np.empty((nb, n, 3)),
                        np.empty((nb, n, 3)), {k: np.empty(nb) for k in self.efforts},
                        np.empty(nb))

    def scatter(self, sel: Selection, part: Outputs) -> None:
        if not isinstance(sel, slice):
            self.shaking_force[sel] = part.shaking_force
            self.shaking_moment[sel] = part.shaking_moment
            self.reaction_force[sel] = part.reaction_force
            self.reaction_moment[sel] = part.reaction_moment
            for k, v in part.efforts.items():
                self.efforts[k][sel] = v
            self.residual[sel] = part.residual
        self.scale = max(self.scale, part.scale)



def as_dynamics(linkage: Linkage, joint_centres: Array, s: Setup, out: Outputs) -> Dynamics:
    """Filled outputs → a :class:`Dynamics`."""
    reactions = {
        j.name: Reaction(out.reaction_force[:, k], out.reaction_moment[:, k],
                         joint_centres[:, k])
        for k, j in enumerate(linkage.joints)
    }
    return Dynamics(
        input_names=tuple(linkage.inputs),
        inputs=s.inputs,
        valid=s.valid,
        shaking_force=out.shaking_force,
        shaking_moment=out.shaking_moment,
        moment_point=s.moment_point,
        reactions=reactions,
        joint_centres=joint_centres,
        efforts=out.efforts,
        indeterminacy=indeterminacy(s),
        residual=out.residual,
        residual_scale=out.scale,
        gravity=s.gravity,
    )


def indeterminacy(s: Setup) -> Indeterminacy:
    """What the joints leave undetermined (:class:`Indeterminacy`), self-stress directions
    with their moments about the world origin."""
    directions = s.structure.indeterminate_directions.copy()
    directions[:, 3:] += cross(np.broadcast_to(s.reference, directions[:, :3].shape),
                                directions[:, :3])
    return Indeterminacy(count=s.structure.indeterminate_count, directions=directions,
                         idle_freedoms=s.structure.idle_count)
