//! The worlds of the `column-collapse` scenario: the column deposited behind its gate, then
//! released.

use datasets::error::{DatasetError, Result};
use datasets::generators::{deposit, uniform_radii};
use dem::math::Vector;
use dem::World;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::config::ColumnCollapseConfig;
use crate::scenarios::common::build::{
    rough_row, world_with_laws, BUILD_TOLERANCE, GRAIN, SIDE, WALL,
};

/// Overlap tolerated when a settled packing is rebuilt into a new world (m per m of the smallest
/// radius): the penetration limit of the phases (`crate::scenarios::phases::PENETRATION_LIMIT`).
const REBUILD_TOLERANCE: f64 = crate::scenarios::phases::PENETRATION_LIMIT;

/// A `column-collapse` world: the rough floor, the flat base under it, the symmetry wall and,
/// before the release, the gate; then the grains.
#[derive(Debug, Clone)]
pub struct CollapseWorld {
    /// The world: bodies `floor`, `base`, `wall` (and `gate`), then the grains.
    pub world: World,
    /// Body index of the rough floor: glued disks of the mean radius whose tops are at y = 0,
    /// touching each other, over `[0, floor_length R₀]`.
    pub floor: usize,
    /// Body index of the flat wall through the floor disks' centres (y = −R̄), which holds any
    /// grain that would reach past the rough floor's end.
    pub base: usize,
    /// Body index of the symmetry wall x = 0.
    pub wall: usize,
    /// Body index of the gate x = R₀ (before the release only).
    pub gate: Option<usize>,
}

/// Contact laws of `column-collapse`: materials `grain` (0), `wall` (1, the floor) and `side`
/// (2, the symmetry wall and the gate), friction `friction.grain_grain`, `friction.floor`,
/// `friction.wall`, and the normal restitution `restitution` on every grain contact.
fn collapse_laws(c: &ColumnCollapseConfig) -> dem::ContactLaws {
    let mut laws = dem::ContactLaws::new(&["grain", "wall", "side"], c.friction.grain_grain);
    laws.set_friction(GRAIN, WALL, c.friction.floor);
    laws.set_friction(GRAIN, SIDE, c.friction.wall);
    for m in [GRAIN, WALL, SIDE] {
        laws.set_restitution(GRAIN, m, c.restitution);
    }
    laws
}

/// Adds the floor, its base and the symmetry wall of `column-collapse` (see [`CollapseWorld`]);
/// returns `(floor, base, wall)`.
fn collapse_walls(w: &mut World, c: &ColumnCollapseConfig) -> (usize, usize, usize) {
    let rf = c.grain.radius_mean;
    let (fc, fr) = rough_row(c.floor_extent(), rf, -rf);
    let floor = w.add_clump("floor", &fc, &fr, WALL) as usize;
    let base = w.add_line_wall("base", Vector::new(0.0, -rf), Vector::new(0.0, 1.0), WALL);
    let wall = w.add_line_wall("wall", Vector::zeros(), Vector::new(1.0, 0.0), SIDE);
    (floor, base as usize, wall as usize)
}

/// The column of `column-collapse` before its release: [`ColumnCollapseConfig::poured_grains`]
/// seeded polydisperse grains deposited by drop and roll ([`datasets::generators::deposition`])
/// between the symmetry wall x = 0 and the gate x = R₀, on the rough floor (the deposition's
/// floor y = 0 is the floor disks' tops). Time step `dt / deposit.substeps`, gravity −g ŷ.
pub fn column_collapse_deposit(c: &ColumnCollapseConfig) -> Result<CollapseWorld> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let radii = uniform_radii(
        &mut rng,
        c.poured_grains(),
        c.grain.radius_mean,
        c.grain.radius_spread,
    );
    let gap = 0.02 * c.grain.radius_min();
    let centres = deposit(&mut rng, &radii, c.half_width(), gap)?.centres;
    let mut w = world_with_laws(
        c.dt / c.deposit.substeps as f64,
        Vector::new(0.0, -super::config::GRAVITY),
        None,
        c.grain.radius_min(),
        collapse_laws(c),
    );
    c.deposit.solver.apply(&mut w.params);
    let (floor, base, wall) = collapse_walls(&mut w, c);
    let gate = w.add_line_wall(
        "gate",
        Vector::new(c.half_width(), 0.0),
        Vector::new(-1.0, 0.0),
        SIDE,
    ) as usize;
    for (p, r) in centres.iter().zip(&radii) {
        w.add_grain(*p, *r, c.grain.density, GRAIN);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(CollapseWorld {
        world: w,
        floor,
        base,
        wall,
        gate: Some(gate),
    })
}

/// The column released: a new world with the walls of [`column_collapse_deposit`] but no gate,
/// and, at rest, the grains of the settled column `settled` whose top `y + R` is at most `H₀`
/// (the column trimmed to its height, in their order). Time step `dt`, the settled world's
/// parameters otherwise. Fails when the settled column is lower than `H₀` (no grain was
/// trimmed) or overlaps by more than the phases' penetration limit.
pub fn column_collapse_release(c: &ColumnCollapseConfig, settled: &World) -> Result<CollapseWorld> {
    let h0 = c.height();
    let grains: Vec<&dem::Body> = settled
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .collect();
    let top = grains
        .iter()
        .map(|b| b.position.y + b.radius)
        .fold(f64::NEG_INFINITY, f64::max);
    if top.is_nan() || top <= h0 {
        return Err(DatasetError::Generator(format!(
            "the settled column is {top:.4e} m high, not above H₀ = {h0:.4e} m: it cannot be \
             trimmed to the aspect ratio"
        )));
    }
    let mut params = settled.params;
    params.dt = c.dt;
    let mut w = World::new(params, collapse_laws(c));
    let (floor, base, wall) = collapse_walls(&mut w, c);
    for b in grains.iter().filter(|b| b.position.y + b.radius <= h0) {
        w.add_grain(b.position, b.radius, b.density, GRAIN);
    }
    w.validate(REBUILD_TOLERANCE * c.grain.radius_min())?;
    Ok(CollapseWorld {
        world: w,
        floor,
        base,
        wall,
        gate: None,
    })
}
