"""Former name of `screwkit.synthesis.overlay_synthesis` (the overlay technique as a synthesis
route, Bagci 1969 §5.4); kept so that existing imports keep working.  Import from
`screwkit.synthesis.overlay_synthesis` in new code."""

from screwkit.synthesis.overlay_synthesis import OverlayOutcome, OverlayProblem, synthesize_overlay

__all__ = ["OverlayOutcome", "OverlayProblem", "synthesize_overlay"]
