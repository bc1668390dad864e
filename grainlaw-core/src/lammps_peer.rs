//! The soft-contact peer of `grainlaw bench`'s Janssen columns: LAMMPS run on the same initial
//! column, in the same run as the engine, one core.
//!
//! [`PeerColumn::from_world`] takes the grains (centres, radii, density), the box (floor and the
//! two vertical walls, from the world's line walls), gravity and friction from the [`World`]
//! that `crate::benchmarks::janssen_column` returns before settling.
//! [`PeerColumn::write_input`] writes a LAMMPS data file and input script; [`run`] runs
//! `lmp -in` serially (`OMP_NUM_THREADS=1`, no MPI launcher), wall-clock timed, and reads back
//! its log ([`parse_log`]) and final state ([`parse_dump`], [`largest_overlap`]).
//!
//! # Contact model
//!
//! 2D (`dimension 2`, `atom_style sphere`), disks of mass `m = ρ π r²` per metre of thickness
//! (`set … density/disc`), moment of inertia `½ m r²` (`fix nve/sphere disc`), linear spring
//! with tangential history and Coulomb friction (`pair_style gran/hooke/history`, the walls
//! `fix wall/gran hooke/history` with the same parameters; Cundall & Strack 1979):
//!
//! `F_n = k_n δ − m_eff γ_n v_n`, `F_t = −min(μ |F_n|, |k_t ξ + m_eff γ_t v_t|)`,
//! `m_eff = m_i m_j / (m_i + m_j)` between grains, `m_i` against a wall.
//!
//! - Stiffness `k_n = 2·10⁵ m̄ g / d̄` (Silbert et al., Phys. Rev. E 64, 051302, 2001: stiff
//!   enough that the grains behave as rigid), `m̄`, `d̄` the mean grain mass and diameter;
//!   `k_t = 2/7 k_n`, `γ_t = γ_n / 2` (LAMMPS' defaults for `NULL`). The price of the softness is
//!   the overlap: a grain under `H / d̄` grains' weight overlaps by about `(H / d̄) d̄ / 2·10⁵`
//!   on average, i.e. 2.5·10⁻⁴ d̄ (7.5·10⁻⁴ of the smallest radius) under 50 grains, less where
//!   the walls carry the weight (Janssen), a few times more along force chains: the settled
//!   benchmark columns ended with largest overlaps of 0.22 % (2000 grains, deposited), 0.34 %
//!   (2000, poured) and 0.79 % (10⁴, deposited) of the smallest radius, against 0.01–0.02 % for
//!   the engine. The bench prints the largest final overlap of each run.
//! - Damping `γ_n` such that two grains of the mean mass collide with restitution
//!   [`RESTITUTION`] = 0.2: `e = exp(−π ζ / √(1 − ζ²))`, `ζ = γ_n / (2 √(k_n / m_eff))`. With
//!   radii 1–2 mm the restitution between grains spans 0.10 (two largest) to 0.37 (two
//!   smallest), and 0.007–0.23 against a wall ([`ContactModel::restitution`]).
//! - Time step `h = t_c / 15` ([`STEPS_PER_COLLISION`]), `t_c = π / √(2 k_n / m_min − γ_n² / 4)`
//!   the collision time of the two smallest grains (the shortest of the system): in the
//!   `t_c / 10` – `t_c / 20` that users of soft-contact DEM take (a finer step would make the
//!   peer slower than its users run it, and flatter grainlaw).
//!
//! # Stop criterion
//!
//! As the engine's (`dem::settle::energy_ratio`): `KE / PE < 10⁻⁸` with
//! `KE = Σ ½ m |v|² + ¼ m r² ω²` and `PE = Σ m g y` (floor at `y = 0`), checked every
//! [`CHECK_EVERY`] steps by `fix halt`, within the engine's longest simulated time and a
//! wall-clock limit (`timer timeout`). Whether the column settled is decided here from the
//! ratio LAMMPS prints at the end, not from how the run stopped.

use dem::math::Vector;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use dem::collider::{rotate, Shape};
use dem::{Body, BodyKind, World};

use crate::error::{CliError, Result};

/// Silbert et al.'s stiffness factor: `k_n = KN_FACTOR · m̄ g / d̄`.
pub const KN_FACTOR: f64 = 2e5;
/// Restitution of two grains of the mean mass.
pub const RESTITUTION: f64 = 0.2;
/// Time steps per collision time of the two smallest grains (`h = t_c / 15`).
pub const STEPS_PER_COLLISION: f64 = 15.0;
/// Steps between two checks of `KE / PE` (`fix halt`).
pub const CHECK_EVERY: u64 = 100;
/// Default wall-clock limit of one peer run (s); `GRAINLAW_LAMMPS_TIMEOUT` overrides it.
pub const DEFAULT_WALL_LIMIT: f64 = 600.0;

