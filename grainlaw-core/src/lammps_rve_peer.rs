//! The soft-contact peer of `grainlaw bench --rve`: LAMMPS run on the representative volume of
//! grainlaw's `simple-shear` scenario, from the same initial grains, in the same run, one core.
//!
//! [`PeerRve::from_config`] builds the scenario's initial loose packing
//! (`crate::scenarios::simple_shear::build::simple_shear`, the same seed, radii and cell as
//! `grainlaw run simple-shear`) and takes the grains' centres and radii and the cell from it.
//! [`PeerRve::write_input`] writes a LAMMPS data file and input script; [`run`] runs `lmp -in`
//! serially (`OMP_NUM_THREADS=1`, no MPI launcher), wall-clock timed, and reads back its log
//! ([`parse_log`]: typed thermo rows, [`ThermoRow`]) and its snapshots (largest overlap,
//! [`largest_cell_overlap`]).
//!
//! # Units in 2D
//!
//! LAMMPS' `units si` with `dimension 2` and `set density/disc ρ` gives every disk the mass
//! `ρ π r²`: with ρ in kg/m³ that is the mass of a disk one metre thick, so LAMMPS' masses are kg
//! per metre of thickness, its forces N per metre, its stiffnesses N/m per metre, and its 2D
//! pressure (virial over `d · area`, [LAMMPS `compute pressure`]) is N/m per metre of length:
//! Pa, the stress of grainlaw's convention (2D quantities per metre of thickness). So `p_yy` of
//! the thermo output is `−σ_yy` in Pa, directly comparable with grainlaw's.
//!
//! # Contact model
//!
//! `pair_style gran/hooke/history` (Cundall & Strack 1979): linear spring–dashpot with
//! tangential history and Coulomb friction μ_p, the parameters of
//! [`crate::lammps_peer::ContactModel::with_stiffness`]:
//!
//! - `k_n = κ P · (1 m)` with κ = [`KAPPA`] = 10⁴ (`grainlaw bench --rve-kappa K`): the rigid limit of da Cruz et al. (Phys.
//!   Rev. E 72, 021309, 2005), whose 2D criterion is the stiffness number `κ = k_n / P ≥ 10⁴`
//!   (with `k_n` in N/m per metre of thickness and `P` in Pa, `k_n / P` is a length: over 1 m,
//!   the κ of a unit thickness); 10⁷ N/m per metre at P = 1 kPa. The mean overlap is then
//!   about `d / κ` of a diameter, 0.01 %.
//! - `k_t = 2/7 k_n`, `γ_t = γ_n / 2` (LAMMPS' `NULL` defaults), `γ_n` for a normal restitution
//!   `e` between two grains of the mean mass, a setting of the race (`grainlaw bench
//!   --rve-restitution E`, default [`RESTITUTION`]).
//! - Time step `h = t_c / 12` ([`STEPS_PER_COLLISION`]), `t_c = π / √(2 k_n / m_min − γ_n² / 4)`
//!   the collision time of the two smallest grains: in the `t_c / 10` – `t_c / 20` that
//!   soft-contact users take.
//!
//! # The run
//!
//! Biperiodic triclinic box (`boundary p p p`, the cell of the world: `a₁ = (l_x, 0)`,
//! `a₂ = (xy, l_y)`), disks (`fix nve/sphere disc`, `fix enforce2d`).
//!
//! 1. Isotropic compression to P for the scenario's `compression_duration · t_g`: each length
//!    follows its own normal stress, `dl_i/dt = ε̇_i l_i`, `ε̇_i = clamp(g (p_ii − P), ±ε̇_max)`,
//!    with `g = ε̇_max / P` and `ε̇_max = control_inertial_number · √(P/ρ) / d̄`, grainlaw's cap
//!    of the cell's strain rate (`fix deform x variable … y variable … remap x`).
//! 2. Simple shear at the scenario's `γ̇ = I √(P/ρ) / d̄` for the scenario's strain: `fix deform
//!    … xy erate γ̇ remap v flip yes` (Lees–Edwards through LAMMPS' deforming triclinic box),
//!    the grains given the streaming profile `v_x = γ̇ (y − y_lo)` at the start
//!    (`velocity … ramp`), `σ_yy = −P` held by the same servo on the height (cap
//!    `max(ε̇_max, γ̇)`, as grainlaw's), `l_x` fixed.
//!
//! The servo is `fix deform … variable`, the proportional control that later versions of LAMMPS
//! made a fix of (`fix deform/pressure`, with `normalize/pressure` and `max/rate`); LAMMPS 29 Sep
//! 2021 has no barostat for a triclinic box that leaves `xy` to `fix deform` and is first order
//! (`fix press/berendsen` refuses triclinic boxes; a Nosé–Hoover `fix nph/sphere` made the
//! compressed packing bounce off jamming). It acts every [`SERVO_EVERY`] steps, less than a
//! collision time, on the pressure of that step (`fix ave/time`), so that LAMMPS computes its
//! virial every tenth step only: a servo every step cost 19 % more time for the same hold of
//! σ_yy (2000 grains, measured on 2026-12-05).
//!
//! # Measurement
//!
//! The thermo output of the shear run, every `average_strain / (γ̇ h)` / [`WINDOW_SAMPLES`]
//! steps: `p_xx, p_yy, p_xy` of `compute pressure` with the kinetic part about the streaming
//! profile (`compute temp/deform`, as grainlaw's cell stress counts the fluctuations), the cell
//! `l_x, l_y, xy`, and the mean contacts per grain (`compute contact/atom`). Over the last
//! `average_strain`, per sample `μ = |p_xy| / p_yy`, `φ = Σ π r² / (l_x l_y)`, and their means
//! with block-averaged standard errors by the scenario's own code
//! (`crate::scenarios::simple_shear::RheologyPoint`, `homogenise::averaging::block_average`).
//! The largest overlap is measured on [`OVERLAP_SNAPSHOTS`] snapshots spread over the whole run
//! (`dump custom`, read by [`crate::readers::read_lammps`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use dem::cell::Cell;
use dem::math::Vector as Vect;
use dem::BodyKind;

