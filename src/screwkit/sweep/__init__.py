"""Design-space sweeps, tolerance analysis and distributed multistart synthesis on Dask
(docs/sweeps.md).

A design is the spec with some values replaced (:mod:`screwkit.sweep.keys`); a sweep runs one
job on every design through a :class:`~screwkit.pipeline.Pipeline` and writes one row per
design (:mod:`screwkit.sweep.run`, :mod:`screwkit.sweep.table`). The engine
(:mod:`screwkit.sweep.engine`) is an embedded Dask cluster by default, or an existing
scheduler.
"""

from screwkit.sweep.designs import DesignError, DesignSet, make_designs
from screwkit.sweep.engine import EngineConfig, EngineError, start_engine
from screwkit.sweep.jobs import JOBS, JobOptions
from screwkit.sweep.run import SweepDefinition, SweepResult, define_sweep, run_sweep

__all__ = ["JOBS", "DesignError", "DesignSet", "EngineConfig", "EngineError", "JobOptions",
           "SweepDefinition", "SweepResult", "define_sweep", "make_designs", "run_sweep",
           "start_engine"]
