//! Packing generators: seeded polydisperse radii, grains rained without overlap above a floor
//! (then settled by gravity in the engine, see [`crate::phases`]), and regular stacks.

pub mod lattice;
pub mod radii;
pub mod rain;

pub use lattice::{lattice, Arrangement};
pub use radii::{total_area, uniform_radii};
pub use rain::{rain, RainBox};