use crate::error::{CliError, Result};
use crate::lammps_peer::{disk_masses, run_and_read, write_input_files, ContactModel, Outcome};
use crate::readers::{read_lammps, ReadOptions};
use crate::scenarios::simple_shear::config::SimpleShearConfig;
use crate::scenarios::simple_shear::{CellSamples, RheologyPoint};

/// Stiffness number κ = k_n / (P · 1 m) of the peer: the rigid limit (da Cruz et al. 2005).
pub const KAPPA: f64 = 1e4;
/// Default normal restitution of the race's peer between two grains of the mean mass
/// (`grainlaw bench --rve-restitution`): 0.2, the value soft-contact users commonly take.
pub const RESTITUTION: f64 = 0.2;
/// The race's settings of the peer's contacts (`grainlaw bench --rve-kappa`,
/// `--rve-restitution`); [`Default`]: κ = [`KAPPA`], e = [`RESTITUTION`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeerContact {
    /// Stiffness number κ = k_n / (P · 1 m), ≥ 10² (the rigid limit from 10⁴ on).
    pub kappa: f64,
    /// Normal restitution of two grains of the mean mass, in [0, 1).
    pub restitution: f64,
}

impl Default for PeerContact {
    fn default() -> Self {
        PeerContact {
            kappa: KAPPA,
            restitution: RESTITUTION,
        }
    }
}

/// Time steps per collision time of the two smallest grains (`h = t_c / 12`).
pub const STEPS_PER_COLLISION: f64 = 12.0;
/// Steps between two actions of the stress servo (`fix deform N`, `fix ave/time N`).
pub const SERVO_EVERY: u64 = 10;
/// Thermo samples over the averaging window (about).
pub const WINDOW_SAMPLES: u64 = 500;
/// Snapshots dumped over the whole run for the largest overlap.
pub const OVERLAP_SNAPSHOTS: u64 = 40;

/// The representative volume handed to LAMMPS.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerRve {
    /// Grain centres `[x, y]` (m), in the world's grain order (LAMMPS ids 1, 2, …), inside the
    /// cell whose corner is at the origin.
    pub centres: Vec<[f64; 2]>,
    /// Grain radii (m).
    pub radii: Vec<f64>,
    /// Grain masses per metre of thickness (kg/m), `ρ π r²`.
    pub masses: Vec<f64>,
    /// Grain density (kg/m³).
    pub density: f64,
    /// The cell: `a₁ = (l_x, 0)`, `a₂ = (xy, l_y)` (m), as `[l_x, l_y, xy]`.
    pub cell: [f64; 3],
    /// Friction grain–grain.
    pub mu: f64,
    /// Confining pressure P (Pa).
    pub pressure: f64,
    /// Mean diameter d̄ (m), as the scenario computes it.
    pub mean_diameter: f64,
    /// Target inertial number.
    pub inertial_number: f64,
    /// Shear rate `γ̇ = I √(P/ρ) / d̄` (1/s).
    pub gamma_dot: f64,
    /// Shear strain of the run.
    pub strain: f64,
    /// The last `average_strain` is averaged.
    pub average_strain: f64,
    /// Duration of the isotropic compression (s).
    pub compression_time: f64,
    /// Cap of the cell's strain rate under stress control `ε̇_max` (1/s).
    pub rate_cap: f64,
    /// Contact model and time step.
    pub model: ContactModel,
    /// Normal restitution of two grains of the mean mass that the model's damping gives.
    pub restitution: f64,
    /// Stiffness number κ = k_n / (P · 1 m).
    pub kappa: f64,
    /// Wall-clock limit of the run (s).
    pub wall_limit: f64,
}

fn bad(reason: impl Into<String>) -> CliError {
    CliError::Usage(format!("LAMMPS RVE peer: {}", reason.into()))
}

/// `x` as LAMMPS reads it back to the bit (17 significant digits).
fn full(x: f64) -> String {
    format!("{x:.16e}")
}

