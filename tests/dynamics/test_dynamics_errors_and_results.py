"""Bad input gives specific errors; results serialise to JSON."""

from __future__ import annotations

import json
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from mechanisms import full_cycle

from screwkit.dynamics import (
    DynamicsInputError,
    ExternalLoad,
    MissingMassError,
    NonAssemblingMotionError,
    inverse_dynamics,
    regressor,
)
from screwkit.model.linkage import Link
from screwkit.model.mass import PhysicalConsistencyError


def test_missing_mass_names_the_link() -> None:
    linkage, _, mode = full_cycle("fourbar", 0)
    links = list(linkage.links)
    links[1] = Link(links[1].name)
    with pytest.raises(MissingMassError, match="link 'coupler'"):
        inverse_dynamics(linkage.with_links(links), mode)


def test_impossible_inertia_names_the_link() -> None:
    linkage, _, mode = full_cycle("fourbar", 0)
    links = list(linkage.links)
    fake = SimpleNamespace(mass=1.0, com=np.zeros(3), inertia=np.diag([1.0, 0.1, 0.1]))
    links[2] = Link(links[2].name, fake)
    with pytest.raises(PhysicalConsistencyError, match="(?s)link .rocker.*triangle inequality"):
        inverse_dynamics(linkage.with_links(links), mode)


def test_non_assembling_samples_are_named_by_their_inputs() -> None:
    linkage, motion, mode = full_cycle("fourbar", 0)
    bad = mode.assembles.copy()
    bad[[3, 4]] = False
    broken = replace(mode, assembles=bad)
    with pytest.raises(NonAssemblingMotionError, match=r"2 of 24 samples: #3 \(input.theta = 45 deg\)"):
        inverse_dynamics(linkage, broken, inputs=motion.inputs)
    partial = inverse_dynamics(linkage, broken, inputs=motion.inputs, allow_partial=True)
    assert np.all(np.isnan(partial.shaking_force[[3, 4]]))
    assert np.all(np.isfinite(partial.shaking_force[bad]))
    out = json.loads(json.dumps(partial.as_dict()))
    assert out["shaking_force"][3] is None and out["reactions"]["input"]["force"][4] is None
    assert out["efforts"]["input.theta"][5] is not None
    # the document's array form (issue 30: built column by column, no float per value) writes
    # the same JSON, a non-assembling vector sample as one null
    from screwkit.io.results import dumps_bytes

    arrays = json.loads(dumps_bytes(partial.as_dict(arrays=True)))
    assert arrays == json.loads(dumps_bytes(partial.as_dict()))
    full = inverse_dynamics(linkage, mode, inputs=motion.inputs)
    assert isinstance(full.as_dict(arrays=True)["shaking_force"], np.ndarray)
    assert json.loads(dumps_bytes(full.as_dict(arrays=True))) == json.loads(json.dumps(full.as_dict()))


def test_other_bad_input() -> None:
    linkage, _, mode = full_cycle("fourbar", 0)
    with pytest.raises(DynamicsInputError, match="gravity must be a finite 3-vector"):
        inverse_dynamics(linkage, mode, gravity=[0.0, -9.81])
    with pytest.raises(DynamicsInputError, match="no such moving link"):
        inverse_dynamics(linkage, mode, external_loads={"frame": ExternalLoad()})
    with pytest.raises(DynamicsInputError, match="length 30"):
        regressor(linkage, mode).apply(np.ones(7))
    other, _, other_mode = full_cycle("cssp", 0)
    with pytest.raises(DynamicsInputError, match="does not carry joint"):
        inverse_dynamics(linkage, replace(other_mode, joint_axes=mode.joint_axes[:, :4] * 0 + [1, 0, 0]))


def test_summary_and_dict() -> None:
    linkage, _, mode = full_cycle("rsrc", 0)
    dyn = inverse_dynamics(linkage, mode, gravity=[0, 0, -9.81])
    summary = dyn.summary()
    f = summary["shaking_force"]
    assert 0 < f["rms"] <= f["peak"]
    assert f["peak"] == pytest.approx(np.max(np.linalg.norm(dyn.shaking_force, axis=-1)))
    assert {"input.force", "output_C.moment", "effort input.theta"} <= set(summary)
    d = json.loads(json.dumps(dyn.as_dict()))
    assert len(d["shaking_moment"]) == mode.assembles.size
    assert d["indeterminacy"]["count"] == 0
