"""Any mechanism as a graph: the stacked closure of its loop basis, continuation of the drawn
mode, and the motion of every body (docs/mechanisms.md)."""

from screwkit.kinematics.graph.motion import MechanismMode, MechanismMotion, solve_mechanism

__all__ = ["MechanismMode", "MechanismMotion", "solve_mechanism"]
