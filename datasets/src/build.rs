//! Worlds of the scenarios, ready to step: walls (named), grains, contact laws.
//!
//! Materials: `grain` (0) and `wall` (1); friction from the scenario's [`FrictionSpec`].
//! The engine's checks ([`dem::World::validate`]) run on every built world: no overlap, no
//! grain behind a wall, finite positive sizes.

use dem::math::Vector;
use dem::{Dof, World, WorldParams};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::config::{
    ArrangementsConfig, ColumnCollapseConfig, FrictionSpec, GrainSpec, InclinedFlowConfig,
    RollingConfig, ShearCellConfig,
};
use crate::error::{DatasetError, Result};
use crate::generators::{deposit, lattice, rain, total_area, uniform_radii, Arrangement, RainBox};

/// Material index of grains.
pub const GRAIN: u16 = 0;
/// Material index of walls.
pub const WALL: u16 = 1;
/// Material index of the symmetry wall and the gate of `column-collapse` (their own friction).
pub const SIDE: u16 = 2;

/// Solid fraction assumed to size a column before it is deposited (2D polydisperse disks).
pub const PACKING_GUESS: f64 = 0.8;

/// Tolerance of the overlap check of built worlds (m): rounding only.
const BUILD_TOLERANCE: f64 = 1e-12;