impl PeerRve {
    /// The representative volume of the `simple-shear` scenario `c` sheared at the inertial number
    /// `inertial` (its `strain`, `average_strain`, `pressure`, `compression_duration`,
    /// `control_inertial_number`, friction and grains), the initial grains and cell those of
    /// `crate::scenarios::simple_shear::build::simple_shear(c)`; `wall_limit` seconds of wall clock
    /// at most; `k_n = κ P · 1 m` and the dashpot for a normal restitution `e` ∈ [0, 1) between two
    /// grains of the mean mass, `contact` ([`ContactModel::with_stiffness`]; e = 0.2 is the users'
    /// choice, grainlaw's model has `c.restitution`, 0 by default).
    pub fn from_config(
        c: &SimpleShearConfig,
        inertial: f64,
        wall_limit: f64,
        contact: PeerContact,
    ) -> Result<Self> {
        let PeerContact { kappa, restitution } = contact;
        if !(kappa.is_finite() && kappa >= 1e2) {
            return Err(bad(format!("the peer's κ must be ≥ 100, got {kappa}")));
        }
        if !(inertial.is_finite() && inertial > 0.0) {
            return Err(bad(format!(
                "the inertial number must be > 0, got {inertial}"
            )));
        }
        if !(0.0..1.0).contains(&restitution) {
            return Err(bad(format!(
                "the peer's restitution must lie in [0, 1), got {restitution}"
            )));
        }
        let w = crate::scenarios::simple_shear::build::simple_shear(c)?;
        let cell = w
            .cell()
            .ok_or_else(|| bad("the scenario's world has no biperiodic cell"))?;
        let h = cell.h;
        if h[(1, 0)] != 0.0 || h[(0, 0)] <= 0.0 || h[(1, 1)] <= 0.0 {
            return Err(bad(format!(
                "LAMMPS' triclinic box needs a₁ along x and a₂ upwards, got h = {h:?}"
            )));
        }
        let grains: Vec<_> = w
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .collect();
        let Some(first) = grains.first() else {
            return Err(bad("no grains"));
        };
        let (density, radii, masses) = disk_masses(first, &grains).map_err(bad)?;
        let d = crate::scenarios::common::mean_diameter(&w);
        let (p, rho) = (c.pressure, c.grain.density);
        let model = ContactModel::with_stiffness(
            kappa * p * 1.0,
            &masses,
            STEPS_PER_COLLISION,
            restitution,
        );
        if !model.is_usable() {
            return Err(bad(format!(
                "restitution {restitution} overdamps the two smallest grains (no collision time): take e > 0"
            )));
        }
        Ok(PeerRve {
            centres: grains
                .iter()
                .map(|b| [b.position.x, b.position.y])
                .collect(),
            model,
            restitution,
            kappa,
            radii,
            masses,
            density,
            cell: [h[(0, 0)], h[(1, 1)], h[(0, 1)]],
            mu: c.friction.grain_grain,
            pressure: p,
            mean_diameter: d,
            inertial_number: inertial,
            gamma_dot: inertial * (p / rho).sqrt() / d,
            strain: c.strain,
            average_strain: c.average_strain,
            compression_time: c.compression_duration * c.grain_time(),
            rate_cap: c.control_inertial_number * (p / rho).sqrt() / d,
            wall_limit,
        })
    }

    /// Area of the grains `Σ π r²` (m² per metre).
    pub fn grain_area(&self) -> f64 {
        self.radii
            .iter()
            .map(|r| std::f64::consts::PI * r * r)
            .sum()
    }

    /// Steps of the compression: `⌈compression_time / h⌉`, rounded up to a multiple of
    /// [`SERVO_EVERY`].
    pub fn compression_steps(&self) -> u64 {
        let n = (self.compression_time / self.model.dt).ceil() as u64;
        n.div_ceil(SERVO_EVERY) * SERVO_EVERY
    }

    /// Steps of the shear: `⌈strain / (γ̇ h)⌉`.
    pub fn shear_steps(&self) -> u64 {
        (self.strain / (self.gamma_dot * self.model.dt)).ceil() as u64
    }

    /// Steps between two thermo samples of the shear: `average_strain / (γ̇ h)` over
    /// [`WINDOW_SAMPLES`], at least 1.
    pub fn sample_every(&self) -> u64 {
        ((self.average_strain / (self.gamma_dot * self.model.dt)) / WINDOW_SAMPLES as f64)
            .floor()
            .max(1.0) as u64
    }

    /// The servo's gain `g = ε̇_max / P` (1/(Pa s)).
    pub fn gain(&self) -> f64 {
        self.rate_cap / self.pressure
    }

    /// The data file (triclinic box, `atom_style sphere`: id, type, diameter, density, x, y,
    /// z), numbers with 17 significant digits.
    pub fn data_file(&self) -> String {
        let r_max = self.radii.iter().copied().fold(0.0, f64::max);
        let [lx, ly, xy] = self.cell;
        let mut s = String::new();
        let _ = writeln!(s, "grainlaw simple-shear RVE (LAMMPS peer)\n");
        let _ = writeln!(s, "{} atoms\n1 atom types\n", self.centres.len());
        let _ = writeln!(
            s,
            "0 {} xlo xhi\n0 {} ylo yhi\n{} {} zlo zhi\n{} 0 0 xy xz yz\n",
            full(lx),
            full(ly),
            full(-r_max),
            full(r_max),
            full(xy)
        );
        let _ = writeln!(s, "Atoms # sphere\n");
        for (i, (c, r)) in self.centres.iter().zip(&self.radii).enumerate() {
            let _ = writeln!(
                s,
                "{} 1 {} {} {} {} 0",
                i + 1,
                full(2.0 * r),
                self.density,
                full(c[0]),
                full(c[1])
            );
        }
        s
    }

