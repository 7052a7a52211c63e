"""Every assembly mode's joint variables, rates and accelerations over an input sweep, without
the links' frames and twists: the generic solver's counterpart of a closed form's bare branches
(e.g. :func:`~screwkit.kinematics.closed_forms.rsrc.rsrc_motion`), for sweeps where only the joints matter.

The modes are the generic solver's (:func:`~screwkit.kinematics.tracker.generic_motion.generic_motion`:
continuation from root searches, the same mode order and numbering), their rates and
accelerations the loop's rate equations' (:func:`~screwkit.kinematics.tracker.rates.joint_rates`: the
same values and the same singular samples as the Motion's). An S–S rod's idle spin is held at
zero as in a Motion (docs/kinematics.md, "Idle spin"), so a ball joint's rotation here is the
Motion's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.budget import check_memory
from screwkit.errors import InputError, InputTypeError, UnknownNameError, expect_number
from screwkit.kinematics.motion import AssemblyError, as_input_array, per_sample
from screwkit.kinematics.registry import family_of
from screwkit.kinematics.solve_motion import MODES_ESTIMATE, check_motion_time
from screwkit.kinematics.tracker.generic_motion import (
    Progress,
    all_branches,
    closes_nowhere,
    progress_reporter,
)
from screwkit.kinematics.tracker.loop import Array, Configuration, forward, layout
from screwkit.kinematics.tracker.mode_frames import idle_spin_held
from screwkit.kinematics.tracker.rates import joint_rates, rate_equations, spin_links
from screwkit.messages import listing
from screwkit.model.linkage import Linkage


@dataclass(frozen=True, eq=False)
class JointMotion:
    """Joint freedoms of every assembly mode k over N input samples.

    ``names`` (m,) the freedoms in loop order (the Jacobian's columns: a ball joint's
    ``<joint>.wx|wy|wz``, its body rates); ``configurations[k]`` the closed configurations of
    mode k (scalar freedoms and ball-joint rotations, where ``assembles[k]``);
    ``rates``/``accelerations`` (K, N, m) the freedoms' first and second time derivatives,
    NaN where mode k does not assemble or is ``singular`` (its rate equations have no unique
    solution there)."""

    linkage: Linkage
    inputs: Array  # (N, n_in)
    names: tuple[str, ...]
    assembles: NDArray[np.bool_]  # (K, N)
    singular: NDArray[np.bool_]  # (K, N)
    configurations: tuple[Configuration, ...]
    rates: Array
    accelerations: Array

    @property
    def modes(self) -> int:
        """How many assembly modes the sweep has."""
        return int(self.assembles.shape[0])

    def variable(self, name: str, mode: int = 0, *, derivative: int = 0) -> Array:
        """One freedom of one mode over the sweep (N,): ``derivative`` 0 its value (a scalar
        freedom: rad or m, as tracked — not unwrapped), 1 its rate, 2 its acceleration (e.g.
        ``joints.variable("output_C.s", mode=1, derivative=1)``); NaN where the mode does not
        assemble (and, for rates, where it is singular)."""
        if isinstance(mode, bool) or not isinstance(mode, int | np.integer):
            raise InputTypeError(f"mode must be an integer index 0…{self.modes - 1}; got "
                                 f"{mode!r}")
        if not 0 <= mode < self.modes:
            raise AssemblyError(
                f"{self.linkage.name}: assembly mode {mode} asked for, but the mechanism has "
                f"{self.modes} assembly mode(s) over these inputs (0…{self.modes - 1})")
        if derivative not in (0, 1, 2):
            raise InputError(f"derivative must be 0, 1 or 2; got {derivative!r}")
        if name not in self.names:
            raise UnknownNameError(f"{self.linkage.name}: no freedom {name!r}; the freedoms "
                                   f"are {listing(self.names)}")
        f = self.names.index(name)
        if derivative:
            return np.asarray((self.rates, self.accelerations)[derivative - 1][mode][:, f])
        col = layout(self.linkage).scalar_col[f]
        if col < 0:
            raise InputError(f"{name} is a ball joint's body rate: it has rates but no value "
                             "of its own (the joint's rotation is configurations[mode]"
                             ".spherical)")
        return np.where(self.assembles[mode], self.configurations[mode].scalars[:, col],
                        np.nan)


def solve_joints(
    linkage: Linkage,
    inputs: ArrayLike,
    *,
    rates: ArrayLike = 1.0,
    accelerations: ArrayLike = 0.0,
    starts: int = 48,
    seed: int = 0,
    progress: Progress | bool | None = None,
) -> JointMotion:
    """Every assembly mode's joint variables, rates and accelerations over an input sweep of any
    single loop, by the generic solver (docs/kinematics.md, "Joints only"), without the links'
    frames and twists: for long sweeps where only the joints matter. SI units and radians;
    arguments as :func:`~screwkit.kinematics.solve_motion.solve_motion`'s. The modes are the
    generic solver's, in its order (``solve_motion`` renumbers them as a closed form's)."""
    expect_number(starts, "starts", integer=True, positive=True)
    expect_number(seed, "seed", integer=True)
    X = as_input_array(linkage, inputs, "inputs")  # checks the linkage's type first
    lay = layout(linkage)
    N = X.shape[0]
    m = len(lay.names)
    per_mode_sample = 8 * (lay.n_scalar + 9 * lay.n_spherical + 2 * m + 2)
    check_memory(3.0 * per_mode_sample * (family_of(linkage).max_modes or MODES_ESTIMATE) * N,
                 f"the joint motion of {N} samples", "use fewer input samples")
    # the root searches are the generic Motion's; the per-sample cost is a fraction of it
    seconds = check_motion_time(linkage, N, family_of(linkage).max_modes or MODES_ESTIMATE,
                                generic=True, closed=False)
    Xd = per_sample(linkage, rates, "rates", X)
    Xdd = per_sample(linkage, accelerations, "accelerations", X)
    with progress_reporter(progress, N, seconds=seconds) as report:
        tracks = all_branches(linkage, lay, X, starts, seed, report, (Xd, Xdd))
    if not tracks:
        raise closes_nowhere(linkage, X)
    rods = bool(spin_links(linkage))
    confs: list[Configuration] = []
    velocities: list[Array] = []
    accs: list[Array] = []
    singular: list[NDArray[np.bool_]] = []
    for tr in tracks:
        conf, mask = tr.configuration(), tr.mask
        if tr.rates is not None:  # found by the tracker at the configurations it accepted
            qd, qdd, sing = tr.rates.qd, tr.rates.qdd, tr.rates.singular
            known = mask & tr.rates.known
            qd[~mask], qdd[~mask], sing[~mask] = np.nan, np.nan, False
        else:
            m = len(lay.names)
            qd, qdd = np.full((N, m), np.nan), np.full((N, m), np.nan)
            sing, known = np.zeros(N, dtype=bool), np.zeros(N, dtype=bool)
        if rods:  # every rate anew: the poses are turned to hold the rods' idle spin
            fr = forward(linkage, conf, lay)
            eq = rate_equations(linkage, lay, fr, mask, exact_sigma=False)
            conf, fr, eq = idle_spin_held(linkage, lay, conf, mask, X, fr, eq)
            jr = joint_rates(linkage, lay, eq, mask, Xd, Xdd)
            qd, qdd, sing = jr.qd, jr.qdd, jr.singular
        elif not known.all():  # the samples the tracker corrected by Newton or did not reach
            rest = np.nonzero(~known)[0]
            fr = forward(linkage, conf.take(rest), lay, frames=False)
            eq = rate_equations(linkage, lay, fr, mask[rest], exact_sigma=False)
            jr = joint_rates(linkage, lay, eq, mask[rest], Xd[rest], Xdd[rest])
            qd[rest], qdd[rest], sing[rest] = jr.qd, jr.qdd, jr.singular
        confs.append(conf)
        velocities.append(qd)
        accs.append(qdd)
        singular.append(sing & mask)
    return JointMotion(linkage, X, lay.names, np.stack([tr.mask for tr in tracks]),
                       np.stack(singular), tuple(confs), np.stack(velocities), np.stack(accs))


__all__ = ["JointMotion", "solve_joints"]
