"""Family constructors with the seeds' parameter names.

Each returns a general :class:`~screwkit.model.Linkage`, so the generic solver, dynamics and
mobility work on it; the closed forms of :mod:`screwkit.kinematics` are registered per family
and checked against the generic solver in the tests.

The parameter sketch of each family is a module constant (``RSRC_SKETCH`` …), shown by
``docs/families.md`` and the family registry.
"""

from __future__ import annotations

import numbers

import numpy as np

from screwkit.dual import ScrewMatrix
from screwkit.dual.spatial import rot_y
from screwkit.model.joints import Joint
from screwkit.model.linkage import Link, Linkage, LinkageError

RSRC_SKETCH = """RSRC (Bagci 1969, Fig. 5 as rebuilt in the reference spec §3.1):

        Z                      output (C) axis u3 = (cos λ0, 0, −sin λ0) through O3 = (b, a, 0)
        |   sphere O1          output crank d3 ⟂ u3, turned φ0 about u3, slides S along −u3
        |  /  coupler d2 ── R axis (skew δ0 to u3, offset e) ── output crank d3
        | / d1 (θ0 from +Y about +X)
        O──────────── Y        fixed link a along +Y, input crank plane X = 0, offset b along X
       /
      X  (input R axis)"""

CSSP_SKETCH = """CSSP (Rahman 1996 §1): crank a1 about z1 with offset s1 (C joint; s1 constant or a
second input), rod a2 between two balls, slider on the axis k4 = (0, sin α4, cos α4) at distance
a4 from z1 — Hartenberg–Denavit form M1 L2 L3 M4 = I."""

FOURBAR_SKETCH = """Planar 4R (Bagci's special case): frame a (input pivot → output pivot), crank d1,
coupler d2, rocker d3; the world x axis is the line of centres, θ0 and φ0 are measured from it."""

RSSR_SKETCH = """RSSR: the RSRC's frame geometry with ball joints at both coupler ends: input axis X,
output R axis u3 = (cos λ0, 0, −sin λ0) through (b, a, 0), crank d1, coupler d2 between the ball
centres, output crank d3 whose ball lies output_offset along u3 from the crank plane."""

RCCC_SKETCH = """RCCC (Bagci App. B, Fig. 29c): input R then three C joints, Hartenberg–Denavit links
a1…a4 with twists α1…α4; input_offset is the input joint's constant offset along its axis."""


# columns e2, e3, e1: a frame whose z axis is the x axis of the frame it is expressed in
_P = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _rt(R: np.ndarray, p: np.ndarray | list[float]) -> ScrewMatrix:
    return ScrewMatrix.from_rotation_translation(R, np.asarray(p, dtype=float))


def _number(family: str, key: str, v: object) -> None:
    """A LinkageError naming ``key`` unless ``v`` is a real number."""
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise LinkageError(f"{family}: {key} must be a number (SI units, radians); got "
                           f"{type(v).__name__} {v!r:.40}")


def _positive(name: str, family: str, **values: float) -> None:
    for key, v in values.items():
        _number(family, key, v)
        if not np.isfinite(v):
            raise LinkageError(f"{family}: {key} must be a finite number; got {v}")
        if v <= 0:
            raise LinkageError(
                f"{family}: {key} must be a positive length; got {v} "
                f"(lengths are magnitudes; directions are set by the angles)"
            )


def _finite(family: str, **values: float) -> None:
    for key, v in values.items():
        _number(family, key, v)
        if not np.isfinite(v):
            raise LinkageError(f"{family}: {key} must be a finite number; got {v}")


def rsrc(d1: float, d2: float, d3: float, a: float, b: float, e: float, delta0: float,
         lambda0: float) -> Linkage:
    """Bagci's RSRC space mechanism (input R, S, coupler R, output C), SI units and radians.

    Joint variables map to the seed's as θ0 = ``input.theta``, χ0 = ``coupler_R.theta``,
    φ0 = −``output_C.theta``, S = ``output_C.s`` (see :func:`rsrc_seed_variables`).
    """
    _positive("rsrc", "RSRC", d1=d1, d2=d2)
    _finite("RSRC", d3=d3, a=a, b=b, e=e, delta0=delta0, lambda0=lambda0)
    if d3 < 0:
        raise LinkageError(f"RSRC: d3 must be ≥ 0 (output crank length); got {d3}")
    Ry_l = rot_y(lambda0)
    L1 = _rt(np.eye(3), [d1, 0.0, 0.0])
    L2 = _rt(_P, [0.0, d2, 0.0])
    L3 = _rt(_P.T @ rot_y(delta0) @ _P, [-d3, 0.0, -e])
    R4 = _P.T @ Ry_l.T @ _P
    L4 = _rt(R4, -(_P.T @ Ry_l.T @ np.array([b, a, 0.0])))
    joints = (Joint("input", "R"), Joint("sphere", "S"), Joint("coupler_R", "R"),
              Joint("output_C", "C"))
    return Linkage(
        name="RSRC",
        joints=joints,
        link_transforms=(L1, L2, L3, L4),
        links=(Link("crank"), Link("coupler"), Link("output")),
        inputs=("input.theta",),
        base=_rt(_P, [0.0, 0.0, 0.0]),
        family="RSRC",
        parameters=dict(d1=d1, d2=d2, d3=d3, a=a, b=b, e=e, delta0=delta0, lambda0=lambda0),
    )