    /// The input script reading `data_file` and dumping the snapshots into `dump_file`.
    pub fn input_script(&self, data_file: &str, dump_file: &str) -> String {
        let m = &self.model;
        let r_min = self.radii.iter().copied().fold(f64::INFINITY, f64::min);
        let (p, g) = (self.pressure, self.gain());
        let clamp = |v: &str, cap: f64| {
            format!("0.5*(abs(v_{v}+{c})-abs(v_{v}-{c}))", c = full(cap), v = v)
        };
        let (ncomp, nshear) = (self.compression_steps(), self.shear_steps());
        let servo_dt = SERVO_EVERY as f64 * m.dt;
        let limit = self.wall_limit.max(1.0).ceil() as u64;
        format!(
            "# grainlaw bench --rve: LAMMPS peer of the simple-shear RVE (see grainlaw-core/src/lammps_rve_peer.rs)
units si
dimension 2
atom_style sphere
boundary p p p
comm_modify vel yes
read_data {data_file}
set type 1 density/disc {density}
pair_style gran/hooke/history {kn} {kt} {gn} {gt} {mu} 1
pair_coeff * *
neighbor {skin} bin
neigh_modify delay 0 every 1 check yes
timestep {dt}
fix integrate all nve/sphere disc
fix planar all enforce2d
compute contacts all contact/atom
compute z all reduce ave c_contacts
dump overlap all custom {ndump} {dump_file} id x y vx vy omegaz radius mass
dump_modify overlap sort id time yes format float %.17g
timer timeout {hh:02}:{mm:02}:{ss:02} every 100
# 1. isotropic compression to P: each length servoed on its own normal stress
compute pc all pressure thermo_temp
fix pav all ave/time {every} 1 {every} c_pc[1] c_pc[2]
variable rx equal {g}*(f_pav[1]-{p})
variable ry equal {g}*(f_pav[2]-{p})
variable ex equal {ex}
variable ey equal {ey}
variable lx0 equal $(lx)
variable ly0 equal $(ly)
variable vx equal v_ex*lx
variable vy equal v_ey*ly
variable dx equal lx-v_lx0+{servo_dt}*v_vx
variable dy equal ly-v_ly0+{servo_dt}*v_vy
fix cell all deform {every} x variable v_dx v_vx y variable v_dy v_vy remap x
thermo_style custom step c_pc[1] c_pc[2] c_pc[4] lx ly xy c_z
thermo_modify format float %.10g
thermo {thermo_comp}
run {ncomp}
unfix cell
unfix pav
# 2. simple shear at gamma_dot, sigma_yy = -P held by the servo on the height
compute tdef all temp/deform
compute p all pressure tdef
fix pav all ave/time {every} 1 {every} c_p[2]
variable rs equal {g}*(f_pav-{p})
variable es equal {es}
variable ly0 equal $(ly)
variable vs equal v_es*ly
variable ds equal ly-v_ly0+{servo_dt}*v_vs
velocity all ramp vx 0 $({gd}*ly) y $(ylo) $(yhi) sum yes units box
print \"GRAINLAW_SHEAR step $(step)\"
fix cell all deform {every} y variable v_ds v_vs xy erate {gd} remap v flip yes
thermo_style custom step c_p[1] c_p[2] c_p[4] lx ly xy c_z
thermo_modify format float %.10g
thermo {sample}
run {nshear}
print \"GRAINLAW_END step $(step)\"
",
            density = self.density,
            kn = full(m.kn),
            kt = full(m.kt),
            gn = full(m.gamma_n),
            gt = full(m.gamma_t),
            mu = self.mu,
            skin = full(0.1 * r_min),
            dt = full(m.dt),
            ndump = ((ncomp + nshear) / OVERLAP_SNAPSHOTS).max(1),
            hh = limit / 3600,
            mm = limit / 60 % 60,
            ss = limit % 60,
            every = SERVO_EVERY,
            g = full(g),
            p = full(p),
            ex = clamp("rx", self.rate_cap),
            ey = clamp("ry", self.rate_cap),
            es = clamp("rs", self.rate_cap.max(self.gamma_dot)),
            servo_dt = full(servo_dt),
            thermo_comp = (ncomp / 10).max(1),
            gd = full(self.gamma_dot),
            sample = self.sample_every(),
        )
    }

    /// Writes `rve.data` and `in.rve` into `dir`; returns the input's path.
    pub fn write_input(&self, dir: &Path) -> Result<PathBuf> {
        write_input_files(
            dir,
            ("rve.data", &self.data_file()),
            ("in.rve", &self.input_script("rve.data", "overlap.dump")),
        )
    }
}

/// One thermo line of the shear run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermoRow {
    /// Step (LAMMPS' count, from the start of the compression).
    pub step: u64,
    /// `p_xx = −σ_xx` (Pa).
    pub pxx: f64,
    /// `p_yy = −σ_yy` (Pa).
    pub pyy: f64,
    /// `p_xy = −σ_xy` (Pa).
    pub pxy: f64,
    /// Cell length along x (m).
    pub lx: f64,
    /// Cell height (m).
    pub ly: f64,
    /// Cell tilt (m).
    pub xy: f64,
    /// Mean contacts per grain (`compute contact/atom`).
    pub z: f64,
}

/// The columns of the shear run's thermo output, in [`ThermoRow`]'s order.
const THERMO_COLUMNS: [&str; 8] = [
    "Step", "c_p[1]", "c_p[2]", "c_p[4]", "Lx", "Ly", "Xy", "c_z",
];

/// What the log of a peer run says.
#[derive(Debug, Clone, PartialEq)]
pub struct RveLog {
    /// LAMMPS' loop time of the compression (s).
    pub compression_seconds: f64,
    /// Steps of the compression.
    pub compression_steps: u64,
    /// Step at which the shear started.
    pub shear_start: u64,
    /// LAMMPS' loop time of the shear (s).
    pub shear_seconds: f64,
    /// Steps of the shear run.
    pub shear_steps: u64,
    /// The last step.
    pub end_step: u64,
    /// The thermo rows of the shear run.
    pub rows: Vec<ThermoRow>,
}

/// `Loop time of T on P procs for N steps ...`: `(T, N)`.
fn loop_line(l: &str) -> Option<(f64, u64)> {
    let rest = l.trim().strip_prefix("Loop time of ")?;
    let w: Vec<&str> = rest.split_whitespace().collect();
    let t = w.first()?.parse().ok()?;
    let n = w.iter().position(|x| *x == "for")?;
    Some((t, w.get(n + 1)?.parse().ok()?))
}

/// The step of a `MARKER step N` line.
fn marker(text: &str, name: &str) -> Result<u64> {
    let line = text
        .lines()
        .find_map(|l| l.trim().strip_prefix(name))
        .ok_or_else(|| {
            bad(format!(
                "no {name} line in the log (the run did not get there)"
            ))
        })?;
    line.trim()
        .strip_prefix("step ")
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| bad(format!("{name} line without a step: {line}")))
}

