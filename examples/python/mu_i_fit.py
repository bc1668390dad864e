"""A μ(I) fit from your own arrays: inertial numbers and stress ratios measured in a shear cell
(here made up from a known law and a little noise), the law with its intervals, its JSON, and
its evaluation on a grid, its verdict. A refused fit says why and what simpler form to try."""

import numpy as np

import grainlaw

rng = np.random.default_rng(7)
I = np.geomspace(2e-3, 0.8, 30)                                   # inertial number (1)
mu = 0.38 + (0.64 - 0.38) * I / (I + 0.28) + rng.normal(0, 0.004, I.size)  # τ/P (1)

law = grainlaw.fit_mu_i(I, mu, grain_diameter=1e-3, grain_density=2500.0)  # d (m), ρ_s (kg/m³)
for name, value in law.values.items():
    lo, hi = law.intervals[name]
    print(f"{name:5} = {value:.4f}  (95 % CI {lo:.4f} … {hi:.4f})")
print(f"R² = {law.r_squared:.4f}; μ at I = 0.01, 0.1, 1: {np.round(law.evaluate([0.01, 0.1, 1.0]), 4)}")
print(f"verdict: {law.verdict}")  # ok: every check passed (a refused fit raises FitRefused)
law.save("mu_i_law.json")  # schema 2, readable by grainlaw.load_law and continuum solvers

try:  # a narrow range of I does not resolve the saturation: refused, with the simpler form
    grainlaw.fit_mu_i(I[:8], 0.3 + 0.5 * I[:8], grain_diameter=1e-3, grain_density=2500.0)
except grainlaw.FitRefused as e:
    print(f"refused: {e.reason}\n  suggestion: {e.suggestion}")
