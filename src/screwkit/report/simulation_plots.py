"""Plots of a simulation (``screwkit simulate``; a graph's: :func:`graph_simulation_plots`): speed against the input angle (one curve per
cycle) and against time, the motor torque and the shaft torque into the loop against time, and
the coefficient of speed fluctuation per cycle — as report-scene plots (the viewer's plot
dictionaries, :mod:`screwkit.report.scene`) and as one matplotlib PNG (``--plot``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from screwkit.errors import InputError
from screwkit.io.results import jsonable

DEG = 180.0 / np.pi
RPM = 60.0 / (2.0 * np.pi)
GROUP = "simulation"


def _plot(pid: str, title: str, x_label: str, y_label: str, series: list[dict[str, Any]],
          x_scale: float = 1.0, y_scale: float = 1.0) -> dict[str, Any]:
    return {"id": pid, "group": GROUP, "title": title, "kind": "line", "x_label": x_label,
            "y_label": y_label, "x_scale": x_scale, "y_scale": y_scale, "linked": False,
            "series": series}


def _series(name: str, x: Any, y: Any, style: str = "line") -> dict[str, Any]:
    return {"name": name, "mode": None, "style": style, "x": np.asarray(x, dtype=float),
            "y": np.asarray(y, dtype=float)}


def simulation_scene_plots(doc: dict[str, Any], mode: int | None = None
                           ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Scene plots and their group from a simulation document (``SpecSimulation.as_dict``)."""
    s = {k: np.asarray(v, dtype=float) for k, v in doc["samples"].items()}
    n_cycles = max(len(doc["cycles"]), 1)
    per = s["time"].size // n_cycles if s["time"].size else 0
    by_cycle = [_series(f"cycle {k + 1}", s["cycle_angle"][k * per:(k + 1) * per],
                        s["speed"][k * per:(k + 1) * per]) for k in range(len(doc["cycles"]))]
    plots = [
        _plot("sim-speed-angle", "input speed against input angle (one curve per cycle)",
              "input angle in the cycle (deg)", "speed (rpm)", by_cycle, DEG, RPM),
        _plot("sim-speed-time", "input speed against time", "time (s)", "speed (rpm)",
              [_series("speed", s["time"], s["speed"])], 1.0, RPM),
        _plot("sim-torque-time", "motor torque and shaft torque into the loop", "time (s)",
              "torque (N·m)", [_series("motor", s["time"], s["motor_torque"])]),
    ]
    if np.any(s.get("friction_torque", np.zeros(0))):
        plots[-1]["series"].append(_series("joint friction (on the input)", s["time"],
                                           s["friction_torque"]))
    loads = doc.get("loads")
    if loads:
        for name, e in loads["efforts"].items():
            plots[-1]["series"].append(_series(f"shaft ({name})", s["time"],
                                               [np.nan if v is None else v for v in e]))
    cyc = doc["cycles"]
    plots.append(_plot("sim-fluctuation", "coefficient of speed fluctuation per cycle", "cycle",
                       "C_s", [_series("C_s", [c["cycle"] for c in cyc],
                                       [c["fluctuation"] for c in cyc], "line+points")]))
    steady = doc.get("steady") or {}
    note = (f"Forward simulation with the [drive] table: {doc['message']}. Flywheel "
            f"{doc['flywheel']:.6g} kg·m²; steady (last cycle) mean speed "
            f"{steady.get('mean_speed', float('nan')) * RPM:.6g} rpm, C_s "
            f"{steady.get('fluctuation', float('nan')):.4g}, motor torque RMS "
            f"{steady.get('motor_torque_rms', float('nan')):.4g} N·m (docs/simulation.md).")
    sizing = doc.get("flywheel_sizing")
    if sizing:
        note += (f" Flywheel sized for C_s = {sizing['requested_fluctuation']:g}: "
                 f"{sizing['flywheel']:.6g} kg·m² (energy method "
                 f"{sizing['energy_method']['flywheel']:.6g}).")
    return jsonable(plots), [{"id": GROUP, "title": "Simulation (motor and flywheel)",
                              "note": note}]


def write_simulation_png(doc: dict[str, Any], path: str | Path) -> None:
    """Speed against angle and time, torques against time and C_s per cycle in one PNG (or
    SVG/PDF, by the suffix); needs matplotlib (the ``plot`` extra)."""
    plots, _ = simulation_scene_plots(doc)
    plots_png(plots, f"{doc['name']}: simulation", path)


