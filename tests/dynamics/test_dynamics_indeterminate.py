"""What the rigid joint model cannot determine is detected and reported."""

from __future__ import annotations

import numpy as np
from mechanisms import ROD, full_cycle

from screwkit.dynamics import inverse_dynamics
from screwkit.model.linkage import Link
from screwkit.model.mass import MassProperties


def test_planar_fourbar_has_three_indeterminate_components_and_min_norm_reactions() -> None:
    linkage, _, mode = full_cycle("fourbar", 0)
    dyn = inverse_dynamics(linkage, mode)
    info = dyn.indeterminacy
    assert info.count == 3 and info.idle_freedoms == 0
    # the self-stresses: force along the joint axes (world z) and moments in the plane
    d = info.directions
    assert np.allclose(d[:, :2], 0.0, atol=1e-12)
    assert np.linalg.matrix_rank(np.c_[d[:, 2], d[:, 3:5]], tol=1e-9) == 3
    assert np.allclose(d[:, 5], 0.0, atol=1e-12)
    assert "3 reaction component(s) statically indeterminate" in info.describe()
    # minimum norm: adding any self-stress to every joint raises Σ|f|² + |m/ℓ|²
    ell = linkage.length_scale

    def norm2(extra: np.ndarray) -> np.ndarray:
        total = np.zeros(mode.assembles.size)
        for k, r in enumerate(dyn.reactions.values()):
            sign = -1.0 if k == len(dyn.reactions) - 1 else 1.0
            c = mode.joint_centres[:, k]
            f = r["force"] + sign * extra[:3]
            m = r["moment"] + sign * (extra[3:] - np.cross(c, extra[:3]))
            total += np.sum(f**2, -1) + np.sum(m**2, -1) / ell**2
        return total

    base = norm2(np.zeros(6))
    for direction in d:
        for step in (1e-3, -1e-3):
            assert np.all(norm2(step * direction * np.sqrt(base.mean())) > base)


def test_ss_rod_is_an_idle_freedom_and_axial_inertia_is_reported_as_residual() -> None:
    linkage, _, mode = full_cycle("cssp", 0)
    line_mass = inverse_dynamics(linkage, mode)
    assert line_mass.indeterminacy.count == 0 and line_mass.indeterminacy.idle_freedoms == 1
    assert np.max(line_mass.relative_residual) < 1e-12
    k, _ = ROD["cssp"]
    rod = linkage.links[k].mass
    links = list(linkage.links)
    # an axisymmetric solid rod (axial moment > 0): with the kinematics' zero-spin rule
    # (ω·u = 0, hence α·u = 0) its axial inertia does no work, so the balance still closes
    solid = MassProperties(rod.mass, rod.com, rod.inertia + np.diag([0.2 * rod.inertia[1, 1], 0, 0]))
    links[k] = Link(links[k].name, solid)
    assert np.max(inverse_dynamics(linkage.with_links(links), mode).relative_residual) < 1e-10
    # a rod that is not axisymmetric needs a torque about its own axis that two ball joints
    # cannot supply: the inconsistency is reported as a residual, not hidden
    flat = MassProperties(rod.mass, rod.com, rod.inertia + np.diag([0.2 * rod.inertia[1, 1], 0.1 * rod.inertia[1, 1], 0]))
    links[k] = Link(links[k].name, flat)
    assert np.max(inverse_dynamics(linkage.with_links(links), mode).relative_residual) > 1e-4


def test_rsrc_and_rccc_are_determinate() -> None:
    for family in ("rsrc", "rccc"):
        linkage, _, mode = full_cycle(family, 0)
        info = inverse_dynamics(linkage, mode).indeterminacy
        assert (info.count, info.idle_freedoms) == (0, 0), family
        assert info.describe() == "statically determinate"