/// The linear spring–dashpot parameters of the peer (per metre of thickness).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactModel {
    /// Normal stiffness `k_n` (N/m per m).
    pub kn: f64,
    /// Tangential stiffness `k_t = 2/7 k_n` (N/m per m).
    pub kt: f64,
    /// Normal damping rate `γ_n` (1/s): force `m_eff γ_n v_n`.
    pub gamma_n: f64,
    /// Tangential damping rate `γ_t = γ_n / 2` (1/s).
    pub gamma_t: f64,
    /// Collision time of the two smallest grains `t_c` (s).
    pub collision_time: f64,
    /// Time step `t_c / n` (s), `n` steps per collision ([`STEPS_PER_COLLISION`] for the
    /// column).
    pub dt: f64,
}

impl ContactModel {
    /// The column's model for grains of masses `masses` and radii `radii` under gravity `g`
    /// (m/s²): `k_n = 2·10⁵ m̄ g / d̄` ([`ContactModel::with_stiffness`], `h = t_c / 15`).
    pub fn new(masses: &[f64], radii: &[f64], g: f64) -> Self {
        let n = masses.len().max(1) as f64;
        let m_mean = masses.iter().sum::<f64>() / n;
        let d_mean = 2.0 * radii.iter().sum::<f64>() / n;
        Self::with_stiffness(
            KN_FACTOR * m_mean * g / d_mean,
            masses,
            STEPS_PER_COLLISION,
            RESTITUTION,
        )
    }

    /// The model of normal stiffness `kn` (N/m per metre of thickness) for grains of masses
    /// `masses` (kg per metre): `k_t = 2/7 k_n`, `γ_n` for restitution `restitution` between
    /// two grains of the mean mass `m̄` (`e = exp(−π ζ / √(1 − ζ²))`,
    /// `ζ = γ_n / (2 √(k_n / (m̄/2)))`, [`damping_ratio`]), `γ_t = γ_n / 2`, and the time step
    /// `h = t_c / steps_per_collision` with `t_c = π / √(2 k_n / m_min − γ_n² / 4)` the collision
    /// time of the two smallest grains. The column takes [`RESTITUTION`]; `restitution` outside
    /// [0, 1), or so low that the two smallest grains are overdamped (no `t_c`), gives a
    /// non-finite `dt`: callers check it ([`ContactModel::is_usable`]).
    pub fn with_stiffness(
        kn: f64,
        masses: &[f64],
        steps_per_collision: f64,
        restitution: f64,
    ) -> Self {
        let n = masses.len().max(1) as f64;
        let m_mean = masses.iter().sum::<f64>() / n;
        let m_min = masses.iter().copied().fold(f64::INFINITY, f64::min);
        let zeta = damping_ratio(restitution);
        let gamma_n = 2.0 * zeta * (kn / (0.5 * m_mean)).sqrt();
        let collision_time =
            std::f64::consts::PI / (2.0 * kn / m_min - 0.25 * gamma_n * gamma_n).sqrt();
        ContactModel {
            kn,
            kt: 2.0 / 7.0 * kn,
            gamma_n,
            gamma_t: 0.5 * gamma_n,
            collision_time,
            dt: collision_time / steps_per_collision,
        }
    }

    /// Whether the model can be run: finite positive stiffness, damping, collision time and
    /// step (false for a restitution outside [0, 1) or one that overdamps the two smallest
    /// grains).
    pub fn is_usable(&self) -> bool {
        [self.kn, self.collision_time, self.dt]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
            && self.gamma_n.is_finite()
            && self.gamma_n >= 0.0
    }

