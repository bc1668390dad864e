//! Effective wall friction against normalised slip velocity.
//!
//! `μ_eff = τ_w / σ_w` (1) as a function of `V = V_s / √(g d)` (1), `V_s` the slip velocity of
//! the grains along the wall (m/s), `d` the mean grain diameter (m):
//! - exponential saturation: `μ_eff = μ_∞ − (μ_∞ − μ_0) exp(−V/V*)`;
//! - hyperbolic saturation: `μ_eff = μ_0 + (μ_∞ − μ_0) V/(V + V*)`;
//! - power law: `μ_eff = μ_0 + k V^n`.

use serde::{Deserialize, Serialize};

/// One of the candidate wall-friction laws.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "form", rename_all = "kebab-case")]
pub enum WallFrictionLaw {
    /// `μ_∞ − (μ_∞ − μ_0) exp(−V/V*)`.
    Exponential {
        /// `μ_eff(0)`.
        mu_0: f64,
        /// `μ_eff(∞)`.
        mu_inf: f64,
        /// Velocity scale `V*` (1).
        v_star: f64,
    },
    /// `μ_0 + (μ_∞ − μ_0) V/(V + V*)`.
    Hyperbolic {
        /// `μ_eff(0)`.
        mu_0: f64,
        /// `μ_eff(∞)`.
        mu_inf: f64,
        /// Velocity scale `V*` (1), where half the rise is reached.
        v_star: f64,
    },
    /// `μ_0 + k V^n`.
    PowerLaw {
        /// `μ_eff(0)`.
        mu_0: f64,
        /// Prefactor `k`.
        k: f64,
        /// Exponent `n`.
        n: f64,
    },
}

impl WallFrictionLaw {
    /// `μ_eff(V)` for `V ≥ 0`.
    pub fn mu_eff(&self, v: f64) -> f64 {
        match *self {
            WallFrictionLaw::Exponential {
                mu_0,
                mu_inf,
                v_star,
            } => mu_inf - (mu_inf - mu_0) * (-v / v_star).exp(),
            WallFrictionLaw::Hyperbolic {
                mu_0,
                mu_inf,
                v_star,
            } => mu_0 + (mu_inf - mu_0) * v / (v + v_star),
            WallFrictionLaw::PowerLaw { mu_0, k, n } => mu_0 + k * v.max(0.0).powf(n),
        }
    }

    /// Parameter vector in fit order.
    pub fn parameters(&self) -> [f64; 3] {
        match *self {
            WallFrictionLaw::Exponential {
                mu_0,
                mu_inf,
                v_star,
            }
            | WallFrictionLaw::Hyperbolic {
                mu_0,
                mu_inf,
                v_star,
            } => [mu_0, mu_inf, v_star],
            WallFrictionLaw::PowerLaw { mu_0, k, n } => [mu_0, k, n],
        }
    }

    /// `∂μ_eff/∂θ` in fit order.
    pub fn gradient(&self, v: f64) -> [f64; 3] {
        match *self {
            WallFrictionLaw::Exponential {
                mu_0,
                mu_inf,
                v_star,
            } => {
                let e = (-v / v_star).exp();
                [e, 1.0 - e, -(mu_inf - mu_0) * e * v / (v_star * v_star)]
            }
            WallFrictionLaw::Hyperbolic {
                mu_0,
                mu_inf,
                v_star,
            } => {
                let s = v / (v + v_star);
                [
                    1.0 - s,
                    s,
                    -(mu_inf - mu_0) * v / ((v + v_star) * (v + v_star)),
                ]
            }
            WallFrictionLaw::PowerLaw { k, n, .. } => {
                if v <= 0.0 {
                    return [1.0, 0.0, 0.0];
                }
                let p = v.powf(n);
                [1.0, p, k * p * v.ln()]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_gradients() {
        let e = WallFrictionLaw::Exponential {
            mu_0: 0.1,
            mu_inf: 0.4,
            v_star: 0.5,
        };
        assert!((e.mu_eff(0.0) - 0.1).abs() < 1e-15);
        assert!((e.mu_eff(100.0) - 0.4).abs() < 1e-15);
        let h = WallFrictionLaw::Hyperbolic {
            mu_0: 0.1,
            mu_inf: 0.4,
            v_star: 0.5,
        };
        assert!((h.mu_eff(0.5) - 0.25).abs() < 1e-15);
        for law in [
            e,
            h,
            WallFrictionLaw::PowerLaw {
                mu_0: 0.1,
                k: 0.2,
                n: 0.5,
            },
        ] {
            let v = 0.7;
            let g = law.gradient(v);
            let p = law.parameters();
            for j in 0..3 {
                let mut q = p;
                let h = 1e-6;
                q[j] += h;
                let up = rebuild(&law, q).mu_eff(v);
                q[j] -= 2.0 * h;
                let dn = rebuild(&law, q).mu_eff(v);
                assert!((g[j] - (up - dn) / (2.0 * h)).abs() < 1e-8);
            }
        }
    }

    fn rebuild(law: &WallFrictionLaw, p: [f64; 3]) -> WallFrictionLaw {
        match law {
            WallFrictionLaw::Exponential { .. } => WallFrictionLaw::Exponential {
                mu_0: p[0],
                mu_inf: p[1],
                v_star: p[2],
            },
            WallFrictionLaw::Hyperbolic { .. } => WallFrictionLaw::Hyperbolic {
                mu_0: p[0],
                mu_inf: p[1],
                v_star: p[2],
            },
            WallFrictionLaw::PowerLaw { .. } => WallFrictionLaw::PowerLaw {
                mu_0: p[0],
                k: p[1],
                n: p[2],
            },
        }
    }
}
