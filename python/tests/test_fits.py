"""Fits from numpy arrays: known laws recovered within their intervals, refusals, bad input,
calibrated-law JSON (schemas 1 and 2) and vectorised evaluation."""

import json

import numpy as np
import pytest

import grainlaw

# A deterministic ±1 pattern uncorrelated with the regressors (no random seed to depend on).
def wiggle(n, phase=0):
    return np.array([1.0 if (3 * i + phase) % 7 < 3 else -1.0 for i in range(n)])


def mu_i_law(I, mu_s, mu_2, I_0):
    return mu_s + (mu_2 - mu_s) * I / (I + I_0)


def test_mu_i_recovers_the_generating_law_within_its_interval():
    truth = {"mu_s": 0.38, "mu_2": 0.64, "I_0": 0.279}
    I = np.geomspace(1e-3, 1.0, 40)
    mu = mu_i_law(I, **truth) + 0.004 * wiggle(I.size)
    law = grainlaw.fit_mu_i(I, mu, grain_diameter=1e-3, grain_density=2500.0)
    assert law.name == "mu-i"
    for name, value in truth.items():
        lo, hi = law.intervals[name]
        assert lo <= value <= hi, (name, value, lo, hi)
        # the noise is 1 % of μ: each parameter within 10 % of the truth
        assert abs(law.values[name] - value) <= 0.1 * value, (name, law.values[name])
    assert law.r_squared > 0.99
    assert law.n == 40 and law.dof == 37
    cov = law.covariance
    assert cov.shape == (3, 3)
    assert law.covariance_order == ["mu_s", "mu_2", "I_0"]
    # the standard errors are the square roots of the covariance's diagonal (1e-12 relative)
    for k, name in enumerate(law.covariance_order):
        assert abs(np.sqrt(cov[k, k]) - law.std_errors[name]) <= 1e-12 * law.std_errors[name]
    # the constants record the grain scale
    assert law.constants == {"d": 1e-3, "rho_s": 2500.0}
    # a fit that passed every check carries the verdict a run's laws carry: ok, no reasons
    assert law.verdict == "ok" and law.verdict_reasons == []
    assert law.to_dict()["verdict"] == "ok"
    assert grainlaw.law_from_json(law.to_json()).verdict == "ok"


def test_mu_i_linear_recovers_slope_and_intercept():
    I = np.linspace(0.01, 0.2, 25)
    mu = 0.3 + 0.9 * I + 0.002 * wiggle(I.size, 1)
    law = grainlaw.fit_mu_i_linear(I, mu, grain_diameter=2e-3, grain_density=2600.0)
    assert law.intervals["mu_s"][0] <= 0.3 <= law.intervals["mu_s"][1]
    assert law.intervals["b"][0] <= 0.9 <= law.intervals["b"][1]
    assert abs(law["b"] - 0.9) < 0.05
    # evaluation is the line, to rounding
    x = np.array([0.05, 0.1, 0.15])
    assert np.allclose(law.evaluate(x), law["mu_s"] + law["b"] * x, rtol=1e-14, atol=0)


def test_janssen_recovers_k_and_wall_friction():
    W, rho_b, g = 0.03, 1600.0, 9.81
    K, mu_w = 0.6, 0.2
    z = 0.01 * np.arange(1, 21)
    sv = rho_b * g * W / (2 * K * mu_w) * (1 - np.exp(-2 * K * mu_w * z / W))
    w = wiggle(z.size)
    law = grainlaw.fit_janssen(
        z, sv + 5.0 * w, K * sv - 3.0 * w, width=W, bulk_density=rho_b, wall_friction=0.25
    )
    assert law.intervals["K"][0] <= K <= law.intervals["K"][1]
    assert law.intervals["mu_w"][0] <= mu_w <= law.intervals["mu_w"][1]
    assert abs(law["K"] - K) < 0.02
    # σ_v of the fitted law at the data's depths is within 1 % of the generating profile
    assert np.max(np.abs(law.evaluate(z) / sv - 1)) < 0.01
    # evaluate keeps the input's shape
    assert law.evaluate(z.reshape(4, 5)).shape == (4, 5)


def test_mohr_coulomb_cohesionless_from_mohr_circles():
    phi = np.radians(30.0)
    p = np.linspace(1e3, 1e4, 8)
    q = p * np.sin(phi) * (1 + 0.002 * wiggle(p.size))
    law = grainlaw.fit_mohr_coulomb(p=p, q=q, cohesionless=True)
    lo, hi = law.intervals["friction_angle"]
    assert lo <= phi <= hi
    assert abs(law["friction_angle"] - phi) < np.radians(0.5)
    assert law.parameters["cohesion"]["at_bound"] is True