    /// Normal restitution of a collision of effective mass `m_eff` (kg/m):
    /// `exp(−π ζ / √(1 − ζ²))`, `ζ = γ_n / (2 √(k_n / m_eff))`; 0 when overdamped (ζ ≥ 1).
    pub fn restitution(&self, m_eff: f64) -> f64 {
        let zeta = self.gamma_n / (2.0 * (self.kn / m_eff).sqrt());
        if zeta >= 1.0 {
            0.0
        } else {
            (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
        }
    }
}

/// The damping ratio `ζ` of a linear spring–dashpot whose collision has normal restitution `e`:
/// the inverse of `e = exp(−π ζ / √(1 − ζ²))` (Schäfer, Dippel & Wolf, J. Phys. I France 6, 5,
/// 1996), `ζ = −ln e / √(π² + ln² e)`; `ζ = 1` (critical damping) at `e = 0`, 0 at `e = 1`, NaN
/// outside [0, 1].
pub fn damping_ratio(e: f64) -> f64 {
    if !(0.0..=1.0).contains(&e) {
        return f64::NAN;
    }
    if e == 0.0 {
        return 1.0;
    }
    let l = -e.ln();
    l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// The column handed to LAMMPS.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerColumn {
    /// Grain centres `[x, y]` (m), in the world's grain order (LAMMPS ids 1, 2, …).
    pub centres: Vec<[f64; 2]>,
    /// Grain radii (m).
    pub radii: Vec<f64>,
    /// Grain masses per metre of thickness (kg/m), `ρ π r²`.
    pub masses: Vec<f64>,
    /// Grain density (kg/m³), the same for all.
    pub density: f64,
    /// Gravity (m/s², along −y).
    pub gravity: f64,
    /// Left wall `x` (m).
    pub x_left: f64,
    /// Right wall `x` (m).
    pub x_right: f64,
    /// Floor `y` (m).
    pub floor: f64,
    /// Friction grain–grain.
    pub mu_grains: f64,
    /// Friction grain–wall.
    pub mu_walls: f64,
    /// Contact model and time step.
    pub model: ContactModel,
    /// Target of `KE / PE`.
    pub target: f64,
    /// Longest simulated time (s).
    pub max_time: f64,
    /// Wall-clock limit of the run (s).
    pub wall_limit: f64,
}

fn bad(reason: impl Into<String>) -> CliError {
    CliError::Usage(format!("LAMMPS peer: {}", reason.into()))
}

/// The density of disk grains `grains` (that of `first`, one of them; an error if another
/// differs), their radii (m) and masses per metre of thickness `ρ π r²` (kg/m).
pub(crate) fn disk_masses(
    first: &Body,
    grains: &[&Body],
) -> std::result::Result<(f64, Vec<f64>, Vec<f64>), &'static str> {
    let density = first.density;
    if grains.iter().any(|b| b.density != density) {
        return Err("grains of different densities");
    }
    let radii: Vec<f64> = grains.iter().map(|b| b.radius).collect();
    let masses: Vec<f64> = radii
        .iter()
        .map(|r| density * std::f64::consts::PI * r * r)
        .collect();
    Ok((density, radii, masses))
}

impl PeerColumn {
    /// The column of `w` (grains of one density and material, floor `y = 0` with normal `+y`,
    /// walls with normals `±x`, gravity along `−y`), settled to `KE / PE < target` within
    /// `max_time` simulated seconds and `wall_limit` wall seconds.
    pub fn from_world(w: &World, target: f64, max_time: f64, wall_limit: f64) -> Result<Self> {
        let g = w.params.gravity;
        if g.x != 0.0 || g.y >= 0.0 {
            return Err(bad(format!("gravity must point along −y, got {g:?}")));
        }
        let (mut floor, mut x_left, mut x_right) = (None, None, None);
        let (mut grain_mat, mut wall_mat) = (None::<u16>, None::<u16>);
        let mut grain_collider = vec![false; w.bodies.len()];
        for c in &w.colliders {
            let b = &w.bodies[c.body as usize];
            match (&c.shape, b.kind) {
                (Shape::Line { point, normal }, _) => {
                    let p = b.position + rotate(*point, b.angle);
                    let n = rotate(*normal, b.angle);
                    let slot = if (n.y - 1.0).abs() < 1e-12 {
                        floor.replace(p.y)
                    } else if (n.x - 1.0).abs() < 1e-12 {
                        x_left.replace(p.x)
                    } else if (n.x + 1.0).abs() < 1e-12 {
                        x_right.replace(p.x)
                    } else {
                        return Err(bad(format!("wall `{}` is not axis-aligned", b.name)));
                    };
                    if slot.is_some() {
                        return Err(bad(format!("a second wall like `{}`", b.name)));
                    }
                    if wall_mat
                        .replace(c.material)
                        .is_some_and(|m| m != c.material)
                    {
                        return Err(bad("walls of different materials"));
                    }
                }
                (Shape::Disk { offset, .. }, BodyKind::Grain) if *offset == Vector::zeros() => {
                    if grain_mat
                        .replace(c.material)
                        .is_some_and(|m| m != c.material)
                    {
                        return Err(bad("grains of different materials"));
                    }
                    grain_collider[c.body as usize] = true;
                }
                _ => {
                    return Err(bad(format!(
                        "body `{}`: not a disk grain or a line wall",
                        b.name
                    )))
                }
            }
        }
        let (Some(floor), Some(x_left), Some(x_right)) = (floor, x_left, x_right) else {
            return Err(bad("needs a floor and two vertical walls"));
        };
        if floor != 0.0 {
            return Err(bad(format!(
                "the floor must be at y = 0 (PE = Σ m g y), got {floor}"
            )));
        }
        let grains: Vec<_> = w
            .bodies
            .iter()
            .zip(&grain_collider)
            .filter(|(b, _)| b.kind == BodyKind::Grain)
            .map(|(b, &c)| {
                c.then_some(b)
                    .ok_or_else(|| bad(format!("grain `{}` is not one disk", b.name)))
            })
            .collect::<Result<_>>()?;
        let (Some(gm), Some(wm), Some(first)) = (grain_mat, wall_mat, grains.first()) else {
            return Err(bad("no grains"));
        };
        let (density, radii, masses) = disk_masses(first, &grains).map_err(bad)?;
        let gravity = -g.y;
        Ok(PeerColumn {
            centres: grains
                .iter()
                .map(|b| [b.position.x, b.position.y])
                .collect(),
            model: ContactModel::new(&masses, &radii, gravity),
            radii,
            masses,
            density,
            gravity,
            x_left,
            x_right,
            floor,
            mu_grains: w.laws.friction(gm, gm),
            mu_walls: w.laws.friction(gm, wm),
            target,
            max_time,
            wall_limit,
        })
    }

