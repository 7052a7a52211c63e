"""screwkit — analysis, synthesis and dynamic balancing of spatial linkages with dual-number
screw calculus.

Layers (imports go down only): :mod:`screwkit.dual` → :mod:`screwkit.model` →
:mod:`screwkit.kinematics` → :mod:`screwkit.mobility`, :mod:`screwkit.dynamics` → ... →
:mod:`screwkit.io`, :mod:`screwkit.cli`.
"""

__version__ = "0.1.0"
