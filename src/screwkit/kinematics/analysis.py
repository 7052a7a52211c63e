"""One call from a spec to an analysis document: every mode, every variable (general and under
the seed's names), rates, coupler point, events. Used by the CLI and reports."""

from __future__ import annotations

from typing import Any

import numpy as np

from screwkit.kinematics.motion import Motion, motion
from screwkit.kinematics.named import seed_variables
from screwkit.model.linkage import Linkage

CLOSED_FORM_FAMILIES = ("RSRC", "4R", "CSSP")


def analyze(linkage: Linkage, inputs: np.ndarray, speed: float = 1.0, acceleration: float = 0.0,
            coupler_point: tuple[float, float, float] | None = None,
            method: str = "auto") -> tuple[Motion | None, dict[str, Any]]:
    """Motion of every assembly mode over ``inputs`` and its JSON-able document (SI).

    ``method``: ``"closed"`` uses the family's closed form (RSRC quartic, Bagci eqs. 3.59–3.82;
    the planar 4R as its δ0 = λ0 = b = e = 0 case; the CSSP quadratic in s4, Rahman §1.2),
    ``"generic"`` the generic loop solver, and
    ``"auto"`` the closed form where the family has one and the sweep has ≥ 2 samples. The
    closed form returns the seed's variables only; the generic solver every joint variable too.
    """
    if method not in ("auto", "closed", "generic"):
        raise ValueError(f"method must be 'auto', 'closed' or 'generic'; got {method!r}")
    has_closed = linkage.family in CLOSED_FORM_FAMILIES and len(inputs) >= 2
    if method == "closed" and not has_closed:
        raise ValueError(
            f"no closed form for a {linkage.family or 'general loop'} (closed forms: "
            f"{', '.join(CLOSED_FORM_FAMILIES)}, with at least 2 input samples); use --method generic"
        )
    if method in ("auto", "closed") and has_closed and linkage.family == "CSSP":
        return None, _cssp_closed_form(linkage, np.asarray(inputs, dtype=float), speed, acceleration)
    if method in ("auto", "closed") and has_closed:
        return None, _closed_form(linkage, np.asarray(inputs, dtype=float), speed, acceleration,
                                  coupler_point)
    m = motion(linkage, inputs, speed, acceleration)
    modes: list[dict[str, Any]] = []
    for k, md in enumerate(m.modes):
        v, vd, vdd = seed_variables(linkage, md)
        entry: dict[str, Any] = {
            "mode": k,
            "assembles": md.assembles,
            "singular": md.singular,
            "events": md.events,
            "variables": {**v, **md.variables},
            "velocities": {**vd, **md.velocities},
            "accelerations": {**vdd, **md.accelerations},
            "closure_residual": md.closure_residual,
        }
        if coupler_point is not None:
            # Bagci App. C: P = O1 + f B e1 + g B e2 + h B e3 (coupler frame B at the sphere)
            R = md.link_rotation[:, 1]
            p = md.link_origin[:, 1] + np.einsum("nij,j->ni", R, np.asarray(coupler_point))
            entry["coupler_point"] = {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
        modes.append(entry)
    doc = _document(linkage, "generic", inputs, speed, acceleration, modes)
    if method == "auto" and linkage.family in CLOSED_FORM_FAMILIES and not has_closed:
        doc["method_note"] = ("one input sample: the generic solver was used (the closed form "
                              "tracks branches over at least 2 samples)")
    return m, doc


def _document(linkage: Linkage, method: str, inputs: np.ndarray, speed: float,
              acceleration: float, modes: list[dict[str, Any]]) -> dict[str, Any]:
    """The analysis document (SI), the same for every method (docs/cli.md)."""
    return {
        "method": method,
        "mechanism": linkage.name,
        "family": linkage.family,
        "units": {"length": "m", "angle": "rad", "time": "s",
                  "velocities": "d/dt of each variable (rad/s or m/s)",
                  "accelerations": "d2/dt2 of each variable (rad/s^2 or m/s^2)"},
        "input_name": linkage.inputs[0],
        "input": inputs,
        "input_speed": speed,
        "input_acceleration": acceleration,
        "parameters": dict(linkage.parameters),
        "modes": modes,
    }


def _closed_form(linkage: Linkage, theta: np.ndarray, speed: float, acceleration: float,
                 coupler_point: tuple[float, float, float] | None) -> dict[str, Any]:
    from screwkit.kinematics.rsrc import (
        RSRCDimensions,
        RSRCPositions,
        rsrc_coupler_point,
        rsrc_motion,
        rsrc_rates,
    )

    p = dict(linkage.parameters)
    planar = linkage.family == "4R"
    if planar:
        dims = RSRCDimensions(d1=p["d1"], d2=p["d2"], d3=p["d3"], a=p["a"], b=0.0, e=0.0,
                              delta0=0.0, lambda0=0.0)
    else:
        dims = RSRCDimensions(**p)
    mot = rsrc_motion(dims, theta)
    case = "delta0_n_pi" if planar else _case(dims)
    pos = RSRCPositions(mot.theta0, mot.phi0, mot.chi0, mot.S, mot.assembles, case)  # type: ignore[arg-type]
    rates = rsrc_rates(dims, pos, speed, acceleration)
    cp = rsrc_coupler_point(dims, pos, *coupler_point) if coupler_point is not None else None
    residual = _master_loop_residual(dims, pos)
    modes: list[dict[str, Any]] = []
    for j in range(mot.phi0.shape[1]):
        ok = mot.assembles[:, j]
        if not ok.any():
            continue
        variables = {"theta0": theta, "phi0": mot.phi0[:, j], "chi0": mot.chi0[:, j]}
        velocities = {"theta0": np.full_like(theta, speed), "phi0": rates.phi0_dot[:, j],
                      "chi0": rates.chi0_dot[:, j]}
        accelerations = {"theta0": np.full_like(theta, acceleration), "phi0": rates.phi0_ddot[:, j],
                         "chi0": rates.chi0_ddot[:, j]}
        if not planar:
            variables["S"] = mot.S[:, j]
            velocities["S"] = rates.S_dot[:, j]
            accelerations["S"] = rates.S_ddot[:, j]
        for table in (variables, velocities, accelerations):
            for key, values in table.items():
                if key != "theta0":
                    table[key] = np.where(ok, values, np.nan)
        events = [f"{e.kind} assembling at input [{e.theta0!r}] (limit position or dead centre)"
                  for e in mot.events if e.branch == j]
        entry: dict[str, Any] = {
            "mode": len(modes),
            "assembles": ok,
            "singular": ok & ~rates.valid[:, j],
            "events": events,
            "variables": variables,
            "velocities": velocities,
            "accelerations": accelerations,
            "closure_residual": np.where(ok, residual[:, j], np.nan),
        }
        if cp is not None:
            xyz = cp.global_xyz[:, j]
            entry["coupler_point"] = {"x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]}
        modes.append(entry)
    if not modes:
        from screwkit.kinematics.motion import AssemblyError

        raise AssemblyError(
            f"{linkage.name}: the loop does not close at any of the {len(theta)} inputs "
            f"(from {theta[0]!r} to {theta[-1]!r}); check the dimensions"
        )
    return _document(linkage, "closed", theta, speed, acceleration, modes)


def _unwrap_runs(angle: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Continuous angles along each run of assembling samples, each run starting in (−π, π]."""
    out = np.array(angle, dtype=float)
    idx = np.flatnonzero(ok & np.isfinite(out))
    if idx.size == 0:
        return out
    for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
        values = np.unwrap(out[run])
        out[run] = values - 2 * np.pi * np.round(values[0] / (2 * np.pi))
    return out


def _case(dims: Any) -> str:
    s = np.sin(dims.delta0)
    c = np.cos(dims.delta0)
    if abs(s) < 1e-12:
        return "delta0_n_pi"
    if abs(c) < 1e-12:
        return "delta0_half_pi"
    return "general"


def _master_loop_residual(dims: Any, pos: Any) -> np.ndarray:
    """|sphere centre from the input side − from the output side| / length scale, Bagci's
    master position loop (reference spec §3.1) — an independent check of the closed form."""
    th = pos.theta0[:, None]
    phi, S, chi = pos.phi0, pos.S, pos.chi0
    lam, dl = dims.lambda0, dims.delta0
    # vectors in the output frame, then R_y(λ0); rotations written out per component
    # w = e e1 − d2 R_x(−χ) e2 = (e, −d2 cos χ, d2 sin χ)
    wx, wy, wz = dims.e, -dims.d2 * np.cos(chi), dims.d2 * np.sin(chi)
    # R_y(−δ) w
    ux = np.cos(dl) * wx - np.sin(dl) * wz
    uy = wy
    uz = np.sin(dl) * wx + np.cos(dl) * wz
    # d3 e2 + that, then R_x(φ)
    yy = dims.d3 + uy
    rx, ry, rz = ux, np.cos(phi) * yy - np.sin(phi) * uz, np.sin(phi) * yy + np.cos(phi) * uz
    # −S e1 + that, then R_y(λ)
    rx = rx - S
    gx = np.cos(lam) * rx + np.sin(lam) * rz
    gy = ry
    gz = -np.sin(lam) * rx + np.cos(lam) * rz
    ex = dims.b + gx - 0.0
    ey = dims.a + gy - dims.d1 * np.cos(th)
    ez = gz - dims.d1 * np.sin(th)
    L = dims.d1 + dims.d2 + abs(dims.d3) + abs(dims.a) + abs(dims.b) + abs(dims.e)
    return np.asarray(np.sqrt(ex**2 + ey**2 + ez**2) / L)


def limits(linkage: Linkage, dwell_tolerance: float = 1e-6, max_order: int = 5,
           at: list[float] | None = None) -> dict[str, Any]:
    """Limit positions of the output rotation and translation over a full input turn, each with
    the order of its instantaneous dwell (Bagci 1969, App. D: rotation limits Q4 = 0, eq. D.1;
    translation limits by the corrected eq. D.3; dwell order = number of vanishing consecutive
    derivatives dᵏφ0/dθ0ᵏ, k = 1…max_order, within ``dwell_tolerance`` rad/radᵏ)."""
    from screwkit.kinematics.assembly_range import assembling_intervals, describe_intervals
    from screwkit.kinematics.rsrc import (
        RSRCDimensions,
        rsrc_dwell_order,
        rsrc_rotation_limits,
        rsrc_translation_limits,
    )

    if linkage.family not in ("RSRC", "4R"):
        raise ValueError(
            f"limit positions and dwells are computed for the RSRC and the planar 4R "
            f"(Bagci App. D); this is a {linkage.family or 'general loop'}"
        )
    if not dwell_tolerance > 0:
        raise ValueError(f"the dwell tolerance must be positive; got {dwell_tolerance}")
    p = dict(linkage.parameters)
    planar = linkage.family == "4R"
    dims = (RSRCDimensions(d1=p["d1"], d2=p["d2"], d3=p["d3"], a=p["a"], b=0.0, e=0.0,
                           delta0=0.0, lambda0=0.0) if planar else RSRCDimensions(**p))
    out: list[dict[str, Any]] = []
    rot = rsrc_rotation_limits(dims)
    runs = assembling_intervals(dims)
    if not runs and not rot:
        raise ValueError(f"{linkage.name}: the mechanism does not assemble at any input angle "
                         "(scanned every 0.25° over a full turn), so it has no limit positions; "
                         "check the dimensions (docs/kinematics.md)")
    if rot:
        order, deriv = rsrc_dwell_order(dims, np.array([r.theta0 for r in rot]),
                                        np.array([r.phi0 for r in rot]), tol=dwell_tolerance,
                                        max_order=max_order)
    for k, r in enumerate(rot):
        out.append({"kind": "rotation", "theta0": r.theta0, "phi0": r.phi0, "chi0": r.chi0,
                    "S": None if planar else r.S, "second_derivative": r.second_derivative,
                    "branch": r.branch, "dwell_order": int(order[k]),
                    "derivatives": deriv[k]})
    if not planar:
        for r in rsrc_translation_limits(dims):
            out.append({"kind": "translation", "theta0": r.theta0, "phi0": r.phi0, "chi0": r.chi0,
                        "S": r.S, "second_derivative": r.second_derivative, "branch": r.branch})
    dwells: list[dict[str, Any]] = []
    if at:
        from screwkit.kinematics.rsrc import rsrc_positions

        th = np.asarray(at, dtype=float)
        pos = rsrc_positions(dims, th)
        nowhere = ~np.asarray(pos.assembles).any(axis=1)
        if nowhere.any():
            shown = ", ".join(f"{np.degrees(t):.6g}°" for t in th[nowhere][:8])
            raise ValueError(f"{linkage.name}: the mechanism does not assemble at the input "
                             f"angle(s) {shown} asked for; it assembles {describe_intervals(runs)} "
                             "(sampled every 0.25°)")
        for j in range(pos.phi0.shape[1]):
            ok = pos.assembles[:, j]
            if not ok.any():
                continue
            order, deriv = rsrc_dwell_order(dims, th[ok], pos.phi0[ok, j], tol=dwell_tolerance,
                                            max_order=max_order)
            for t, ph, o, dv in zip(th[ok], pos.phi0[ok, j], order, deriv, strict=True):
                dwells.append({"theta0": t, "inversion_label": j + 1, "phi0": ph,
                               "dwell_order": int(o), "derivatives": dv})
    return {"mechanism": linkage.name, "family": linkage.family,
            "dwell_tolerance": dwell_tolerance, "units": {"angle": "rad", "length": "m"},
            "limits": out, "dwells_at": dwells}


def _cssp_closed_form(linkage: Linkage, theta: np.ndarray, speed: float,
                      acceleration: float) -> dict[str, Any]:
    """Both roots of Rahman's quadratic in s4 (§1.2) with exact rates; the two roots are the
    two assembly modes and stay separate (they meet only at a branch point, where the mode
    stops)."""
    from screwkit.kinematics.cssp import CSSPDimensions, cssp_motion

    p = dict(linkage.parameters)
    dims = CSSPDimensions(p["a1"], p["a2"], p["a4"], p["alpha4"], p.get("s1", 0.0))
    modes: list[dict[str, Any]] = []
    for root in (1, -1):
        cf = cssp_motion(dims, theta, speed, acceleration, mode=root, allow_partial=True)
        ok = np.asarray(cf.assembles)
        if not ok.any():
            continue
        names = ("s4", "theta2", "eta2", "theta3", "eta3")
        variables = {"theta1": theta, **{n: getattr(cf, n) for n in names}}
        velocities = {"theta1": np.full_like(theta, speed),
                      **{n: getattr(cf, f"{n}_dot") for n in names}}
        accelerations = {"theta1": np.full_like(theta, acceleration),
                         **{n: getattr(cf, f"{n}_ddot") for n in names}}
        for table in (variables, velocities, accelerations):
            for key in names:
                table[key] = np.where(ok, table[key], np.nan)
        for key in ("theta2", "eta2", "theta3", "eta3"):
            variables[key] = _unwrap_runs(variables[key], ok)
        stops = np.nonzero(ok[:-1] & ~ok[1:])[0]
        starts = np.nonzero(~ok[:-1] & ok[1:])[0] + 1
        events = [f"stops assembling after input [{theta[i]!r}] (branch point before [{theta[i + 1]!r}])"
                  for i in stops]
        events += [f"starts assembling at input [{theta[i]!r}]" for i in starts]
        modes.append({
            "mode": len(modes),
            "root": "s4 = -b + sqrt(b^2 - c)" if root == 1 else "s4 = -b - sqrt(b^2 - c)",
            "assembles": ok,
            "singular": np.zeros_like(ok),
            "events": events,
            "variables": variables,
            "velocities": velocities,
            "accelerations": accelerations,
            "closure_residual": np.where(ok, cf.loop_closure_gap / (p["a1"] + p["a2"]), np.nan),
        })
    if not modes:
        from screwkit.kinematics.motion import AssemblyError

        raise AssemblyError(f"{linkage.name}: the loop does not close at any of the {len(theta)} inputs")
    return _document(linkage, "closed", theta, speed, acceleration, modes)


def mode_motion(linkage: Linkage, inputs: np.ndarray, speed: float, acceleration: float,
                mode: int = 0) -> Any:
    """The full link motion (a :class:`~screwkit.kinematics.motion.ModeMotion`) of assembly mode
    ``mode``, as dynamics and balancing need it. The CSSP takes its closed form (no Newton;
    mode 0 is the seed's root s4 = −b + √(b² − c), mode 1 the other), with the same numbering
    as ``analyze``; every other loop the generic solver's modes."""
    from screwkit.kinematics.motion import AssemblyError

    if mode < 0:
        raise ValueError(f"the assembly mode is an index ≥ 0; got {mode}")
    if linkage.family == "CSSP":
        from screwkit.kinematics.cssp_motion import cssp_mode_motion

        if mode > 1:
            raise ValueError(f"a CSSP has 2 assembly modes (0: s4 = −b + √(b² − c), 1: the other root); got mode {mode}")
        mm = cssp_mode_motion(linkage, inputs, speed, acceleration, mode=1 if mode == 0 else -1,
                              allow_partial=True)
        if not np.any(mm.assembles):
            raise AssemblyError(f"{linkage.name}: assembly mode {mode} does not close at any input")
        return mm
    m = motion(linkage, inputs, speed, acceleration)
    if linkage.family in ("RSRC", "4R") and len(inputs) >= 2:
        # number the modes as `analyze` does (the closed form's branches): pick the generic
        # branch that is the same configuration as closed-form mode `mode`
        _, doc = analyze(linkage, inputs, speed, acceleration, method="closed")
        if mode >= len(doc["modes"]):
            raise ValueError(f"{linkage.name}: assembly mode {mode} asked for, but the mechanism "
                             f"has {len(doc['modes'])} assembly mode(s) over these inputs "
                             f"(0…{len(doc['modes']) - 1}, numbered as `screwkit analyze`)")
        target = doc["modes"][mode]
        best, overlap = None, 0
        for md in m.modes:
            v, _, _ = seed_variables(linkage, md)
            both = np.asarray(target["assembles"]) & md.assembles
            if not both.any():
                continue
            d = np.angle(np.exp(1j * (v["phi0"][both] - target["variables"]["phi0"][both])))
            if np.max(np.abs(d)) < 1e-6 and both.sum() > overlap:
                best, overlap = md, int(both.sum())
        if best is None:
            raise ValueError(f"{linkage.name}: the generic solver did not find assembly mode "
                             f"{mode} of the closed form (a finer step may help)")
        # where the closed form continues the branch past a limit position the generic solver
        # starts a new one: the samples beyond it are reported as not assembling
        return best
    if mode >= len(m.modes):
        raise ValueError(f"{linkage.name}: assembly mode {mode} asked for, but the mechanism has "
                         f"{len(m.modes)} assembly mode(s) over these inputs (0…{len(m.modes) - 1})")
    return m.modes[mode]