/// Reads the log of [`PeerRve::input_script`]: the compression's and the shear's loop times
/// and steps, the shear's start and end (the `GRAINLAW_SHEAR` and `GRAINLAW_END` lines) and the
/// thermo rows of the shear (columns found by their header names, [`ThermoRow`]).
pub fn parse_log(text: &str) -> Result<RveLog> {
    let shear_start = marker(text, "GRAINLAW_SHEAR ")?;
    let end_step = marker(text, "GRAINLAW_END ")?;
    let (head, tail) = text
        .split_once("\nGRAINLAW_SHEAR ")
        .ok_or_else(|| bad("no GRAINLAW_SHEAR line at the start of a line"))?;
    let (compression_seconds, compression_steps) = head
        .lines()
        .rev()
        .find_map(loop_line)
        .ok_or_else(|| bad("no `Loop time` line of the compression"))?;
    let mut lines = tail.lines();
    let header: Vec<&str> = lines
        .by_ref()
        .find(|l| l.trim_start().starts_with("Step "))
        .ok_or_else(|| bad("no thermo header of the shear run"))?
        .split_whitespace()
        .collect();
    let cols: Vec<usize> = THERMO_COLUMNS
        .iter()
        .map(|c| {
            header
                .iter()
                .position(|h| h == c)
                .ok_or_else(|| bad(format!("the shear's thermo header has no `{c}`")))
        })
        .collect::<Result<_>>()?;
    let mut rows = Vec::new();
    let mut shear = None;
    for l in lines {
        if let Some(t) = loop_line(l) {
            shear = Some(t);
            break;
        }
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.len() != header.len() {
            continue; // a warning or message inside the run
        }
        let Some(v) = w
            .iter()
            .map(|x| x.parse::<f64>().ok())
            .collect::<Option<Vec<f64>>>()
        else {
            continue;
        };
        let step = w[cols[0]]
            .parse::<u64>()
            .map_err(|_| bad(format!("thermo line with a step that is not a count: {l}")))?;
        rows.push(ThermoRow {
            step,
            pxx: v[cols[1]],
            pyy: v[cols[2]],
            pxy: v[cols[3]],
            lx: v[cols[4]],
            ly: v[cols[5]],
            xy: v[cols[6]],
            z: v[cols[7]],
        });
    }
    let (shear_seconds, shear_steps) =
        shear.ok_or_else(|| bad("no `Loop time` line of the shear run"))?;
    Ok(RveLog {
        compression_seconds,
        compression_steps,
        shear_start,
        shear_seconds,
        shear_steps,
        end_step,
        rows,
    })
}

/// μ, φ (and P, Z) over the averaging window, as the scenario reports them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RveMeasure {
    /// μ = ⟨|p_xy| / p_yy⟩.
    pub mu: f64,
    /// Its block-averaged standard error.
    pub mu_se: f64,
    /// φ = ⟨Σ π r² / (l_x l_y)⟩.
    pub phi: f64,
    /// Its block-averaged standard error.
    pub phi_se: f64,
    /// ⟨p_yy⟩ (Pa).
    pub pn: f64,
    /// Its standard error (Pa).
    pub pn_se: f64,
    /// Mean contacts per grain.
    pub z: f64,
    /// The inertial number `γ̇ d̄ / √(⟨p_yy⟩/ρ)`.
    pub inertial_number: f64,
    /// Samples averaged.
    pub samples: usize,
}

impl RveLog {
    /// The measure over the rows of the last `rve.average_strain` of the shear (a row's strain
    /// is `γ̇ h` times its steps since the shear started), by the scenario's
    /// `RheologyPoint::of`: means with block-averaged standard errors.
    pub fn measure(&self, rve: &PeerRve) -> Result<RveMeasure> {
        let area = rve.grain_area();
        let per_step = rve.gamma_dot * rve.model.dt;
        let from = rve.strain - rve.average_strain;
        let window: Vec<&ThermoRow> = self
            .rows
            .iter()
            .filter(|r| {
                r.step > self.shear_start
                    && (r.step - self.shear_start) as f64 * per_step > from * (1.0 + 1e-12)
            })
            .collect();
        let mut s = CellSamples::default();
        for r in &window {
            s.normal_stress.push(r.pyy);
            s.mu.push(if r.pyy > 0.0 {
                r.pxy.abs() / r.pyy
            } else {
                f64::NAN
            });
            s.phi.push(area / (r.lx * r.ly));
            s.pressure.push(0.5 * (r.pxx + r.pyy));
            s.coordination.push(r.z);
        }
        let p = RheologyPoint::of(&s, rve.gamma_dot, rve.mean_diameter, rve.density)?;
        Ok(RveMeasure {
            mu: p.mu,
            mu_se: p.mu_se,
            phi: p.phi,
            phi_se: p.phi_se,
            pn: p.pn,
            pn_se: p.pn_se,
            z: p.z,
            inertial_number: p.i,
            samples: window.len(),
        })
    }
}

/// Largest overlap (m) between two disks of `grains` (centre, radius) in the biperiodic `cell`,
/// each pair taken at its minimum image ([`Cell::min_image`]); 0 if none. For a cell with
/// `a₁` along x (LAMMPS' boxes) the grains are sorted by `y` modulo the height `l_y` and each
/// compared with those less than `2 r_max` above it (cyclically); otherwise every pair.
pub fn largest_cell_overlap(cell: &Cell, grains: &[(Vect, f64)]) -> f64 {
    let n = grains.len();
    let r_max = grains.iter().map(|g| g.1).fold(0.0, f64::max);
    let pair = |i: usize, j: usize| {
        let (d, _) = cell.min_image(&(grains[j].0 - grains[i].0));
        grains[i].1 + grains[j].1 - d.norm()
    };
    let mut worst = 0.0f64;
    if cell.h[(1, 0)] != 0.0 {
        for i in 0..n {
            for j in i + 1..n {
                worst = worst.max(pair(i, j));
            }
        }
        return worst;
    }
    let ly = cell.h[(1, 1)];
    let y = |i: usize| grains[i].0.y.rem_euclid(ly);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| y(a).total_cmp(&y(b)));
    for (a, &i) in order.iter().enumerate() {
        for k in 1..n {
            let j = order[(a + k) % n];
            if (y(j) - y(i)).rem_euclid(ly) > 2.0 * r_max {
                break;
            }
            worst = worst.max(pair(i, j));
        }
    }
    worst
}

