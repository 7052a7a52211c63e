"""Closed-form kinematics of Bagci's RSRC space four-bar (Bagci 1969, Chapter III, App. C, App. D).

One module per job:

* `dimensions` - `RSRCDimensions` (Bagci's names d1, d2, d3, a, b, e, delta0, lambda0) and the
  checks of input-angle arrays;
* `loop_equation` - the loop equation and its terms M0, N0, W1, W2 (eqs. 3.58-3.61), shared with
  the dimensional synthesis;
* `positions` - phi0, chi0 and S of every inversion (quartic 3.63 and the special cases, §3.4);
  the result layout and NaN policy are described there;
* `rates` - velocities and accelerations (eqs. 3.77-3.82) and `rsrc_kinematics` (both in one
  pass);
* `coupler_point` - coupler-point coordinates (App. C);
* `branches` - continuous assembly-mode branches over a sweep (`rsrc_motion`);
* `limits` - rotation and translation limits of the output (App. D);
* `dwell` - derivatives of phi0(theta0) of any order and the order of a dwell (App. D).

Everything is in SI units and radians, batch-first over the input angles theta0; every name
below can be imported from ``screwkit.kinematics.closed_forms.rsrc``.
"""

from screwkit.kinematics.closed_forms.rsrc.branches import BranchEvent, RSRCMotion, rsrc_motion
from screwkit.kinematics.closed_forms.rsrc.coupler_point import RSRCCouplerPoint, rsrc_coupler_point
from screwkit.kinematics.closed_forms.rsrc.dimensions import SPECIAL_ANGLE_TOL, RSRCDimensions
from screwkit.kinematics.closed_forms.rsrc.dwell import (
    dwell_order,
    rsrc_dwell_order,
    rsrc_output_derivatives,
)
from screwkit.kinematics.closed_forms.rsrc.limits import (
    LimitPosition,
    rsrc_rotation_limits,
    rsrc_translation_limits,
)
from screwkit.kinematics.closed_forms.rsrc.positions import RSRCPositions, rsrc_positions
from screwkit.kinematics.closed_forms.rsrc.rates import (
    LOCK_TOL,
    RSRCRates,
    rsrc_kinematics,
    rsrc_rates,
)

__all__ = [
    "LOCK_TOL",
    "SPECIAL_ANGLE_TOL",
    "BranchEvent",
    "LimitPosition",
    "RSRCCouplerPoint",
    "RSRCDimensions",
    "RSRCMotion",
    "RSRCPositions",
    "RSRCRates",
    "dwell_order",
    "rsrc_coupler_point",
    "rsrc_dwell_order",
    "rsrc_kinematics",
    "rsrc_motion",
    "rsrc_output_derivatives",
    "rsrc_positions",
    "rsrc_rates",
    "rsrc_rotation_limits",
    "rsrc_translation_limits",
]
