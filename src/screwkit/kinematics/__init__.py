"""Position, velocity and acceleration analysis, in folders by job:

* ``closed_forms/`` — the families' closed forms (the RSRC quartic and ``rsrc/``, the planar 4R,
  the RSSR, the RCCC, the CSSP) and the Motion they build;
* ``tracker/`` — the generic single-loop solver: the loop-closure map (``loop.py``), Newton, the
  continuation tracker and its fill, the motion build, rates, idle spins, singular samples;
* ``graph/`` — any mechanism as a graph: the stacked closure of its loop basis, the drawn mode's
  continuation, topology and redundancy;
* ``analysis/`` — what is computed on a solved motion: coupler curves, transmission, limit
  positions and dwells, sensitivities, loop mobility;
* here: ``solve_motion`` (the front door), ``Motion``, its table, and the family registry.
"""
