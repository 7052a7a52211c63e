"""Forward simulation speed: simulated cycles per second of the reduced equation of motion
(DOP853, Fourier-series coefficients) on Rahman's CSSP and the Fig. 7 RSRC, free running and
with a motor and a load, at the default tolerance (rtol 1e-9) and a tight one (1e-12); and the
one-off cost of building the reduced model (grid solve + fit)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import screwkit as sk
from screwkit.io.drive_table import DriveConfig, LoadConfig, MotorConfig
from screwkit.simulation.drive import equation_of_motion
from screwkit.simulation.integrate import simulate_cycles

ROOT = Path(__file__).resolve().parents[1]


def _drive(loaded: bool, freedom: str) -> DriveConfig:
    motor = MotorConfig("linear", stall_torque=20.0, no_load_speed=400.0) if loaded else MotorConfig()
    load = LoadConfig(freedom, 5.0, 0.001) if loaded else None
    return DriveConfig(motor, load, 0.05 if loaded else 0.0, 300.0, 10, 72, 1e-9, None, False,
                       None)


def run() -> list[dict[str, Any]]:
    rows = []
    for name in ("rahman_cssp", "rsrc_fig7_dynamics"):
        spec = sk.load_spec(ROOT / "examples" / f"{name}.toml")
        freedom = spec.linkage.joints[-1].freedom_names()[0]
        t = time.perf_counter()
        eom0 = equation_of_motion(spec.linkage, _drive(False, freedom))
        rows.append({"name": f"{name}: reduced model (grid solve + Fourier fit)",
                     "value": time.perf_counter() - t, "unit": "s", "target": "< 1",
                     "note": f"{eom0.model.grid.size} samples, {eom0.model.series.harmonics} "
                             "harmonics"})
        for loaded in (False, True):
            eom = equation_of_motion(spec.linkage, _drive(loaded, freedom))
            for rtol in (1e-9, 1e-12):
                cycles = 20
                t = time.perf_counter()
                simulate_cycles(eom, cycles=cycles, initial_speed=spec.speed, rtol=rtol)
                dt = time.perf_counter() - t
                what = "motor + load + flywheel" if loaded else "free running"
                rows.append({"name": f"{name}: {what}, rtol {rtol:g}", "value": cycles / dt,
                             "unit": "cycles/s", "target": "≥ 5",
                             "note": f"{cycles} cycles in {dt:.2f} s"})
    return rows


if __name__ == "__main__":
    for r in run():
        print(f"{r['name']:60s} {r['value']:10.3g} {r['unit']}  ({r['note']})")
