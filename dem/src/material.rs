//! Contact laws between materials: Coulomb friction coefficient and Newton restitution per pair.

use serde::{Deserialize, Serialize};

/// Symmetric tables of friction coefficient μ and normal restitution e between materials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactLaws {
    names: Vec<String>,
    friction: Vec<f64>,
    restitution: Vec<f64>,
}

impl ContactLaws {
    /// One material per name; every pair gets friction `mu` and restitution 0.
    pub fn new(names: &[&str], mu: f64) -> Self {
        let n = names.len();
        ContactLaws {
            names: names.iter().map(|s| s.to_string()).collect(),
            friction: vec![mu; n * n],
            restitution: vec![0.0; n * n],
        }
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when there is no material.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Index of a material by name.
    pub fn index(&self, name: &str) -> Option<u16> {
        self.names.iter().position(|n| n == name).map(|i| i as u16)
    }

    /// Material names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Set μ for the pair (a, b) and (b, a).
    pub fn set_friction(&mut self, a: u16, b: u16, mu: f64) {
        let n = self.names.len();
        self.friction[a as usize * n + b as usize] = mu;
        self.friction[b as usize * n + a as usize] = mu;
    }

    /// Set the normal restitution coefficient e ∈ [0, 1] for the pair (a, b).
    pub fn set_restitution(&mut self, a: u16, b: u16, e: f64) {
        let n = self.names.len();
        self.restitution[a as usize * n + b as usize] = e;
        self.restitution[b as usize * n + a as usize] = e;
    }

    /// Friction coefficient μ of the pair.
    #[inline]
    pub fn friction(&self, a: u16, b: u16) -> f64 {
        self.friction[a as usize * self.names.len() + b as usize]
    }

    /// Normal restitution coefficient of the pair.
    #[inline]
    pub fn restitution(&self, a: u16, b: u16) -> f64 {
        self.restitution[a as usize * self.names.len() + b as usize]
    }

    /// All friction coefficients (row-major n×n).
    pub fn friction_table(&self) -> &[f64] {
        &self.friction
    }

    /// All restitution coefficients (row-major n×n).
    pub fn restitution_table(&self) -> &[f64] {
        &self.restitution
    }
}