def rsrc_seed_variables(values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Bagci's names from the general joint variables (or their rates): θ0, φ0, S, χ0."""
    return {
        "theta0": values["input.theta"],
        "phi0": -values["output_C.theta"],
        "S": values["output_C.s"],
        "chi0": values["coupler_R.theta"],
    }


def rssr(d1: float, d2: float, d3: float, a: float, b: float, lambda0: float,
         output_offset: float = 0.0) -> Linkage:
    """R–S–S–R loop with the RSRC's frame geometry: input axis X, output R axis
    u3 = (cos λ0, 0, −sin λ0) through (b, a, 0), input crank d1, coupler d2 between the ball
    centres, output crank d3 whose ball lies ``output_offset`` along u3 from the crank plane.
    The coupler can spin about its own axis (a passive freedom)."""
    _positive("rssr", "RSSR", d1=d1, d2=d2, d3=d3)
    _finite("RSSR", a=a, b=b, lambda0=lambda0, output_offset=output_offset)
    Ry_l = rot_y(lambda0)
    L1 = _rt(np.eye(3), [d1, 0.0, 0.0])
    L2 = _rt(np.eye(3), [d2, 0.0, 0.0])
    L3 = _rt(np.eye(3), [-d3, 0.0, -output_offset])
    L4 = _rt(_P.T @ Ry_l.T @ _P, -(_P.T @ Ry_l.T @ np.array([b, a, 0.0])))
    joints = (Joint("input", "R"), Joint("ball1", "S"), Joint("ball2", "S"), Joint("output", "R"))
    return Linkage("RSSR", joints, (L1, L2, L3, L4),
                   (Link("crank"), Link("coupler"), Link("output")), ("input.theta",),
                   base=_rt(_P, [0.0, 0.0, 0.0]), family="RSSR",
                   parameters=dict(d1=d1, d2=d2, d3=d3, a=a, b=b, lambda0=lambda0,
                                   output_offset=output_offset))


def cssp(a1: float, a2: float, a4: float, alpha4: float, s1: float = 0.0,
         s1_is_input: bool = False) -> Linkage:
    """Rahman's generalised slider-crank (C–S–S–P), Hartenberg–Denavit form (Rahman §1.1):
    crank a1, rod a2, slider axis offset a4 and twist α4, crank offset s1 along z1 (a constant,
    or a second prescribed input when ``s1_is_input``)."""
    _positive("cssp", "CSSP", a1=a1, a2=a2)
    _finite("CSSP", a4=a4, alpha4=alpha4, s1=s1)
    if s1_is_input:
        j1 = Joint("crank", "C")
        inputs: tuple[str, ...] = ("crank.theta", "crank.s")
    else:
        j1 = Joint("crank", "R", offset=s1)
        inputs = ("crank.theta",)
    joints = (j1, Joint("pin", "S"), Joint("ball", "S"), Joint("slider", "P"))
    from screwkit.dual import Dual

    L1 = ScrewMatrix.rot_x(Dual(0.0, a1))
    L2 = ScrewMatrix.rot_x(Dual(0.0, a2))
    L3 = ScrewMatrix.rot_x(Dual(np.pi / 2, 0.0))
    L4 = ScrewMatrix.rot_x(Dual(alpha4, a4))
    return Linkage("CSSP", joints, (L1, L2, L3, L4),
                   (Link("crank"), Link("rod"), Link("slider")), inputs, family="CSSP",
                   parameters=dict(a1=a1, a2=a2, a4=a4, alpha4=alpha4, s1=s1))


def fourbar(a: float, d1: float, d2: float, d3: float) -> Linkage:
    """Planar 4R with Bagci's names: frame a, input crank d1, coupler d2, output crank d3.
    The world x axis runs from the input pivot to the output pivot (line of centres)."""
    _positive("fourbar", "4R", a=a, d1=d1, d2=d2, d3=d3)
    joints = (Joint("input", "R"), Joint("crank_pin", "R"), Joint("rocker_pin", "R"),
              Joint("output", "R"))
    from screwkit.dual import Dual

    # the frame link runs from the output pivot back to the input pivot and then turns by π, so
    # the ground x axis is the line of centres (input pivot → output pivot) and θ0 is measured
    # from it, as in Bagci's 4R special case (reference spec §3.4)
    transforms = tuple(ScrewMatrix.rot_x(Dual(0.0, length)) for length in (d1, d2, d3))
    frame = _rt(np.diag([-1.0, -1.0, 1.0]), [a, 0.0, 0.0])
    return Linkage("4R", joints, (*transforms, frame),
                   (Link("crank"), Link("coupler"), Link("rocker")), ("input.theta",),
                   family="4R", parameters=dict(a=a, d1=d1, d2=d2, d3=d3))


def rccc(lengths: tuple[float, float, float, float], twists: tuple[float, float, float, float],
         input_offset: float = 0.0) -> Linkage:
    """R–C–C–C loop in Hartenberg–Denavit form: input R, then three cylindrical joints;
    ``lengths`` a1…a4 and ``twists`` α1…α4 of the four links (Bagci App. B, Fig. 29c)."""
    for k, v in enumerate(lengths):
        _finite("RCCC", **{f"a{k + 1}": v})
    joints = [Joint("input", "R", offset=input_offset), Joint("C2", "C"), Joint("C3", "C"),
              Joint("C4", "C")]
    return Linkage.from_hartenberg_denavit(
        "RCCC", joints, list(lengths), list(twists), inputs=["input.theta"],
        links=[Link("link1"), Link("link2"), Link("link3")], family="RCCC",
        parameters={**{f"a{k + 1}": v for k, v in enumerate(lengths)},
                    **{f"alpha{k + 1}": v for k, v in enumerate(twists)}})
