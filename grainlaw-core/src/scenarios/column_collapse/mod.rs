//! The `column-collapse` scenario: a 2D granular column collapsing onto a rough floor
//! (Lajeunesse, Mangeney-Castelnau & Vilotte, Phys. Fluids 16, 2004; Lube et al., J. Fluid
//! Mech. 508, 2004; Staron & Hinch, J. Fluid Mech. 545, 2005; Lagrée, Staron & Popinet, J.
//! Fluid Mech. 686, 2011), `docs/runs.md` §5.
//!
//! 1. *Deposit*: polydisperse disks poured by drop and roll between the frictionless symmetry
//!    wall x = 0 and a gate at x = R₀, on a rough floor (glued disks whose tops are y = 0),
//!    settle under gravity until at rest ([`build::column_collapse_deposit`]).
//! 2. *Collapse*: the column is trimmed to `H₀ = a R₀` (grains whose top is above `H₀`
//!    removed), the gate removed, and the time set to 0 ([`build::column_collapse_release`]);
//!    the grains collapse and spread until at rest (`collapse.rest_energy`) or
//!    `collapse.max_time`.
//!
//! Measured on the way ([`profile`]): the front `x_f(t)` every `analysis.sample_t_star`, the
//! height profiles at the reference instants `t* = t √(g/H₀)` and at rest; at rest the runout
//! `r_∞ = x_f`, the final height `h(0)` and the rest time. Outputs per the contract of the
//! continuum comparison: `summary.json` (object `column`), `front.csv`, `profiles.csv`.

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use super::common::{grain_weight, mean_diameter, solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::{CliError, Result};
use crate::output::{CsvTable, OutputDir, Summary};
use crate::progress::{info, warn};
use crate::verdict::{Checks, RunVerdict, Verdict, WindowStats};
use config::ColumnCollapseConfig;

pub mod build;
pub mod config;
mod figures;
pub mod profile;

pub use profile::{scaling, HeightProfile};

/// The published contact-dynamics front of the case a = 6.26 (Staron & Hinch 2005, as shipped
/// with the Gerris example `column` of Lagrée, Staron & Popinet 2011): the CSV with its source.
pub const REFERENCE_CSV: &str =
    include_str!("../../../../datasets/reference/column-collapse-contact-dynamics-a6.26.csv");

/// Aspect ratio of the reference run.
pub const REFERENCE_ASPECT_RATIO: f64 = 6.26;

/// Label of the profile at rest in `profiles.csv`.
pub const REST_LABEL: &str = "rest";

/// Energy gained over the collapse, `E_end − E_start − E_correction` over the load energy
/// `E_load = Σ m g d`, above which the run is suspect (1): the scheme only dissipates
/// (`crate::scenarios::phases`), so a gain is accumulated solver inexactness.
pub const ENERGY_GAIN_SUSPECT: f64 = 0.01;
/// The same, above which the run is refused (1).
pub const ENERGY_GAIN_REFUSED: f64 = 0.1;

/// One sample of the front.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrontSample {
    /// Time since the gate was removed (s).
    #[serde(with = "dem::serde_float")]
    pub t: f64,
    /// Front position `x_f` (m).
    #[serde(with = "dem::serde_float")]
    pub x_f: f64,
}

/// One collapse step of `history.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HistoryRow {
    /// Time since the gate was removed (s).
    #[serde(with = "dem::serde_float")]
    pub t: f64,
    /// Kinetic energy of the grains (J per m).
    #[serde(with = "dem::serde_float")]
    pub kinetic_energy: f64,
    /// Active contacts.
    pub contacts: usize,
    /// Sweeps of the step's solve.
    pub sweeps: usize,
    /// Error of the step's solve (1).
    #[serde(with = "dem::serde_float")]
    pub solver_error: f64,
}

/// A height profile at a labelled instant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelledProfile {
    /// `t0.66`, …, `rest` (or `t0` for the initial column, not written to `profiles.csv`).
    pub label: String,
    /// Time since the gate was removed (s).
    #[serde(with = "dem::serde_float")]
    pub t: f64,
    /// The profile.
    pub profile: HeightProfile,
}

