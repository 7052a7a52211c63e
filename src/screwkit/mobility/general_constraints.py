"""General constraints of a loop in Bagci's m(M_R1 M_R2 M_R3, M_T1 M_T2 M_T3) notation.

Bagci 1969, Appendix B ("General Constraints"): without general constraints the motion of
every link is described by three basic screws (three rotations and three translations about
three basic screw axes, BSA). A general constraint removes one of these six components from
the motion of *every* link. M_Rj = 1 means no link rotates about BSA j, M_Tj = 1 that no link
translates along BSA j, and m = Σ (M_Rj + M_Tj) ≤ 5.

Examples (Bagci): plane mechanisms m(110,001) = 3, spherical m(000,111) = 3, all-prism
m(111,000) = 3.

Which axis is called 1, 2 or 3 is a labelling choice, so two notations describe the same
*type* when one is an axis permutation of the other; :meth:`GeneralConstraints.canonical`
picks one representative per type (axes ordered: constrained in rotation and translation,
rotation only, translation only, free). Bagci counts 19 types; :func:`general_constraint_types`
lists them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from itertools import combinations_with_replacement

from screwkit.mobility.errors import MobilityInputError

#: Most general constraints a moving loop can have (m = 5 leaves a class-I pair's motion).
MAX_GENERAL_CONSTRAINTS = 5

_NOTATION = re.compile(
    r"^\s*m?\s*\(?\s*([01]{3})\s*[, ]\s*([01]{3})\s*\)?\s*(?:=\s*(\d+))?\s*$", re.IGNORECASE
)


@dataclass(frozen=True)
class GeneralConstraints:
    """General constraints of one loop: ``rotation[j]`` / ``translation[j]`` are M_Rj / M_Tj.

    Built with :func:`general_constraints` from Bagci's notation (``"m(110,001)"``).
    """

    rotation: tuple[int, int, int]
    translation: tuple[int, int, int]

    def __post_init__(self) -> None:
        for what, bits in (("rotation", self.rotation), ("translation", self.translation)):
            if len(bits) != 3 or any(b not in (0, 1) for b in bits):
                raise MobilityInputError(
                    f"general constraints on {what} must be three 0/1 flags (one per basic "
                    f"screw axis); got {bits!r}"
                )

    @property
    def count(self) -> int:
        """m = Σ (M_Rj + M_Tj)."""
        return sum(self.rotation) + sum(self.translation)

    @property
    def on_rotation(self) -> int:
        """M_R = Σ M_Rj, the general constraints on rotation."""
        return sum(self.rotation)

    @property
    def on_translation(self) -> int:
        """M_T = Σ M_Tj, the general constraints on translation."""
        return sum(self.translation)

    @property
    def notation(self) -> str:
        """Bagci's notation, e.g. ``"m(110,001)"``."""
        r = "".join(map(str, self.rotation))
        t = "".join(map(str, self.translation))
        return f"m({r},{t})"

    def canonical(self) -> GeneralConstraints:
        """The representative of this type: axes sorted as (rotation and translation
        constrained, rotation only, translation only, free)."""
        # axis state 2·M_R + M_T: 3 both, 2 rotation only, 1 translation only, 0 free
        states = sorted(
            (2 * r + t for r, t in zip(self.rotation, self.translation, strict=True)),
            reverse=True,
        )
        return _from_states(states)

    def same_type(self, other: GeneralConstraints | str) -> bool:
        """True if ``other`` is this notation with the basic screw axes relabelled."""
        return self.canonical() == general_constraints(other).canonical()

    def __str__(self) -> str:
        return f"{self.notation} = {self.count}"


def _from_states(states: list[int] | tuple[int, ...]) -> GeneralConstraints:
    rot = tuple(s // 2 for s in states)
    tra = tuple(s % 2 for s in states)
    return GeneralConstraints(rot, tra)  # type: ignore[arg-type]


def general_constraints(spec: str | GeneralConstraints) -> GeneralConstraints:
    """Parse Bagci's notation: ``"m(110,001)"``, ``"(110,001)"``, ``"110,001"``,
    ``"m(110,001) = 3"`` (a count after ``=`` must agree with the flags).

    The six flags are M_R1 M_R2 M_R3 (rotation about the basic screw axes) then M_T1 M_T2 M_T3
    (translation along them); Bagci 1969, Appendix B.
    """
    if isinstance(spec, GeneralConstraints):
        return spec
    if not isinstance(spec, str):
        raise MobilityInputError(
            f"general constraints are written as Bagci's notation 'm(110,001)'; got {spec!r}"
        )
    m = _NOTATION.match(spec)
    if m is None:
        raise MobilityInputError(
            f"cannot read general constraints {spec!r}; write 'm(R1R2R3,T1T2T3)' with 0/1 "
            "flags, e.g. 'm(110,001)' for a plane loop (no rotation about axes 1, 2, no "
            "translation along axis 3)"
        )
    rot = tuple(int(c) for c in m.group(1))
    tra = tuple(int(c) for c in m.group(2))
    gc = GeneralConstraints(rot, tra)  # type: ignore[arg-type]
    if m.group(3) is not None and int(m.group(3)) != gc.count:
        raise MobilityInputError(
            f"general constraints {spec!r}: the flags add up to {gc.count}, not {m.group(3)}"
        )
    return gc


def general_constraints_from_counts(
    on_rotation: int, on_translation: int, shared_axes: int
) -> GeneralConstraints:
    """The canonical notation for M_R rotation constraints, M_T translation constraints and
    ``shared_axes`` basic screw axes constrained in both (rotation and translation)."""
    free = 3 - (on_rotation + on_translation - shared_axes)
    if min(on_rotation, on_translation, shared_axes, free) < 0 or shared_axes > min(
        on_rotation, on_translation
    ):
        raise MobilityInputError(
            f"no set of basic screw axes has {on_rotation} rotation and {on_translation} "
            f"translation constraints with {shared_axes} shared axes"
        )
    states = (
        [3] * shared_axes
        + [2] * (on_rotation - shared_axes)
        + [1] * (on_translation - shared_axes)
        + [0] * free
    )
    return _from_states(states)


def general_constraint_types() -> tuple[GeneralConstraints, ...]:
    """Every type of general constraints with m ≤ 5, one canonical notation each.

    Each basic screw axis is free, constrained in rotation, in translation, or in both; a type
    is a multiset of three such states, excluding the rigid m = 6. Bagci (Appendix B) counts
    19 types, including m = 0.
    """
    types = {
        _from_states(states).canonical()
        for states in combinations_with_replacement(range(4), 3)
        if sum(s // 2 + s % 2 for s in states) <= MAX_GENERAL_CONSTRAINTS
    }
    return tuple(sorted(types, key=lambda g: (g.count, g.notation)))