    /// Steps of the longest run: `⌈max_time / h⌉`.
    pub fn max_steps(&self) -> u64 {
        (self.max_time / self.model.dt).ceil() as u64
    }

    /// The data file (`atom_style sphere`: id, type, diameter, density, x, y, z), coordinates
    /// with 17 significant digits. The box spans the walls and twice the column's height.
    pub fn data_file(&self) -> String {
        let r_max = self.radii.iter().copied().fold(0.0, f64::max);
        let top = self
            .centres
            .iter()
            .zip(&self.radii)
            .map(|(c, r)| c[1] + r)
            .fold(self.floor, f64::max);
        let mut s = String::new();
        let _ = writeln!(s, "grainlaw Janssen column (LAMMPS peer)\n");
        let _ = writeln!(s, "{} atoms\n1 atom types\n", self.centres.len());
        let _ = writeln!(
            s,
            "{:.17e} {:.17e} xlo xhi\n{:.17e} {:.17e} ylo yhi\n{:.17e} {:.17e} zlo zhi\n",
            self.x_left - r_max,
            self.x_right + r_max,
            self.floor - r_max,
            self.floor + 2.0 * (top - self.floor) + 4.0 * r_max,
            -r_max,
            r_max
        );
        let _ = writeln!(s, "Atoms # sphere\n");
        for (i, (c, r)) in self.centres.iter().zip(&self.radii).enumerate() {
            let _ = writeln!(
                s,
                "{} 1 {:.17e} {} {:.17e} {:.17e} 0",
                i + 1,
                2.0 * r,
                self.density,
                c[0],
                c[1]
            );
        }
        s
    }

    /// The input script reading `data_file`, writing the final state to `dump_file`.
    pub fn input_script(&self, data_file: &str, dump_file: &str) -> String {
        let m = &self.model;
        let r_min = self.radii.iter().copied().fold(f64::INFINITY, f64::min);
        let pair = |mu: f64| {
            format!(
                "{:.10e} {:.10e} {:.10e} {:.10e} {mu} 1",
                m.kn, m.kt, m.gamma_n, m.gamma_t
            )
        };
        let limit = self.wall_limit.max(1.0).ceil() as u64;
        format!(
            "# grainlaw bench: LAMMPS peer of a Janssen column (see grainlaw-core/src/lammps_peer.rs)
units si
dimension 2
atom_style sphere
boundary f f p
comm_modify vel yes
read_data {data_file}
set type 1 density/disc {density}
pair_style gran/hooke/history {pair_grains}
pair_coeff * *
neighbor {skin:.6e} bin
neigh_modify delay 0 every 1 check yes
timestep {dt:.10e}
fix gravity all gravity {g} vector 0 -1 0
fix integrate all nve/sphere disc
fix floor all wall/gran hooke/history {pair_walls} yplane {floor:.17e} NULL
fix sides all wall/gran hooke/history {pair_walls} xplane {xl:.17e} {xr:.17e}
fix planar all enforce2d
compute spin all property/atom radius omegaz
variable ke atom 0.5*mass*(vx*vx+vy*vy)+0.25*mass*c_spin[1]*c_spin[1]*c_spin[2]*c_spin[2]
variable pe atom mass*{g}*y
compute ke all reduce sum v_ke
compute pe all reduce sum v_pe
variable ratio equal c_ke/c_pe
thermo_style custom step time c_ke c_pe v_ratio
thermo {thermo}
fix halt all halt {check} v_ratio < {target:e} error continue
timer timeout {hh:02}:{mm:02}:{ss:02} every 100
run {steps}
print \"GRAINLAW_END step $(step) time $(time:%.9e) ratio $(v_ratio:%.9e)\"
write_dump all custom {dump_file} id x y radius
",
            density = self.density,
            pair_grains = pair(self.mu_grains),
            pair_walls = pair(self.mu_walls),
            skin = 0.1 * r_min,
            dt = m.dt,
            g = self.gravity,
            floor = self.floor,
            xl = self.x_left,
            xr = self.x_right,
            thermo = 100 * CHECK_EVERY,
            check = CHECK_EVERY,
            target = self.target,
            hh = limit / 3600,
            mm = limit / 60 % 60,
            ss = limit % 60,
            steps = self.max_steps(),
        )
    }

    /// Writes `column.data` and `in.column` into `dir`; returns the input's path.
    pub fn write_input(&self, dir: &Path) -> Result<PathBuf> {
        write_input_files(
            dir,
            ("column.data", &self.data_file()),
            ("in.column", &self.input_script("column.data", "final.dump")),
        )
    }
}