/// The label of reference instant `t*`: `t` and two decimals (`t0.66`).
pub fn instant_label(t_star: f64) -> String {
    format!("t{t_star:.2}")
}

/// Everything the phases collect (serialisable, for checkpoints).
#[derive(Serialize, Deserialize)]
struct CollapseState {
    deposit: PhaseStats,
    collapse: PhaseStats,
    /// Numerics of every collapse step.
    window: WindowStats,
    /// Mean diameter of the released grains (m): bin width and front threshold.
    #[serde(with = "dem::serde_float")]
    d: f64,
    /// Grains of the released column and their mass (kg per m of thickness).
    grains: u64,
    #[serde(with = "dem::serde_float")]
    mass: f64,
    /// Mechanical energy (kinetic + potential) at the release (J).
    #[serde(with = "dem::serde_float")]
    e_start: f64,
    /// Potential energy at the release (J).
    #[serde(with = "dem::serde_float")]
    e_pot_start: f64,
    /// Load energy `Σ m g d` of the released column (J).
    #[serde(with = "dem::serde_float")]
    e_load: f64,
    /// Solid fraction of the released column, grain area over `R₀ H₀`.
    #[serde(with = "dem::serde_float")]
    phi: f64,
    /// Grains poured and settled behind the gate, before the trim.
    deposited: u64,
    front: Vec<FrontSample>,
    profiles: Vec<LabelledProfile>,
    /// Grain snapshots (contacts left out) at the labelled instants, for the figures.
    frames: Vec<(String, dem::Snapshot)>,
    /// Next reference instant to record.
    next_instant: usize,
    /// Collapse steps done.
    steps: u64,
    /// Start of the current run of quiet steps (s).
    quiet_start: Option<f64>,
    /// Rest time (s), once at rest.
    rest_time: Option<f64>,
    history: Vec<HistoryRow>,
    vtk: VtkFrames,
}

const DEPOSIT: usize = 0;
const COLLAPSE: usize = 1;

struct Collapse<'a> {
    c: &'a ColumnCollapseConfig,
}

impl Collapse<'_> {
    fn t_star(&self, t: f64) -> f64 {
        t / self.c.time_scale()
    }

    /// Collapse steps between two front samples.
    fn sample_every(&self) -> u64 {
        ((self.c.analysis.sample_t_star * self.c.time_scale() / self.c.dt).round() as u64).max(1)
    }

    /// Records the profile and the grains of `w` under `label`, at time `t` (s).
    fn record_profile(&self, st: &mut CollapseState, w: &dem::World, label: String, t: f64) {
        let snap = w.snapshot();
        st.profiles.push(LabelledProfile {
            label: label.clone(),
            t,
            profile: HeightProfile::of_snapshot(&snap, st.d),
        });
        st.frames.push((
            label,
            dem::Snapshot {
                contacts: Vec::new(),
                ..snap
            },
        ));
    }

    fn sample_front(&self, st: &mut CollapseState, w: &dem::World) {
        let p = HeightProfile::of_world(w, st.d);
        st.front.push(FrontSample {
            t: w.time,
            x_f: p.front(st.d),
        });
    }
}

