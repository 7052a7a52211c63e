"""Any mechanism as a graph: the stacked closure of its loop basis, closed-form sub-chains (every
mode of a mechanism built of planar dyads), continuation of the drawn mode otherwise, and the
motion of every body (docs/mechanisms.md)."""

from screwkit.kinematics.graph.motion import MechanismMode, MechanismMotion, solve_mechanism

__all__ = ["MechanismMode", "MechanismMotion", "solve_mechanism"]
