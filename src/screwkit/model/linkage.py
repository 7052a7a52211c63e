"""The immutable model of one closed loop: joints, the constant link transforms between them,
the moving links, which freedoms are driven, and where the loop sits in the world.

Loop convention (Rahman 1996 eq. 2.2 generalised): joint i acts about the z axis of its own
frame; after its motion J_i(q_i) a constant link transform L_i (a screw matrix, for the
Hartenberg–Denavit form L_i = X(α_i + ε a_i)) leads to the frame of joint i+1. Going once round
the loop returns to the ground frame:

    J_1(q_1) L_1 J_2(q_2) L_2 ··· J_n(q_n) L_n = I          (loop closure)

The ground frame is joint 1's frame; ``base`` places it in the world. Moving link i (i = 1 … n−1)
lies between joints i and i+1 and its body frame is joint i's frame after the joint motion.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from screwkit.dual import ScrewMatrix
from screwkit.errors import InputError
from screwkit.messages import listing
from screwkit.model.joints import Joint
from screwkit.model.mass import MassProperties


class LinkageError(InputError):
    """A mechanism description that cannot be right (bad lengths, names, inputs ...)."""


@dataclass(frozen=True)
class Link:
    """A moving link. ``mass`` (a :class:`screwkit.model.mass.MassProperties`) is given in the
    link's body frame; ``None`` when no dynamics is asked for."""

    name: str
    mass: MassProperties | None = None