def test_mu_i_on_a_straight_line_is_refused_with_the_linear_form_suggested():
    # data without the saturation of μ(I): the three-parameter law is not supported
    I = np.linspace(0.01, 0.05, 20)
    mu = 0.3 + 0.5 * I + 0.001 * wiggle(I.size)
    with pytest.raises(grainlaw.FitRefused) as e:
        grainlaw.fit_mu_i(I, mu, grain_diameter=1e-3, grain_density=2500.0)
    assert isinstance(e.value, grainlaw.GrainlawError)
    assert e.value.reason
    assert e.value.suggestion is not None and "mu-i-linear" in e.value.suggestion


def test_bad_input_raises_input_error_naming_the_problem():
    with pytest.raises(grainlaw.InputError, match="mu"):
        grainlaw.fit_mu_i([0.1, 0.2, 0.3], [0.4, 0.5], grain_diameter=1e-3, grain_density=2500.0)
    with pytest.raises(grainlaw.InputError, match=r"not finite"):
        grainlaw.fit_mu_i(
            [0.1, 0.2, np.nan, 0.4, 0.5], [0.4, 0.5, 0.5, 0.6, 0.6], grain_diameter=1e-3, grain_density=2500.0
        )
    with pytest.raises(grainlaw.InputError, match="unknown law"):
        grainlaw.fit("hooke", {"x": [1.0, 2.0]})
    I = np.geomspace(1e-3, 1.0, 20)
    mu = mu_i_law(I, 0.38, 0.64, 0.279) + 0.004 * wiggle(I.size)
    with pytest.raises(grainlaw.InputError, match="grain_density_kg_m3"):
        grainlaw.fit("mu-i", {"I": I, "mu": mu}, {"grain_diameter_m": 1e-3})


def test_law_json_round_trip_and_formula_evaluation(tmp_path):
    I = np.geomspace(1e-3, 1.0, 30)
    law = grainlaw.fit_mu_i(I, mu_i_law(I, 0.4, 0.7, 0.3) + 0.003 * wiggle(I.size), grain_diameter=1e-3, grain_density=2500.0)
    path = tmp_path / "mu_i_law.json"
    law.save(path)
    back = grainlaw.load_law(path)
    assert back.schema_version == 2
    assert back.values == law.values and back.intervals == law.intervals
    assert np.array_equal(back.covariance, law.covariance)
    x = np.linspace(1e-3, 1.0, 101)
    y = back.evaluate(x)
    # the typed law, the JSON's formula text and the closed form agree to 1e-13
    assert np.allclose(y, back.evaluate_formula(x), rtol=1e-13, atol=0)
    v = back.values
    assert np.allclose(y, mu_i_law(x, v["mu_s"], v["mu_2"], v["I_0"]), rtol=1e-13, atol=0)
    assert list(back.in_validity_range([1e-4, 0.5, 2.0])) == [False, True, False]
    assert json.loads(back.to_json())["law"] == "mu-i"


SCHEMA_1 = """{
  "schema_version": 1, "law": "janssen",
  "formula": "sigma_v(z) = rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W)); sigma_h = K*sigma_v; tau_w = mu_w*sigma_h",
  "input": {"name": "z", "unit": "m"}, "output": {"name": "sigma_v", "unit": "Pa"},
  "parameters": [
    {"name": "K", "unit": "1", "value": 0.6, "std_error": 0.01, "ci_low": 0.58, "ci_high": 0.62, "at_bound": false},
    {"name": "mu_w", "unit": "1", "value": 0.2, "std_error": 0.01, "ci_low": 0.18, "ci_high": 0.22, "at_bound": false},
    {"name": "K_mu_w", "unit": "1", "value": 0.12, "std_error": 0.003, "ci_low": 0.114, "ci_high": 0.126, "at_bound": false}
  ],
  "constants": [{"name": "width", "unit": "m", "value": 0.03}, {"name": "bulk_density", "unit": "kg/m^3", "value": 1600.0},
                {"name": "gravity", "unit": "m/s^2", "value": 9.81}, {"name": "wall_friction", "unit": "1", "value": 0.25}],
  "validity": [{"variable": "z", "unit": "m", "min": 0.01, "max": 0.3}],
  "fit": {"n": 60, "dof": 58, "r_squared": 0.998, "aic": 0.0, "bic": 0.0, "confidence": 0.95},
  "model_selection": null,
  "provenance": {"scenario": "janssen", "seed": 1, "grainlaw_version": "0.1.0", "source": null}
}"""


def test_schema_1_law_is_read_and_evaluated_vectorised():
    law = grainlaw.law_from_json(SCHEMA_1)
    assert law.schema_version == 1
    assert law.covariance is None
    z = np.linspace(0.0, 0.3, 7)
    W, rho_b, g, K, mu_w = 0.03, 1600.0, 9.81, 0.6, 0.2
    expected = rho_b * g * W / (2 * K * mu_w) * (1 - np.exp(-2 * K * mu_w * z / W))
    assert np.allclose(law.evaluate(z), expected, rtol=1e-13, atol=1e-12)


def test_malformed_law_json_is_an_input_error():
    with pytest.raises(grainlaw.InputError):
        grainlaw.law_from_json('{"schema_version": 3}')
    with pytest.raises(grainlaw.InputError):
        grainlaw.law_from_json("not json")