/// The largest overlap over the snapshots of the dump `path` (read by
/// [`crate::readers::read_lammps`]), over the smallest radius.
pub fn largest_overlap_ratio(path: &Path) -> Result<f64> {
    let snaps = read_lammps(
        &[path.to_path_buf()],
        &ReadOptions {
            gravity: [0.0, 0.0],
            ..ReadOptions::default()
        },
    )
    .map_err(|e| bad(e.to_string()))?;
    let mut worst = 0.0f64;
    for s in &snaps {
        let cell = s
            .snapshot
            .cell
            .ok_or_else(|| bad(format!("{}: a snapshot without its cell", path.display())))?;
        let grains: Vec<(Vect, f64)> = s
            .snapshot
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| (b.position, b.radius))
            .collect();
        let r_min = grains.iter().map(|g| g.1).fold(f64::INFINITY, f64::min);
        worst = worst.max(largest_cell_overlap(&cell, &grains) / r_min);
    }
    Ok(worst)
}

/// A finished peer run.
#[derive(Debug, Clone, PartialEq)]
pub struct RveRun {
    /// Wall-clock seconds of `lmp` (start to exit, reading the data included).
    pub wall_seconds: f64,
    /// What the log says.
    pub log: RveLog,
    /// Whether both runs made all their steps (not stopped by the wall-clock limit).
    pub finished: bool,
    /// μ, φ over the window.
    pub measure: RveMeasure,
    /// Largest overlap over the smallest radius, over [`OVERLAP_SNAPSHOTS`] snapshots.
    pub overlap_ratio: f64,
}

/// The outcome of a representative volume's peer run (finished or not: see
/// [`RveRun::finished`]).
pub type RveOutcome = Outcome<RveRun>;