@dataclass(frozen=True, eq=False)
class Linkage:
    """One closed loop. Never modified: solvers return new result objects.

    Use :meth:`from_hartenberg_denavit` or the family constructors in
    :mod:`screwkit.model.families` rather than building the transforms by hand.
    """

    name: str
    joints: tuple[Joint, ...]
    link_transforms: tuple[ScrewMatrix, ...]
    links: tuple[Link, ...]
    inputs: tuple[str, ...]
    base: ScrewMatrix = field(default_factory=ScrewMatrix.identity)
    family: str | None = None
    parameters: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for what, items, kind in (("joints", self.joints, Joint), ("links", self.links, Link)):
            if isinstance(items, str) or not all(isinstance(x, kind) for x in items):
                bad = items if isinstance(items, str) else next(
                    x for x in items if not isinstance(x, kind))
                raise LinkageError(f"linkage {self.name!r}: {what} must be {kind.__name__} "
                                   f"objects (sk.{kind.__name__}(...)); got "
                                   f"{type(bad).__name__} {bad!r:.40}")
        if isinstance(self.inputs, str) or not all(isinstance(x, str) for x in self.inputs):
            raise LinkageError(f"linkage {self.name!r}: inputs must be a list of freedom names "
                               f"such as ['crank.theta']; got {self.inputs!r:.60}")
        n = len(self.joints)
        if n < 2:
            raise LinkageError(f"linkage {self.name!r}: a closed loop needs at least 2 joints; got {n}")
        if len(self.link_transforms) != n:
            raise LinkageError(
                f"linkage {self.name!r}: {n} joints need {n} link transforms (one after each "
                f"joint); got {len(self.link_transforms)}"
            )
        if len(self.links) != n - 1:
            raise LinkageError(
                f"linkage {self.name!r}: {n} joints close a loop of {n - 1} moving links plus the "
                f"ground; got {len(self.links)} links"
            )
        names = [j.name for j in self.joints]
        dup = sorted({x for x in names if names.count(x) > 1})
        if dup:
            raise LinkageError(f"linkage {self.name!r}: joint names must be unique; repeated: {listing(dup)}")
        lnames = [lk.name for lk in self.links]
        dupl = sorted({x for x in lnames if lnames.count(x) > 1})
        if dupl:
            raise LinkageError(f"linkage {self.name!r}: link names must be unique; repeated: {dupl}")
        for k, t in enumerate(self.link_transforms):
            if t.shape != ():
                raise LinkageError(
                    f"linkage {self.name!r}: link transform {k} must be a single screw matrix"
                )
            if float(t.orthogonality_error()) > 1e-9:
                raise LinkageError(
                    f"linkage {self.name!r}: link transform after joint {names[k]!r} is not a "
                    "rigid displacement (its screw matrix is not orthogonal)"
                )
        all_freedoms = self.freedom_names
        if not self.inputs:
            raise LinkageError(
                f"linkage {self.name!r}: name at least one driven freedom (input), e.g. "
                f"{all_freedoms[0]!r}"
            )
        for inp in self.inputs:
            if inp not in all_freedoms:
                raise LinkageError(
                    f"linkage {self.name!r}: input {inp!r} is not a freedom of this loop; "
                    f"freedoms are {listing(all_freedoms)}"
                )
            if inp.split(".")[0] in {j.name for j in self.joints if j.kind == "S"}:
                raise LinkageError(
                    f"linkage {self.name!r}: a spherical joint cannot be driven ({inp!r})"
                )
        if len(set(self.inputs)) != len(self.inputs):
            raise LinkageError(f"linkage {self.name!r}: an input is named twice: "
                               f"{listing(self.inputs)}")

    # --- construction -------------------------------------------------------------------
    @classmethod
    def from_hartenberg_denavit(
        cls,
        name: str,
        joints: Sequence[Joint],
        lengths: Sequence[float],
        twists: Sequence[float],
        inputs: Sequence[str],
        links: Sequence[Link] | None = None,
        base: ScrewMatrix | None = None,
        family: str | None = None,
        parameters: Mapping[str, float] | None = None,
    ) -> Linkage:
        """Loop from Hartenberg–Denavit link parameters: link i has length a_i (common normal
        from axis i to axis i+1) and twist α_i, so L_i = X(α_i + ε a_i) (Rahman eq. 2.2)."""
        if not (len(joints) == len(lengths) == len(twists)):
            raise LinkageError(
                f"linkage {name!r}: give one length and one twist per joint "
                f"({len(joints)} joints, {len(lengths)} lengths, {len(twists)} twists)"
            )
        for k, a in enumerate(lengths):
            if not np.isfinite(a):
                raise LinkageError(f"linkage {name!r}: length a_{k + 1} is not finite")
        transforms = tuple(
            ScrewMatrix.rot_x(_dual(alpha, a)) for a, alpha in zip(lengths, twists, strict=True)
        )
        if links is None:
            links = [Link(f"link{k + 1}") for k in range(len(joints) - 1)]
        return cls(
            name=name,
            joints=tuple(joints),
            link_transforms=transforms,
            links=tuple(links),
            inputs=tuple(inputs),
            base=ScrewMatrix.identity() if base is None else base,
            family=family,
            parameters=dict(parameters or {}),
        )

    # --- derived data ---------------------------------------------------------------------
    @property
    def freedom_names(self) -> list[str]:
        """All freedoms, in loop order, as ``"<joint>.<freedom>"``."""
        return [f for j in self.joints for f in j.freedom_names()]

    @property
    def passive_names(self) -> list[str]:
        return [f for f in self.freedom_names if f not in self.inputs]

    @property
    def length_scale(self) -> float:
        """A characteristic length: the sum of the link lengths and joint offsets (≥ tiny)."""
        total = 0.0
        for t, j in zip(self.link_transforms, self.joints, strict=True):
            total += float(np.linalg.norm(t.translation))
            if j.kind != "P":
                total += abs(j.offset)
        return max(total, 1e-9)

    def with_links(self, links: Sequence[Link]) -> Linkage:
        """A copy with other link data (e.g. mass properties)."""
        return Linkage(
            name=self.name,
            joints=self.joints,
            link_transforms=self.link_transforms,
            links=tuple(links),
            inputs=self.inputs,
            base=self.base,
            family=self.family,
            parameters=self.parameters,
        )

    def describe(self) -> str:
        """One line per joint: what the loop is made of."""
        lines = [f"{self.name}: {len(self.joints)} joints "
                 f"({''.join(j.kind for j in self.joints)}), inputs {listing(self.inputs)}"]
        return "\n".join(lines)


def _dual(real: float, dual: float) -> Any:
    from screwkit.dual import Dual

    return Dual(real, dual)