/// What the end of a LAMMPS log says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeerLog {
    /// Steps run.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_seconds: f64,
    /// Final `KE / PE`.
    pub energy_ratio: f64,
    /// LAMMPS' own loop time (s), when printed.
    pub loop_seconds: Option<f64>,
}

/// Reads the `GRAINLAW_END step … time … ratio …` line the input script prints after the run,
/// and the last `Loop time of T on …` line.
pub fn parse_log(text: &str) -> Result<PeerLog> {
    let end = text
        .lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix("GRAINLAW_END "))
        .ok_or_else(|| bad("no GRAINLAW_END line in the log (the run did not finish)"))?;
    let words: Vec<&str> = end.split_whitespace().collect();
    let field = |key: &str| -> Result<&str> {
        words
            .iter()
            .position(|w| *w == key)
            .and_then(|i| words.get(i + 1).copied())
            .ok_or_else(|| bad(format!("GRAINLAW_END line without `{key}`: {end}")))
    };
    let num = |key: &str| -> Result<f64> {
        let v = field(key)?;
        v.parse::<f64>()
            .map_err(|_| bad(format!("GRAINLAW_END `{key}` is not a number: {v}")))
    };
    let steps = field("step")?
        .parse::<u64>()
        .map_err(|_| bad(format!("GRAINLAW_END `step` is not a count: {end}")))?;
    let loop_seconds = text.lines().rev().find_map(|l| {
        l.trim()
            .strip_prefix("Loop time of ")
            .and_then(|r| r.split_whitespace().next())
            .and_then(|v| v.parse::<f64>().ok())
    });
    Ok(PeerLog {
        steps,
        simulated_seconds: num("time")?,
        energy_ratio: num("ratio")?,
        loop_seconds,
    })
}

/// Reads `write_dump … custom … id x y radius`: `(id, [x, y], radius)` per atom.
pub fn parse_dump(text: &str) -> Result<Vec<(u64, [f64; 2], f64)>> {
    let mut lines = text.lines();
    let header = lines
        .by_ref()
        .find(|l| l.starts_with("ITEM: ATOMS"))
        .ok_or_else(|| bad("dump without `ITEM: ATOMS`"))?;
    let cols: Vec<&str> = header.split_whitespace().skip(2).collect();
    let col = |k: &str| {
        cols.iter()
            .position(|c| *c == k)
            .ok_or_else(|| bad(format!("dump without column `{k}`")))
    };
    let (id, x, y, r) = (col("id")?, col("x")?, col("y")?, col("radius")?);
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<&str> = l.split_whitespace().collect();
            let f = |i: usize| {
                v.get(i)
                    .and_then(|s| s.parse::<f64>().ok())
                    .ok_or_else(|| bad(format!("dump line `{l}`")))
            };
            let idv = v
                .get(id)
                .and_then(|s| s.parse::<u64>().ok())
                .ok_or_else(|| bad(format!("dump line `{l}`")))?;
            Ok((idv, [f(x)?, f(y)?], f(r)?))
        })
        .collect()
}

/// Largest overlap (m) between two disks of `grains` (`[x, y]`, radius) or a disk and the
/// floor `y = floor` or the walls `x = x_left`, `x = x_right`; 0 if none. Grains sorted by `x`,
/// each compared with those within `2 r_max` to its right.
pub fn largest_overlap(grains: &[([f64; 2], f64)], floor: f64, x_left: f64, x_right: f64) -> f64 {
    let mut sorted: Vec<&([f64; 2], f64)> = grains.iter().collect();
    sorted.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]));
    let r_max = grains.iter().map(|g| g.1).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (i, (c, r)) in sorted.iter().map(|g| (g.0, g.1)).enumerate() {
        worst = worst
            .max(floor + r - c[1])
            .max(x_left + r - c[0])
            .max(c[0] + r - x_right);
        for (d, s) in sorted[i + 1..].iter().map(|g| (g.0, g.1)) {
            if d[0] - c[0] > r + r_max {
                break;
            }
            let dist = ((d[0] - c[0]).powi(2) + (d[1] - c[1]).powi(2)).sqrt();
            worst = worst.max(r + s - dist);
        }
    }
    worst
}

/// The LAMMPS executable of the bench: `GRAINLAW_LAMMPS` (a path, or `off` to disable), else
/// `lmp` on `PATH`; `None` when not found or disabled.
pub fn find_lammps() -> Option<PathBuf> {
    match std::env::var_os("GRAINLAW_LAMMPS") {
        Some(v) if v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::split_paths(&std::env::var_os("PATH")?)
            .map(|d| d.join("lmp"))
            .find(|p| p.is_file()),
    }
}