def plots_png(plots: list[dict[str, Any]], title: str, path: str | Path) -> None:
    """Four scene plots (``_plot`` dictionaries) in a 2 × 2 figure written to ``path``
    (PNG, SVG or PDF by the suffix); needs matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("--plot needs matplotlib: pip install 'screwkit[plot]'") from exc
    from screwkit.io.outputs import atomic_path
    from screwkit.report.plots import tidy_axes

    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    for ax, p in zip(axes.ravel(), plots, strict=True):
        for s in p["series"]:
            x = np.asarray(s["x"], dtype=float) * p["x_scale"]
            y = np.array([np.nan if v is None else v for v in s["y"]], dtype=float) * p["y_scale"]
            ax.plot(x, y, "o-" if "points" in s["style"] else "-", lw=1, ms=3,
                    label=s["name"] if len(p["series"]) <= 6 else None)
        ax.set_title(p["title"], fontsize=9)
        ax.set_xlabel(p["x_label"])
        ax.set_ylabel(p["y_label"])
        ax.grid(alpha=0.3)
        if len(p["series"]) <= 6:
            ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=11)
    tidy_axes(fig)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=Path(path).suffix.lstrip(".") or "png", dpi=110)
    plt.close(fig)


def graph_simulation_plots(doc: dict[str, Any]) -> list[dict[str, Any]]:
    """Four plots of a graph run (``GraphSpecSimulation.as_dict``): every input and every input
    rate against time (degrees for rotating inputs, metres for slides), every input's motor and
    friction effort, and the energy account (kinetic, potential from the start, the motors'
    and the friction's work, and the balance E − E₀ − W, which is zero up to the integrator's
    tolerance)."""
    t = np.asarray(doc["time"], dtype=float)
    inputs = doc["inputs"]

    def scale(name: str) -> float:
        return 1.0 if name.endswith(".s") else DEG

    def unit(rate: bool) -> str:
        kinds = {n.endswith(".s") for n in inputs}
        base = "deg or m" if len(kinds) == 2 else ("m" if kinds == {True} else "deg")
        return f"{base}/s" if rate else base

    values = [_series(n, t, np.asarray(v["value"], dtype=float) * scale(n))
              for n, v in inputs.items()]
    rates = [_series(n, t, np.asarray(v["rate"], dtype=float) * scale(n))
             for n, v in inputs.items()]
    efforts = [_series(f"{n} {part}", t, v[part]) for n, v in inputs.items()
               for part in ("motor", "friction", "load")
               if part in v and np.any(np.asarray(v[part]))]
    kinetic = np.asarray(doc["kinetic_energy"], dtype=float)
    potential = np.asarray(doc["potential_energy"], dtype=float)
    load_work = np.asarray(doc.get("load_work", np.zeros_like(t)), dtype=float)
    works = (np.asarray(doc["motor_work"], dtype=float) + np.asarray(doc["friction_work"])
             + load_work)
    energy = [_series("kinetic", t, kinetic), _series("potential (from the start)", t,
                                                       potential - potential[0]),
              _series("motor work", t, doc["motor_work"]),
              _series("friction work", t, doc["friction_work"]),
              *([_series("load work", t, load_work)] if "load_work" in doc else []),
              _series("E − E₀ − W", t, kinetic + potential - kinetic[0] - potential[0] - works)]
    return jsonable([
        _plot("gsim-inputs", "inputs against time", "time (s)", unit(False), values),
        _plot("gsim-rates", "input rates against time", "time (s)", unit(True), rates),
        _plot("gsim-efforts", "motor, friction and load efforts on the inputs", "time (s)",
              "N·m (N on a slide)", efforts or [_series("none", t, np.zeros_like(t))]),
        _plot("gsim-energy", "energy account", "time (s)", "J", energy)])


def write_graph_simulation_png(doc: dict[str, Any], path: str | Path) -> None:
    """The four plots of :func:`graph_simulation_plots` in one PNG (or SVG/PDF)."""
    plots_png(graph_simulation_plots(doc), f"{doc['name']}: simulation", path)



def graph_cycles_plots(doc: dict[str, Any], samples: dict[str, Any]) -> list[dict[str, Any]]:
    """The loop's four cycle plots for a graph's crank cycles (``GraphSpecCycles``: ``doc`` its
    ``as_dict``, ``samples`` its run's samples): the crank speed against the angle turned in
    the cycle (one curve per cycle) and against time, the motor torque against time, and C_s
    per cycle."""
    s = {k: np.asarray(v, dtype=float) for k, v in samples.items()}
    n = len(doc["cycles"]["period"])
    per = s["time"].size // n if n else 0
    by_cycle = [_series(f"cycle {k + 1}", s["cycle_angle"][k * per:(k + 1) * per],
                        s["speed"][k * per:(k + 1) * per]) for k in range(n)]
    name = doc["input"]
    return jsonable([
        _plot("gcyc-speed-angle", f"{name} speed against its turn in the cycle (one curve per "
              "cycle)", "angle in the cycle (deg)", "speed (rpm)", by_cycle, DEG, RPM),
        _plot("gcyc-speed-time", f"{name} speed against time", "time (s)", "speed (rpm)",
              [_series("speed", s["time"], s["speed"])], 1.0, RPM),
        _plot("gcyc-torque-time", "motor torque", "time (s)", "torque (N·m)",
              [_series("motor", s["time"], s["motor_torque"])]),
        _plot("gcyc-fluctuation", "coefficient of speed fluctuation per cycle", "cycle", "C_s",
              [_series("C_s", np.arange(1, n + 1), doc["cycles"]["fluctuation"],
                       "line+points")])])


def write_graph_cycles_png(doc: dict[str, Any], samples: dict[str, Any], path: str | Path
                           ) -> None:
    """The four plots of :func:`graph_cycles_plots` in one PNG (or SVG/PDF)."""
    plots_png(graph_cycles_plots(doc, samples), f"{doc['name']}: crank cycles", path)
