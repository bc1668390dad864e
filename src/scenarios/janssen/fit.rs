//! The Janssen fit of a measured column profile, and the confidence band of its stresses.
//!
//! Janssen's law `σ_v(z) = ρ_b g W/(2Kμ_w) (1 − exp(−2Kμ_w z/W))`, `σ_h = K σ_v`,
//! `τ_w = μ_w σ_h` (Janssen 1895; Sperl 2006, Granular Matter 8, 59) is fitted jointly for K and
//! μ_w (bounded by the wall friction, `identify::janssen`); if μ_w ends at that bound, the fit
//! with μ_w = μ_wall (full mobilisation, Janssen's assumption) is reported instead.

use identify::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, JanssenFit, JanssenOptions, JanssenProfile,
    JanssenSetup,
};
use identify::IdentifyError;

use super::measure::ColumnProfile;

/// The Janssen fit of a column, with how it was obtained.
pub struct JanssenOutcome {
    /// The fit.
    pub fit: JanssenFit,
    /// `joint` (K and μ_w free) or `full_mobilisation` (μ_w = μ_wall).
    pub mode: &'static str,
    /// Whether τ_w entered the fit (left out when a bin in the window has τ_w < 0, i.e. the
    /// wall friction pushes the grains down there).
    pub uses_tau_w: bool,
}

/// Fits Janssen's law (joint; full mobilisation if μ_w reaches the wall friction).
pub fn fit_profile(
    p: &ColumnProfile,
    setup: &JanssenSetup,
    window: (f64, f64),
) -> std::result::Result<JanssenOutcome, IdentifyError> {
    let uses_tau_w = p.negative_tau_w(window).is_empty();
    let profile = JanssenProfile {
        z_m: p.z.clone(),
        sigma_v_pa: p.sigma_v.clone(),
        sigma_h_pa: Some(p.sigma_h.clone()),
        tau_w_pa: uses_tau_w.then(|| p.tau_w.clone()),
    };
    let opts = JanssenOptions {
        depth_window: Some(window),
        ..Default::default()
    };
    match fit_janssen(&profile, setup, &opts) {
        Ok(fit) => Ok(JanssenOutcome {
            fit,
            mode: "joint",
            uses_tau_w,
        }),
        Err(IdentifyError::ParameterAtBound { name, bound, .. })
            if name == "mu_w"
                && (bound - setup.wall_friction).abs() <= 1e-12 * bound.abs().max(1.0) =>
        {
            let fit = fit_janssen_full_mobilisation(&profile, setup, &opts)?;
            Ok(JanssenOutcome {
                fit,
                mode: "full_mobilisation",
                uses_tau_w,
            })
        }
        Err(e) => Err(e),
    }
}

/// 95 % band of `σ_v(z)` and `σ_h(z)` of a fit by the delta method on (K, μ_w):
/// rows `(z, σ_v, σ_v lo, σ_v hi, σ_h, σ_h lo, σ_h hi)`.
pub fn fit_band(fit: &JanssenFit, zs: &[f64]) -> Vec<[f64; 7]> {
    let law = fit.law;
    let cov = &fit.report.covariance;
    let t = fit.report.t_critical;
    let free_mu = cov.len() >= 2;
    let eval = |k: f64, mu: f64, z: f64| {
        let l = identify::laws::janssen::JanssenLaw { k, mu_w: mu, ..law };
        (l.sigma_v(z), l.sigma_h(z))
    };
    zs.iter()
        .map(|&z| {
            let (sv, sh) = eval(law.k, law.mu_w, z);
            let hk = 1e-6 * law.k.abs().max(1e-9);
            let hm = 1e-6 * law.mu_w.abs().max(1e-9);
            let (svk, shk) = eval(law.k + hk, law.mu_w, z);
            let (svm, shm) = eval(law.k, law.mu_w + hm, z);
            let gv = [(svk - sv) / hk, (svm - sv) / hm];
            let gh = [(shk - sh) / hk, (shm - sh) / hm];
            let var = |g: [f64; 2]| {
                let mut v = g[0] * g[0] * cov[0][0];
                if free_mu {
                    v += 2.0 * g[0] * g[1] * cov[0][1] + g[1] * g[1] * cov[1][1];
                }
                v.max(0.0)
            };
            let (ev, eh) = (t * var(gv).sqrt(), t * var(gh).sqrt());
            [z, sv, sv - ev, sv + ev, sh, sh - eh, sh + eh]
        })
        .collect()
}