/// Writes the RVE's input into `dir`, runs `lmp -in in.rve` there on one core and reads the
/// result. `dir` is removed after a run that was read, kept after a failure.
pub fn run(lmp: &Path, rve: &PeerRve, dir: &Path) -> Result<RveOutcome> {
    rve.write_input(dir)?;
    Ok(run_and_read(lmp, dir, "in.rve", |wall_seconds, text| {
        let log = parse_log(text).map_err(|e| e.to_string())?;
        let finished = log.end_step == rve.compression_steps() + rve.shear_steps()
            && log.shear_steps == rve.shear_steps();
        let measure = log
            .measure(rve)
            .map_err(|e| format!("the window's samples: {e}"))?;
        let overlap_ratio = largest_overlap_ratio(&dir.join("overlap.dump"))
            .map_err(|e| format!("overlap.dump: {e}"))?;
        Ok(RveRun {
            wall_seconds,
            log,
            finished,
            measure,
            overlap_ratio,
        })
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scenario's configuration with `n` grains, strain `s`, the last `a` averaged.
    fn config(n: usize, s: f64, a: f64) -> SimpleShearConfig {
        let sets = [
            format!("grains={n}"),
            "inertial_numbers=[0.01]".to_string(),
            format!("strain={s}"),
            format!("average_strain={a}"),
            r#"leave_out=["mu-i","mu-i-linear","phi-i"]"#.to_string(),
        ];
        let loaded = crate::scenarios::registry::load("simple-shear", &sets).unwrap();
        crate::scenarios::registry::config_of(&loaded).unwrap()
    }

    /// The race's contact settings reach the model: κ sets `k_n = κ P · 1 m` (the step falls
    /// as `1/√κ` at fixed damping ratio), e sets the mean pair's restitution and the script's
    /// `γ_n`; κ below 100 and e outside [0, 1) are refused with a message, not a panic.
    #[test]
    fn the_races_contact_settings_reach_the_model() {
        let c = config(100, 0.5, 0.25);
        let base = PeerRve::from_config(&c, 0.01, 600.0, PeerContact::default()).unwrap();
        let stiff = PeerContact {
            kappa: 1e5,
            restitution: 0.01,
        };
        let p = PeerRve::from_config(&c, 0.01, 600.0, stiff).unwrap();
        assert_eq!((p.kappa, p.restitution), (1e5, 0.01));
        assert!((p.model.kn / (1e5 * c.pressure) - 1.0).abs() < 1e-15);
        let n = p.masses.len() as f64;
        let m_mean = p.masses.iter().sum::<f64>() / n;
        assert!((p.model.restitution(0.5 * m_mean) - 0.01).abs() < 1e-12);
        let script = p.input_script("rve.data", "rve.dump");
        assert!(script.contains(&full(p.model.gamma_n)), "{script}");
        // same e at 10× κ: the step shrinks by √10
        let same_e = PeerContact {
            kappa: 1e5,
            restitution: base.restitution,
        };
        let q = PeerRve::from_config(&c, 0.01, 600.0, same_e).unwrap();
        assert!((base.model.dt / q.model.dt / 10f64.sqrt() - 1.0).abs() < 1e-12);
        for bad in [
            PeerContact {
                kappa: 10.0,
                restitution: 0.2,
            },
            PeerContact {
                kappa: 1e4,
                restitution: 1.0,
            },
            PeerContact {
                kappa: f64::NAN,
                restitution: 0.2,
            },
        ] {
            assert!(
                PeerRve::from_config(&c, 0.01, 600.0, bad).is_err(),
                "{bad:?}"
            );
        }
    }

    /// Numbers of the data lines after `Atoms # sphere`.
    fn atoms(data: &str) -> Vec<Vec<f64>> {
        data.split("Atoms # sphere")
            .nth(1)
            .unwrap()
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect()
    }

    /// The input holds the scenario's grains (every one, its radius and centre to 1e-15
    /// relative), the triclinic box of its cell, k_n = 10⁴ P, k_t = 2/7 k_n, and h = t_c / 12
    /// with t_c recomputed from the two smallest grains; the restitution of the mean pair is
    /// 0.2; γ̇ = I √(P/ρ)/d̄.
    #[test]
    fn the_input_holds_the_scenarios_grains_cell_and_settings() {
        let c = config(100, 0.5, 0.25);
        let p = PeerRve::from_config(&c, 0.01, 600.0, PeerContact::default()).unwrap();
        let w = crate::scenarios::simple_shear::build::simple_shear(&c).unwrap();
        let cell = w.cell().unwrap();
        let grains: Vec<_> = w
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .collect();
        assert_eq!(grains.len(), 100);
        let data = p.data_file();
        assert!(data.contains("\n100 atoms\n"));
        let h = cell.h;
        assert!(data.contains(&format!("0 {} xlo xhi\n", full(h[(0, 0)]))));
        assert!(data.contains(&format!("0 {} ylo yhi\n", full(h[(1, 1)]))));
        assert!(data.contains(&format!("\n{} 0 0 xy xz yz\n", full(h[(0, 1)]))));
        let a = atoms(&data);
        assert_eq!(a.len(), grains.len());
        for (k, (row, b)) in a.iter().zip(&grains).enumerate() {
            assert_eq!(row.len(), 7);
            assert_eq!(row[0], (k + 1) as f64);
            assert!((row[2] / 2.0 - b.radius).abs() <= 1e-15 * b.radius);
            assert_eq!(row[3], 2500.0);
            assert!((row[4] - b.position.x).abs() <= 1e-15 * h[(0, 0)]);
            assert!((row[5] - b.position.y).abs() <= 1e-15 * h[(1, 1)]);
        }
        // stiffness, damping, step
        let m = p.model;
        assert!((m.kn - 1e4 * 1000.0).abs() <= 1e-9 * m.kn);
        assert!((m.kt / m.kn - 2.0 / 7.0).abs() < 1e-15);
        let m_min = p.masses.iter().copied().fold(f64::INFINITY, f64::min);
        let m_mean = p.masses.iter().sum::<f64>() / p.masses.len() as f64;
        let tc = std::f64::consts::PI / (2.0 * m.kn / m_min - m.gamma_n.powi(2) / 4.0).sqrt();
        assert!((m.collision_time / tc - 1.0).abs() < 1e-12);
        assert!((m.dt * 12.0 / tc - 1.0).abs() < 1e-12);
        assert!((m.restitution(0.5 * m_mean) - 0.2).abs() < 1e-12);
        let d = 2.0 * p.radii.iter().sum::<f64>() / 100.0;
        assert!((p.gamma_dot - 0.01 * (1000.0f64 / 2500.0).sqrt() / d).abs() < 1e-12);
        let script = p.input_script("rve.data", "overlap.dump");
        for needle in [
            "dimension 2".to_string(),
            "boundary p p p".into(),
            "set type 1 density/disc 2500".into(),
            "fix integrate all nve/sphere disc".into(),
            "fix planar all enforce2d".into(),
            format!(
                "pair_style gran/hooke/history {} {} {} {} 0.5 1",
                full(m.kn),
                full(m.kt),
                full(m.gamma_n),
                full(m.gamma_t)
            ),
            format!("timestep {}", full(m.dt)),
            format!("xy erate {} remap v flip yes", full(p.gamma_dot)),
            format!("run {}", p.compression_steps()),
            format!("run {}", p.shear_steps()),
            "compute tdef all temp/deform".into(),
        ] {
            assert!(script.contains(&needle), "no `{needle}` in\n{script}");
        }
        // the shear's steps make the strain
        let s = p.shear_steps() as f64 * p.gamma_dot * m.dt;
        assert!(s >= 0.5 && s < 0.5 + p.gamma_dot * m.dt, "{s}");
    }

    /// The number after `key` on the last line of `script` that starts with it.
    fn script_number(script: &str, key: &str) -> f64 {
        script
            .lines()
            .rev()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no `{key}` in the script"))
    }

    /// The log of a real run (100 grains, strain 0.5, the last 0.25 averaged; LAMMPS 29 Sep
    /// 2021, `datasets/external/lammps-rve-peer/`, its input and data beside it): the runs'
    /// loop times and steps, the shear's start and end, every thermo row of the shear (one at
    /// the start, then every 35 steps, and the last step), and μ, φ of the window against the
    /// rows recomputed by hand. Everything about the run is read from its own files, not from
    /// the scenario's current defaults.
    #[test]
    fn the_log_of_a_real_run_is_read() {
        let dir =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../datasets/external/lammps-rve-peer");
        let text = crate::readers::read_text(&dir.join("log.lammps.gz")).unwrap();
        let script = std::fs::read_to_string(dir.join("in.rve")).unwrap();
        let data = std::fs::read_to_string(dir.join("rve.data")).unwrap();
        let l = parse_log(&text).unwrap();
        let runs: Vec<u64> = script
            .lines()
            .filter_map(|l| l.strip_prefix("run ")?.trim().parse().ok())
            .collect();
        assert_eq!(runs, [22560, 35325]);
        assert_eq!(l.compression_steps, 22560);
        assert_eq!(l.shear_start, 22560);
        assert_eq!(l.shear_steps, 35325);
        assert_eq!(l.end_step, 22560 + 35325);
        assert!(l.compression_seconds > 0.0 && l.shear_seconds > 0.0);
        // rows: the start, every multiple of 35 after it, the last step
        let every = script_number(&script, "thermo ") as u64;
        assert_eq!(every, 35);
        let multiples = l.end_step / every - l.shear_start / every;
        let last = u64::from(!l.end_step.is_multiple_of(every));
        assert_eq!(l.rows.len() as u64, 1 + multiples + last);
        assert_eq!(l.rows[0].step, l.shear_start);
        assert!(l.rows[1..l.rows.len() - 1]
            .iter()
            .all(|r| r.step.is_multiple_of(every)));
        assert_eq!(l.rows.last().unwrap().step, l.end_step);
        assert!(l.rows.windows(2).all(|w| w[1].step > w[0].step));
        for r in &l.rows {
            assert!(r.pyy > 0.0 && r.lx > 0.0 && r.ly > 0.0, "{r:?}");
        }
        assert!(l.rows.iter().any(|r| r.z > 0.0 && r.xy != 0.0));
        // the run's peer: its radii, step and shear rate from its own files
        let c = config(100, 0.5, 0.25);
        let mut p = PeerRve::from_config(&c, 0.01, 600.0, PeerContact::default()).unwrap();
        p.radii = atoms(&data).iter().map(|a| a[2] / 2.0).collect();
        p.model.dt = script_number(&script, "timestep ");
        p.gamma_dot = script
            .lines()
            .find_map(|l| l.split_once("xy erate "))
            .and_then(|(_, r)| r.split_whitespace().next()?.parse().ok())
            .unwrap();
        let m = l.measure(&p).unwrap();
        let per_step = p.gamma_dot * p.model.dt;
        let window: Vec<&ThermoRow> = l
            .rows
            .iter()
            .filter(|r| (r.step - l.shear_start) as f64 * per_step > 0.25 + 1e-9)
            .collect();
        assert_eq!(m.samples, window.len());
        assert!(m.samples > 400, "{}", m.samples);
        let n = window.len() as f64;
        let mu = window.iter().map(|r| r.pxy.abs() / r.pyy).sum::<f64>() / n;
        let area: f64 = p.radii.iter().map(|r| std::f64::consts::PI * r * r).sum();
        let phi = window.iter().map(|r| area / (r.lx * r.ly)).sum::<f64>() / n;
        assert!((m.mu - mu).abs() < 1e-12 && (m.phi - phi).abs() < 1e-12);
        assert!(m.mu_se > 0.0 && m.phi_se > 0.0);
        assert!(
            m.mu > 0.05 && m.mu < 0.6 && m.phi > 0.7 && m.phi < 0.9,
            "{m:?}"
        );
        // a log cut before the end of the shear is refused
        let cut = text.split("GRAINLAW_END").next().unwrap();
        assert!(parse_log(cut).is_err());
    }

    /// Two disks across the tilted cell's top and bottom edges, and across its right and left
    /// edges, overlap by 0.5 mm at their minimum image; far grains do not overlap.
    #[test]
    fn overlaps_are_found_across_the_periodic_edges() {
        use dem::math::Tensor as Mat;
        // a₁ = (0.1, 0), a₂ = (0.03, 0.08)
        let cell = Cell::new(Mat::new(0.1, 0.03, 0.0, 0.08), Mat::zeros()).unwrap();
        // b − a₂ is 1.5 mm below a: the pair meets across the tilted top and bottom edges
        let a = Vect::new(0.05, 0.0005);
        let b = a + Vect::new(0.03, 0.08) - Vect::new(0.0, 0.0015);
        let o = largest_cell_overlap(&cell, &[(a, 0.001), (b, 0.001)]);
        assert!((o - 0.0005).abs() < 1e-12, "{o}");
        // across the right and left edges, 1.5 mm apart
        let grains = [
            (Vect::new(0.0005, 0.04), 0.001),
            (Vect::new(0.099, 0.04), 0.001),
            (Vect::new(0.05, 0.02), 0.001),
        ];
        let o = largest_cell_overlap(&cell, &grains);
        assert!((o - 0.0005).abs() < 1e-12, "{o}");
        // the every-pair path of a cell whose a₁ is not along x finds the same
        let turned = Cell::new(Mat::new(0.1, 0.03, 1e-12, 0.08), Mat::zeros()).unwrap();
        assert!((largest_cell_overlap(&turned, &grains) - 0.0005).abs() < 1e-9);
        // far apart: none
        let far = [
            (Vect::new(0.01, 0.01), 0.001),
            (Vect::new(0.05, 0.04), 0.001),
        ];
        assert_eq!(largest_cell_overlap(&cell, &far), 0.0);
    }

    /// LAMMPS on a 100-grain RVE, strain 1, the last 0.5 averaged (only where `lmp` is found):
    /// it finishes, μ is in the range of a sheared frictional packing and φ in (0.7, 0.9), p_yy
    /// held at P within 10 %, overlaps below 1 % of the smallest radius.
    #[test]
    fn lammps_shears_a_tiny_rve() {
        let Some(lmp) = crate::lammps_peer::find_lammps() else {
            println!("skipped: LAMMPS not found (lmp on PATH or GRAINLAW_LAMMPS)");
            return;
        };
        let c = config(100, 1.0, 0.5);
        let p = PeerRve::from_config(&c, 0.01, 300.0, PeerContact::default()).unwrap();
        let dir = std::env::temp_dir().join(format!("grainlaw-test-rve-{}", std::process::id()));
        let r = match run(&lmp, &p, &dir).unwrap() {
            RveOutcome::Ran(r) => r,
            RveOutcome::Failed { reason, dir } => panic!("{reason} ({})", dir.display()),
        };
        assert!(r.finished);
        let m = r.measure;
        assert!(m.mu > 0.1 && m.mu < 0.6, "{m:?}");
        assert!(m.phi > 0.7 && m.phi < 0.9, "{m:?}");
        assert!((m.pn / 1000.0 - 1.0).abs() < 0.1, "{m:?}");
        assert!(
            r.overlap_ratio > 0.0 && r.overlap_ratio < 0.01,
            "{}",
            r.overlap_ratio
        );
        assert!(!dir.exists());
    }
}
