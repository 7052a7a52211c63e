"""Mechanism closures written as polynomial systems F(x; p) = 0 (issue 27).

Each formulation compiles one :class:`~screwkit.algebraic.polynomial.PolynomialSystem` per
topology; the geometry (and, for loops at one input value, the input) are its parameters p, so one
compiled system serves every instance of the topology and a parameter homotopy can move between
instances (Sommese & Wampler 2005, ch. 7). Every formulation is chosen so that the physical
instances are generic members of its parameter family (the parameters are free: any complex
value is an instance with the same number of isolated solutions), which is what a parameter
homotopy started at a random complex instance needs to find every solution.

- :mod:`.stewart`: 6-6 Stewart–Gough forward kinematics in Study coordinates (40 solutions);
  solved by an elimination template (:mod:`.stewart_template`, a 526 × 526 block-triangular
  solve and a 40 × 40 action matrix) with the homotopy as the fallback (:mod:`.stewart_solve`);
- :mod:`.delta`: a Delta robot read from its graph: plate positions (three spheres), leg
  branches, every plate pose by the Stewart system with the elbow balls as base points;
- :mod:`.loop6r`: a 6R loop, the inverse kinematics of a 6R arm (:mod:`.arm6r`), a 7R loop at
  one input (16); solved by elimination (:mod:`.sixr_elimination`, a 24 × 24 eigenproblem)
  with the homotopy as the fallback (:mod:`.loop6r_solve`); :mod:`.eigen_first`: the polish,
  α-test, relabelling and fallback that both eigen routes share;
- :mod:`.planar`: planar R-joint mechanisms as graphs (distance equations; 4R: 2, Stephenson III: 6);
- :mod:`.rod_loops`: the RSSR (2) and RSRC (4) loops at one input;
- :mod:`.rccc`: the RCCC loop at one input, in Plücker coordinates (2);
- :mod:`.r_loop`: a Mechanism's single R loop (6R, 7R at one input) as a 6R instance;
- :mod:`.rpc_quadrics`: a single loop of R, P and C joints with six free freedoms as quadrics
  in its joint axes (5R1P 16, 4R2P 8, 3R3P 2, C loops measured); :mod:`.rpc_loop`: such a loop
  of a Mechanism (U joints as two R joints), relabelled cyclically, its generic counts and
  start solutions;
  :mod:`.general_loop`: the same loop in joint cosines and sines (its reading and way back,
  and the independent check);
- :mod:`.starts`: start solutions per topology, kept on disk by :mod:`.start_store`;
  :mod:`.continuum`: a continuum told from
  isolated roots at a singular end point.
- :mod:`.every_mode`: every real mode of a Mechanism at given inputs; :mod:`.along`: every mode
  over a motion (the homotopy at anchor samples, the graph tracker between them).
"""
