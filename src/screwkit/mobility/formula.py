"""Formula (structural) mobility: Malytcheff, Kutzbach and Kolchin, Bagci 1969 Appendix B.

* (B.1) Malytcheff: F0 = 6(n − 1) − Σ_{i=1..5} (6 − i) N_i, n links, N_i pairs of class i.
* (B.2) Kutzbach / Artobolevskii–Dobrovolskii, m general constraints in every loop:
  F_m = (6 − m)(n − 1) − Σ_{i=1..5−m} (6 − m − i) N_i.
* (B.3) loops: (n − 1) + k = Σ N_i; hence (B.4) F_m = F0 + m k and (B.5) F = F0 + M with
  M = Σ_j m_j when the loops have different m_j.
* (B.6) passive freedoms: F = F0 + M − F_p; (B.7b) F = b(n − 1) − Σ_pairs (b − h_i), b = 6 − m,
  h_i = i − f_i the active freedoms of pair i.
* (B.8)–(B.10) Kolchin: F = F0 + M − F_p + F_c = F0 + H, H = M − F_p + F_c, F_c = Σ_j q_j the
  overclosing constraints.

Redundant freedoms (the coupler spin of an R-S-S-R) are *not* a term of (B.8): they are counted
in F. Bagci removes them by pair substitution; :mod:`screwkit.mobility.numeric` finds them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from screwkit.mobility.errors import MobilityInputError, check_count
from screwkit.mobility.general_constraints import (
    MAX_GENERAL_CONSTRAINTS,
    GeneralConstraints,
    general_constraints,
)
from screwkit.mobility.pairs import PairKind, count_pairs_by_class

#: Bagci's names (Appendix B, "Classification of Mechanisms") for F_p, F_c both zero, only
#: F_p ≠ 0, only F_c ≠ 0, and both ≠ 0.
BASIC = "basic"
WITH_PASSIVE_FREEDOMS = "with passive freedoms"
OVERCLOSED = "overclosed"
OVERCLOSED_WITH_PASSIVE_FREEDOMS = "overclosed with passive freedoms"

#: Kolchin's groups by comparing his parameter H with M (Appendix B).
KOLCHIN_BASIC = "basic"  # H = M
KOLCHIN_UNLIMITED = "unlimited"  # H < M
KOLCHIN_SPECIAL = "special"  # H > M

PLANE = general_constraints("m(110,001)")
SPHERICAL = general_constraints("m(000,111)")

PairsArg = str | Iterable[str | PairKind] | Mapping[str, int]
GeneralConstraintsArg = int | str | GeneralConstraints


def loop_count(n_links: int, pair_count: int) -> int:
    """k = Σ N_i − (n − 1), Bagci eq. (B.3). Raises if the pairs cannot connect the links."""
    n_links = check_count(n_links, "number of links n", minimum=2)
    pair_count = check_count(pair_count, "number of pairs")
    k = pair_count - (n_links - 1)
    if k < 0:
        raise MobilityInputError(
            f"{pair_count} pairs cannot connect {n_links} links: a connected mechanism needs "
            f"at least n − 1 = {n_links - 1} pairs (Bagci eq. B.3: (n − 1) + k = Σ N_i)"
        )
    return k


def malytcheff_mobility(n_links: int, pairs_by_class: Sequence[int]) -> int:
    """F0 = 6(n − 1) − Σ (6 − i) N_i, Bagci eq. (B.1); ``pairs_by_class[i-1]`` is N_i."""
    return 6 * (n_links - 1) - sum((6 - i) * n for i, n in enumerate(pairs_by_class, 1))


def kutzbach_mobility(n_links: int, active_freedoms: Sequence[int], motion_components: int = 6
                      ) -> int:
    """F = b(n − 1) − Σ_pairs (b − h_i), Bagci eq. (B.7b).

    ``active_freedoms`` holds h_i = i − f_i for every pair; ``motion_components`` is
    b = 6 − m. With b = 3 this is the plane (Grübler) or spherical form: a plane four-bar
    ``kutzbach_mobility(4, [1, 1, 1, 1], 3)`` gives 1.
    """
    n_links = check_count(n_links, "number of links n", minimum=2)
    b = check_count(motion_components, "motion components b = 6 − m", minimum=1)
    if b > 6:
        raise MobilityInputError(f"motion components b = 6 − m must be ≤ 6; got {b}")
    h = [check_count(x, f"active freedoms of pair {j}") for j, x in enumerate(active_freedoms)]
    for j, x in enumerate(h):
        if x > b:
            raise MobilityInputError(
                f"pair {j} has {x} active freedoms but the motion has only b = {b} components; "
                f"count the extra {x - b} as passive (h = i − f)"
            )
    loop_count(n_links, len(h))
    return b * (n_links - 1) - sum(b - x for x in h)


@dataclass(frozen=True)
class FormulaMobility:
    """Every term of Bagci's mobility count (Appendix B); build with :func:`formula_mobility`.

    The stored inputs are n, k, N_1…N_5, the pair kinds (if given by name), m_j per loop,
    F_p and F_c; the derived terms are properties and all appear in :meth:`as_dict`.
    """

    n_links: int
    loops: int
    pairs_by_class: tuple[int, int, int, int, int]
    pair_kinds: tuple[tuple[str, int], ...]
    general_constraints: tuple[int, ...]
    general_constraint_notation: tuple[str | None, ...]
    passive_freedoms: int
    overclosing_constraints: int
    overclosing_per_loop: tuple[int, ...] | None = None
    name: str | None = None

    @property
    def pair_count(self) -> int:
        """Σ N_i."""
        return sum(self.pairs_by_class)

    @property
    def freedom_count(self) -> int:
        """Σ i N_i, all pair freedoms (the columns of the loop Jacobian)."""
        return sum(i * n for i, n in enumerate(self.pairs_by_class, 1))

    @property
    def malytcheff(self) -> int:
        """F0, eq. (B.1)."""
        return malytcheff_mobility(self.n_links, self.pairs_by_class)

    @property
    def total_general_constraints(self) -> int:
        """M = Σ_j m_j, eq. (B.5)."""
        return sum(self.general_constraints)

    @property
    def kolchin_parameter(self) -> int:
        """H = M − F_p + F_c, eq. (B.10)."""
        return self.total_general_constraints - self.passive_freedoms + self.overclosing_constraints

    @property
    def mobility(self) -> int:
        """F = F0 + M − F_p + F_c, eq. (B.8) (= F0 + H, eq. B.9)."""
        return self.malytcheff + self.kolchin_parameter

    @property
    def uniform_general_constraints(self) -> int | None:
        """m when every loop has the same m (Kolchin's class of the mechanism), else None."""
        ms = set(self.general_constraints)
        return ms.pop() if len(ms) == 1 else None

    @property
    def kutzbach(self) -> int | None:
        """F_m of eq. (B.2) as printed (sum to i = 5 − m), for a uniform m; else None.

        It ignores F_p and F_c, and pairs of class ≥ 6 − m; it equals F0 + m k (B.4) when no
        such pair is present.
        """
        m = self.uniform_general_constraints
        if m is None:
            return None
        return (6 - m) * (self.n_links - 1) - sum(
            (6 - m - i) * n for i, n in enumerate(self.pairs_by_class, 1) if i <= 5 - m
        )

    @property
    def classification(self) -> str:
        """Bagci's extended name: basic, with passive freedoms, overclosed, or overclosed
        with passive freedoms (Appendix B, "Classification of Mechanisms")."""
        if self.passive_freedoms == 0:
            return BASIC if self.overclosing_constraints == 0 else OVERCLOSED
        return (
            WITH_PASSIVE_FREEDOMS
            if self.overclosing_constraints == 0
            else OVERCLOSED_WITH_PASSIVE_FREEDOMS
        )

    @property
    def kolchin_group(self) -> str:
        """Kolchin's group: basic (H = M), unlimited (H < M) or special (H > M)."""
        h, m = self.kolchin_parameter, self.total_general_constraints
        return KOLCHIN_BASIC if h == m else (KOLCHIN_UNLIMITED if h < m else KOLCHIN_SPECIAL)

    def _malytcheff_text(self) -> str:
        terms = " − ".join(
            f"{6 - i}·{n}" for i, n in enumerate(self.pairs_by_class, 1) if n
        )
        return f"6({self.n_links}−1)" + (f" − {terms}" if terms else "") + f" = {self.malytcheff}"

    def describe(self) -> str:
        """A few lines for a terminal: every term, with the equation it comes from."""
        title = self.name or "mechanism"
        counts = ", ".join(f"N{i}={n}" for i, n in enumerate(self.pairs_by_class, 1) if n)
        kinds = ", ".join(f"{n}×{s}" for s, n in self.pair_kinds)
        loops_m = ", ".join(
            note if note else str(m)
            for m, note in zip(
                self.general_constraints, self.general_constraint_notation, strict=True
            )
        )
        lines = [
            f"{title}: F = {self.mobility}",
            f"  links n = {self.n_links}; pairs {self.pair_count} ({counts or 'none'}"
            + (f"; {kinds}" if kinds else "")
            + f"); loops k = {self.loops} (B.3)",
            f"  Malytcheff (B.1): F0 = {self._malytcheff_text()}",
            f"  general constraints (B.5): M = {self.total_general_constraints}"
            + (f" [per loop: {loops_m}]" if self.loops else ""),
            f"  passive freedoms F_p = {self.passive_freedoms}; "
            f"overclosing constraints F_c = {self.overclosing_constraints}",
            f"  Kolchin (B.8–B.10): H = M − F_p + F_c = {self.kolchin_parameter}; "
            f"F = F0 + H = {self.mobility}",
        ]
        if self.kutzbach is not None:
            lines.append(
                f"  Kutzbach (B.2, m = {self.uniform_general_constraints} in every loop): "
                f"F_m = {self.kutzbach}"
            )
        m = self.uniform_general_constraints
        lines.append(
            f"  classification: {self.classification}; Kolchin group {self.kolchin_group}"
            + (f", class {m}" if m is not None else "")
        )
        return "\n".join(lines)

    def as_dict(self) -> dict[str, object]:
        """Plain JSON-able dict of the inputs and every derived term."""
        return {
            "name": self.name,
            "n_links": self.n_links,
            "loops": self.loops,
            "pairs_by_class": {f"N{i}": n for i, n in enumerate(self.pairs_by_class, 1)},
            "pair_kinds": dict(self.pair_kinds),
            "pair_count": self.pair_count,
            "freedom_count": self.freedom_count,
            "general_constraints_per_loop": list(self.general_constraints),
            "general_constraint_notation": list(self.general_constraint_notation),
            "total_general_constraints": self.total_general_constraints,
            "passive_freedoms": self.passive_freedoms,
            "overclosing_constraints": self.overclosing_constraints,
            "overclosing_per_loop": (
                None if self.overclosing_per_loop is None else list(self.overclosing_per_loop)
            ),
            "malytcheff": self.malytcheff,
            "kutzbach": self.kutzbach,
            "kolchin_parameter": self.kolchin_parameter,
            "mobility": self.mobility,
            "mechanism_class": self.uniform_general_constraints,
            "classification": self.classification,
            "kolchin_group": self.kolchin_group,
        }


def _pairs_by_class_arg(arg: Mapping[int, int] | Sequence[int]) -> tuple[int, ...]:
    if isinstance(arg, Mapping):
        out = [0] * 5
        for cls, n in arg.items():
            c = check_count(cls, "pair class i")
            if not 1 <= c <= 5:
                raise MobilityInputError(
                    f"pair class i must be 1…5 (a class-i pair allows i freedoms); got {cls!r}"
                )
            out[c - 1] += check_count(n, f"number of class-{c} pairs N{c}")
        return tuple(out)
    seq = list(arg)
    if len(seq) > 5:
        raise MobilityInputError(
            f"pairs_by_class lists N_1…N_5 (at most 5 numbers); got {len(seq)}: {seq!r}"
        )
    return tuple(check_count(n, f"number of class-{i} pairs N{i}") for i, n in
                 enumerate(seq, 1)) + (0,) * (5 - len(seq))


def _one_loop_constraints(value: GeneralConstraintsArg, where: str) -> tuple[int, str | None]:
    if isinstance(value, str | GeneralConstraints):
        gc = general_constraints(value)
        m, note = gc.count, gc.notation
    else:
        m, note = check_count(value, f"general constraints m {where}"), None
    if m > MAX_GENERAL_CONSTRAINTS:
        raise MobilityInputError(
            f"general constraints m {where} must be 0…{MAX_GENERAL_CONSTRAINTS}; got {m} "
            "(m = 6 would leave no motion; Bagci, Appendix B)"
        )
    return m, note


def _per_loop_constraints(general_constraints: GeneralConstraintsArg
                          | Sequence[GeneralConstraintsArg], k: int) -> list[tuple[int, str | None]]:
    """(m_j, notation) for each of the k loops, from one value for all or one per loop (B.5)."""
    if isinstance(general_constraints, str | GeneralConstraints) or not isinstance(
        general_constraints, Iterable
    ):
        m, note = _one_loop_constraints(general_constraints, "of every loop")
        if k == 0 and m:
            raise MobilityInputError(
                f"general constraints m = {m} given, but the mechanism has no loop (k = 0 by "
                "eq. B.3): an open chain has no general constraints"
            )
        return [(m, note)] * k
    entries = list(general_constraints)
    if len(entries) != k:
        raise MobilityInputError(
            f"{len(entries)} per-loop general constraints given for k = {k} loops "
            "(eq. B.3); give one entry per loop or a single m for all"
        )
    return [_one_loop_constraints(v, f"of loop {j + 1}") for j, v in enumerate(entries)]


def _overclosing(overclosing_constraints: int | Sequence[int], k: int
                 ) -> tuple[int, tuple[int, ...] | None]:
    """F_c and the per-loop q_j (None when F_c was given as one number)."""
    q: tuple[int, ...] | None
    if not isinstance(overclosing_constraints, Iterable):
        fc, q = check_count(overclosing_constraints, "overclosing constraints F_c"), None
    else:
        q = tuple(check_count(x, f"overclosing constraints q_{j + 1}")
                  for j, x in enumerate(overclosing_constraints))
        if len(q) != k:
            raise MobilityInputError(
                f"{len(q)} per-loop overclosing constraints q_j given for k = {k} loops"
            )
        fc = sum(q)
    if fc and k < 2:
        raise MobilityInputError(
            f"overclosing constraints F_c = {fc} need a multi-loop mechanism (Bagci, Appendix "
            f"B); this one has k = {k} loop(s)"
        )
    return fc, q


def formula_mobility(
    n_links: int,
    pairs: PairsArg | None = None,
    *,
    pairs_by_class: Mapping[int, int] | Sequence[int] | None = None,
    loops: int | None = None,
    general_constraints: GeneralConstraintsArg | Sequence[GeneralConstraintsArg] = 0,
    passive_freedoms: int = 0,
    overclosing_constraints: int | Sequence[int] = 0,
    name: str | None = None,
) -> FormulaMobility:
    """Mobility of a mechanism by Kolchin's formula F = F0 + M − F_p + F_c, Bagci eq. (B.8).

    Parameters
    ----------
    n_links:
        n, all links including the fixed one.
    pairs:
        The pairs by kind: a compact string (``"RSRC"``, ``"RS_sRC"``, ``"4R"``), a sequence
        of names, or ``{name: count}``. Give either this or ``pairs_by_class``.
    pairs_by_class:
        N_1…N_5 as ``{class: count}`` or a sequence ``(N_1, N_2, …)``.
    loops:
        k. If omitted it follows from eq. (B.3), (n − 1) + k = Σ N_i; if given it must agree.
    general_constraints:
        m for every loop (one int, or one notation such as ``"m(110,001)"``), or one entry per
        loop (int or notation), m_j = 0…5. M = Σ m_j (B.5).
    passive_freedoms:
        F_p = Σ f_i, pair freedoms idled by the geometry (B.6).
    overclosing_constraints:
        F_c, or the per-loop q_j (F_c = Σ q_j). Overclosing needs at least two loops.
    name:
        Label for :meth:`FormulaMobility.describe`.
    """
    if (pairs is None) == (pairs_by_class is None):
        raise MobilityInputError(
            "give the pairs either by kind (pairs='RSRC' or {'R': 2, ...}) or by class "
            "(pairs_by_class={1: 2, 2: 1, 3: 1}), not both and not neither"
        )
    if pairs is not None:
        by_class, by_kind = count_pairs_by_class(pairs)
        kinds = tuple(by_kind.items())
    else:
        assert pairs_by_class is not None
        by_class, kinds = _pairs_by_class_arg(pairs_by_class), ()
    n = check_count(n_links, "number of links n", minimum=2)
    k = loop_count(n, sum(by_class))
    if loops is not None and check_count(loops, "number of loops k") != k:
        raise MobilityInputError(
            f"loops k = {loops} contradicts Bagci eq. (B.3), (n − 1) + k = Σ N_i: n = {n} "
            f"links and Σ N_i = {sum(by_class)} pairs give k = {k}; check the link and pair "
            "counts"
        )

    per_loop = _per_loop_constraints(general_constraints, k)
    freedoms = sum(i * c for i, c in enumerate(by_class, 1))
    fp = check_count(passive_freedoms, "passive freedoms F_p")
    if fp > freedoms:
        raise MobilityInputError(
            f"passive freedoms F_p = {fp} exceed the {freedoms} freedoms of all the pairs"
        )
    fc, q = _overclosing(overclosing_constraints, k)

    return FormulaMobility(
        n_links=n,
        loops=k,
        pairs_by_class=by_class,  # type: ignore[arg-type]
        pair_kinds=kinds,
        general_constraints=tuple(m for m, _ in per_loop),
        general_constraint_notation=tuple(note for _, note in per_loop),
        passive_freedoms=fp,
        overclosing_constraints=fc,
        overclosing_per_loop=q,
        name=name,
    )


def planar_mobility(
    n_links: int,
    pairs: PairsArg | None = None,
    *,
    pairs_by_class: Mapping[int, int] | Sequence[int] | None = None,
    loops: int | None = None,
    passive_freedoms: int = 0,
    overclosing_constraints: int | Sequence[int] = 0,
    name: str | None = None,
) -> FormulaMobility:
    """Plane mechanism: :func:`formula_mobility` with m(110,001) = 3 in every loop (b = 3).

    Pairs keep their spatial class: R and P are class 1; a cam or gear contact is a cylinder on
    a plane (class 4) whose two out-of-plane freedoms are passive (add 2 to F_p each). This
    reproduces Grübler's 3(n − 1) − 2 j_1 − j_2.
    """
    return formula_mobility(
        n_links, pairs, pairs_by_class=pairs_by_class, loops=loops, general_constraints=PLANE,
        passive_freedoms=passive_freedoms, overclosing_constraints=overclosing_constraints,
        name=name,
    )


def spherical_mobility(
    n_links: int,
    pairs: PairsArg | None = None,
    *,
    pairs_by_class: Mapping[int, int] | Sequence[int] | None = None,
    loops: int | None = None,
    passive_freedoms: int = 0,
    overclosing_constraints: int | Sequence[int] = 0,
    name: str | None = None,
) -> FormulaMobility:
    """Spherical mechanism: :func:`formula_mobility` with m(000,111) = 3 in every loop
    (b = 3; all pair axes through one point)."""
    return formula_mobility(
        n_links, pairs, pairs_by_class=pairs_by_class, loops=loops,
        general_constraints=SPHERICAL, passive_freedoms=passive_freedoms,
        overclosing_constraints=overclosing_constraints, name=name,
    )
