"""Forward dynamics of a one-degree-of-freedom loop driven by a motor: the reduced equation of
motion in the input coordinate (:mod:`screwkit.simulation.reduced`), the drive (motor, flywheel,
load; :mod:`screwkit.simulation.drive`), the integration (:mod:`screwkit.simulation.integrate`),
flywheel sizing (:mod:`screwkit.simulation.flywheel`) and a MuJoCo model writer
(:mod:`screwkit.simulation.mjcf`). docs/simulation.md."""
