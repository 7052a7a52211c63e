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
# # A Bagci synthesis: an RSRC for a desired screw displacement
#
# `examples/bagci_example1_synthesis.toml` is Bagci's Example 1 (1969, Ch. V, Program B): find
# the RSRC whose output dwells in rotation while it translates as asked, by least squares with
# exact derivatives. We run it, read the dimensions in the spec's units (inches, degrees),
# compare desired and generated motion, and analyse the mechanism we found over a full turn.

# %%
from pathlib import Path

import numpy as np

import screwkit as sk

HERE = Path.cwd()
EXAMPLES = next(p for p in (HERE / "..", HERE / "examples", HERE)
                if (p / "bagci_example1_synthesis.toml").exists())
spec = sk.load_spec(EXAMPLES / "bagci_example1_synthesis.toml")
run = sk.synthesize(spec.synthesis)
best = run.results[0]
print(f"{best.status}: {best.iterations} iterations, RMSE {best.rmse:.3g}")

# %% [markdown]
# ## The dimensions found, in the spec's units

# %%
units = spec.display_units()
angles = {"delta0", "lambda0", "theta01"}
for name, value in best.dimensions.items():
    kind = "angle" if name in angles else "length"
    print(f"{name:>8} = {units.show(kind, value):10.5f} {units.label(kind)}")

# %% [markdown]
# ## Desired against generated at the design points (as Bagci's tables)

# %%
from screwkit.io.documents import synthesis_document  # noqa: E402
from screwkit.io.tables import synthesis_table  # noqa: E402

doc = synthesis_document(run, spec.path)
table = synthesis_table(doc)
print(table.csv_text(units).splitlines()[0])
conv = {name: values for name, _, values in table.converted(units)}
worst = np.nanmax(np.abs(conv["psi_d0_minus_psi_g0"]))
print(f"largest rotation error: {worst:.4f} {units.label('angle')}")
assert worst < 0.05

# %%
import matplotlib.pyplot as plt  # noqa: E402

fig, (a0, a1) = plt.subplots(1, 2, figsize=(10, 3.5))
a0.plot(conv["theta"], conv["psi_d0"], "o", label="desired ψ_d0")
a0.plot(conv["theta"], conv["psi_g0"], "x-", label="generated ψ_g0")
a0.set(xlabel=f"θ from θ01 ({units.label('angle')})", ylabel=f"rotation ({units.label('angle')})")
a1.plot(conv["theta"], conv["S_d"], "o", label="desired S_d")
a1.plot(conv["theta"], conv["S_g"], "x-", label="generated S_g")
a1.set(xlabel=f"θ from θ01 ({units.label('angle')})",
       ylabel=f"translation ({units.label('length')})")
a0.legend()
a1.legend()
fig.tight_layout()

# %% [markdown]
# ## The mechanism over a full turn
# Build the RSRC from the dimensions found and solve it: it must run the whole range on one
# branch (the synthesis checked it; here the analysis shows it).

# %%
d = best.dimensions
mechanism = sk.rsrc(d["d1"], d["d2"], d["d3"], d["a"], d["b"], d["e"], d["delta0"],
                    d["lambda0"])
theta = d["theta01"] + np.radians(np.arange(0.0, 360.0, 5.0))
motion = sk.solve_motion(mechanism, theta, rates=1.0)
for m in motion.modes:
    print(f"mode {m.index}: assembles at {int(m.assembles.sum())} of {m.samples} inputs")
print(best.range_check.message)