/// The wall-clock limit of one peer run: `GRAINLAW_LAMMPS_TIMEOUT` (s) or
/// [`DEFAULT_WALL_LIMIT`].
pub fn wall_limit() -> Result<f64> {
    match std::env::var("GRAINLAW_LAMMPS_TIMEOUT") {
        Ok(v) => v
            .parse::<f64>()
            .ok()
            .filter(|t| t.is_finite() && *t > 0.0)
            .ok_or_else(|| {
                CliError::Usage(format!(
                    "GRAINLAW_LAMMPS_TIMEOUT: expected seconds > 0, got `{v}`"
                ))
            }),
        Err(_) => Ok(DEFAULT_WALL_LIMIT),
    }
}

/// The outcome of a LAMMPS peer run whose finished run is `R` (a [`PeerRun`] of the column,
/// [`crate::lammps_rve_peer::RveRun`] of the representative volume).
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome<R> {
    /// The run ended and its output was read (settled or finished or not: see the run).
    Ran(R),
    /// The run failed (could not start, non-zero exit, unreadable log or output): the reason,
    /// and the directory kept for inspection.
    Failed {
        /// One line.
        reason: String,
        /// Where the input and log are.
        dir: PathBuf,
    },
}

/// The outcome of a column's peer run (settled or not: see [`PeerRun::settled`]).
pub type PeerOutcome = Outcome<PeerRun>;

/// Writes a peer's data file and input script, each `(name, text)`, into `dir` (created);
/// returns the input's path.
pub(crate) fn write_input_files(
    dir: &Path,
    (data_name, data_text): (&str, &str),
    (input_name, input_text): (&str, &str),
) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| CliError::io(dir, e))?;
    let data = dir.join(data_name);
    std::fs::write(&data, data_text).map_err(|e| CliError::io(&data, e))?;
    let input = dir.join(input_name);
    std::fs::write(&input, input_text).map_err(|e| CliError::io(&input, e))?;
    Ok(input)
}

/// Runs `lmp -in input` in `dir` ([`run_lmp`], the input already written there) and reads the
/// finished run with `read(wall_seconds, log text)`: [`Outcome::Ran`] and `dir` removed when
/// it was read, [`Outcome::Failed`] with the reason and `dir` kept when the run or the reading
/// failed.
pub(crate) fn run_and_read<R>(
    lmp: &Path,
    dir: &Path,
    input: &str,
    read: impl FnOnce(f64, &str) -> std::result::Result<R, String>,
) -> Outcome<R> {
    match run_lmp(lmp, dir, input).and_then(|(wall_seconds, log)| read(wall_seconds, &log)) {
        Ok(r) => {
            let _ = std::fs::remove_dir_all(dir);
            Outcome::Ran(r)
        }
        Err(reason) => Outcome::Failed {
            reason,
            dir: dir.to_path_buf(),
        },
    }
}

/// A finished peer run.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerRun {
    /// Wall-clock seconds of `lmp` (start to exit, reading the data included).
    pub wall_seconds: f64,
    /// What the log says.
    pub log: PeerLog,
    /// Whether `KE / PE` ended below the target.
    pub settled: bool,
    /// Largest final overlap (grain–grain or grain–wall) over the smallest radius.
    pub overlap_ratio: f64,
}

/// Runs `lmp -in INPUT` in `dir` on one core (serial, `OMP_NUM_THREADS=1`, log `log.lammps`, no
/// screen output), wall-clock timed from start to exit: `(seconds, log text)`, or one line saying
/// why it failed (could not start, or a non-zero exit with LAMMPS' `ERROR` line).
pub(crate) fn run_lmp(
    lmp: &Path,
    dir: &Path,
    input: &str,
) -> std::result::Result<(f64, String), String> {
    let t0 = Instant::now();
    let out = Command::new(lmp)
        .args([
            "-in",
            input,
            "-log",
            "log.lammps",
            "-screen",
            "none",
            "-nocite",
        ])
        .current_dir(dir)
        .env("OMP_NUM_THREADS", "1")
        .output();
    let wall_seconds = t0.elapsed().as_secs_f64();
    let out = out.map_err(|e| format!("cannot run {}: {e}", lmp.display()))?;
    let log = std::fs::read_to_string(dir.join("log.lammps")).unwrap_or_default();
    if !out.status.success() {
        let why = log
            .lines()
            .chain(String::from_utf8_lossy(&out.stderr).lines())
            .find(|l| l.starts_with("ERROR"))
            .map_or_else(|| "no ERROR line".to_string(), str::to_string);
        return Err(format!(
            "{} ({why}), input {}",
            out.status,
            dir.join(input).display()
        ));
    }
    Ok((wall_seconds, log))
}

