"""Formula mobility against numeric mobility, with the reason for any difference.

The count of Bagci's eq. (B.8) knows the geometry only through the terms the user supplies
(M, F_p, F_c). The loop Jacobian knows the geometry exactly but only at one configuration.
With the same pairs and loops, F0 is the same on both sides and

    numeric F − F0 = 6k − rank = redundant constraints,
    formula F − F0 = H = M − F_p + F_c (Kolchin's parameter, B.10),

so the difference of the two mobilities is the redundant constraints the formula did not
account for (positive: overconstrained by geometry the formula ignored; negative: the formula
assumed special geometry that the configuration does not have, or the configuration is
singular).
"""

from __future__ import annotations

from dataclasses import dataclass

from screwkit.mobility.formula import FormulaMobility
from screwkit.mobility.numeric import NumericMobility


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if abs(n) == 1 else "s")


@dataclass(frozen=True, eq=False)
class MobilityComparison:
    """Result of :func:`compare_mobility`."""

    formula: FormulaMobility
    numeric: NumericMobility
    explanation: tuple[str, ...]
    name: str | None = None

    @property
    def difference(self) -> int:
        """numeric F − formula F."""
        return self.numeric.mobility - self.formula.mobility

    @property
    def agree(self) -> bool:
        return self.difference == 0

    def describe(self) -> str:
        return "\n".join(
            [self.explanation[0], *("  " + line for line in self.explanation[1:])]
        )

    def as_dict(self) -> dict[str, object]:
        return {
            "name": self.name,
            "formula_mobility": self.formula.mobility,
            "numeric_mobility": self.numeric.mobility,
            "difference": self.difference,
            "agree": self.agree,
            "explanation": list(self.explanation),
            "formula": self.formula.as_dict(),
            "numeric": self.numeric.as_dict(),
        }


def compare_mobility(
    formula: FormulaMobility, numeric: NumericMobility, name: str | None = None
) -> MobilityComparison:
    """Explain the difference between a formula count and the Jacobian's mobility.

    Example: a Bennett loop counted by Malytcheff alone gives "Bennett: formula gives -2, the
    loop moves with 1: 3 redundant constraints (overconstrained)".
    """
    label = name or formula.name or "mechanism"
    f_formula, f_numeric = formula.mobility, numeric.mobility
    redundant = numeric.redundant_constraints
    h = formula.kolchin_parameter
    what = "the loop" if numeric.loops == 1 else "the mechanism"
    head = f"{label}: formula gives {f_formula}, {what} moves with {f_numeric}"
    lines: list[str] = []

    same_chain = (
        formula.freedom_count == numeric.freedom_count and formula.loops == numeric.loops
    )
    if not same_chain:
        lines.append(
            f"the formula counts {formula.freedom_count} pair freedoms in {formula.loops} "
            f"loop(s), the Jacobian has {numeric.freedom_count} columns in {numeric.loops} loop "
            "block(s): they do not describe the same chain, so F0 differs "
            f"({formula.malytcheff} vs {numeric.malytcheff})"
        )

    if f_formula == f_numeric:
        head += " (agree)"
        if redundant:
            lines.append(
                f"{_plural(redundant, 'redundant constraint')} (6k − rank), matched by the "
                f"formula's H = M − F_p + F_c = {h}"
            )
    elif same_chain and h == 0 and redundant > 0:
        head += f": {_plural(redundant, 'redundant constraint')} (overconstrained)"
    elif same_chain:
        unaccounted = redundant - h
        if unaccounted > 0:
            lines.append(
                f"{_plural(redundant, 'redundant constraint')} (6k − rank) but the formula "
                f"accounts for H = M − F_p + F_c = {h}: {unaccounted} more from geometry the "
                "formula did not include (overconstrained)"
            )
        else:
            lines.append(
                f"the formula assumes H = M − F_p + F_c = {h} but the Jacobian shows only "
                f"{_plural(redundant, 'redundant constraint')}: this configuration lacks the "
                "special geometry (parallel, concurrent or symmetric axes) the formula "
                "assumed"
            )

    if f_formula != f_numeric or formula.total_general_constraints or redundant:
        lines.append(
            "terms formula / Jacobian: "
            f"F0 {formula.malytcheff} / {numeric.malytcheff}, "
            f"M {formula.total_general_constraints} / {numeric.total_general_constraints}, "
            f"F_p {formula.passive_freedoms} / -, "
            f"F_c {formula.overclosing_constraints} / {numeric.overclosing_constraints}"
        )
        if numeric.total_general_constraints:
            lines.append(
                "general constraints in the Jacobian: "
                + "; ".join(f"loop {lc.loop} {lc.general}" for lc in numeric.loop_constraints)
            )
    if formula.passive_freedoms:
        lines.append(
            f"the formula's F_p = {formula.passive_freedoms} passive freedom(s) are idle over "
            "the finite motion; at one configuration their screws still count, so the Jacobian "
            "shows them as fewer general constraints (they cancel in F)"
        )
    if numeric.locked_freedoms:
        lines.append(
            "stationary at this configuration (no instantaneous motion moves them): "
            + ", ".join(numeric.locked_freedoms)
        )
    if numeric.redundant_freedoms:
        lines.append(
            f"{_plural(numeric.redundant_freedoms, 'redundant freedom')} moving neither inputs "
            f"nor outputs ({', '.join(numeric.redundant_involves or ())}): counted in F, as in "
            "Bagci's R-S-S-R"
        )
    elif numeric.undetermined_motions:
        lines.append(
            f"the inputs leave {numeric.undetermined_motions} motion(s) free, involving "
            + ", ".join(numeric.undetermined_involves or ())
        )
    if f_numeric > f_formula:
        lines.append(
            "the Jacobian gives the instantaneous mobility: at a singular configuration it "
            "exceeds the finite mobility, so check a second configuration"
        )
    return MobilityComparison(formula, numeric, (head, *lines), name=label)
