"""Polynomial systems and the homotopy continuation that finds all their isolated solutions.

This package knows nothing of mechanisms: :mod:`.polynomial` holds sparse polynomial systems with
parameters, evaluated batched over many points; the formulations of mechanism closures as
polynomial systems live in ``screwkit.kinematics``.
"""