/// Writes the column's input into `dir`, runs `lmp -in in.column` there on one core and reads
/// the result. `dir` is removed after a run that ended, kept after a failure.
pub fn run(lmp: &Path, column: &PeerColumn, dir: &Path) -> Result<PeerOutcome> {
    column.write_input(dir)?;
    Ok(run_and_read(lmp, dir, "in.column", |wall_seconds, log| {
        let parsed = parse_log(log).map_err(|e| e.to_string())?;
        let dump = std::fs::read_to_string(dir.join("final.dump"))
            .map_err(|e| bad(format!("final.dump: {e}")))
            .and_then(|t| parse_dump(&t))
            .map_err(|e| e.to_string())?;
        if dump.len() != column.radii.len() {
            return Err(format!(
                "final.dump holds {} grains, {} were written",
                dump.len(),
                column.radii.len()
            ));
        }
        let grains: Vec<([f64; 2], f64)> = dump.iter().map(|&(_, c, r)| (c, r)).collect();
        let r_min = column.radii.iter().copied().fold(f64::INFINITY, f64::min);
        let overlap = largest_overlap(&grains, column.floor, column.x_left, column.x_right);
        Ok(PeerRun {
            wall_seconds,
            settled: parsed.energy_ratio < column.target,
            log: parsed,
            overlap_ratio: overlap / r_min,
        })
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{janssen_column, ColumnRun, Preparation, COLUMN_WIDTH};

    fn column(n: usize, prep: Preparation) -> (World, PeerColumn) {
        let run = ColumnRun::for_column(prep, n);
        let w = janssen_column(n, prep, &run, 1).unwrap();
        let p = PeerColumn::from_world(&w, 1e-8, run.max_time, 600.0).unwrap();
        (w, p)
    }

    /// Every grain of the world is written once, with its radius and centre to 1e-15 relative,
    /// and the box is the world's: floor 0, walls 0 and the column width.
    #[test]
    fn the_data_file_holds_the_worlds_grains_and_box() {
        let (w, p) = column(300, Preparation::Deposit);
        assert_eq!(p.floor, 0.0);
        assert_eq!(p.x_left, 0.0);
        assert!((p.x_right - COLUMN_WIDTH).abs() < 1e-15);
        assert_eq!((p.mu_grains, p.mu_walls), (0.5, 0.5));
        assert_eq!(p.density, 2500.0);
        let data = p.data_file();
        let atoms: Vec<Vec<f64>> = data
            .split("Atoms # sphere")
            .nth(1)
            .unwrap()
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect();
        let grains: Vec<_> = w
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .collect();
        assert_eq!(grains.len(), 300);
        assert_eq!(atoms.len(), grains.len());
        assert!(data.contains("\n300 atoms\n"));
        for (a, b) in atoms.iter().zip(&grains) {
            assert_eq!(a.len(), 7);
            assert!((a[2] / 2.0 - b.radius).abs() <= 1e-15 * b.radius);
            assert!((a[4] - b.position.x).abs() <= 1e-15 * COLUMN_WIDTH);
            assert!((a[5] - b.position.y).abs() <= 1e-15 * COLUMN_WIDTH);
            assert_eq!(a[6], 0.0);
        }
        let script = p.input_script("column.data", "final.dump");
        let walls = format!("xplane {:.17e} {:.17e}", 0.0, COLUMN_WIDTH);
        assert!(script.contains(&walls), "{script}");
        assert!(script.contains(&format!("yplane {:.17e} NULL", 0.0)));
        assert!(script.contains("dimension 2") && script.contains("nve/sphere disc"));
        assert!(script.contains("density/disc 2500"));
    }

    /// The step is t_c / 15 with t_c recomputed from the smallest grain of the world (the
    /// users' t_c / 10 – t_c / 20, not a finer step that would flatter grainlaw); k_n = 2·10⁵ m̄ g / d̄ and the restitution of the mean pair
    /// is 0.2, those of the extreme pairs between 0.05 and 0.5 (underdamped).
    #[test]
    fn the_time_step_resolves_the_smallest_collision() {
        let (_, p) = column(300, Preparation::Pour);
        let m = p.model;
        let m_min = p.masses.iter().copied().fold(f64::INFINITY, f64::min);
        let m_max = p.masses.iter().copied().fold(0.0, f64::max);
        let m_mean = p.masses.iter().sum::<f64>() / p.masses.len() as f64;
        let d_mean = 2.0 * p.radii.iter().sum::<f64>() / p.radii.len() as f64;
        assert!((m.kn / (2e5 * m_mean * 9.81 / d_mean) - 1.0).abs() < 1e-12);
        assert!((m.kt / m.kn - 2.0 / 7.0).abs() < 1e-15);
        let tc = std::f64::consts::PI / (2.0 * m.kn / m_min - m.gamma_n.powi(2) / 4.0).sqrt();
        assert!((m.collision_time / tc - 1.0).abs() < 1e-12);
        // t_c / 15: within the t_c / 10 – t_c / 20 of the code's users, not a finer step
        assert!((m.dt * 15.0 / tc - 1.0).abs() < 1e-12);
        assert!(m.dt >= tc / 20.0 && m.dt <= tc / 10.0);
        assert!((m.restitution(0.5 * m_mean) - 0.2).abs() < 1e-12);
        let (e_small, e_large) = (m.restitution(0.5 * m_min), m.restitution(0.5 * m_max));
        assert!(e_small > 0.3 && e_small < 0.5, "{e_small}");
        assert!(e_large > 0.05 && e_large < 0.15, "{e_large}");
        assert!(m.restitution(m_max) > 0.0);
        let script = p.input_script("d", "f");
        assert!(script.contains(&format!("timestep {:.10e}", m.dt)));
        assert!(script.contains(&format!("run {}", p.max_steps())));
        assert!(p.max_steps() as f64 * m.dt >= p.max_time);
    }

    const LOG: &str = "\
   49000        0.049 5.0787389e-06 0.00095517291 0.0053170885 
   49100       0.0491 2.1e-14 0.00095517291 9.7e-9 
Fix halt condition for fix-id halt met on step 49100 with value 9.7e-09 (src/fix_halt.cpp:253)
Loop time of 12.5 on 1 procs for 49100 steps with 2000 atoms

GRAINLAW_END step 49100 time 4.910000000e-02 ratio 9.700000000e-09
Total wall time: 0:00:13
";

    #[test]
    fn the_log_end_is_read() {
        let l = parse_log(LOG).unwrap();
        assert_eq!(l.steps, 49100);
        assert_eq!(l.simulated_seconds, 0.0491);
        assert_eq!(l.energy_ratio, 9.7e-9);
        assert_eq!(l.loop_seconds, Some(12.5));
        let cut = LOG.split("GRAINLAW_END").next().unwrap();
        assert!(parse_log(cut).is_err());
        assert!(parse_log(&LOG.replace("ratio 9.7", "ratio x9.7")).is_err());
    }

    #[test]
    fn the_final_dump_and_its_overlaps_are_read() {
        let dump = "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-1 1\nITEM: ATOMS id x y radius\n1 0.01 0.0009999 0.001\n2 0.0129995 0.001 0.002\n3 0.5 0.5 0.001\n";
        let d = parse_dump(dump).unwrap();
        assert_eq!(d.len(), 3);
        assert_eq!(d[1], (2, [0.0129995, 0.001], 0.002));
        let grains: Vec<_> = d.iter().map(|&(_, c, r)| (c, r)).collect();
        // grains 1 and 2: 3 mm apart by centres less 0.5 µm; grain 2 into the floor by 1 mm
        let o = largest_overlap(&grains, 0.0, 0.0, 1.0);
        assert!((o - 1e-3).abs() < 1e-12, "{o}");
        let o = largest_overlap(&grains[..1], 0.0, 0.0, 1.0);
        assert!((o - 1e-7).abs() < 1e-12, "{o}");
        // 0.5 µm less 1.7 pm from the 0.1 µm vertical offset
        let o = largest_overlap(&grains[..2], -1.0, -1.0, 1.0);
        assert!((o - 5e-7).abs() < 1e-11, "{o}");
    }

    /// The damping of a restitution: `e = exp(−π ζ / √(1 − ζ²))` recovered from `ζ` over
    /// e = 0.01 – 0.9, the mean pair of a model at `e` collides with restitution `e`, `e = 0` is
    /// critical damping (ζ = 1) and a restitution outside [0, 1) is refused.
    #[test]
    fn the_damping_gives_the_asked_restitution() {
        for &e in &[0.01, 0.05, 0.1, 0.2, 0.5, 0.9] {
            let z = damping_ratio(e);
            assert!(z > 0.0 && z < 1.0, "{e}: {z}");
            let back = (-std::f64::consts::PI * z / (1.0 - z * z).sqrt()).exp();
            assert!((back / e - 1.0).abs() < 1e-12, "{e}: {back}");
        }
        assert_eq!(damping_ratio(0.0), 1.0);
        assert_eq!(damping_ratio(1.0), 0.0);
        assert!(damping_ratio(-0.1).is_nan() && damping_ratio(1.5).is_nan());
        // 2000 masses spread as the RVE's (radii 1.2–1.8 mm): the mean pair at e
        let masses: Vec<f64> = (0..2000)
            .map(|k| {
                let r = 1.2e-3 + 0.6e-3 * k as f64 / 1999.0;
                2500.0 * std::f64::consts::PI * r * r
            })
            .collect();
        let m_mean = masses.iter().sum::<f64>() / masses.len() as f64;
        for &e in &[0.0, 0.01, 0.05, 0.2] {
            let m = ContactModel::with_stiffness(1e7, &masses, 12.0, e);
            assert!(m.is_usable(), "{e}");
            assert!((m.restitution(0.5 * m_mean) - e).abs() < 1e-12, "{e}");
            assert!((m.gamma_t / m.gamma_n - 0.5).abs() < 1e-15);
        }
        // less bouncing: more damping, a longer damped collision, a longer step
        let (a, b) = (
            ContactModel::with_stiffness(1e7, &masses, 12.0, 0.2),
            ContactModel::with_stiffness(1e7, &masses, 12.0, 0.01),
        );
        assert!(b.gamma_n > a.gamma_n && b.dt > a.dt);
        assert!(!ContactModel::with_stiffness(1e7, &masses, 12.0, 1.5).is_usable());
    }
}
