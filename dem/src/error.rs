//! Typed errors of the engine.

use thiserror::Error;

/// What can go wrong when building or stepping a world.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DemError {
    /// A world parameter is out of range.
    #[error("parameter `{name}`: {reason}")]
    Parameter {
        /// Parameter name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A body or collider is ill-formed.
    #[error("body {index}{label}: `{field}` {reason}")]
    Body {
        /// Body index.
        index: usize,
        /// ` (name)` or empty.
        label: String,
        /// Field name.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// Two grains overlap at the start.
    #[error("grains {a} and {b} overlap by {overlap:.3e} m at the start")]
    Overlap {
        /// First body.
        a: usize,
        /// Second body.
        b: usize,
        /// Overlap depth (m).
        overlap: f64,
    },
    /// A grain is on the wrong side of a wall at the start.
    #[error("grain {grain} lies outside wall `{wall}` by {depth:.3e} m at the start")]
    Outside {
        /// Grain body index.
        grain: usize,
        /// Wall name.
        wall: String,
        /// Depth (m).
        depth: f64,
    },
    /// A non-finite value appeared during a step.
    #[error("step {step}: non-finite {what} in body {body}")]
    NonFinite {
        /// Step index.
        step: u64,
        /// Body index.
        body: usize,
        /// What became non-finite.
        what: String,
    },
    /// The biperiodic cell's velocity gradient or shape became non-finite during a step (its
    /// stress control ran away).
    #[error("step {step}: the cell's velocity gradient or shape became non-finite (its stress control ran away)")]
    NonFiniteCell {
        /// Step index.
        step: u64,
    },
    /// A checkpoint could not be written or read.
    #[error("checkpoint {path}: {reason}")]
    Checkpoint {
        /// File.
        path: String,
        /// What went wrong.
        reason: String,
    },
}