impl PhasedRun for Collapse<'_> {
    type State = CollapseState;

    fn phase_count(&self) -> usize {
        2
    }

    fn enter(&self, st: &mut CollapseState, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, env, world) = (at.k, at.env, at.world);
        let c = self.c;
        Ok(match k {
            DEPOSIT => Some(PhasePlan::new(
                "deposit",
                Stop::UntilRest(c.deposit.until_rest()),
            )),
            COLLAPSE => {
                st.deposited = grain_count(world);
                let released = build::column_collapse_release(c, world)?;
                *world = released.world;
                c.collapse.solver.apply(&mut world.params);
                st.d = mean_diameter(world);
                st.grains = grain_count(world);
                st.mass = grain_weight(world) / world.params.gravity.norm();
                st.e_pot_start = world.potential_energy();
                st.e_start = world.kinetic_energy() + st.e_pot_start;
                st.e_load = crate::scenarios::phases::load_energy_scale(world);
                st.phi = crate::scenarios::common::build::grain_area(world)
                    / (c.half_width() * c.height());
                info(
                    env.verbosity,
                    &format!(
                        "     released: {} grains (of {} deposited) trimmed to H0 = {:.4} m, solid fraction {:.3}",
                        st.grains, st.deposited, c.height(), st.phi
                    ),
                );
                self.record_profile(st, world, "t0".into(), 0.0);
                self.sample_front(st, world);
                Some(PhasePlan::new(
                    "collapse",
                    Stop::UntilRest(c.collapse.until_rest()),
                ))
            }
            _ => None,
        })
    }

    fn step(&self, st: &mut CollapseState, at: Step<'_>) -> Result<()> {
        let (k, out, w, r, p) = (at.k, at.out, at.world, at.report, at.progress);
        if k != COLLAPSE {
            return Ok(());
        }
        st.steps += 1;
        st.window.step(true, w, r, &p.stats);
        if p.quiet_steps == 1 {
            st.quiet_start = Some((w.time - w.params.dt).max(0.0));
        }
        if st.steps.is_multiple_of(self.sample_every()) {
            self.sample_front(st, w);
        }
        let instants = &self.c.analysis.reference_t_star;
        while st.next_instant < instants.len()
            && self.t_star(w.time) + 1e-9 >= instants[st.next_instant]
        {
            let label = instant_label(instants[st.next_instant]);
            self.record_profile(st, w, label, w.time);
            st.next_instant += 1;
        }
        st.history.push(HistoryRow {
            t: w.time,
            kinetic_energy: w.kinetic_energy(),
            contacts: r.active_contacts,
            sweeps: r.solver.iterations,
            solver_error: r.solver.error,
        });
        st.vtk.maybe(out, w)
    }

    fn leave(&self, st: &mut CollapseState, at: Leave<'_>) -> Result<()> {
        let (k, world, stats) = (at.k, at.world, at.stats);
        match k {
            DEPOSIT => st.deposit = *stats,
            _ => {
                st.collapse = *stats;
                if stats.at_rest {
                    st.rest_time = st.quiet_start;
                }
                if st.front.last().map(|f| f.t) != Some(world.time) {
                    self.sample_front(st, world);
                }
                // Instants after the rest: the deposit no longer changes.
                let instants = &self.c.analysis.reference_t_star;
                while stats.at_rest && st.next_instant < instants.len() {
                    let t_star = instants[st.next_instant];
                    let t = t_star * self.c.time_scale();
                    self.record_profile(st, world, instant_label(t_star), t);
                    st.next_instant += 1;
                }
                // At rest: the deposit since the rest time; otherwise the last state.
                let t = match st.rest_time {
                    Some(t) => t,
                    None => world.time,
                };
                self.record_profile(st, world, REST_LABEL.into(), t);
            }
        }
        Ok(())
    }
}

fn grain_count(w: &dem::World) -> u64 {
    w.bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .count() as u64
}

/// A number as JSON (`null` when not finite).
fn jnum(v: f64) -> Value {
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}

/// The reference front `(t*, x_f/R₀)` of the contact-dynamics run ([`REFERENCE_CSV`]).
pub fn reference_front() -> Result<Vec<(f64, f64)>> {
    let t = identify::data::Table::parse_csv(REFERENCE_CSV, "column-collapse reference")?;
    let ts = t.column("t_star")?;
    let xs = t.column("x_f_over_r0")?;
    Ok(ts.into_iter().zip(xs).collect())
}

/// Whether the run is the reference case (its aspect ratio within 0.1 % of 6.26).
pub fn is_reference_case(c: &ColumnCollapseConfig) -> bool {
    (c.aspect_ratio - REFERENCE_ASPECT_RATIO).abs() <= 1e-3 * REFERENCE_ASPECT_RATIO
}

/// `x_f` at `t` by linear interpolation of the samples (m; NaN outside them).
fn front_at(front: &[FrontSample], t: f64) -> f64 {
    match front.iter().position(|f| f.t >= t) {
        Some(0) => front[0].x_f,
        Some(i) => {
            let (a, b) = (front[i - 1], front[i]);
            a.x_f + (b.x_f - a.x_f) * (t - a.t) / (b.t - a.t)
        }
        None => f64::NAN,
    }
}

