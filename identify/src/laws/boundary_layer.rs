//! Velocity boundary layer along a wall: `u(y) = u_b − (u_b − u_s) exp(−y/δ)`, `y` the distance
//! from the wall (m), `u_s` the slip velocity at the wall (m/s), `u_b` the bulk velocity (m/s)
//! and `δ` the boundary-layer thickness (m).

use serde::{Deserialize, Serialize};

/// `u(y) = u_b − (u_b − u_s) exp(−y/δ)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VelocityBoundaryLayer {
    /// Bulk velocity far from the wall `u_b` (m/s).
    pub u_bulk: f64,
    /// Slip velocity at the wall `u_s = u(0)` (m/s).
    pub u_slip: f64,
    /// Thickness `δ` (m).
    pub delta_m: f64,
}

impl VelocityBoundaryLayer {
    /// `u(y)` (m/s).
    pub fn velocity(&self, y: f64) -> f64 {
        self.u_bulk - (self.u_bulk - self.u_slip) * (-y / self.delta_m).exp()
    }

    /// `∂u/∂(u_b, u_s, δ)`.
    pub fn gradient(&self, y: f64) -> [f64; 3] {
        let e = (-y / self.delta_m).exp();
        [
            1.0 - e,
            e,
            -(self.u_bulk - self.u_slip) * e * y / (self.delta_m * self.delta_m),
        ]
    }
}
