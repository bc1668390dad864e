"""The Janssen pipeline from Python: run a small column, fit Janssen's law to its wall profile,
print K with its 95 % interval (the same fit the run made, from the same numbers)."""

import sys

import grainlaw

grains = int(sys.argv[1]) if len(sys.argv) > 1 else 140
result = grainlaw.run("janssen", overrides={"grains": grains})  # GIL released while it runs
summary, profile = result["summary"], result["tables"]["wall_profile"]
setup = result["constants"]["wall_profile"]  # width_m, bulk_density_kg_m3, wall_friction, ...

law = grainlaw.fit_janssen(
    profile["z_m"], profile["sigma_v_Pa"], profile["sigma_h_Pa"],  # m, Pa (compressive positive)
    tau_w=profile.get("tau_w_Pa"),
    width=setup["width_m"], bulk_density=setup["bulk_density_kg_m3"], wall_friction=setup["wall_friction"],
    gravity=setup["gravity_m_s2"], depth_min=setup["depth_min_m"], depth_max=setup["depth_max_m"],
    full_mobilisation=setup.get("full_mobilisation", 0.0) == 1.0,
)
lo, hi = law.intervals["K"]
print(f"{grains} grains, {summary['wall_seconds']:.1f} s of simulation")
print(f"K    = {law['K']:.3f}  (95 % CI {lo:.3f} … {hi:.3f}); the run's own fit: {summary['janssen_K']:.3f}")
print(f"μ_w  = {law['mu_w']:.3f}  (95 % CI {law.intervals['mu_w'][0]:.3f} … {law.intervals['mu_w'][1]:.3f}), R² = {law.r_squared:.3f}")
