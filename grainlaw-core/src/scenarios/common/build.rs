//! What the worlds of several scenarios share, ready to step: walls (named), grains, contact
//! laws. Each scenario's own world is in its folder (`scenarios/NAME/build.rs`).
//!
//! Materials: `grain` (0) and `wall` (1); friction from the scenario's [`FrictionSpec`].
//! The engine's checks ([`dem::World::validate`]) run on every built world: no overlap, no
//! grain behind a wall, finite positive sizes.

use datasets::error::Result;
use datasets::generators::{rain, total_area, uniform_radii, RainBox};
use dem::cell::Cell;
use dem::math::Vector;
use dem::{World, WorldParams};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::config::{FrictionSpec, GrainSpec, SolverSpec};

/// Material index of grains.
pub const GRAIN: u16 = 0;
/// Material index of walls.
pub const WALL: u16 = 1;
/// Material index of the symmetry wall and the gate of `column-collapse` (their own friction).
pub const SIDE: u16 = 2;

/// Solid fraction assumed to size a column before it is deposited (2D polydisperse disks).
pub const PACKING_GUESS: f64 = 0.8;

/// Tolerance of the overlap check of built worlds (m): rounding only.
pub(crate) const BUILD_TOLERANCE: f64 = 1e-12;

/// A world of time step `dt`, gravity, optional periodic x interval, detection gap a tenth of
/// the smallest radius `r_min`, and the contact laws of `friction`.
pub(crate) fn world(
    dt: f64,
    gravity: Vector,
    periodic_x: Option<[f64; 2]>,
    r_min: f64,
    friction: &FrictionSpec,
) -> World {
    world_with_laws(dt, gravity, periodic_x, r_min, friction.laws())
}

/// A world of time step `dt`, gravity, optional periodic x interval, detection gap a tenth of
/// the smallest radius `r_min`, and the contact laws `laws`.
pub(crate) fn world_with_laws(
    dt: f64,
    gravity: Vector,
    periodic_x: Option<[f64; 2]>,
    r_min: f64,
    laws: dem::ContactLaws,
) -> World {
    let params = WorldParams {
        dt,
        gravity,
        periodic_x,
        detection_gap: 0.1 * r_min,
        ..Default::default()
    };
    World::new(params, laws)
}

/// Adds the line walls `bottom` (y = 0), `left` (x = 0) and `right` (x = `width`, m) of a box,
/// material [`WALL`], and returns their body indices.
pub fn box_walls(w: &mut World, width: f64) -> [usize; 3] {
    w.add_box_walls(width, WALL).map(|b| b as usize)
}

/// A box of two vertical walls and a floor filled with rained grains.
#[derive(Debug, Clone)]
pub struct ColumnWorld {
    /// The world: bodies 0, 1, 2 are the walls `bottom`, `left`, `right`, then the grains.
    pub world: World,
    /// Inner width of the box W (m).
    pub width: f64,
    /// Body index of the floor.
    pub bottom: usize,
    /// Body index of the left wall.
    pub left: usize,
    /// Body index of the right wall.
    pub right: usize,
}

/// Width (m) of a column of `n` grains of `grain` whose settled height is `aspect` widths:
/// `W = √(n π ⟨R²⟩ / (φ₀ aspect))`, φ₀ = [`PACKING_GUESS`].
pub fn column_width(grain: &GrainSpec, n: usize, aspect: f64) -> f64 {
    (n as f64 * std::f64::consts::PI * grain.mean_square_radius() / (PACKING_GUESS * aspect)).sqrt()
}

/// `n` seeded polydisperse grains rained without overlap into a box `width` wide with line
/// walls `bottom` (y = 0), `left` (x = 0), `right` (x = W). Time step `dt`, gravity −9.81 ŷ.
pub fn column(
    grain: &GrainSpec,
    n: usize,
    width: f64,
    friction: &FrictionSpec,
    seed: u64,
    dt: f64,
) -> Result<ColumnWorld> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let radii = uniform_radii(&mut rng, n, grain.radius_mean, grain.radius_spread);
    let gap = 0.02 * grain.radius_min();
    let centres = rain(
        &mut rng,
        &radii,
        &RainBox {
            x_min: 0.0,
            x_max: width,
            y_min: 0.0,
            gap,
            periodic: false,
        },
    )?;
    let mut w = world(
        dt,
        Vector::new(0.0, -9.81),
        None,
        grain.radius_min(),
        friction,
    );
    let [bottom, left, right] = box_walls(&mut w, width);
    for (c, r) in centres.iter().zip(&radii) {
        w.add_grain(*c, *r, grain.density, GRAIN);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(ColumnWorld {
        world: w,
        width,
        bottom,
        left,
        right,
    })
}

