"""Dimensional synthesis of the RSRC (and its plane 4R case) for screw generation.

Bagci 1969, Chapters IV-V: least-squares fit of a desired screw displacement
psi_d(theta) = psi_d0(theta) + eps S_d(theta) with exact derivatives (App. E), constraints for
dwells and exact ranges through the parameters of constraint q1, q2 (eqs. 5.13-5.21) or as
equality constraints, multi-start over starts and assembly modes, and the overlay technique (§5.4) as a route of
its own (`synthesize_overlay`).
See docs/synthesis.md.
"""

from screwkit.synthesis.constraints import output_crank_from_constraints, q_from_dwell
from screwkit.synthesis.equality_constrained import RangeConstraint, synthesize_equality_constrained
from screwkit.synthesis.expressions import ExpressionError, parse_expression
from screwkit.synthesis.overlay import (
    OverlayCircle,
    OverlayDwell,
    OverlayResult,
    ellipse_curvature_radius,
    fit_overlay_circles,
    overlay_fit,
)
from screwkit.synthesis.overlay_synthesis import OverlayOutcome, OverlayProblem, synthesize_overlay
from screwkit.synthesis.problem import (
    ConstraintConstruction,
    ConstraintPoint,
    RSRCSynthesisProblem,
)
from screwkit.synthesis.residuals import NotAssembled, ResidualModel
from screwkit.synthesis.solve import (
    RangeCheck,
    SynthesisError,
    SynthesisResult,
    check_range,
    evaluate_design,
    synthesize,
    synthesize_multistart,
)
from screwkit.synthesis.targets import LIBRARY, ScrewTarget, data_function, library_function

__all__ = [
    "LIBRARY",
    "ConstraintConstruction",
    "ConstraintPoint",
    "ExpressionError",
    "NotAssembled",
    "OverlayCircle",
    "OverlayDwell",
    "OverlayOutcome",
    "OverlayProblem",
    "OverlayResult",
    "RSRCSynthesisProblem",
    "RangeCheck",
    "RangeConstraint",
    "ResidualModel",
    "ScrewTarget",
    "SynthesisError",
    "SynthesisResult",
    "check_range",
    "data_function",
    "ellipse_curvature_radius",
    "evaluate_design",
    "fit_overlay_circles",
    "library_function",
    "output_crank_from_constraints",
    "overlay_fit",
    "parse_expression",
    "q_from_dwell",
    "synthesize",
    "synthesize_equality_constrained",
    "synthesize_multistart",
    "synthesize_overlay",
]
