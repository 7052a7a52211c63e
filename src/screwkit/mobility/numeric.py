"""Numerical (instantaneous) mobility from a loop's screw Jacobian — pure linear algebra.

Input: a (6k, m) matrix whose columns are the unit joint screws of the m pair freedoms in the
world frame, one 6-row block per independent loop, each screw written (ω; v) = (direction;
moment): (u; r × u) for a revolute through point r, (0; u) for a prismatic, (u; p u + r × u)
for a helical of pitch p. A freedom that is not in loop j has zeros in block j. The joint
rates q̇ of a closed configuration satisfy J q̇ = 0 (the loop's twists add up to zero).

What is counted (all at the given configuration, hence "instantaneous"):

* ``rank``: independent loop constraints; ``mobility`` = m − rank = dim null(J).
* ``redundant_constraints`` = 6k − rank: constraints the loops repeat (over-constraint).
* Bagci's terms (Appendix B) for the instantaneous screw systems: general constraints
  m_j = 6 − rank of loop j's block (all its pair screws), split into constraints on rotation and
  on translation and written in Bagci's m(…) notation; F0 = m − 6k (eq. B.1 with B.3);
  overclosing constraints F_c = F − F0 − M (eq. B.8 solved for F_c, = Σ_j rank J_j − rank J).
  Bagci's passive freedoms F_p — pair freedoms that the *finite* motion never uses — cannot be
  seen at one configuration (a spherical pair of a one-freedom loop uses one rotation at each
  instant, a different one at the next), so F_p is not a numeric term: their screws stay in
  the rank, and Bagci's M and F_p, which cancel in F, appear here as smaller M and F_p = 0
  (R-S-R-C with δ0 = 0: Bagci M = 1, F_p = 1; numeric M = 0). ``locked_freedoms`` lists the
  freedoms that no instantaneous motion moves (e.g. the input R of an R-C-C-C whose last two
  C axes are parallel).
* Inputs: the null-space directions that leave the inputs still (``undetermined_motions``) and
  the freedoms taking part in them; with outputs, those that also leave the outputs still are
  Bagci's *redundant freedoms* (the coupler spin of an R-S-S-R; other texts call it a passive
  or idle freedom).

Units and tolerance. The moment rows carry length, so every block's moment rows are divided by
a characteristic length L (``length_scale``; by default the root-mean-square distance of the
rotation axes from the origin, or 1 if they all pass through it), and prismatic columns are
multiplied by L (their rates become ḋ/L). The matrix is then dimensionless and a singular value
σ counts as zero when σ ≤ ``rtol`` · σ_max (default 1e-8: exact geometry leaves ~1e-15, a loop
closed by a solver to 1e-10 leaves spurious singular values near 1e-10, still below; a geometric
change of 1e-6 or more shows). Subspace decisions on orthonormal bases (which freedoms take part
in a motion) use the threshold √rtol (1e-4).
Both thresholds and the singular values around the rank decision are reported.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.messages import shown
from screwkit.mobility.errors import MobilityInputError
from screwkit.mobility.general_constraints import (
    GeneralConstraints,
    general_constraints_from_counts,
)

Array = NDArray[np.float64]

#: Relative singular-value threshold for the rank of the dimensionless Jacobian.
DEFAULT_RTOL = 1e-8
#: How far a column's |ω| (or |v| for a prismatic) may be from 1.
UNIT_SCREW_TOL = 1e-6


def _blocks(jac: Array) -> Array:
    """(..., 6k, m) → (..., k, 6, m)."""
    return jac.reshape(*jac.shape[:-2], jac.shape[-2] // 6, 6, jac.shape[-1])


def check_screw_jacobian(jacobian: ArrayLike, tol: float = UNIT_SCREW_TOL) -> Array:
    """``jacobian`` as a float array (..., 6k, m) of unit screws; raise on anything else.

    Each column, in each 6-row loop block, must be zero (freedom not in that loop), a unit
    rotation screw (|ω| = 1) or a unit translation (ω = 0, |v| = 1), and appear in some loop.
    """
    jac = np.asarray(jacobian, dtype=float)
    if jac.ndim < 2 or jac.shape[-2] % 6 or jac.shape[-2] == 0 or jac.shape[-1] == 0:
        raise MobilityInputError(
            f"a screw Jacobian has shape (6k, m): 6 rows (ω; v) per loop and one column per "
            f"pair freedom; got shape {jac.shape}"
        )
    bad = ~np.isfinite(jac)
    if bad.any():
        raise MobilityInputError(
            f"the screw Jacobian holds NaN or inf at {tuple(int(i) for i in np.argwhere(bad)[0])}"
        )
    b = _blocks(jac)
    nw = np.linalg.norm(b[..., :3, :], axis=-2)
    nv = np.linalg.norm(b[..., 3:, :], axis=-2)
    absent = (nw <= tol) & (nv <= tol)
    ok = (np.abs(nw - 1.0) <= tol) | ((nw <= tol) & (np.abs(nv - 1.0) <= tol)) | absent
    if not ok.all():
        idx = tuple(int(i) for i in np.argwhere(~ok)[0])
        raise MobilityInputError(
            f"column {idx[-1]} in loop block {idx[-2] + 1} is not a unit screw (|ω| = "
            f"{nw[idx]:.6g}, |v| = {nv[idx]:.6g}): write (u; r × u) for a revolute, (0; u) for a "
            "prismatic, (u; p u + r × u) for a helical, with |u| = 1"
        )
    nowhere = absent.all(axis=-2)
    if nowhere.any():
        idx = tuple(int(i) for i in np.argwhere(nowhere)[0])
        raise MobilityInputError(
            f"column {idx[-1]} is zero in every loop block: each freedom must belong to a loop"
        )
    return jac


def characteristic_length(jacobian: ArrayLike) -> float:
    """Root-mean-square distance of the rotation (and helical) axes from the origin, from the
    moment parts of the screws; 1.0 when every axis passes through the origin.

    For a helical column (u; p u + r × u) the pitch part p u is left out.
    """
    b = _blocks(np.asarray(jacobian, dtype=float))
    w, v = b[..., :3, :], b[..., 3:, :]
    rot = np.linalg.norm(w, axis=-2) > 0.5
    perp = v - w * np.sum(w * v, axis=-2, keepdims=True)
    d = np.linalg.norm(perp, axis=-2)[rot]
    rms = float(np.sqrt(np.mean(d**2))) if d.size else 0.0
    return rms if rms > 0.0 else 1.0


def dimensionless_jacobian(jacobian: ArrayLike, length_scale: float) -> Array:
    """Moment rows divided by L, prismatic columns multiplied by L (batched over leading axes).

    The columns then map the rates (θ̇, ḋ/L) to the twists (ω; v/L).
    """
    jac = np.asarray(jacobian, dtype=float)
    b = _blocks(jac).copy()
    b[..., 3:, :] /= length_scale
    translation = np.linalg.norm(b[..., :3, :], axis=(-3, -2)) <= UNIT_SCREW_TOL  # (..., m)
    b *= np.where(translation, length_scale, 1.0)[..., None, None, :]
    return b.reshape(jac.shape)


def _length_scale(jac: Array, length_scale: float | None) -> float:
    if length_scale is None:
        return characteristic_length(jac)
    L = float(length_scale)
    if not math.isfinite(L) or L <= 0.0:
        raise MobilityInputError(
            f"length_scale must be a positive length (a typical link length); got {length_scale!r}"
        )
    return L


def _check_rtol(rtol: float) -> float:
    r = float(rtol)
    if not 0.0 < r < 1.0:
        raise MobilityInputError(f"rtol must be in (0, 1); got {rtol!r}")
    return r


def jacobian_rank(
    jacobians: ArrayLike, *, length_scale: float | None = None, rtol: float = DEFAULT_RTOL
) -> NDArray[np.int64]:
    """Rank of a batch of screw Jacobians (..., 6k, m), e.g. over a motion cycle.

    Same normalisation and threshold as :func:`mobility_from_jacobian`; the instantaneous
    mobility of each sample is ``m - rank``. A rise of the mobility at a few samples marks a
    singular (e.g. dead-centre or bifurcation) configuration.
    """
    jac = check_screw_jacobian(jacobians)
    L = _length_scale(jac, length_scale)
    s = np.linalg.svd(dimensionless_jacobian(jac, L), compute_uv=False)
    return np.sum(s > _check_rtol(rtol) * s[..., :1], axis=-1).astype(np.int64)


def _rank(a: Array, tol: float) -> int:
    if a.size == 0:
        return 0
    return int(np.sum(np.linalg.svd(a, compute_uv=False) > tol))


def _null(a: Array, tol: float) -> Array:
    """Orthonormal basis (columns) of the null space of ``a`` (rows × n) → (n, d)."""
    n = a.shape[1]
    if a.shape[0] == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(a, full_matrices=True)
    r = int(np.sum(s > tol))
    return vt[r:].T.copy()


def _range(a: Array, tol: float) -> tuple[Array, Array]:
    """Orthonormal bases of the range of ``a`` and of its orthogonal complement."""
    if a.shape[1] == 0:
        return np.zeros((a.shape[0], 0)), np.eye(a.shape[0])
    u, s, _ = np.linalg.svd(a, full_matrices=True)
    r = int(np.sum(s > tol))
    return u[:, :r], u[:, r:]


def _involved(names: Sequence[str], basis: Array, tol: float) -> tuple[str, ...]:
    """Names whose row of ``basis`` (orthonormal columns) is not zero."""
    if basis.shape[1] == 0:
        return ()
    norms = np.linalg.norm(basis, axis=1)
    return tuple(n for n, x in zip(names, norms, strict=True) if x > tol)


def pair_label(freedom_name: str) -> str:
    """The pair a freedom belongs to: the text before the first '.' (``"J2.rx"`` → ``"J2"``);
    a name without '.' is a one-freedom pair of its own."""
    return freedom_name.split(".", 1)[0]


@dataclass(frozen=True)
class LoopConstraints:
    """General constraints of one loop: what its pair screws (at this configuration) cannot
    produce."""

    loop: int  # 1-based
    freedoms: tuple[str, ...]
    motion_rank: int  # dimension of the loop's screw system, 6 − m_j
    general: GeneralConstraints

    @property
    def count(self) -> int:
        """m_j."""
        return self.general.count

    def as_dict(self) -> dict[str, object]:
        return {
            "loop": self.loop,
            "freedoms": list(self.freedoms),
            "motion_rank": self.motion_rank,
            "general_constraints": self.count,
            "on_rotation": self.general.on_rotation,
            "on_translation": self.general.on_translation,
            "notation": self.general.notation,
        }


@dataclass(frozen=True, eq=False)
class NumericMobility:
    """Result of :func:`mobility_from_jacobian` (see the module notes for every term)."""

    freedom_names: tuple[str, ...]
    loops: int
    length_scale: float
    rtol: float
    singular_values: tuple[float, ...]
    rank: int
    null_space: Array = field(repr=False)  # (m, F), orthonormal, rates (θ̇, ḋ/L)
    locked_freedoms: tuple[str, ...]
    loop_constraints: tuple[LoopConstraints, ...]
    input_names: tuple[str, ...] | None = None
    output_names: tuple[str, ...] | None = None
    independent_inputs: int | None = None
    undetermined_motions: int | None = None
    undetermined_involves: tuple[str, ...] | None = None
    redundant_freedoms: int | None = None
    redundant_involves: tuple[str, ...] | None = None

    @property
    def freedom_count(self) -> int:
        """m, the columns."""
        return len(self.freedom_names)

    @property
    def mobility(self) -> int:
        """F = m − rank: instantaneous degrees of freedom, redundant freedoms included."""
        return self.freedom_count - self.rank

    @property
    def redundant_constraints(self) -> int:
        """6k − rank: loop constraints that repeat others."""
        return 6 * self.loops - self.rank

    @property
    def malytcheff(self) -> int:
        """F0 = m − 6k, Bagci eq. (B.1) with (B.3) for the k loops of the Jacobian."""
        return self.freedom_count - 6 * self.loops

    @property
    def total_general_constraints(self) -> int:
        """M = Σ m_j."""
        return sum(lc.count for lc in self.loop_constraints)

    @property
    def overclosing_constraints(self) -> int:
        """F_c = F − F0 − M (eq. B.8 with F_p = 0) = Σ_j rank J_j − rank J: loop equations that
        repeat those of other loops. Always 0 for a single loop."""
        return self.mobility - self.malytcheff - self.total_general_constraints

    @property
    def inputs_determine_motion(self) -> bool | None:
        """True if the inputs fix every joint rate; None when no inputs were given."""
        return None if self.undetermined_motions is None else self.undetermined_motions == 0

    @property
    def inputs_determine_outputs(self) -> bool | None:
        """True if the inputs fix the outputs; None unless inputs and outputs were given."""
        if self.redundant_freedoms is None or self.undetermined_motions is None:
            return None
        return self.undetermined_motions == self.redundant_freedoms

    @property
    def rank_gap(self) -> tuple[float, float]:
        """(smallest kept, largest dropped) dimensionless singular value — how clear the rank
        decision is (the dropped one is 0.0 when none is dropped)."""
        s = self.singular_values
        kept = s[self.rank - 1] if self.rank else 0.0
        dropped = s[self.rank] if self.rank < len(s) else 0.0
        return kept, dropped

    def describe(self) -> str:
        """A few lines for a terminal."""
        k = self.loops
        kept, dropped = self.rank_gap
        lines = [
            f"numeric (instantaneous) mobility: F = {self.mobility}",
            f"  {self.freedom_count} pair freedoms, {k} loop{'s' if k > 1 else ''}: rank "
            f"{self.rank} of {6 * k} loop equations, {self.redundant_constraints} redundant "
            "constraint(s)",
            f"  singular values (L = {shown(self.length_scale, 'length')}, rtol = {self.rtol:g}): "
            "smallest kept "
            f"{kept:.3g}, largest dropped {dropped:.3g}",
            f"  Kolchin terms (Bagci B.8): F0 = {self.malytcheff}, M = "
            f"{self.total_general_constraints}, F_c = {self.overclosing_constraints}",
            "  general constraints: "
            + "; ".join(f"loop {lc.loop} {lc.general}" for lc in self.loop_constraints),
        ]
        if self.locked_freedoms:
            lines.append("  stationary at this configuration (no instantaneous motion moves them): "
                         + ", ".join(self.locked_freedoms))
        if self.input_names is not None:
            ins = ", ".join(self.input_names)
            if self.undetermined_motions == 0:
                lines.append(f"  inputs {ins} determine the motion")
            else:
                lines.append(
                    f"  inputs {ins} leave {self.undetermined_motions} motion(s) free, involving "
                    + ", ".join(self.undetermined_involves or ())
                )
            if self.independent_inputs is not None and self.independent_inputs < len(
                self.input_names
            ):
                lines.append(
                    f"  only {self.independent_inputs} of the {len(self.input_names)} inputs "
                    "can be chosen freely"
                )
        if self.output_names is not None and self.redundant_freedoms is not None:
            outs = ", ".join(self.output_names)
            free_out = (self.undetermined_motions or 0) - self.redundant_freedoms
            lines.append(
                f"  outputs {outs}: "
                + ("determined" if free_out == 0 else f"{free_out} motion(s) still free")
                + (
                    f"; {self.redundant_freedoms} redundant freedom(s) involving "
                    + ", ".join(self.redundant_involves or ())
                    if self.redundant_freedoms
                    else ""
                )
            )
        return "\n".join(lines)

    def as_dict(self) -> dict[str, object]:
        """Plain JSON-able dict (the null space as a list of rows, rates θ̇ and ḋ/L)."""
        kept, dropped = self.rank_gap
        return {
            "freedom_names": list(self.freedom_names),
            "loops": self.loops,
            "length_scale": self.length_scale,
            "rtol": self.rtol,
            "singular_values": list(self.singular_values),
            "smallest_kept_singular_value": kept,
            "largest_dropped_singular_value": dropped,
            "rank": self.rank,
            "mobility": self.mobility,
            "redundant_constraints": self.redundant_constraints,
            "malytcheff": self.malytcheff,
            "total_general_constraints": self.total_general_constraints,
            "overclosing_constraints": self.overclosing_constraints,
            "loop_constraints": [lc.as_dict() for lc in self.loop_constraints],
            "locked_freedoms": list(self.locked_freedoms),
            "null_space": self.null_space.tolist(),
            "input_names": None if self.input_names is None else list(self.input_names),
            "output_names": None if self.output_names is None else list(self.output_names),
            "independent_inputs": self.independent_inputs,
            "undetermined_motions": self.undetermined_motions,
            "undetermined_involves": (
                None if self.undetermined_involves is None else list(self.undetermined_involves)
            ),
            "inputs_determine_motion": self.inputs_determine_motion,
            "redundant_freedoms": self.redundant_freedoms,
            "redundant_involves": (
                None if self.redundant_involves is None else list(self.redundant_involves)
            ),
            "inputs_determine_outputs": self.inputs_determine_outputs,
        }


def _select(
    what: str, chosen: str | Iterable[str] | None, names: tuple[str, ...]
) -> list[int] | None:
    """Column indices of the chosen freedoms; a pair label selects all its freedoms."""
    if chosen is None:
        return None
    items = [chosen] if isinstance(chosen, str) else list(chosen)
    idx: list[int] = []
    for item in items:
        if item in names:
            hits = [names.index(item)]
        else:
            hits = [j for j, n in enumerate(names) if pair_label(n) == item]
        if not hits:
            raise MobilityInputError(
                f"{what} {item!r} is neither a freedom nor a pair of the Jacobian; freedoms "
                f"are: {', '.join(names)}"
            )
        for j in hits:
            if j in idx:
                raise MobilityInputError(f"{what} {names[j]!r} is given twice")
            idx.append(j)
    if not idx:
        raise MobilityInputError(f"{what} list is empty; give at least one freedom or None")
    return idx


def mobility_from_jacobian(
    jacobian: ArrayLike,
    freedom_names: Sequence[str],
    inputs: str | Iterable[str] | None = None,
    outputs: str | Iterable[str] | None = None,
    *,
    length_scale: float | None = None,
    rtol: float = DEFAULT_RTOL,
) -> NumericMobility:
    """Instantaneous mobility of one configuration from its screw Jacobian.

    Parameters
    ----------
    jacobian:
        (6k, m): unit joint screws (ω; v) in the world frame, one 6-row block per loop.
    freedom_names:
        m names; the text before the first '.' names the pair (``"J2.rx"`` is a freedom of
        pair ``"J2"``); an input or output may name a whole pair.
    inputs, outputs:
        Freedom names (or pair names, meaning all their freedoms) driven / watched.
    length_scale:
        Characteristic length L of the mechanism (same unit as the moments). Default: the
        RMS distance of the rotation axes from the origin.
    rtol:
        Relative singular-value threshold (module notes).

    Returns
    -------
    NumericMobility
        rank, mobility m − rank, redundant constraints 6k − rank, Bagci's terms, input and
        output determination.
    """
    jac = check_screw_jacobian(jacobian)
    if jac.ndim != 2:
        raise MobilityInputError(
            f"mobility_from_jacobian takes one configuration (6k, m); got shape {jac.shape} "
            "(use jacobian_rank for a batch)"
        )
    names = tuple(freedom_names)
    if len(names) != jac.shape[1] or not all(isinstance(n, str) and n for n in names):
        raise MobilityInputError(
            f"give one non-empty name per Jacobian column: {jac.shape[1]} columns, "
            f"{len(names)} names"
        )
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise MobilityInputError(f"freedom names must be unique; repeated: {', '.join(dup)}")
    rtol = _check_rtol(rtol)
    sub_tol = math.sqrt(rtol)
    L = _length_scale(jac, length_scale)
    in_idx = _select("input", inputs, names)
    out_idx = _select("output", outputs, names)
    if out_idx is not None and in_idx is None:
        raise MobilityInputError("outputs are judged against inputs: give the inputs too")

    k, m = jac.shape[0] // 6, jac.shape[1]
    jn = dimensionless_jacobian(jac, L)
    _, s, vt = np.linalg.svd(jn, full_matrices=True)
    tol = rtol * s[0]
    rank = int(np.sum(s > tol))
    null = vt[rank:].T.copy()  # (m, F)

    loop_constraints = [_loop_constraints(j, jn[6 * j: 6 * j + 6], names, tol, sub_tol)
                        for j in range(k)]
    result = NumericMobility(
        freedom_names=names,
        loops=k,
        length_scale=L,
        rtol=rtol,
        singular_values=tuple(float(x) for x in s) + (0.0,) * (m - len(s)),
        rank=rank,
        null_space=null,
        locked_freedoms=tuple(
            n for n, row in zip(names, null, strict=True) if np.linalg.norm(row) <= sub_tol
        ),
        loop_constraints=tuple(loop_constraints),
    )
    if in_idx is None:
        return result

    return _with_inputs(result, names, null, in_idx, out_idx, sub_tol)


def _loop_constraints(j: int, block: NDArray[np.float64], names: tuple[str, ...], tol: float,
                      sub_tol: float) -> LoopConstraints:
    """General constraints of loop j: what its screw system cannot produce. M_R = 3 − rank of
    the angular parts; M_T = 3 − dim of the pure translations in the system; an axis is
    constrained in both when it is normal to the angular span and to the pure translations."""
    basis, _ = _range(block, tol)
    r = basis.shape[1]
    angular, _ = _range(basis[:3], sub_tol)
    a = angular.shape[1]
    translations, _ = _range(basis[3:] @ _null(basis[:3], sub_tol), sub_tol)
    shared = 3 - _rank(np.concatenate([angular, translations], axis=1), sub_tol)
    return LoopConstraints(
        loop=j + 1,
        freedoms=tuple(n for n, c in zip(names, block.T, strict=True) if c.any()),
        motion_rank=r,
        general=general_constraints_from_counts(3 - a, 3 - (r - a), shared),
    )


def _with_inputs(result: NumericMobility, names: tuple[str, ...], null: NDArray[np.float64],
                 in_idx: list[int], out_idx: list[int] | None, sub_tol: float) -> NumericMobility:
    """The result with how the inputs (and outputs) determine the motion."""
    null_in = null[in_idx]
    free = null @ _null(null_in, sub_tol)  # motions that leave the inputs still
    fields: dict[str, object] = {
        "input_names": tuple(names[j] for j in in_idx),
        "independent_inputs": _rank(null_in, sub_tol),
        "undetermined_motions": free.shape[1],
        "undetermined_involves": _involved(names, free, sub_tol),
    }
    if out_idx is not None:
        redundant = free @ _null(free[out_idx], sub_tol)  # ... and the outputs too
        fields |= {
            "output_names": tuple(names[j] for j in out_idx),
            "redundant_freedoms": redundant.shape[1],
            "redundant_involves": _involved(names, redundant, sub_tol),
        }
    return replace(result, **fields)  # type: ignore[arg-type]
