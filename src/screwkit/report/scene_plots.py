"""The plots and arrows of a scene (:mod:`screwkit.report.scene`): variables, rates and
accelerations over the input; shaking force, shaking moment, joint reactions and input torque
(``Dynamics.as_dict()``); before/after curves of a balancing run (``BalanceResult.as_dict()``);
desired vs generated output of a synthesis (the ``screwkit synthesize`` document).

Values stay SI; each plot carries the factor that turns them into the unit of its label, so an
angle and its rates are shown in deg, deg/s and deg/s² (never degrees beside rad/s)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
DEG = 180.0 / np.pi
#: seed variable names that are lengths (every other seed name is an angle)
SEED_LENGTHS = {"S", "s4"}
#: joint freedoms that are not plotted: a spherical joint's rotation is no output variable
SPHERICAL_SUFFIXES = (".rx", ".ry", ".rz", ".wx", ".wy", ".wz")


def is_length(name: str) -> bool:
    """A joint freedom ``<joint>.s`` or a seed length (S, s4); everything else is an angle."""
    return name.endswith(".s") or name in SEED_LENGTHS


def _input_axis(input_name: str, kind: str) -> tuple[str, float]:
    return (f"{input_name} (deg)", DEG) if kind == "angle" else (f"{input_name} (m)", 1.0)


def _plot(pid: str, group: str, title: str, kind: str, x_label: str, y_label: str,
          series: list[dict[str, Any]], *, x_scale: float = 1.0, y_scale: float = 1.0,
          linked: bool = True) -> dict[str, Any]:
    return {"id": pid, "group": group, "title": title, "kind": kind, "x_label": x_label,
            "y_label": y_label, "x_scale": x_scale, "y_scale": y_scale, "linked": linked,
            "series": series}


def _series(name: str, y: Any, mode: int | None = None, x: Any = None,
            style: str = "line") -> dict[str, Any]:
    out: dict[str, Any] = {"name": name, "mode": mode, "style": style,
                           "y": np.asarray(y, dtype=float)}
    if x is not None:
        out["x"] = np.asarray(x, dtype=float)
    return out


def _variable_names(modes: list[Any], inputs: tuple[str, ...],
                    seeds: list[tuple[dict[str, Array], dict[str, Array], dict[str, Array]]] | None,
                    ) -> list[str]:
    if seeds and seeds[0][0]:
        source = [s[0] for s in seeds]
    else:
        source = [m.variables for m in modes]
    names: list[str] = []
    for table in source:
        for n in table:
            if n in inputs or n in names or n.endswith(SPHERICAL_SUFFIXES):
                continue
            if seeds and seeds[0][0] and n in ("theta0", "theta1"):
                continue  # the seeds' input angle, already the x axis
            names.append(n)
    return names


def kinematic_plots(modes: list[Any], x: Array, input_name: str, kind: str,
                    units: dict[str, Any], inputs: tuple[str, ...],
                    seeds: list[tuple[dict[str, Array], dict[str, Array], dict[str, Array]]] | None = None,
                    ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Each output variable, its rate and its acceleration against the input, one series per
    assembly mode (joint variables; the seed's names instead when ``seeds`` is given)."""
    x_label, x_scale = _input_axis(input_name, kind)
    plots = []
    for name in _variable_names(modes, inputs, seeds):
        length = is_length(name)
        unit = units["length"] if length else "deg"
        scale = units["factor"] if length else DEG
        for key, suffix, title in ((0, "", "position"), (1, "/s", "rate"),
                                   (2, "/s²", "acceleration")):
            series = []
            for k, m in enumerate(modes):
                table = (seeds[k][key] if seeds and seeds[0][0]
                         else (m.variables, m.velocities, m.accelerations)[key])
                if name in table:
                    series.append(_series(f"mode {k}", table[name], mode=k))
            plots.append(_plot(f"kin-{name}-{key}", "kinematics", f"{name}: {title}", "line",
                               x_label, f"{name} ({unit}{suffix})", series, x_scale=x_scale,
                               y_scale=scale))
    groups = [{"id": "kinematics", "title": "Variables, rates and accelerations",
               "note": "One curve per assembly mode; the cursor follows the animation, a click "
                       "on a plot moves it."}]
    return plots, groups


def _vectors(rows: list[Any], n: int) -> Array:
    """A document's per-sample vectors (``None`` where not valid) as an (n, 3) array."""
    out = np.full((n, 3), np.nan)
    for i, r in enumerate(rows):
        if r is not None:
            out[i] = r
    return out


def _scalars(rows: list[Any]) -> Array:
    return np.array([np.nan if r is None else r for r in rows], dtype=float)


