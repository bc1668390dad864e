//! The law's uncertainty carried through a continuum run (`docs/continuum.md` §5).
//!
//! **Which parameter sets.** The law JSON carries, for its parameters `θ` (registry order),
//! estimates, standard errors, 95 % intervals and the full covariance `Σ` of the fit. The
//! intervals' corners (2^p sets) ignore the correlation of the parameters — strong in μ(I)
//! fits, where `μ_s`, `μ₂` and `I₀` trade off along the data — so most corners lie far outside
//! the confidence region the data allow, and a band drawn through them is too wide. Random
//! draws from `N(θ̂, Σ)` respect it but need tens of runs for stable percentiles. The runs here
//! are the 2p + 1 points `θ̂` and `θ̂ ± t √λ_k e_k` along the principal axes `(λ_k, e_k)` of
//! `Σ`, `t` the critical value of the law's own intervals (`t_{0.975, dof}`): the edges of the
//! law's confidence region along each independent direction (the sigma points of the unscented
//! transform, Julier & Uhlmann 1997, scaled to the law's confidence).
//!
//! **The band.** For an output `f` of the run (the front `x_f` at an instant, the runout), the
//! half-width is `h = √(Σ_k ((f_k⁺ − f_k⁻)/2)²)`: for `f` linear in `θ` over the region it is
//! exactly `t √(∇fᵀ Σ ∇f)`, the law's interval carried to `f` (delta method), measured by
//! finite differences across the whole region rather than a derivative at `θ̂`. A pair with one
//! run missing (an unphysical set: `μ₂ ≤ μ_s`, `I₀ ≤ 0`, …, not run) counts its one-sided
//! difference. The band is `[f(θ̂) − h, f(θ̂) + h]`; the runs' envelope is reported too.

use nalgebra::{DMatrix, SymmetricEigen};
use serde::Serialize;

use identify::law::CalibratedLaw;

use crate::error::{CliError, Result};

/// One parameter set of the band's runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterSet {
    /// `central`, or `axis{k}+` / `axis{k}-`.
    pub label: String,
    /// Parameter values, in the law's order.
    pub values: Vec<f64>,
    /// `(k, ±1)` for a point on the k-th principal axis, `None` for the central set.
    pub axis: Option<(usize, i8)>,
}

/// The parameter sets (module documentation): the central one first, then `+`/`−` along each
/// principal axis of the covariance with a positive eigenvalue, largest first. Errors:
/// [`CliError::Input`] when the law has no covariance (schema 1) or it is not finite.
pub fn parameter_sets(law: &CalibratedLaw, path: &str) -> Result<Vec<ParameterSet>> {
    let cov = law.covariance.as_ref().ok_or_else(|| CliError::Input {
        path: path.into(),
        reason: "the law carries no covariance (a schema-1 law): no uncertainty band; fit it again with grainlaw fit".into(),
    })?;
    let n = law.parameters.len();
    // the covariance in the parameters' order
    let index: Vec<usize> = law
        .parameters
        .iter()
        .map(|p| cov.order.iter().position(|o| *o == p.name))
        .collect::<Option<_>>()
        .ok_or_else(|| CliError::Input {
            path: path.into(),
            reason: format!(
                "covariance order {:?} does not name every parameter",
                cov.order
            ),
        })?;
    let m = DMatrix::from_fn(n, n, |i, j| cov.matrix[index[i]][index[j]]);
    if m.iter().any(|v| !v.is_finite()) {
        return Err(CliError::Input {
            path: path.into(),
            reason: "the covariance holds a number that is not finite".into(),
        });
    }
    let t = identify::stats::t_critical(law.fit.confidence, law.fit.dof.max(1));
    let eig = SymmetricEigen::new(m.clone());
    let mut axes: Vec<(f64, Vec<f64>)> = (0..n)
        .map(|k| {
            (
                eig.eigenvalues[k],
                eig.eigenvectors.column(k).iter().copied().collect(),
            )
        })
        .filter(|(l, _)| *l > 1e-14 * m.diagonal().max().max(0.0))
        .collect();
    axes.sort_by(|a, b| b.0.total_cmp(&a.0));
    let central: Vec<f64> = law.parameters.iter().map(|p| p.value).collect();
    let mut sets = vec![ParameterSet {
        label: "central".into(),
        values: central.clone(),
        axis: None,
    }];
    for (k, (lambda, e)) in axes.iter().enumerate() {
        for sign in [1i8, -1] {
            let s = f64::from(sign) * t * lambda.sqrt();
            sets.push(ParameterSet {
                label: format!("axis{}{}", k + 1, if sign > 0 { '+' } else { '-' }),
                values: central.iter().zip(e).map(|(c, ek)| c + s * ek).collect(),
                axis: Some((k, sign)),
            });
        }
    }
    Ok(sets)
}

