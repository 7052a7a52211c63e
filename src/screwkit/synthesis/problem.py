"""The synthesis problem: target, unknowns, design constants, bounds, constraints, scale.

Bagci 1969, §5.1: the RSRC's dimensions x = (e, d1, d2, d3, a, b, delta0, lambda0, theta01) are
split by the user into unknowns and design constants.  With parameters of constraint (§5.3,
`ConstraintConstruction`) d3, a and b are derived from (d1, d2, lambda0, theta01, q1, q2) by
eqs. 5.19-5.21 and q1, q2 are either unknowns ("free"), fixed, or set by the dwell condition
5.13 at their input position.

Error measure (eq. 5.4): E = E_phi + E_S / L^2 with E_phi = sum R_phi^2 [rad^2] and
E_S = sum R_S^2 [m^2].  E adds radians to lengths, so its optimum depends on the length scale L
(Bagci's "screw of unit radius": L = 1 in).  `length_scale` makes L explicit; the solver and the
report use the same L.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.messages import given, listing, shown
from screwkit.synthesis.constraints import output_crank_from_constraints, q_from_dwell
from screwkit.synthesis.targets import ScrewTarget

__all__ = [
    "ANGLE_NAMES",
    "DIMENSION_NAMES",
    "LENGTH_NAMES",
    "ConstraintConstruction",
    "ConstraintPoint",
    "RSRCSynthesisProblem",
]

DIMENSION_NAMES = ("e", "d1", "d2", "d3", "a", "b", "delta0", "lambda0", "theta01")
LENGTH_NAMES = frozenset({"e", "d1", "d2", "d3", "a", "b"})
ANGLE_NAMES = frozenset({"delta0", "lambda0", "theta01", "q1", "q2"})
DERIVED_BY_CONSTRAINTS = ("d3", "a", "b")

Array = NDArray[Any]


@dataclass(frozen=True)
class ConstraintPoint:
    """A parameter of constraint q_i at the input position theta (from theta01), §5.3.

    kind: "dwell" (q by eq. 5.13: a rotation limit there), "free" (q is an unknown, started at
    ``value``) or "fixed" (q = ``value``).  ``other_tangency`` adds pi to a dwell's q.
    """

    theta: float
    kind: Literal["dwell", "free", "fixed"] = "dwell"
    value: float = 0.0
    other_tangency: bool = False

    def __post_init__(self) -> None:
        if self.kind not in ("dwell", "free", "fixed"):
            raise InputError(f"constraint point kind must be dwell, free or fixed, got {self.kind!r}")
        for name in ("theta", "value"):
            if not math.isfinite(float(getattr(self, name))):
                raise InputError(f"constraint point {name} must be finite")


@dataclass(frozen=True)
class ConstraintConstruction:
    """Bagci's parameters of constraint (eqs. 5.13-5.21, delta0 = 0): two points and the output
    rotation between them.

    ``rotation_between`` is the generated output rotation phi0(theta_2) - phi0(theta_1) (rad);
    None takes it from the desired rotation (the exact range, e.g. a quick-return stroke).
    """

    first: ConstraintPoint
    second: ConstraintPoint
    rotation_between: float | None = None

    def __post_init__(self) -> None:
        if self.first.theta == self.second.theta:
            raise InputError("the two constraint points must be at different input positions")


@dataclass(frozen=True)
class RSRCSynthesisProblem:
    """Everything a synthesis run needs (SI units, radians).

    Attributes
    ----------
    target : the desired screw and its design points.
    start : value of every dimension in DIMENSION_NAMES (the start for unknowns, the value for
        constants); with a construction, q1/q2 starts for "free" points; d3, a, b are then ignored.
    unknowns : names solved for.
    bounds : optional (lower, upper) per unknown.
    inversion : program label 1..4 of the start's assembly mode at theta = 0 (Bagci's I8/I9
        "positive/negative signed radical"); None tries every mode that assembles.
    input_direction : +1 for theta0 = theta01 + theta, -1 for theta01 - theta (Program C KDRCT).
    output_direction : +1 when psi_g = phi0 - phi01, -1 for phi01 - phi0 (Program C NCLOCK).
    length_scale : L of E = E_phi + E_S / L^2 (m).
    construction : parameters of constraint (Program C), or None (Program B).
    max_iterations, time_limit : solver limits (the solve never runs longer).
    """

    target: ScrewTarget
    start: Mapping[str, float]
    unknowns: tuple[str, ...]
    bounds: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    inversion: int | None = None
    input_direction: int = 1
    output_direction: int = 1
    length_scale: float = 0.0254
    construction: ConstraintConstruction | None = None
    max_iterations: int = 200
    time_limit: float = 10.0

    def __post_init__(self) -> None:
        allowed = set(DIMENSION_NAMES) | self.free_q_names
        if self.construction is not None:
            allowed -= set(DERIVED_BY_CONSTRAINTS)
        if len(set(self.unknowns)) != len(self.unknowns) or not self.unknowns:
            raise InputError(f"unknowns must be distinct and not empty, got {self.unknowns!r}")
        bad = [u for u in self.unknowns if u not in allowed]
        if bad:
            why = (" (with parameters of constraint d3, a and b are derived by eqs. 5.19-5.21)"
                   if self.construction is not None else "")
            raise InputError(f"unknown(s) {listing(bad)} cannot be solved for; choose among "
                             f"{listing(sorted(allowed))}{why}")
        missing_free = sorted(self.free_q_names - set(self.unknowns))
        if missing_free:
            raise InputError(f"{listing(missing_free)}: a 'free' parameter of a constraint "
                             "must be an unknown")
        needed = set(DIMENSION_NAMES) - (set(DERIVED_BY_CONSTRAINTS) if self.construction else set())
        missing = sorted(needed - set(self.start))
        if missing:
            raise InputError(f"start/constants lack {listing(missing)}: give a value for every dimension")
        for name, value in self.start.items():
            if not math.isfinite(float(value)):
                raise InputError(f"start value of {name} must be finite, got {given(value)}")
        for name, (lo, hi) in self.bounds.items():
            if name not in self.unknowns:
                raise InputError(f"bounds given for {name!r}, which is not an unknown")
            if not lo < hi:
                raise InputError(f"bounds of {name}: lower {lo!r} must be below upper {hi!r}")
        if self.inversion is not None and self.inversion not in (1, 2, 3, 4):
            raise InputError(f"inversion must be 1, 2, 3, 4 or None (all), got {self.inversion!r}")
        if self.input_direction not in (1, -1) or self.output_direction not in (1, -1):
            raise InputError("input_direction and output_direction must be +1 or -1")
        if not (self.length_scale > 0.0 and math.isfinite(self.length_scale)):
            raise InputError(f"length_scale must be a positive length, got {given(self.length_scale)}")
        if self.max_iterations < 1 or not self.time_limit > 0.0:
            raise InputError("max_iterations must be >= 1 and time_limit > 0")
        if self.construction is not None:
            fixed = {n: float(self.start[n]) for n in ("delta0",) if n not in self.unknowns}
            if "delta0" in self.unknowns or abs(math.sin(fixed.get("delta0", 0.0))) > 1e-12:
                raise InputError("parameters of constraint (eqs. 5.13-5.21) hold for delta0 = 0 "
                                 "only: make delta0 a constant 0, or drop the [synthesis."
                                 "constraint] table and impose the dwell/range as equations "
                                 "with the Python function screwkit.synthesis.equality_constrained."
                                 "synthesize_equality_constrained (not reachable from the CLI)")
            if "lambda0" in self.unknowns and abs(math.sin(float(self.start["lambda0"]))) < 1e-9:
                raise InputError("lambda0 = 0 (plane) cannot be an unknown with parameters of "
                                 "constraint: the plane case re-references the fixed link")
            if (self.construction.rotation_between is None and self.target.rotation is None):
                raise InputError("give the constraint's rotation_between: the target has no "
                                 "rotation to take it from")
            if abs(math.sin(0.5 * self.rotation_between())) < 1e-9:
                raise InputError(
                    "contradictory constraints: the output rotation between the two constraint "
                    f"points is {shown(self.rotation_between(), 'angle')}, a multiple of "
                    "a full turn, so no output crank takes C1 to C2 (eq. 5.21); move a point or "
                    "change rotation_between")

    # ---------------------------------------------------------------------------------------
    @property
    def free_q_names(self) -> set[str]:
        if self.construction is None:
            return set()
        pts = (self.construction.first, self.construction.second)
        return {f"q{i}" for i, p in enumerate(pts, start=1) if p.kind == "free"}

    @property
    def planar(self) -> bool:
        """Plane case lambda0 = 0 with a construction: the fixed link is re-referenced (§5.3)."""
        return (self.construction is not None and "lambda0" not in self.unknowns
                and abs(math.sin(float(self.start["lambda0"]))) < 1e-12)

    def start_vector(self) -> NDArray[np.float64]:
        return np.array([float(self.start[n]) for n in self.unknowns])

    def bound_vectors(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(lower, upper) bounds of the unknown vector, SI: ``bounds`` where given, otherwise
        d1, d2, d3 >= 0 (a crank, coupler or output-crank length, as `RSRCDimensions` requires)
        and no bound on the other unknowns."""
        lo = np.full(len(self.unknowns), -np.inf)
        hi = np.full(len(self.unknowns), np.inf)
        for k, name in enumerate(self.unknowns):
            if name in self.bounds:
                lo[k], hi[k] = self.bounds[name]
            elif name in ("d1", "d2", "d3"):
                lo[k] = 0.0
        return lo, hi

    def rotation_between(self) -> float:
        assert self.construction is not None
        c = self.construction
        if c.rotation_between is not None:
            return float(c.rotation_between)
        psi = self.target.desired_rotation(np.array([c.first.theta, c.second.theta]))
        return float(self.output_direction * (psi[1] - psi[0]))

    def parameters(self, x: Array) -> dict[str, Array]:
        """Every dimension (and q1, q2) for unknown vectors x of shape (B, n); complex-safe.

        With a construction, d3, a, b come from eqs. 5.19-5.21 and ``phi1`` (the output-crank
        angle at theta = 0 of the constructed configuration) is added.
        """
        x = np.atleast_2d(x)
        batch = x.shape[0]
        out: dict[str, Array] = {}
        for name in DIMENSION_NAMES:
            if name in self.start:
                out[name] = np.full(batch, float(self.start[name]))
        for k, name in enumerate(self.unknowns):
            out[name] = x[:, k]
        if self.construction is None:
            return out
        c = self.construction
        lam, th01 = out["lambda0"], out["theta01"]
        qs = []
        for i, pt in enumerate((c.first, c.second), start=1):
            th = th01 + self.input_direction * pt.theta
            if pt.kind == "dwell":
                # Program C's fold into [0, pi) chooses the tangency at the start; the solver
                # then follows that tangency continuously (the fold itself jumps by pi)
                th_start = float(self.start["theta01"]) + self.input_direction * pt.theta
                lam_start = float(self.start["lambda0"])
                offset = float(q_from_dwell(th_start, lam_start, other_tangency=pt.other_tangency)
                               - q_from_dwell(th_start, lam_start, fold=False))
                q = q_from_dwell(th, lam, fold=False) + offset
            elif pt.kind == "free":
                q = out[f"q{i}"]
            else:
                q = np.full(batch, pt.value)
            out[f"q{i}"] = q
            qs.append((th, q))
        crank = output_crank_from_constraints(out["d1"], out["d2"], lam, qs[0][0], qs[1][0],
                                              qs[0][1], qs[1][1], self.rotation_between())
        out["d3"] = crank.d3
        phi1 = crank.phi1
        if self.planar:
            # Program C (L6248-L6262): rotate the plane mechanism about the input axis so that
            # the output axis lies on +Y; theta01 and phi01 shift by the centre's polar angle.
            cx, cy = crank.centre_x, crank.centre_y
            out["a"] = np.sqrt(cx * cx + cy * cy)
            beta = np.arctan(cy / np.where(np.abs(np.real(cx)) < 1e-300, 1e-300, cx))
            beta = beta + np.where(np.real(cx) < 0.0, np.pi, 0.0)
            out["theta01"] = th01 - beta
            phi1 = phi1 - beta
        else:
            out["a"] = crank.centre_x
            out["b"] = crank.centre_y / np.sin(lam)
        out["phi1"] = phi1
        return out
