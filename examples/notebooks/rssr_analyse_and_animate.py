# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Analyse and animate a spatial RSSR
#
# A spatial R–S–S–R crank-rocker (`examples/rssr_spatial.toml`, lengths in mm, angles in
# degrees). We solve its motion in every assembly mode, look at the output angle φ0 and its
# rates as a table in the spec's units, check the loop closes, and show the animated 3-D view
# (the same page as `screwkit report`). Open it with `jupytext --to notebook` or run it as a
# script.

# %%
from pathlib import Path

import numpy as np

import screwkit as sk

HERE = Path.cwd()
EXAMPLES = next(p for p in (HERE / "..", HERE / "examples", HERE)
                if (p / "rssr_spatial.toml").exists())
spec = sk.load_spec(EXAMPLES / "rssr_spatial.toml")
print(spec.describe())

# %% [markdown]
# ## Every assembly mode over a turn of the crank
# `solve_motion` returns a `Motion`: one `ModeMotion` per assembly mode, arrays batch-first over
# the 36 input samples, SI units inside.

# %%
motion = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
print(f"{len(motion.modes)} assembly modes, solver: {motion.solver or motion.method}")
phi0 = motion.variable("phi0", mode=0)          # rad
phi0_rate = motion.variable("phi0", mode=0, derivative=1)   # rad/s
print("output swing (deg):", np.degrees(np.nanmax(phi0) - np.nanmin(phi0)).round(3))

# %% [markdown]
# ## The same numbers as a table, in the spec's units
# `to_dataframe` puts the unit in every column header; `spec.display_units()` is the spec's
# `[units]` (mm and deg here; rates follow: deg/s). `to_csv` writes the same table.

# %%
units = spec.display_units()
try:
    df = motion.to_dataframe(units)
    print(df[["mode", "input [deg]", "phi0 [deg]", "phi0_dot [deg/s]"]].head())
except ImportError:  # pandas is the optional "table" extra
    df = None
    table = motion.table()
    print(table.csv_text(units).splitlines()[0])

# %% [markdown]
# ## Checks: the loop closes, and the rate is the derivative of the angle
# The velocity comes from the loop-closure Jacobian; a finite difference of φ0 over the sweep
# agrees with it to the step's accuracy.

# %%
md = motion.mode(0)
print("largest closure residual:", float(np.nanmax(md.closure_residual)))
t = spec.inputs / spec.speed                  # time of each sample (s)
numeric = np.gradient(np.unwrap(phi0), t)
ok = np.isfinite(phi0_rate)
error = np.max(np.abs(numeric[ok][2:-2] - phi0_rate[ok][2:-2])) / np.max(np.abs(phi0_rate))
print(f"finite-difference rate vs exact rate: {error:.2%} of the peak")
assert float(np.nanmax(md.closure_residual)) < 1e-9 and error < 0.02

# %% [markdown]
# ## Plot φ0 and its rate against the crank angle

# %%
import matplotlib.pyplot as plt  # noqa: E402

x = np.degrees(spec.inputs)
fig, (a0, a1) = plt.subplots(1, 2, figsize=(10, 3.5))
for m in motion.modes:
    a0.plot(x, units.show("angle", m.variables["phi0"]), label=f"mode {m.index}")
    a1.plot(x, units.show("angular_velocity", m.velocities["phi0"]), label=f"mode {m.index}")
a0.set(xlabel="crank angle (deg)", ylabel=f"φ0 ({units.label('angle')})")
a1.set(xlabel="crank angle (deg)", ylabel=f"φ0' ({units.label('angular_velocity')})")
a0.legend()
fig.tight_layout()

# %% [markdown]
# ## Animate it
# `view` returns the report page inline (an iframe in Jupyter): the 3-D view plays the cycle,
# with plots of every variable linked to the frame shown. `.save("rssr.html")` writes it.

# %%
from screwkit.report.notebook import view  # noqa: E402

report = view(motion, spec)
html = report._repr_html_()
print(f"inline report: {len(html) / 1e6:.2f} MB of HTML")
report  # noqa: B018 - the last value of a cell is what Jupyter shows