fn world(
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
fn world_with_laws(
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
    [
        w.add_line_wall("bottom", Vector::zeros(), Vector::new(0.0, 1.0), WALL),
        w.add_line_wall("left", Vector::zeros(), Vector::new(1.0, 0.0), WALL),
        w.add_line_wall(
            "right",
            Vector::new(width, 0.0),
            Vector::new(-1.0, 0.0),
            WALL,
        ),
    ]
    .map(|b| b as usize)
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
    let radii = uniform_radii(&mut rng, n, grain);
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

/// The rolling disk: slope through the origin descending to the right, e₁ = (cos φ, −sin φ)
/// down the slope, e₂ = (sin φ, cos φ) its outward normal; the disk touches the slope at the
/// origin, at rest. Body 0 is the wall `slope`, body 1 the disk.
pub fn rolling(c: &RollingConfig) -> Result<(World, Vector, Vector)> {
    let phi = c.slope_deg.to_radians();
    let e1 = Vector::new(phi.cos(), -phi.sin());
    let e2 = Vector::new(phi.sin(), phi.cos());
    let f = FrictionSpec {
        grain_grain: c.friction,
        grain_wall: c.friction,
    };
    let mut w = world(c.dt, Vector::new(0.0, -9.81), None, c.radius, &f);
    w.params.solver.tolerance = 1e-12;
    w.params.solver.max_iterations = 100;
    w.add_line_wall("slope", Vector::zeros(), e2, WALL);
    w.add_grain(e2 * c.radius, c.radius, c.density, GRAIN);
    w.validate(BUILD_TOLERANCE)?;
    Ok((w, e1, e2))
}

/// A box with four line walls `bottom`, `left`, `right`, `top` holding a regular stack
/// ([`Arrangement`]); the top wall is one radius above the highest disk.
pub fn arrangement(c: &ArrangementsConfig, kind: Arrangement) -> Result<World> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let r = c.radius;
    let centres = lattice(kind, c.columns, c.rows, r, c.gap, c.jitter, &mut rng);
    let width = 2.0 * r * c.columns as f64;
    let top = centres.iter().map(|p| p.y).fold(0.0, f64::max) + 2.0 * r;
    let mut w = world(c.dt, Vector::new(0.0, -9.81), None, r, &c.friction);
    c.solver.apply(&mut w.params);
    box_walls(&mut w, width);
    w.add_line_wall("top", Vector::new(0.0, top), Vector::new(0.0, -1.0), WALL);
    for p in centres {
        w.add_grain(p, r, c.density, GRAIN);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(w)
}

/// Centres of a rough wall: disks of radius `r` evenly spaced along `[0, length)` at height `y`,
/// `gap_fraction · 2r` apart (surface to surface).
fn rough_row(length: f64, r: f64, y: f64) -> (Vec<Vector>, Vec<f64>) {
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
struct RoughBed {
    world: World,
    rng: ChaCha8Rng,
    radii: Vec<f64>,
    centres: Vec<Vector>,
    gap: f64,
}

#[allow(clippy::too_many_arguments)]
fn rough_bed(
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
    let radii = uniform_radii(&mut rng, grains, g);
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

/// A flow down a rough slope in the slope frame: x along the slope (periodic, length
/// `cell_length_diameters · 2 R̄`), y its normal, gravity `g (sin θ, −cos θ)`. Body 0 is the rough
/// bottom `base` (glued disks of the mean radius centred on y = 0), then the grains rained above.
pub fn inclined_flow(c: &InclinedFlowConfig) -> Result<World> {
    let g = &c.grain;
    let length = c.cell_length_diameters * 2.0 * g.radius_mean;
    let theta = c.slope_deg.to_radians();
    let gravity = Vector::new(9.81 * theta.sin(), -9.81 * theta.cos());
    let RoughBed {
        world: mut w,
        mut rng,
        radii,
        centres,
        ..
    } = rough_bed(
        c.seed,
        g,
        c.grains,
        length,
        c.dt,
        gravity,
        &c.friction,
        "base",
    )?;
    c.solver.apply(&mut w.params);
    for (p, r) in centres.iter().zip(&radii) {
        let b = w.add_grain(*p, *r, g.density, GRAIN);
        // A small random velocity breaks the symmetry of the start.
        w.bodies[b as usize].velocity = Vector::new(rng.random_range(-0.01..0.01), 0.0);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(w)
}

/// A plane shear cell without gravity: x periodic (length `cell_length_diameters · 2 R̄`), a
/// fixed rough wall `bottom` (body 0) at y = 0 and a rough wall `top` (body 1) whose y is free
/// (mass `wall_mass_ratio ×` the grains' mass, applied force `−P L t` ŷ) and whose x velocity is
/// imposed (zero until the runner sets it). Grains rained between them.
pub fn shear_cell(c: &ShearCellConfig) -> Result<(World, f64)> {
    let g = &c.grain;
    let length = c.cell_length_diameters * 2.0 * g.radius_mean;
    let RoughBed {
        world: mut w,
        radii,
        centres,
        gap,
        ..
    } = rough_bed(
        c.seed,
        g,
        c.grains,
        length,
        c.dt_max,
        Vector::zeros(),
        &c.friction,
        "bottom",
    )?;
    c.solver.apply(&mut w.params);
    let top_y = centres
        .iter()
        .zip(&radii)
        .map(|(p, r)| p.y + r)
        .fold(0.0, f64::max)
        + gap
        + g.radius_mean;
    let (tc, tr) = rough_row(length, g.radius_mean, top_y);
    let top = w.add_clump("top", &tc, &tr, WALL) as usize;
    let mut grain_mass = 0.0;
    for (p, r) in centres.iter().zip(&radii) {
        let b = w.add_grain(*p, *r, g.density, GRAIN);
        grain_mass += w.bodies[b as usize].mass;
    }
    let body = &mut w.bodies[top];
    body.dofs = [Dof::Imposed, Dof::Free, Dof::Imposed];
    body.mass = c.wall_mass_ratio * grain_mass;
    body.gravity = false;
    body.applied_force = Vector::new(0.0, -c.pressure * length * body.thickness);
    if !(body.mass.is_finite() && body.mass > 0.0) {
        return Err(DatasetError::invalid(
            "wall_mass_ratio",
            "gives a top wall without positive finite mass",
        ));
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok((w, length))
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

/// Overlap tolerated when a settled packing is rebuilt into a new world (m per m of the smallest
/// radius): the penetration limit of the phases (`crate::phases::PENETRATION_LIMIT`).
const REBUILD_TOLERANCE: f64 = crate::phases::PENETRATION_LIMIT;

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
/// seeded polydisperse grains deposited by drop and roll ([`crate::generators::deposition`])
/// between the symmetry wall x = 0 and the gate x = R₀, on the rough floor (the deposition's
/// floor y = 0 is the floor disks' tops). Time step `dt / deposit.substeps`, gravity −g ŷ.
pub fn column_collapse_deposit(c: &ColumnCollapseConfig) -> Result<CollapseWorld> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let radii = uniform_radii(&mut rng, c.poured_grains(), &c.grain);
    let gap = 0.02 * c.grain.radius_min();
    let centres = deposit(&mut rng, &radii, c.half_width(), gap)?.centres;
    let mut w = world_with_laws(
        c.dt / c.deposit.substeps as f64,
        Vector::new(0.0, -crate::config::column_collapse::GRAVITY),
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