/// An output's band from its runs (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Band {
    /// The central run's value.
    pub central: f64,
    /// Lower end `central − h`.
    pub low: f64,
    /// Upper end `central + h`.
    pub high: f64,
    /// Smallest value of the runs.
    pub envelope_low: f64,
    /// Largest value of the runs.
    pub envelope_high: f64,
}

impl Band {
    /// The band of one output: `central` and, per principal axis, the values of its `+` and
    /// `−` runs (`None` for a run not made or without this output). `None` when the central
    /// value is not finite.
    pub fn of(central: f64, pairs: &[(Option<f64>, Option<f64>)]) -> Option<Band> {
        if !central.is_finite() {
            return None;
        }
        let ok = |v: &Option<f64>| v.filter(|x| x.is_finite());
        let mut sq = 0.0;
        let (mut lo, mut hi) = (central, central);
        for (p, m) in pairs {
            let half = match (ok(p), ok(m)) {
                (Some(a), Some(b)) => 0.5 * (a - b),
                (Some(a), None) => a - central,
                (None, Some(b)) => central - b,
                (None, None) => 0.0,
            };
            sq += half * half;
            for v in [ok(p), ok(m)].into_iter().flatten() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let h = sq.sqrt();
        Some(Band {
            central,
            low: central - h,
            high: central + h,
            envelope_low: lo,
            envelope_high: hi,
        })
    }

    /// Whether `v` lies in `[low, high]`.
    pub fn contains(&self, v: f64) -> bool {
        self.low <= v && v <= self.high
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For an output linear in the parameters, the band's half-width from the axis runs is the
    /// delta method's `t √(gᵀ Σ g)`, to rounding.
    #[test]
    fn axis_runs_give_the_delta_method_for_a_linear_output() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/fixtures/continuum/lagree2011_mu_i_law.json"
        ))
        .unwrap();
        let law = CalibratedLaw::from_json_str(&text).unwrap();
        let sets = parameter_sets(&law, "law.json").unwrap();
        assert_eq!(sets.len(), 7);
        assert_eq!(sets[0].label, "central");
        let g = [2.0, -1.5, 4.0];
        let f = |v: &[f64]| v.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>();
        let pairs: Vec<_> = (0..3)
            .map(|k| {
                (
                    Some(f(&sets[1 + 2 * k].values)),
                    Some(f(&sets[2 + 2 * k].values)),
                )
            })
            .collect();
        let band = Band::of(f(&sets[0].values), &pairs).unwrap();
        let c = &law.covariance.as_ref().unwrap().matrix;
        let var: f64 = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| g[i] * c[i][j] * g[j])
            .sum();
        let t = identify::stats::t_critical(law.fit.confidence, law.fit.dof);
        let want = t * var.sqrt();
        assert!(
            ((band.high - band.central) - want).abs() < 1e-9 * want,
            "{} vs {want}",
            band.high - band.central
        );
        assert!(band.contains(band.central) && !band.contains(band.high + 1e-9));
        // a missing run counts its one-sided difference; no finite central value, no band
        let one = Band::of(1.0, &[(Some(1.5), None), (None, Some(0.0))]).unwrap();
        assert!((one.high - (1.0 + (0.25f64 + 1.0).sqrt())).abs() < 1e-15);
        assert_eq!((one.envelope_low, one.envelope_high), (0.0, 1.5));
        assert!(Band::of(f64::NAN, &[]).is_none());
    }
}
