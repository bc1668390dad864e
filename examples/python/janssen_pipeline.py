"""The Janssen pipeline from Python: run a small column, fit Janssen's law to its wall profile,
print K with its 95 % interval (the same fit the run made, from the same numbers), and the
run's verdict, which `grainlaw.run` makes as loud as the command line's exit status."""

import sys

import grainlaw

grains = int(sys.argv[1]) if len(sys.argv) > 1 else 350
try:
    result = grainlaw.run("janssen", overrides={"grains": grains})  # GIL released while it runs
except grainlaw.ResultSuspect as e:
    # suspect: `grainlaw run` exits 3 and exports no law; its numbers are shown below, marked
    result = e.result  # (grainlaw.ResultRefused, a refused run, is not caught: it stops here)
summary, profile = result["summary"], result["tables"]["wall_profile"]
setup = result["constants"]["wall_profile"]  # width_m, bulk_density_kg_m3, wall_friction, ...
print(f"{grains} grains, {summary['wall_seconds']:.1f} s of simulation")
print(f"verdict: {result['verdict']}")
for r in result["verdict_reasons"]:
    print(f"  {r['verdict']}: {r['check']}: {r['message']}")

law = grainlaw.fit_janssen(
    profile["z_m"], profile["sigma_v_Pa"], profile["sigma_h_Pa"],  # m, Pa (compressive positive)
    tau_w=profile.get("tau_w_Pa"),
    width=setup["width_m"], bulk_density=setup["bulk_density_kg_m3"], wall_friction=setup["wall_friction"],
    gravity=setup["gravity_m_s2"], depth_min=setup["depth_min_m"], depth_max=setup["depth_max_m"],
    full_mobilisation=setup.get("full_mobilisation", 0.0) == 1.0,
)
lo, hi = law.intervals["K"]
if result["verdict"] != "ok":
    print(f"NOT a calibrated law: the run that measured this profile is {result['verdict']} (above)")
print(f"K    = {law['K']:.3f}  (95 % CI {lo:.3f} … {hi:.3f}); the run's own fit: {summary['janssen_K']:.3f}")
print(f"μ_w  = {law['mu_w']:.3f}  (95 % CI {law.intervals['mu_w'][0]:.3f} … {law.intervals['mu_w'][1]:.3f}), R² = {law.r_squared:.3f}")
print(f"the fit's own verdict: {law.verdict} (its checks; the data's verdict is the run's)")