def dynamics_arrows(doc: dict[str, Any], centres: Array, linkage: Any) -> dict[str, Any]:
    """Arrows on the 3-D view: the shaking force at the moment point, and each joint's reaction
    force (on the distal link by the proximal link) at the joint centre."""
    n = centres.shape[0]
    names = [j.name for j in linkage.joints]
    sf = _vectors(doc["shaking_force"], n)
    at = np.broadcast_to(np.asarray(doc["moment_point"], dtype=float), (n, 3))
    arrows: dict[str, Any] = {"shaking force": {"kind": "force", "unit": "N", "vectors": sf,
                                                "points": np.array(at)}}
    for joint, r in doc["reactions"].items():
        if joint in names:
            arrows[f"reaction at {joint}"] = {"kind": "force", "unit": "N",
                                              "vectors": _vectors(r["force"], n),
                                              "points": centres[:, names.index(joint)]}
    return arrows


def _components(label: str, v: Array, mode: int | None) -> list[dict[str, Any]]:
    return [_series(f"|{label}|", np.linalg.norm(v, axis=-1), mode)] + [
        _series(f"{label} {a}", v[:, i], mode) for i, a in enumerate("xyz")]


def _load_units(du: Any) -> dict[str, tuple[str, float]]:
    """(label, factor SI → shown) of force and moment in the display units ``du``
    (:class:`~screwkit.io.display_units.DisplayUnits`; None: SI)."""
    if du is None:
        return {"force": ("N", 1.0), "moment": ("N·m", 1.0), "1": ("", 1.0)}
    return {k: (du.pretty(k), 1.0 / du.unit_of(k)[1]) for k in ("force", "moment")} | {
        "1": ("", 1.0)}


