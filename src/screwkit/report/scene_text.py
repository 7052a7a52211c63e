"""The text sections of a scene: units, the solver used, and the validation status of what
is shown — including a check made here, independent of the solver: every drawn link keeps its
joint-to-joint distances over the cycle (a broken or stretched loop would show)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

GENERIC_SOLVER = ("generic single-loop solver (screwkit.kinematics.motion): every assembly mode "
                  "found by Newton from random starts and followed as a continuous branch; "
                  "velocities and accelerations from the loop-closure Jacobian")


def link_span_variation(link_points: Array, assembles: NDArray[np.bool_]) -> float:
    """Largest change over the assembling frames of any distance between two points of a
    drawn link (a loop's link: start, common-normal foot, next joint centre; a body of a graph:
    its joints and points), in metres; 0 for a rigid picture. NaN when no frame assembles."""
    p = link_points[assembles]
    if p.shape[0] == 0:
        return float("nan")
    P = p.shape[2]
    d = np.stack([np.linalg.norm(p[:, :, a] - p[:, :, b], axis=-1)
                  for a in range(P) for b in range(a + 1, P)], axis=-1)
    return float(np.max(d.max(axis=0) - d.min(axis=0)))


def _num(x: Any, fmt: str = ".3g") -> str:
    return "—" if x is None or (isinstance(x, float) and x != x) else format(x, fmt)


def text_sections(linkage: Any, modes: list[dict[str, Any]], units: dict[str, Any], kind: str, *,
                  spec_text: str | None = None, solver: list[str] | None = None,
                  notes: list[str] | None = None, dynamics_doc: dict[str, Any] | None = None,
                  dynamics_mode: int | None = None, balance_doc: dict[str, Any] | None = None,
                  synthesis_doc: dict[str, Any] | None = None) -> dict[str, Any]:
    """``{"spec", "units", "solver", "validation"}`` (lists of lines; ``spec`` the file text)."""
    lu = units["length"]
    unit_lines = [
        f"Lengths are shown in {lu}, angles in degrees; rates per second ({lu}/s, deg/s) and "
        f"accelerations per second squared ({lu}/s², deg/s²); forces in N, moments in N·m.",
        "The numbers inside this page are SI (m, rad, s, N); the input is "
        + ("an angle." if kind == "angle" else "a translation."),
    ]
    solver_lines = list(solver) if solver else [GENERIC_SOLVER]
    joints = ", ".join(f"{j.name} ({j.kind})" for j in linkage.joints)
    solver_lines.append(f"Loop: {joints}; driven freedom {', '.join(linkage.inputs)}.")
    if dynamics_doc is not None:
        solver_lines.append(f"Dynamics (assembly mode {dynamics_mode}): Newton–Euler inverse "
                            "dynamics of the closed loop (screwkit.dynamics.inverse_dynamics); "
                            + str(dynamics_doc.get("indeterminacy", {}).get("description", "")))
    if balance_doc is not None:
        solver_lines.append("Balancing: quadratic programme over the links' point masses "
                            "(screwkit.balancing, Rahman 1996 ch. 4 done right).")
    if synthesis_doc is not None:
        solver_lines.append(f"Synthesis: {synthesis_doc.get('method', 'least_squares')} "
                            "(screwkit.synthesis, Bagci 1969 ch. V).")
    validation = []
    for m in modes:
        ok = np.asarray(m["assembles"], dtype=bool)
        line = f"{m['label']}: assembles at {int(ok.sum())} of {ok.size} frames"
        res = m.get("closure_residual")
        if res is not None and ok.any():
            line += f"; largest loop-closure residual {_num(float(np.nanmax(np.asarray(res)[ok])))}"
        span = link_span_variation(np.asarray(m["link_points"], dtype=float), ok)
        line += (f"; drawn links rigid to {_num(span)} m (largest change of a joint-to-joint "
                 "distance over the cycle)")
        sing = int(np.sum(m["singular"]))
        if sing:
            line += f"; singular at {sing} frame(s) (rates undefined there)"
        validation.append(line + ".")
        validation += [f"{m['label']}: {e}" for e in m["events"]]
    if dynamics_doc is not None:
        rr = dynamics_doc.get("summary", {}).get("relative_residual", {})
        validation.append(f"Dynamics: largest unbalanced load along idle freedoms "
                          f"{_num(rr.get('peak'))} of the largest joint load "
                          "(docs/dynamics.md lists the physical-law checks of the tests).")
    if balance_doc is not None:
        validation.append(f"Balancing: unique optimum {balance_doc['unique']}; active "
                          f"constraints {', '.join(balance_doc['active_constraints']) or 'none'}.")
        validation += [f"Balancing note: {n}" for n in balance_doc.get("notes", [])]
    if synthesis_doc is not None:
        rc = synthesis_doc.get("range_check", {})
        validation.append(f"Synthesis: status {synthesis_doc.get('status')}; whole range: "
                          f"{rc.get('message', '—')}")
    validation += list(notes or [])
    validation.append("How screwkit is checked (seed tables, physical laws, second methods): "
                      "docs/validation.md.")
    return {"spec": spec_text, "units": unit_lines, "solver": solver_lines,
            "validation": validation}
