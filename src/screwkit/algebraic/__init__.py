"""Polynomial systems and the homotopy continuation that finds all their isolated solutions.

This package knows nothing of mechanisms (docs/kinematics.md, "How every mode is found"):

- :mod:`.polynomial`: sparse polynomial systems with parameters, evaluated batched;
- :mod:`.track` (with :mod:`.path` and :mod:`.endgame`): the parameter homotopy
  ``track_parameter_homotopy``, its Cauchy endgame and path-jump check;
- :mod:`.total_degree`: ``solve_total_degree``, the first solve of a small system;
- :mod:`.multi_homogeneous`: ``solve_multi_homogeneous``, the first solve from a linear-product
  start system when a grouping of the unknowns has a smaller Bézout number;
- :mod:`.monodromy`: ``monodromy_solve``, every solution at a generic point from one;
- :mod:`.trace_test`: ``trace_test``, whether a set of solutions at a generic point is all;
- :mod:`.certify`: Smale's α-test, real and distinct certificates;
- :mod:`.solve`: ``solve_all`` from ``StartSolutions``.

The formulations of mechanism closures as polynomial systems live in ``screwkit.kinematics``.
"""
