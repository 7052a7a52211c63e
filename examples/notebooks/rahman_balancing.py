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
# # Rahman's optimum balancing of the CSSP slider-crank, before and after
#
# `examples/rahman_cssp_balance.toml` is Rahman's 1996 example (§5.2) with his balancing
# problem: the point masses of the crank's and the rod's seven-point models may each fall by 5 %,
# pair sums kept. We run the QP, read the measures both normalised (Rahman eq. 4.1) and as RMS
# loads in N and N·m, see which bounds are active, and plot every load before and after.

# %%
from pathlib import Path

import numpy as np

import screwkit as sk
from screwkit.io.documents import active_bounds, measures_rms

HERE = Path.cwd()
EXAMPLES = next(p for p in (HERE / "..", HERE / "examples", HERE)
                if (p / "rahman_cssp_balance.toml").exists())
spec = sk.load_spec(EXAMPLES / "rahman_cssp_balance.toml")
result = sk.Pipeline(spec).balance()
print(spec.describe())

# %% [markdown]
# ## The measures: normalised, and as the RMS loads they stand for

# %%
rms = measures_rms(result)
for key in ("F", "T", "R", "M", "T0"):
    print(f"{key:>2}: {result.measures_before[key]:9.4f} -> {result.measures_after[key]:9.4f}"
          f"   RMS {rms['before'][key]:10.2f} -> {rms['after'][key]:10.2f} {rms['units'][key]}"
          f"  ({rms['change_percent'][key]:+.2f} %)")
print("objective G:", round(result.measures_before["G"], 4), "->",
      round(result.measures_after["G"], 4))

# %% [markdown]
# The RMS shaking force is the measure undone (F0·√F); it must equal the RMS of the per-sample
# shaking force — an independent check of the normalisation.

# %%
direct = np.sqrt(np.mean(result.per_sample_after["shaking_force"] ** 2))
print(f"RMS shaking force after: {rms['after']['F']:.6g} N from F, {direct:.6g} N per sample")
assert abs(direct - rms["after"]["F"]) <= 1e-9 * direct

# %% [markdown]
# ## Which bounds the optimum presses on

# %%
for b in active_bounds(result):
    print(f"{b['variable']:>9} at its {b['bound']} bound ({b['constraint']})")
print("unique optimum:", result.unique)

# %% [markdown]
# ## Every load over the cycle, before and after
# The per-sample table (`result.table()`, `result.to_csv(...)`) in the spec's units.

# %%
import matplotlib.pyplot as plt  # noqa: E402

from screwkit.balancing.result import SAMPLE_LOADS  # noqa: E402

units = spec.display_units()
table = result.table()
conv = {name: (label, values) for name, label, values in table.converted(units)}
x_label, x = conv["input"]
fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
for ax, (key, title, _) in zip(axes.flat, SAMPLE_LOADS, strict=True):
    label, before = conv[f"{key}_before"]
    _, after = conv[f"{key}_after"]
    ax.plot(x, before, "o-", ms=3, label="before")
    ax.plot(x, after, "s--", ms=3, label="after")
    ax.set_title(f"{title}" + (f" ({label})" if label else ""), fontsize=9)
for ax in axes[-1]:
    ax.set_xlabel(f"crank angle ({x_label})")
axes[0, 0].legend()
fig.tight_layout()

# %% [markdown]
# ## New mass properties (like Rahman's Table 5.1)
# In the spec's units (`spec.display_units()`: in, lbf·s²·in); `mass_properties_table()` alone
# gives SI.

# %%
for link, quantity, before, after in result.mass_properties_table(units)[:6]:
    print(f"{link:>6} {quantity:<24} {before:12.6g} -> {after:12.6g}")