/// Centres of a rough wall: `m = ⌊length / 2r⌋` disks of radius `r` evenly spaced along
/// `[0, length)` at height `y`, at the pitch `length / m ≥ 2r` (touching, or a little apart).
pub(crate) fn rough_row(length: f64, r: f64, y: f64) -> (Vec<Vector>, Vec<f64>) {
    let m = ((length / (2.0 * r)).floor() as usize).max(1);
    let pitch = length / m as f64;
    let centres = (0..m)
        .map(|k| Vector::new((k as f64 + 0.5) * pitch, y))
        .collect();
    (centres, vec![r; m])
}

/// A periodic bed shared by the sheared scenarios: a world periodic along x over `length`
/// (m) with a rough bottom `base_name` (glued disks of the mean radius centred on y = 0, body 0),
/// and the seeded radii and centres of `grains` grains rained above it (not yet added).
pub(crate) struct RoughBed {
    pub(crate) world: World,
    pub(crate) rng: ChaCha8Rng,
    pub(crate) radii: Vec<f64>,
    pub(crate) centres: Vec<Vector>,
    pub(crate) gap: f64,
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn rough_bed(
    seed: u64,
    g: &GrainSpec,
    grains: usize,
    length: f64,
    dt: f64,
    gravity: Vector,
    friction: &FrictionSpec,
    base_name: &str,
) -> Result<RoughBed> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let radii = uniform_radii(&mut rng, grains, g.radius_mean, g.radius_spread);
    let mut world = world(dt, gravity, Some([0.0, length]), g.radius_min(), friction);
    let (bc, br) = rough_row(length, g.radius_mean, 0.0);
    world.add_clump(base_name, &bc, &br, WALL);
    let gap = 0.02 * g.radius_min();
    let centres = rain(
        &mut rng,
        &radii,
        &RainBox {
            x_min: 0.0,
            x_max: length,
            y_min: g.radius_mean + gap,
            gap,
            periodic: true,
        },
    )?;
    Ok(RoughBed {
        world,
        rng,
        radii,
        centres,
        gap,
    })
}

/// Total planar area of the grains of a world `Σ π R²` (m²).
pub fn grain_area(world: &World) -> f64 {
    total_area(
        &world
            .bodies
            .iter()
            .filter(|b| b.kind == dem::BodyKind::Grain)
            .map(|b| b.radius)
            .collect::<Vec<_>>(),
    )
}

/// What [`loose_cell`] builds.
pub struct LooseCell<'a> {
    /// Seed of the radii and the placement.
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Radii and density.
    pub grain: &'a GrainSpec,
    /// Grain–grain friction coefficient.
    pub friction: f64,
    /// Grain–grain normal restitution coefficient `e` (Newton's law on impacts; 0: none).
    pub restitution: f64,
    /// θ of the Moreau–Jean position update `q⁺ = q⁻ + h((1 − θ) v⁻ + θ v⁺)`, in [½, 1].
    pub theta: f64,
    /// Solid fraction aimed at (1).
    pub solid_fraction: f64,
    /// Time step (s).
    pub dt: f64,
    /// Contact solver.
    pub solver: &'a SolverSpec,
}

/// The initial loose packing: `grains` disks (radii from `grain`, seeded) on a jittered
/// square lattice in a square cell at the solid fraction `solid_fraction` (lower if the
/// lattice needs it: spacing at least 2 % above the largest diameter), at rest.
pub fn loose_cell(c: &LooseCell) -> Result<World> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let radii = uniform_radii(
        &mut rng,
        c.grains,
        c.grain.radius_mean,
        c.grain.radius_spread,
    );
    let area = total_area(&radii);
    let n_side = (c.grains as f64).sqrt().ceil() as usize;
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let spacing = ((area / c.solid_fraction).sqrt() / n_side as f64).max(2.04 * r_max);
    let side = spacing * n_side as f64;
    let params = dem::WorldParams {
        dt: c.dt,
        gravity: Vector::zeros(),
        detection_gap: 0.1 * c.grain.radius_min(),
        solver: c.solver.params(),
        overlap_rate: c.solver.overlap_rate,
        theta: c.theta,
        ..Default::default()
    };
    let mut laws = dem::ContactLaws::new(&["grain"], c.friction);
    if c.restitution > 0.0 {
        laws.set_restitution(0, 0, c.restitution);
    }
    let mut w = World::new(params, laws);
    let slack = 0.5 * (spacing - 2.0 * r_max) * 0.9;
    for (k, &r) in radii.iter().enumerate() {
        let (i, j) = (k % n_side, k / n_side);
        let jitter = Vector::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * slack;
        let x = Vector::new(i as f64 + 0.5, j as f64 + 0.5) * spacing + jitter;
        w.add_grain(x, r, c.grain.density, 0);
    }
    let cell = Cell::rectangle(side, side)?;
    w.set_cell(Some(cell))?;
    w.validate(BUILD_TOLERANCE)?;
    Ok(w)
}