/// Stage "config": says what is about to run.
fn announce(c: &ColumnCollapseConfig, verbosity: crate::progress::Verbosity) {
    let (r0, h0) = (c.half_width(), c.height());
    info(
        verbosity,
        &format!(
            "column-collapse: a = {}, R0 = {:.4} m ({} mean diameters), H0 = {:.4} m, {} grains poured, radius {:.2} ± {:.2} mm, μ = {} / {} / {} (grains / floor / wall)",
            c.aspect_ratio,
            r0,
            c.half_width_diameters,
            h0,
            c.poured_grains(),
            c.grain.radius_mean * 1e3,
            c.grain.radius_spread * 1e3,
            c.friction.grain_grain,
            c.friction.floor,
            c.friction.wall
        ),
    );
}

/// Stages "build" and "run": the column deposited behind its gate, then released (or resumed
/// from a checkpoint).
fn simulate(
    c: &ColumnCollapseConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<(dem::World, CollapseState)> {
    let ts = c.time_scale();
    let run = Collapse { c };
    let fresh = || -> Result<(dem::World, CollapseState)> {
        let col = build::column_collapse_deposit(c)?;
        let state = CollapseState {
            deposit: PhaseStats::default(),
            collapse: PhaseStats::default(),
            window: WindowStats::default(),
            d: f64::NAN,
            grains: 0,
            mass: f64::NAN,
            e_start: f64::NAN,
            e_pot_start: f64::NAN,
            e_load: f64::NAN,
            phi: f64::NAN,
            deposited: 0,
            front: Vec::new(),
            profiles: Vec::new(),
            frames: Vec::new(),
            next_instant: 0,
            steps: 0,
            quiet_start: None,
            rest_time: None,
            history: Vec::new(),
            vtk: VtkFrames::new(0.1 * ts, c.analysis.vtk_frames.max(1)),
        };
        Ok((col.world, state))
    };
    drive(ctx, ctl, &run, fresh)
}

/// What the end state of a collapse gives ([`measure`]).
#[derive(Debug, Clone, Copy)]
struct Measured {
    /// Runout, final height at the wall and initial surface height (m).
    runout: f64,
    final_height: f64,
    initial_height: f64,
    /// Front of the initial column (m).
    initial_front: f64,
    /// Time of rest and end of the run (s).
    rest_time: f64,
    end_time: f64,
    /// Recession of the front below its running maximum (m).
    recession: f64,
    /// End of the rough floor (m), grains off it, their mass (kg/m), their reach (m).
    floor_end: f64,
    escaped: usize,
    mass_end: f64,
    reach: f64,
    /// Energy dissipated and potential energy released over the collapse (J/m), growth of the
    /// mechanical energy over the load energy.
    dissipated: f64,
    released: f64,
    gain: f64,
}

/// Stage "measure": runout, heights, mass and energy balance of the deposit at the end.
fn measure(c: &ColumnCollapseConfig, world: &dem::World, st: &CollapseState) -> Result<Measured> {
    let d = st.d;
    let rest = st
        .profiles
        .iter()
        .rfind(|p| p.label == REST_LABEL)
        .ok_or_else(|| CliError::Usage("column-collapse: no profile at the end".into()))?;
    let initial = st
        .profiles
        .iter()
        .find(|p| p.label == "t0")
        .ok_or_else(|| CliError::Usage("column-collapse: no initial profile".into()))?;
    let runout = rest.profile.front(d);
    let final_height = rest.profile.height_at_wall();
    let initial_height = initial.profile.height_at_wall();
    let rest_time = st.rest_time.unwrap_or(f64::NAN);
    let end_time = world.time;
    // Recession of the front below its running maximum (m).
    let recession = st
        .front
        .iter()
        .scan(f64::NEG_INFINITY, |m, f| {
            *m = m.max(f.x_f);
            Some(*m - f.x_f)
        })
        .fold(0.0, f64::max);

    // Mass: every grain still on the floor, none escaped past its end or through a wall.
    let floor_end = c.floor_extent();
    let rf = c.grain.radius_mean;
    let grains: Vec<&dem::Body> = world
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .collect();
    let escaped = grains
        .iter()
        .filter(|b| {
            !(b.position.x >= -b.radius
                && b.position.x <= floor_end
                && b.position.y >= -rf - b.radius)
        })
        .count();
    let mass_end: f64 = grains.iter().map(|b| b.mass).sum();
    let reach = grains
        .iter()
        .map(|b| b.position.x + b.radius)
        .fold(0.0, f64::max);

    // Energy balance over the collapse (crate::scenarios::phases): with fixed walls the mechanical
    // energy changes by the residuals δ ≤ 0 and the position corrections' potential energy.
    let e_end = world.kinetic_energy() + world.potential_energy();
    let dissipated = st.e_start - e_end + st.collapse.position_correction_energy;
    let released = st.e_pot_start - world.potential_energy();
    let gain = (-dissipated).max(0.0) / st.e_load;
    Ok(Measured {
        runout,
        final_height,
        initial_height,
        initial_front: initial.profile.front(d),
        rest_time,
        end_time,
        recession,
        floor_end,
        escaped,
        mass_end,
        reach,
        dissipated,
        released,
        gain,
    })
}

/// The front against the contact-dynamics reference (a = 6.26, [`reference_front`]): the
/// reference, `(t*, x_f/R₀ measured, x_f/R₀ reference)` at its instants, the worst relative
/// difference.
struct ReferenceComparison {
    reference: Option<Vec<(f64, f64)>>,
    comparison: Vec<(f64, f64, f64)>,
    worst_reference: f64,
}

/// Stage "fit": the front against the reference when the case is the reference's.
fn compare_reference(c: &ColumnCollapseConfig, st: &CollapseState) -> Result<ReferenceComparison> {
    let (r0, ts) = (c.half_width(), c.time_scale());
    // Reference comparison (a = 6.26).
    let reference = if is_reference_case(c) {
        Some(reference_front()?)
    } else {
        None
    };
    let comparison: Vec<(f64, f64, f64)> = reference
        .iter()
        .flatten()
        .filter(|(t, _)| *t > 0.0)
        .map(|&(t, x)| (t, front_at(&st.front, t * ts) / r0, x))
        .collect();
    let worst_reference = comparison
        .iter()
        .map(|(_, dem, cd)| ((dem - cd) / cd).abs())
        .fold(
            f64::NAN,
            |a: f64, b| if a.is_nan() || b > a { b } else { a },
        );
    Ok(ReferenceComparison {
        reference,
        comparison,
        worst_reference,
    })
}

/// Stage "measure → verdict": at rest, mass conserved, on the floor, energy dissipated.
fn judge(c: &ColumnCollapseConfig, st: &CollapseState, m: &Measured) -> Checks {
    let (r0, ts, d) = (c.half_width(), c.time_scale(), st.d);
    let at_rest = st.collapse.at_rest;
    let Measured {
        end_time,
        escaped,
        mass_end,
        floor_end,
        reach,
        gain,
        ..
    } = *m;
    // Checks.
    let mut checks = Checks::new();
    checks.window("collapse", &st.window);
    if !at_rest {
        checks.fail(
            "column.at_rest",
            Verdict::Refused,
            st.collapse.final_energy_ratio,
            c.collapse.rest_energy,
            format!(
                "the deposit is not at rest after collapse.max_time = {} s (t* = {:.2}; kinetic energy {:.2e} Σ m g d, rest below {:.0e}): the runout is not a runout; raise collapse.max_time",
                c.collapse.max_time,
                end_time / ts,
                st.collapse.final_energy_ratio,
                c.collapse.rest_energy
            ),
        );
    }
    if !st.deposit.at_rest {
        checks.fail(
            "column.deposit_at_rest",
            Verdict::Suspect,
            st.deposit.final_energy_ratio,
            c.deposit.rest_energy,
            format!(
                "the column was not at rest behind the gate after deposit.max_time = {} s: it was released moving",
                c.deposit.max_time
            ),
        );
    }
    if escaped > 0 || (mass_end - st.mass).abs() > 1e-12 * st.mass {
        checks.fail(
            "column.mass_conserved",
            Verdict::Refused,
            escaped as f64,
            0.0,
            format!(
                "{escaped} grains left the floor (past x = {floor_end:.3} m or through it); the grains' mass changed by {:.2e} kg/m",
                mass_end - st.mass
            ),
        );
    }
    if reach > floor_end - d {
        checks.fail(
            "column.floor_length",
            Verdict::Refused,
            reach / r0,
            c.floor_length,
            format!(
                "the grains reached x = {:.2} R0, the end of the rough floor ({} R0): raise floor_length",
                reach / r0,
                c.floor_length
            ),
        );
    }
    checks.at_most(
        "column.energy_balance",
        gain,
        ENERGY_GAIN_SUSPECT,
        Some(ENERGY_GAIN_REFUSED),
        |t| {
            format!(
                "the mechanical energy grew over the collapse by {:.2e} of the load energy Σ m g d (beyond the position corrections; limit {t}): the scheme only dissipates",
                gain
            )
        },
    );
    checks
}

/// Stage "report": the contract's tables, `front.csv`, `profiles.csv` and `history.csv`.
fn write_tables(ctx: &mut RunContext, c: &ColumnCollapseConfig, st: &CollapseState) -> Result<()> {
    let ts = c.time_scale();
    // Outputs: the contract's files.
    let mut front = CsvTable::new(&["t_s", "t_star", "x_f_m"]);
    // no comment line: the contract's header is the file's first line
    for f in &st.front {
        front.push(vec![f.t, f.t / ts, f.x_f]);
    }
    front.write(&mut ctx.out, "front.csv")?;
    write_profiles(ctx, &st.profiles, ts)?;
    let mut history = CsvTable::new(&[
        "time_s",
        "t_star",
        "kinetic_energy_J",
        "contacts",
        "sweeps",
        "solver_error",
    ]);
    for h in &st.history {
        history.push(vec![
            h.t,
            h.t / ts,
            h.kinetic_energy,
            h.contacts as f64,
            h.sweeps as f64,
            h.solver_error,
        ]);
    }
    history.write(&mut ctx.out, "history.csv")?;

    Ok(())
}

/// Stage "report": the summary keys (`column` the contract's, then the run's).
fn summary(
    c: &ColumnCollapseConfig,
    world: &dem::World,
    st: &CollapseState,
    m: &Measured,
    r: &ReferenceComparison,
    frames: usize,
) -> Summary {
    let (r0, h0, ts, d) = (c.half_width(), c.height(), c.time_scale(), st.d);
    let at_rest = st.collapse.at_rest;
    let Measured {
        runout,
        final_height,
        initial_height,
        rest_time,
        end_time,
        recession,
        escaped,
        dissipated,
        released,
        gain,
        ..
    } = *m;
    let (comparison, worst_reference) = (&r.comparison, r.worst_reference);
    let mut s = Summary::new();
    s.set(
        "column",
        json!({
            "initial_half_width_m": jnum(r0),
            "initial_height_m": jnum(h0),
            "aspect_ratio": jnum(c.aspect_ratio),
            "mean_diameter_m": jnum(d),
            "gravity_m_s2": jnum(world.params.gravity.norm()),
            "grain_density_kg_m3": jnum(c.grain.density),
            "initial_packing_fraction": jnum(st.phi),
            "grain_friction": jnum(c.friction.grain_grain),
            "floor_friction": jnum(c.friction.floor),
            "runout_m": jnum(runout),
            "final_height_m": jnum(final_height),
            "rest_time_s": jnum(rest_time),
            "reference_instants_t_star": c.analysis.reference_t_star,
        }),
    );
    s.int("grains", st.grains)
        .int("grains_deposited", st.deposited)
        .num("grains_mass_kg_per_m", st.mass)
        .int("grains_escaped", escaped as u64)
        .num("wall_friction", c.friction.wall)
        .num("restitution", c.restitution)
        .num("time_scale_s", ts)
        .num("initial_surface_height_m", initial_height)
        .num("initial_front_m", m.initial_front)
        .num("runout_over_r0", runout / r0)
        .num("normalised_runout", (runout - r0) / r0)
        .num(
            "runout_scaling_lube_2005",
            scaling::normalised_runout(c.aspect_ratio),
        )
        .num("final_height_over_r0", final_height / r0)
        .num("final_height_over_h0", final_height / h0)
        .num("rest_time_star", rest_time / ts)
        .flag("at_rest", at_rest)
        .num("end_time_s", end_time)
        .num("front_largest_recession_m", recession)
        .num("released_potential_energy_J", released)
        .num("dissipated_energy_J", dissipated)
        .num("energy_gain_over_load_energy", gain)
        .num("load_energy_J", st.e_load);
    if is_reference_case(c) {
        s.num("reference_front_worst_relative_error", worst_reference);
        for (t, dem, cd) in comparison {
            s.num(&format!("front_over_r0_{}", instant_label(*t)), *dem)
                .num(
                    &format!("reference_front_over_r0_{}", instant_label(*t)),
                    *cd,
                );
        }
    }
    let mut all = st.deposit;
    all.merge(&st.collapse);
    solver_keys(&mut s, &all);
    s.int("deposit_steps", st.deposit.steps)
        .flag("deposit_at_rest", st.deposit.at_rest)
        .int("collapse_steps", st.collapse.steps)
        .int("collapse_unconverged_steps", st.collapse.unconverged_steps)
        .num("collapse_worst_error", st.collapse.worst_error);
    st.window.keys(&mut s, "collapse");
    s.int("vtk_frames", frames as u64);
    s
}

/// Stage "report": the headline lines.
fn headline(
    ctx: &RunContext,
    c: &ColumnCollapseConfig,
    m: &Measured,
    r: &ReferenceComparison,
) -> Vec<String> {
    let (r0, h0, ts) = (c.half_width(), c.height(), c.time_scale());
    let Measured {
        runout,
        final_height,
        rest_time,
        ..
    } = *m;
    let (comparison, worst_reference) = (&r.comparison, r.worst_reference);
    let mut headline = vec![format!("report: {}/", ctx.out.path().display())];
    headline.push(format!(
        "runout r_inf = {:.4} m = {:.2} R0 ((r_inf − R0)/R0 = {:.2}; Lube et al. 2005 2D: {:.2}), final height {:.4} m = {:.3} H0, at rest at t* = {:.2}",
        runout,
        runout / r0,
        (runout - r0) / r0,
        scaling::normalised_runout(c.aspect_ratio),
        final_height,
        final_height / h0,
        rest_time / ts
    ));
    if !comparison.is_empty() {
        headline.push(format!(
            "front x_f/R0 against contact dynamics (Staron & Hinch 2005): {} (worst {:.1} %)",
            comparison
                .iter()
                .map(|(t, dem, cd)| format!("t* {t}: {dem:.2} vs {cd:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
            100.0 * worst_reference
        ));
    }
    headline
}

/// Runs the scenario: config, build and run (`simulate`), measure (`measure`), the
/// reference (`compare_reference`), verdict (`judge`), report.
pub fn run(
    c: &ColumnCollapseConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<RunOutcome> {
    announce(c, ctx.verbosity);
    let (world, st) = simulate(c, ctx, ctl)?;
    let world = &world;
    let frames = st.vtk.clone().finish(&mut ctx.out, world)?;
    let m = measure(c, world, &st)?;
    let r = compare_reference(c, &st)?;
    let verdict = RunVerdict {
        run: judge(c, &st, &m),
        ..Default::default()
    };
    if !st.collapse.at_rest {
        warn("column-collapse: the deposit did not come to rest within collapse.max_time");
    }
    write_tables(ctx, c, &st)?;
    let s = summary(c, world, &st, &m, &r, frames);
    figures::draw(
        ctx,
        &figures::Inputs {
            c,
            profiles: &st.profiles,
            frames: &st.frames,
            front: &st.front,
            history: &st.history,
            reference: r.reference.as_deref(),
            runout: m.runout,
            d: st.d,
        },
    )?;
    let headline = headline(ctx, c, &m, &r);
    Ok(RunOutcome {
        summary: s,
        headline,
        verdict,
    })
}

/// `profiles.csv`: `label,t_star,x_m,h_m`, one row per bin of the continuous mass, for the
/// reference instants and at rest (the initial column `t0` is left out).
fn write_profiles(ctx: &mut RunContext, profiles: &[LabelledProfile], ts: f64) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| CliError::Io {
        path: "profiles.csv".into(),
        reason: e.to_string(),
    };
    w.write_record(["label", "t_star", "x_m", "h_m"])
        .map_err(err)?;
    for p in profiles.iter().filter(|p| p.label != "t0") {
        for (x, h) in p.profile.points() {
            w.write_record([
                p.label.clone(),
                format!("{:e}", p.t / ts),
                format!("{x:e}"),
                format!("{h:e}"),
            ])
            .map_err(err)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Io {
        path: "profiles.csv".into(),
        reason: e.to_string(),
    })?;
    ctx.out.write("profiles.csv", &bytes)?;
    Ok(())
}

/// One finished `column-collapse` run of a campaign: its index, the numeric leaves of its
/// `summary.json` (dotted keys: `column.runout_m`, …), its verdict and exit status.
pub struct CampaignRun<'a> {
    /// Run index.
    pub index: usize,
    /// Numeric keys of its summary.
    pub numbers: &'a std::collections::BTreeMap<String, f64>,
    /// Its verdict (`ok`, `suspect`, `refused`; empty when unknown).
    pub verdict: String,
    /// Its exit status, when recorded.
    pub code: Option<i32>,
}

/// The runout against the aspect ratio over the `column-collapse` runs of a campaign (a
/// `[sweep]` of `aspect_ratio`): `runout.csv`, one row per run sorted by `a` (`run, a,
/// r0_m, runout_m, runout_over_r0, normalised_runout, final_height_over_r0, rest_time_star,
/// exit_status, verdict`), and `runout.png`, `(r_∞ − R₀)/R₀` against `a` on log axes with the
/// scalings of [`scaling`] (every run drawn; those not `ok` hollow).
pub fn write_runout(out: &mut OutputDir, runs: &[CampaignRun]) -> Result<()> {
    let num = |r: &CampaignRun, k: &str| r.numbers.get(k).copied().unwrap_or(f64::NAN);
    let mut rows: Vec<&CampaignRun> = runs.iter().collect();
    rows.sort_by(|a, b| {
        num(a, "column.aspect_ratio")
            .total_cmp(&num(b, "column.aspect_ratio"))
            .then(a.index.cmp(&b.index))
    });
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| CliError::Io {
        path: "runout.csv".into(),
        reason: e.to_string(),
    };
    w.write_record([
        "run",
        "a",
        "r0_m",
        "runout_m",
        "runout_over_r0",
        "normalised_runout",
        "final_height_over_r0",
        "rest_time_star",
        "exit_status",
        "verdict",
    ])
    .map_err(err)?;
    let (mut ok, mut other) = (Vec::new(), Vec::new());
    for r in &rows {
        let a = num(r, "column.aspect_ratio");
        let r0 = num(r, "column.initial_half_width_m");
        let runout = num(r, "column.runout_m");
        let h = num(r, "column.final_height_m");
        let ts = num(r, "time_scale_s");
        let rest = num(r, "column.rest_time_s") / ts;
        let n = (runout - r0) / r0;
        let cell = |v: f64| {
            if v.is_finite() {
                format!("{v:e}")
            } else {
                String::new()
            }
        };
        w.write_record([
            format!("{:04}", r.index),
            cell(a),
            cell(r0),
            cell(runout),
            cell(runout / r0),
            cell(n),
            cell(h / r0),
            cell(rest),
            r.code.map(|c| c.to_string()).unwrap_or_default(),
            r.verdict.clone(),
        ])
        .map_err(err)?;
        if r.verdict == "ok" {
            ok.push((a, n));
        } else {
            other.push((a, n));
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Io {
        path: "runout.csv".into(),
        reason: e.to_string(),
    })?;
    out.write("runout.csv", &bytes)?;
    figures::runout_figure(out, &ok, &other)
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for ColumnCollapseConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "column-collapse"
    }

    fn grains(&self) -> usize {
        self.poured_grains()
    }

    fn build_first(&self) -> datasets::Result<()> {
        build::column_collapse_deposit(self).map(drop)
    }
}