def dynamics_plots(doc: dict[str, Any], mode: int, x: Array, input_name: str, kind: str,
                   du: Any = None) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Shaking force (hodographs and against the input), shaking moment, every joint reaction
    and the driven efforts (the input torque), all of assembly mode ``mode``; forces and moments
    in the display units ``du`` (the spec's ``[units]``; None: SI)."""
    n = len(x)
    x_label, x_scale = _input_axis(input_name, kind)
    lu = _load_units(du)
    (fu, ff), (mu, mf) = lu["force"], lu["moment"]
    sf = _vectors(doc["shaking_force"], n)
    sm = _vectors(doc["shaking_moment"], n)
    g = "dynamics"
    plots = [
        _plot("dyn-sf-xy", g, "shaking force hodograph (x–y)", "xy", f"Fx ({fu})", f"Fy ({fu})",
              [_series("shaking force", sf[:, 1], mode, x=sf[:, 0])], x_scale=ff, y_scale=ff),
        _plot("dyn-sf-xz", g, "shaking force hodograph (x–z)", "xy", f"Fx ({fu})", f"Fz ({fu})",
              [_series("shaking force", sf[:, 2], mode, x=sf[:, 0])], x_scale=ff, y_scale=ff),
        _plot("dyn-sf", g, "shaking force", "line", x_label, f"force ({fu})",
              _components("F", sf, mode), x_scale=x_scale, y_scale=ff),
        _plot("dyn-sm", g, "shaking moment (about the moment point)", "line", x_label,
              f"moment ({mu})", _components("M", sm, mode), x_scale=x_scale, y_scale=mf),
    ]
    for name, e in doc["efforts"].items():
        slide = name.endswith(".s")
        unit, factor = (fu, ff) if slide else (mu, mf)
        plots.append(_plot(f"dyn-effort-{name}", g, f"input {'force' if slide else 'torque'}"
                           f" ({name})", "line", x_label, f"effort ({unit})",
                           [_series(name, _scalars(e), mode)], x_scale=x_scale, y_scale=factor))
    for joint, r in doc["reactions"].items():
        plots.append(_plot(f"dyn-reaction-{joint}", g, f"reaction force at {joint}", "line",
                           x_label, f"force ({fu})",
                           _components("f", _vectors(r["force"], n), mode),
                           x_scale=x_scale, y_scale=ff))
    plots.append(_plot("dyn-reaction-moments", g, "reaction moments (about each joint centre)",
                       "line", x_label, f"|moment| ({mu})",
                       [_series(j, np.linalg.norm(_vectors(r["moment"], n), axis=-1), mode)
                        for j, r in doc["reactions"].items()], x_scale=x_scale, y_scale=mf))
    note = (f"Assembly mode {mode}. World frame; forces in {fu}, moments in {mu}. A reaction is "
            "the force on the distal link by the proximal link; the shaking force is what the "
            "moving links exert on the ground. Arrows on the 3-D view show them at the current "
            "frame.")
    indet = doc.get("indeterminacy", {}).get("description")
    if indet:
        note += f" {indet}."
    return plots, [{"id": g, "title": "Dynamics", "note": note}]


def balancing_plots(doc: dict[str, Any], mode: int | None, x: Array, input_name: str,
                    kind: str, du: Any = None,
                    ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Before/after curves of every per-sample load of a balancing run, in the display units
    ``du`` (None: SI)."""
    from screwkit.balancing.result import SAMPLE_LOADS

    ps = doc["per_sample"]
    bx = np.asarray(ps["input"], dtype=float)
    linked = bx.shape == x.shape and bool(np.allclose(bx, x, rtol=0, atol=1e-12))
    x_label, x_scale = _input_axis(input_name, kind)
    lu = _load_units(du)
    kinds = {"N": "force", "N*m": "moment", "1": "1"}
    plots = []
    for key, title, unit in SAMPLE_LOADS:
        # a driven slide's "torque" is a force (balancing/result_table.py)
        slide_force = key == "input_torque" and input_name.endswith(".s")
        label, factor = lu["force" if slide_force else kinds[unit]]
        series = [_series(when, ps[key][when], mode, x=None if linked else bx)
                  for when in ("before", "after")]
        plots.append(_plot(f"bal-{key}", "balancing", f"{title}: before / after", "line",
                           x_label, f"{key} ({label or '1'})", series,
                           x_scale=x_scale, y_scale=factor, linked=linked))
    g = doc["measures"]
    note = (f"Optimum balancing: objective G {g['before']['G']:.6g} → {g['after']['G']:.6g}; "
            f"unique optimum: {doc['unique']}.")
    return plots, [{"id": "balancing", "title": "Balancing (before / after)", "note": note}]


def synthesis_plots(doc: dict[str, Any], units: dict[str, Any], synthesised: bool = False,
                    ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Desired vs generated output rotation and translation at the design points, and the
    error curves, against the design parameter θ (not linked to the animation). ``synthesised``:
    whether the 3-D view shows the synthesised mechanism (else the synthesis start)."""
    rows = sorted(doc["rows"], key=lambda r: r["theta"])

    def col(key: str) -> Array:
        return np.array([np.nan if r.get(key) is None else r[key] for r in rows], dtype=float)

    th = col("theta")
    g = "synthesis"
    x_label = "input θ from θ01 (deg)"
    lu, lf = units["length"], units["factor"]
    plots = [
        _plot("syn-rot", g, "output rotation: desired vs generated", "line", x_label,
              "ψ0 (deg)", [_series("desired ψ_d0 (design points)", col("psi_d0"), x=th,
                                   style="points"),
                           _series("generated ψ_g0", col("psi_g0"), x=th, style="line+points")],
              x_scale=DEG, y_scale=DEG, linked=False),
        _plot("syn-rot-err", g, "rotation error ψ_d0 − ψ_g0", "line", x_label, "error (deg)",
              [_series("ψ_d0 − ψ_g0", col("psi_d0") - col("psi_g0"), x=th,
                       style="line+points")], x_scale=DEG, y_scale=DEG, linked=False),
    ]
    if np.isfinite(col("S_d")).any():
        plots += [
            _plot("syn-tr", g, "output translation: desired vs generated", "line", x_label,
                  f"S ({lu})", [_series("desired S_d (design points)", col("S_d"), x=th,
                                        style="points"),
                                _series("generated S_g", col("S_g"), x=th, style="line+points")],
                  x_scale=DEG, y_scale=lf, linked=False),
            _plot("syn-tr-err", g, "translation error S_d − S_g", "line", x_label,
                  f"error ({lu})", [_series("S_d − S_g", col("S_d") - col("S_g"), x=th,
                                            style="line+points")],
                  x_scale=DEG, y_scale=lf, linked=False),
        ]
    def num(v: Any, scale: float = 1.0) -> str:
        return "—" if v is None or v != v else f"{v * scale:.4g}"

    note = (f"{doc.get('method', 'least_squares')}: status {doc.get('status')}; RMSE ψ "
            f"{num(doc.get('rmse_phi'), DEG)}°, S {num(doc.get('rmse_S'))} m; {len(rows)} design "
            "points. " + ("The 3-D view shows the synthesised mechanism; the plots of its output "
                          "from θ01 follow the animation." if synthesised else
                          "The 3-D view shows the spec's mechanism (the synthesis start), not "
                          "the synthesised one."))
    return plots, [{"id": g, "title": "Synthesis", "note": note}]
