//! Packing generators: seeded polydisperse radii, grains rained without overlap above a floor (then
//! settled by gravity in the engine, by the phases of `grainlaw-core`), regular stacks, and dense
//! packings by sequential geometric deposition.

pub mod deposition;
pub mod lattice;
pub mod ordering;
pub mod radii;
pub mod rain;

pub use deposition::{deposit, Deposition, Support};
pub use lattice::{lattice, Arrangement};
pub use ordering::spatial_order;
pub use radii::{total_area, uniform_radii};
pub use rain::{rain, RainBox};
