"""Design variables of a balancing problem: the inertial parameters are affine in them,
π = π_fixed + B·x, and every constraint on them is linear and named.

Parameterisations (DESIGN.md, "balancing"):

* :func:`point_mass_variables` — the masses of a link's equivalent seven-point model
  (Rahman 1996 §2.2 and ch. 4, design variables x1…x8 of the seed): three ± pairs on the
  principal axes through the CoM and one mass at the CoM, the distances X, Y, Z held fixed. Each
  mass may fall by at most a fraction w′ of its original value (seed eq. 4.5); the pair masses'
  sum may be kept equal (the seed's program) or at most its original value (the seed's text).
* :func:`counterweight_variables` — a point mass added to a link, at a fixed point (one
  variable, its mass) or with a free position inside a box (four variables: the mass μ and its
  first moment μ·p, linear; the position is μp/μ).

Columns of B: a point mass μ at p (link frame) contributes μ·φ(p) to π with
φ(p) = (1, p, py²+pz², px²+pz², px²+py², −px·py, −px·pz, −py·pz) (screwkit.model.mass order).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.balancing.errors import BalancingError
from screwkit.errors import expect_instance, expect_number
from screwkit.messages import given, listing, shown, shown_values
from screwkit.model.linkage import Linkage
from screwkit.model.mass import (
    EQUIVALENT_POINT_LABELS,
    N_INERTIAL_PARAMETERS,
    equivalent_point_masses,
)
from screwkit.model.mechanism import Mechanism

Array = NDArray[np.float64]

#: names of the four masses of the seven-point model (pairs along principal x, y, z; CoM)
POINT_MASS_NAMES = ("m1", "m2", "m3", "m4")


def point_parameters(position: ArrayLike) -> Array:
    """φ(p): inertial parameters (screwkit.model.mass order) of a unit point mass at p."""
    px, py, pz = np.asarray(position, dtype=float)
    return np.array([1.0, px, py, pz, py * py + pz * pz, px * px + pz * pz, px * px + py * py,
                     -px * py, -px * pz, -py * pz])


@dataclass(frozen=True)
class LinearConstraint:
    """``coefficients · x (≤ or =) bound``; ``kind`` is ``"eq"`` or ``"le"``."""

    name: str
    coefficients: Array
    kind: str
    bound: float


@dataclass(frozen=True)
class VariableBlock:
    """Some design variables and how they enter π (columns ``basis`` (P, k))."""

    names: tuple[str, ...]
    link: str
    basis: Array
    original: Array
    scale: Array  # typical size of each variable (for scaling and "nearest original")
    constraints: tuple[LinearConstraint, ...] = ()
    # for a point-mass block: the link's π less the variables' part at their original values
    replaces: Array | None = None
    kind: str = "point_masses"


@dataclass(frozen=True)
class DesignVariables:
    """All design variables: π = pi_fixed + basis @ x; constraints over the whole x."""

    names: tuple[str, ...]
    links: tuple[str, ...]  # the link each variable belongs to
    basis: Array  # (P, n)
    pi_fixed: Array  # (P,)
    original: Array  # (n,)
    scale: Array  # (n,)
    constraints: tuple[LinearConstraint, ...]
    blocks: tuple[VariableBlock, ...] = field(default=())

    def parameters(self, x: ArrayLike) -> Array:
        """π for design x."""
        return np.asarray(self.pi_fixed + self.basis @ np.asarray(x, dtype=float))

    def physical_parameters(self, x: ArrayLike) -> Array:
        """π of the real bodies: as :meth:`parameters`, plus the second moment μ·p·pᵀ of each
        free-position counterweight (p = μp/μ), which the linear variables leave out."""
        xa = np.asarray(x, dtype=float)
        pi = self.parameters(xa)
        start = 0
        for b in self.blocks:
            k = len(b.names)
            if b.kind == "free_counterweight":
                mu, h = xa[start], xa[start + 1 : start + 4]
                if mu > 0:
                    full = mu * point_parameters(h / mu)
                    row = int(np.flatnonzero(b.basis[:, 0])[0])
                    pi[row + 4 : row + 10] += full[4:]
            start += k
        return np.asarray(pi)


#: what balancing works on: a single loop (its moving links) or a mechanism graph (its bodies)
Subject = Linkage | Mechanism


def moving_parts(subject: Subject) -> tuple[Any, ...]:
    """The moving links of a loop or the moving bodies of a graph, in parameter order (each has
    ``name`` and ``mass``); a graph's body frame is the drawing's frame."""
    expect_instance(subject, Linkage | Mechanism, "linkage",
                    "a screwkit Linkage (load_spec(...).linkage) or a Mechanism "
                    "(load_spec(...).mechanism)")
    return tuple(subject.links) if isinstance(subject, Linkage) else tuple(subject.bodies)


def part_word(subject: Subject) -> str:
    """"link" for a loop, "body" for a graph (for messages)."""
    return "body" if isinstance(subject, Mechanism) else "link"


def _link_index(linkage: Subject, link: str) -> int:
    names = [lk.name for lk in moving_parts(linkage)]
    if link not in names:
        word = part_word(linkage)
        raise BalancingError(f"no moving {word} named {link!r}; the "
                             f"{'bodies' if word == 'body' else 'links'} are {listing(names)}")
    return names.index(link)


def point_mass_variables(
    linkage: Subject,
    link: str,
    *,
    split: Sequence[float] | None = None,
    max_decrease: float = 0.05,
    max_increase: float | None = None,
    pair_sum: str = "equal",
    link_mass: str = "free",
    variables: Sequence[str] = POINT_MASS_NAMES,
) -> VariableBlock:
    """The masses of ``link``'s seven-point model as design variables (Rahman 1996 ch. 4, eq. 4.5).

    ``split`` — fractions (m1, m2, m3, m4) of the link mass (default ¼ each, the seed's choice);
    the distances X, Y, Z follow from it and stay fixed. Bounds per mass:
    (1 − max_decrease)·original ≤ x ≤ (1 + max_increase)·original (no upper bound if None).
    ``pair_sum`` constrains m1 + m2 + m3: ``"equal"`` (= original, the seed's program),
    ``"at_most"`` (≤ original, the seed's text, eq. 4.5) or ``"free"``. ``link_mass`` likewise
    constrains m1 + m2 + m3 + m4 (``"free"`` reproduces the seed, which lets it fall).
    ``variables`` — the subset that varies (the others keep their original mass).
    """
    idx = _link_index(linkage, link)
    props = moving_parts(linkage)[idx].mass
    if props is None:
        where = ("mass, com and inertia in its [[bodies]] entry" if part_word(linkage) == "body"
                 else f"[links.{link}] (mass, com, inertia)")
        raise BalancingError(f"{part_word(linkage)} {link!r} has no mass properties; add {where}")
    fractions = np.full(4, 0.25) if split is None else np.asarray(split, dtype=float)
    if fractions.shape != (4,) or np.any(fractions < 0) or abs(fractions.sum() - 1.0) > 1e-9:
        raise BalancingError(
            f"link {link!r}: split must be four fractions >= 0 of the link mass summing to 1 "
            f"(m1, m2, m3, m4); got {given(split)}"
        )
    if not 0.0 <= max_decrease <= 1.0:
        raise BalancingError(
            f"link {link!r}: max_decrease must be a fraction in [0, 1] (w′ = 0.05 for 5 %); "
            f"got {given(max_decrease)}"
        )
    if max_increase is not None and max_increase < 0.0:
        raise BalancingError(f"link {link!r}: max_increase must be >= 0; got {given(max_increase)}")
    for key, val in (("pair_sum", pair_sum), ("link_mass", link_mass)):
        if val not in ("equal", "at_most", "free"):
            raise BalancingError(
                f"link {link!r}: {key} must be 'equal', 'at_most' or 'free'; got {val!r}"
            )
    unknown = [v for v in variables if v not in POINT_MASS_NAMES]
    if unknown or not variables:
        raise BalancingError(
            f"link {link!r}: variables must be a non-empty subset of {listing(POINT_MASS_NAMES)}; "
            f"got {listing(variables)}"
        )
    masses = fractions * props.mass
    model = equivalent_point_masses(props, masses)
    P = N_INERTIAL_PARAMETERS * len(moving_parts(linkage))
    columns = np.zeros((P, 4))
    rows = slice(N_INERTIAL_PARAMETERS * idx, N_INERTIAL_PARAMETERS * (idx + 1))
    for k in range(4):
        pts = [i for i, lab in enumerate(EQUIVALENT_POINT_LABELS) if _group(lab) == k]
        share = 1.0 / len(pts)  # each point of a pair carries half of the pair mass
        columns[rows, k] = sum(share * point_parameters(model.positions[i]) for i in pts)
    chosen = [POINT_MASS_NAMES.index(v) for v in variables]
    fixed = [k for k in range(4) if k not in chosen]
    names = tuple(f"{link}.{POINT_MASS_NAMES[k]}" for k in chosen)
    # the link's parameters not carried by the variables (exact: the model reproduces π)
    replaces = np.zeros(P)
    replaces[rows] = props.inertial_parameters() - columns[rows][:, chosen] @ masses[chosen]
    original = masses[chosen]
    n = len(chosen)
    cons: list[LinearConstraint] = []
    for j, k in enumerate(chosen):
        e = np.zeros(n)
        e[j] = 1.0
        cons.append(LinearConstraint(
            f"{names[j]} >= {1 - max_decrease:g} x original", -e, "le",
            -(1.0 - max_decrease) * masses[k]))
        if max_increase is not None:
            cons.append(LinearConstraint(
                f"{names[j]} <= {1 + max_increase:g} x original", e, "le",
                (1.0 + max_increase) * masses[k]))
    for rule, group, label in ((pair_sum, (0, 1, 2), "m1+m2+m3"),
                               (link_mass, (0, 1, 2, 3), "link mass")):
        in_block = [j for j, k in enumerate(chosen) if k in group]
        if rule == "free" or not in_block:
            continue
        a = np.zeros(n)
        a[in_block] = 1.0
        rhs = float(masses[list(group)].sum() - masses[[k for k in group if k in fixed]].sum())
        sym = "=" if rule == "equal" else "<="
        cons.append(LinearConstraint(f"{link}: {label} {sym} original", a,
                                     "eq" if rule == "equal" else "le", rhs))
    return VariableBlock(names, link, columns[:, chosen], original,
                         np.maximum(original, 1e-12 * props.mass), tuple(cons), replaces)


def _group(label: str) -> int:
    return {"X": 0, "Y": 1, "Z": 2}.get(label[-1], 3)


def counterweight_variables(
    linkage: Subject,
    link: str,
    name: str,
    *,
    mass_max: float,
    mass_min: float = 0.0,
    at: ArrayLike | None = None,
    box: tuple[ArrayLike, ArrayLike] | None = None,
) -> VariableBlock:
    """A point counterweight on ``link`` (link frame, SI): at the fixed point ``at`` (variable:
    its mass μ) or free inside ``box = (lower corner, upper corner)`` (variables μ and the first
    moment μ·p; the bounds μ·lo ≤ μp ≤ μ·hi are linear). A free counterweight's own second
    moment μ p pᵀ is not linear in (μ, μp): only the shaking force is exact for it (the problem
    refuses other weighted measures; see :mod:`screwkit.balancing.problem`)."""
    idx = _link_index(linkage, link)
    expect_number(mass_max, f"counterweight {name!r}: mass_max")
    expect_number(mass_min, f"counterweight {name!r}: mass_min")
    if not (np.isfinite(mass_max) and mass_max > 0 and 0 <= mass_min <= mass_max):
        raise BalancingError(
            f"counterweight {name!r}: need 0 <= mass_min <= mass_max and mass_max > 0; got "
            f"mass_min={mass_min!r}, mass_max={mass_max!r}"
        )
    if (at is None) == (box is None):
        raise BalancingError(f"counterweight {name!r}: give exactly one of at= or box=")
    P = N_INERTIAL_PARAMETERS * len(moving_parts(linkage))
    rows = slice(N_INERTIAL_PARAMETERS * idx, N_INERTIAL_PARAMETERS * (idx + 1))
    if at is not None:
        p = np.asarray(at, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise BalancingError(f"counterweight {name!r}: at must be 3 finite coordinates")
        col = np.zeros((P, 1))
        col[rows, 0] = point_parameters(p)
        cons = [LinearConstraint(f"{name}.mass >= {shown(mass_min, 'mass')}", np.array([-1.0]), "le",
                                 -mass_min),
                LinearConstraint(f"{name}.mass <= {shown(mass_max, 'mass')}", np.array([1.0]), "le",
                                 mass_max)]
        return VariableBlock((f"{name}.mass",), link, col, np.array([0.0]),
                             np.array([mass_max]), tuple(cons), kind="counterweight")
    assert box is not None
    lo, hi = (np.asarray(b, dtype=float) for b in box)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(lo > hi):
        raise BalancingError(
            f"counterweight {name!r}: box must be two corners (3 coordinates each) with "
            f"lower <= upper; got {shown_values(lo, 'length')} and {shown_values(hi, 'length')}"
        )
    col = np.zeros((P, 4))
    col[rows.start, 0] = 1.0
    for k in range(3):
        col[rows.start + 1 + k, 1 + k] = 1.0
    names = (f"{name}.mass", f"{name}.mx", f"{name}.my", f"{name}.mz")
    cons = [LinearConstraint(f"{name}.mass >= {shown(mass_min, 'mass')}", np.array([-1.0, 0, 0, 0]),
                             "le", -mass_min),
            LinearConstraint(f"{name}.mass <= {shown(mass_max, 'mass')}", np.array([1.0, 0, 0, 0]),
                             "le", mass_max)]
    for k, axis in enumerate("xyz"):
        e = np.zeros(4)
        e[1 + k] = 1.0
        lo_row = e.copy()
        lo_row[0] = -lo[k]
        hi_row = e.copy()
        hi_row[0] = -hi[k]
        cons.append(LinearConstraint(f"{name}.{axis} >= {shown(lo[k], 'length')}", -lo_row, "le", 0.0))
        cons.append(LinearConstraint(f"{name}.{axis} <= {shown(hi[k], 'length')}", hi_row, "le", 0.0))
    size = np.array([mass_max, *(mass_max * np.maximum(np.abs(lo), np.abs(hi)) + 1e-12)])
    return VariableBlock(names, link, col, np.zeros(4), size, tuple(cons), kind="free_counterweight")


def assemble(linkage: Subject, blocks: Sequence[VariableBlock]) -> DesignVariables:
    """Stack variable blocks into one :class:`DesignVariables` (π_fixed = the links' own
    parameters minus what the point-mass blocks replace)."""
    if not blocks:
        raise BalancingError("no design variables: list at least one link under "
                             "[balancing.links] or one [[balancing.counterweights]]")
    parts = moving_parts(linkage)
    missing = [lk.name for lk in parts if lk.mass is None]
    if missing:
        word = part_word(linkage)
        where = ("give mass, com and inertia in its [[bodies]] entry" if word == "body"
                 else "add its [links.<name>] table")
        raise BalancingError(f"balancing needs mass properties for every moving {word}; "
                             f"{', '.join(repr(m) for m in missing)} "
                             f"{'has' if len(missing) == 1 else 'have'} none ({where})")
    pi = np.concatenate([lk.mass.inertial_parameters() for lk in parts if lk.mass is not None])
    seen: set[str] = set()
    for b in blocks:
        if b.replaces is not None:
            if b.link in seen:
                raise BalancingError(f"link {b.link!r} has two point-mass variable blocks")
            seen.add(b.link)
            idx = _link_index(linkage, b.link)
            rows = slice(N_INERTIAL_PARAMETERS * idx, N_INERTIAL_PARAMETERS * (idx + 1))
            pi[rows] = b.replaces[rows]
    names = tuple(n for b in blocks for n in b.names)
    if len(set(names)) != len(names):
        raise BalancingError(f"design variable names repeat: {listing(names)}")
    n = len(names)
    cons: list[LinearConstraint] = []
    start = 0
    for b in blocks:
        k = len(b.names)
        for c in b.constraints:
            a = np.zeros(n)
            a[start : start + k] = c.coefficients
            cons.append(LinearConstraint(c.name, a, c.kind, c.bound))
        start += k
    return DesignVariables(
        names=names,
        links=tuple(b.link for b in blocks for _ in b.names),
        basis=np.concatenate([b.basis for b in blocks], axis=1),
        pi_fixed=pi,
        original=np.concatenate([b.original for b in blocks]),
        scale=np.concatenate([b.scale for b in blocks]),
        constraints=tuple(cons),
        blocks=tuple(blocks),
    )
