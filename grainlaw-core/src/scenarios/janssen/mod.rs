//! The `janssen` scenario: deposit → relax → release → homogenise → fit → figures.
//!
//! 1. Grains rained without overlap into a box of two vertical walls and a floor fall under
//!    gravity (deposition, sub-stepped: `dt / deposit.substeps`, loose solver tolerance) until at
//!    rest; then the column is relaxed at the scenario's `dt` with a tight tolerance until at
//!    rest again. The static forces of a rigid column at rest are indeterminate (how much weight
//!    the walls carry depends on the solver's path), so the column is then released: the floor
//!    is lowered slowly (`release`), the grains slide along the walls and the wall contacts reach
//!    the Coulomb limit (the paper's "relâcher le système afin de se mettre dans les conditions
//!    de Coulomb"). The release ends with the measurement window: `analysis.measure_steps`
//!    steps, the floor still sinking, each solved to the tight tolerance with a large sweep cap.
//! 2. Averaged over the window ([`measure`]): the wall normal and shear stress by depth bin on
//!    both side walls (σ_h = −σ_nn, τ_w), the vertical stress across horizontal planes at the
//!    bins' middles (σ_v = −σ_yy, method of planes), the load on the floor and on the walls over
//!    the weight, and the friction mobilisation |f_t|/(μ f_n) of the side-wall contacts; on the
//!    last state, the bulk density ρ_b = φ ρ.
//! 3. Janssen's law `σ_v(z) = ρ_b g W/(2Kμ_w) (1 − exp(−2Kμ_w z/W))`, `σ_h = K σ_v`,
//!    `τ_w = μ_w σ_h` is fitted jointly for K and μ_w (bounded by the wall friction); if μ_w
//!    ends at that bound, the fit with μ_w = μ_wall (full mobilisation, Janssen's assumption)
//!    is reported instead and flagged.

use dem::math::Vector;
use homogenise::state::solid_fraction;
use homogenise::Region;
use identify::janssen::JanssenSetup;
use identify::CalibratedLaw;
use serde::{Deserialize, Serialize};

use super::common::build::{column, column_width};
use super::common::laws::LawNeed;
use super::common::{grain_weight, mean_diameter, solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_csv_table, table_row};
use super::sensitivity::{resolve_last_step, Resolved};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::{CsvTable, OutputDir, Summary};
use crate::progress::{info, warn};
use crate::verdict::{export_law, max_solid_fraction, Checks, RunVerdict, Verdict, WindowStats};
use config::JanssenConfig;

pub mod config;
mod figures;
mod solver_sensitivity;
use solver_sensitivity::JanssenSensitivity;
pub mod fit;
pub mod measure;

pub use fit::{fit_band, fit_profile, fit_profile_like, JanssenOutcome};
pub use measure::{surface_height, ColumnLoads, ColumnProfile, MeasureWindow};

/// Simulated seconds between two VTK frames.
const VTK_INTERVAL: f64 = 0.02;

/// Relative imbalance `|(floor + walls vertical load)/weight − 1|` of the measured column above
/// which it is not at rest and its stresses are suspect (1).
pub const FORCE_BALANCE_SUSPECT: f64 = 0.01;
/// The same, above which the result is refused (1).
pub const FORCE_BALANCE_REFUSED: f64 = 0.05;

/// The phases of the column: deposit, relax, release (floor lowered), measure (one step
/// solved tightly); the release and the measure are skipped when `floor_drop` is 0.
struct Column<'a> {
    c: &'a JanssenConfig,
    /// Width of the box (m).
    width: f64,
}

table_row! {
    /// One step of the column's run: a row of `history.csv`.
    pub(super) struct ColumnStep {
        /// Time (s).
        t: "time_s",
        /// The phase: 0 deposit, 1 relax, 2 release, 3 measure.
        phase: "phase_0deposit_1relax_2release_3measure",
        /// Kinetic energy (J/m).
        kinetic_energy: "kinetic_energy_J",
        /// Active contacts.
        contacts: "contacts",
        /// Sweeps of the step's solve.
        sweeps: "sweeps",
        /// The solve's error.
        solver_error: "solver_error",
        /// Load on the floor over the grains' weight.
        bottom_load: "bottom_load_over_weight",
    }
}

/// What the column's phases collect.
#[derive(Serialize, Deserialize)]
struct ColumnState {
    /// Body index of the floor.
    bottom: usize,
    /// Body indices of the left and right walls.
    left: usize,
    right: usize,
    /// Weight of the grains Σ m g (N).
    weight: f64,
    /// One row per step: `history.csv`.
    #[serde(with = "serde_csv_table")]
    history: Vec<ColumnStep>,
    /// VTK frames.
    vtk: VtkFrames,
    deposit: PhaseStats,
    relax: PhaseStats,
    /// Release and measurement window together.
    release: PhaseStats,
    /// Floor load over the weight at the end of the deposit and of the relaxation.
    #[serde(with = "dem::serde_float")]
    deposit_load: f64,
    #[serde(with = "dem::serde_float")]
    relaxed_load: f64,
    /// Numerics of the measurement window.
    #[serde(default)]
    measured: WindowStats,
    /// The measurement window's sums.
    #[serde(default)]
    window: MeasureWindow,
    /// World step index after the last step (the world counts sub-steps).
    #[serde(default)]
    last_step_index: u64,
    /// Most sub-steps of a step of the measurement window (1 unless one was subdivided).
    #[serde(default)]
    measured_substeps: u64,
    /// The measurement window's sums over its steps solved again to
    /// [`crate::verdict::SENSITIVITY_TOLERANCE`] (the solver sensitivity of the fit).
    #[serde(default)]
    resolved: MeasureWindow,
    /// Measured steps whose re-solve failed.
    #[serde(default)]
    resolve_failed: u64,
    /// Measured steps whose problem was not available to re-solve.
    #[serde(default)]
    resolve_unavailable: u64,
    /// Measured steps whose re-solve stopped short of the tolerance but within a tenth of the
    /// run's own error ([`super::sensitivity::measures_the_run`]).
    #[serde(default)]
    resolve_near: u64,
}

impl Column<'_> {
    fn release_steps(&self) -> u64 {
        let c = self.c;
        (c.release.floor_drop / (c.release.speed * c.dt)).ceil() as u64
    }

    fn floor_load(world: &dem::World, st: &ColumnState) -> f64 {
        -world.contact_force(st.bottom).0.y / st.weight
    }
}

/// The vertical loads of one state on the floor and both side walls, from the walls' contact
/// forces in `snap` (N per metre, upward on the grains positive).
fn column_loads(snap: &dem::Snapshot, st: &ColumnState) -> ColumnLoads {
    let fy = |b: usize| {
        snap.walls
            .iter()
            .find(|x| x.body as usize == b)
            .map_or(0.0, |x| x.force.y)
    };
    ColumnLoads {
        floor: -fy(st.bottom),
        walls: -(fy(st.left) + fy(st.right)),
    }
}

const DEPOSIT: usize = 0;
const RELAX: usize = 1;
const RELEASE: usize = 2;
const MEASURE: usize = 3;

impl PhasedRun for Column<'_> {
    type State = ColumnState;

    fn phase_count(&self) -> usize {
        4
    }

    fn enter(&self, st: &mut ColumnState, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, env, world) = (at.k, at.env, at.world);
        let c = self.c;
        let plan = |name: &str, stop| Some(PhasePlan::new(name, stop));
        Ok(match k {
            DEPOSIT => {
                c.deposit.solver.apply(&mut world.params);
                plan("deposit", Stop::UntilRest(c.deposit.until_rest()))
            }
            // Relaxation at the scenario's time step, tight tolerance.
            RELAX => {
                world.params.dt = c.dt;
                c.relax.solver.apply(&mut world.params);
                plan("relax", Stop::UntilRest(c.relax.until_rest()))
            }
            // Release: the floor is lowered slowly so that the column slides along the walls
            // (Coulomb conditions at the wall contacts).
            RELEASE if self.release_steps() > 0 => {
                world.bodies[st.bottom].velocity = Vector::new(0.0, -c.release.speed);
                c.release.solver.apply(&mut world.params);
                plan("release", Stop::Steps(self.release_steps()))
            }
            // The stresses are measured at the end of the release, over a window of steps
            // solved to the tight tolerance while the floor still moves (at rest without
            // release).
            MEASURE => {
                // The relaxation's settings (tolerance, method, Lemke, error scale, …) with
                // the measured steps' sweep cap and the release's subdivision.
                world.params.solver = dem::SolverParams {
                    max_iterations: c.analysis.final_max_iterations,
                    max_halvings: c.release.solver.max_halvings,
                    // The whole step is tried with the method asked for (`auto`: Newton and
                    // the exact finish after the sweeps), sub-steps only if that fails.
                    gauss_seidel_attempts: false,
                    ..c.relax.solver.params()
                };
                world.params.overlap_rate = c.relax.solver.overlap_rate;
                let (tol, cap) = (c.relax.solver.tolerance, c.analysis.final_max_iterations);
                info(
                    env.verbosity,
                    &if c.analysis.measure_steps == 1 {
                        format!("     measure: one step solved to {tol:.0e} (at most {cap} sweeps)")
                    } else {
                        format!(
                            "     measure: {} steps solved to {tol:.0e} (at most {cap} sweeps each), stresses averaged over them",
                            c.analysis.measure_steps
                        )
                    },
                );
                plan("measure", Stop::Steps(c.analysis.measure_steps as u64))
            }
            _ => None,
        })
    }

    fn step(&self, st: &mut ColumnState, at: Step<'_>) -> Result<()> {
        let (k, out, w, r, p) = (at.k, at.out, at.world, at.report, at.progress);
        let measured = k == MEASURE;
        st.measured.step(measured, w, r, &p.stats);
        if measured {
            st.measured_substeps = st
                .measured_substeps
                .max(r.step.saturating_sub(st.last_step_index));
            let bins = self.c.analysis.depth_bins;
            let snap = w.snapshot();
            let loads = column_loads(&snap, st);
            st.window.observe(&snap, self.width, bins, loads)?;
            // The same step solved again to 1e-8: what the fit would see of an exact solve.
            match resolve_last_step(w) {
                Resolved::Solved((snap, exact)) => {
                    if st.resolved.samples == 0 {
                        // The run's depth bins (the re-solved surface moves by θ h Δv).
                        st.resolved = st.window.empty_like();
                    }
                    let loads = column_loads(&snap, st);
                    if st.resolved.observe(&snap, self.width, bins, loads).is_err() {
                        st.resolve_failed += 1;
                    } else {
                        st.resolve_near += u64::from(!exact);
                    }
                }
                Resolved::Failed => st.resolve_failed += 1,
                Resolved::Unavailable => st.resolve_unavailable += 1,
            }
        }
        st.last_step_index = r.step;
        let load = Self::floor_load(w, st);
        st.history.push(ColumnStep {
            t: w.time,
            phase: k as f64,
            kinetic_energy: w.kinetic_energy(),
            contacts: r.active_contacts as f64,
            sweeps: r.solver.iterations as f64,
            solver_error: r.solver.error,
            bottom_load: load,
        });
        st.vtk.maybe(out, w)
    }

    fn leave(&self, st: &mut ColumnState, at: Leave<'_>) -> Result<()> {
        let (k, world, stats) = (at.k, at.world, at.stats);
        match k {
            DEPOSIT => {
                st.deposit = *stats;
                st.deposit_load = Self::floor_load(world, st);
            }
            RELAX => {
                st.relax = *stats;
                st.relaxed_load = Self::floor_load(world, st);
            }
            RELEASE => st.release = *stats,
            _ => {
                st.release.merge(stats);
                self.c.relax.solver.apply(&mut world.params);
            }
        }
        Ok(())
    }
}

/// Stage "config": says what is about to run.
fn announce(c: &JanssenConfig, verbosity: crate::progress::Verbosity, width: f64) {
    info(
        verbosity,
        &format!(
            "janssen: {} grains, radius {:.2} ± {:.2} mm, box {:.1} mm wide ({:.1} mean diameters), μ = {} / {} (grain / wall)",
            c.grains,
            c.grain.radius_mean * 1e3,
            c.grain.radius_spread * 1e3,
            width * 1e3,
            width / (2.0 * c.grain.radius_mean),
            c.friction.grain_grain,
            c.friction.grain_wall
        ),
    );
}

/// Stages "build" and "run": the column of `width` (m) deposited, relaxed, released and
/// measured (or resumed from a checkpoint).
fn simulate(
    c: &JanssenConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
    width: f64,
) -> Result<(dem::World, ColumnState)> {
    let fresh = || -> Result<(dem::World, ColumnState)> {
        let col = crate::scenarios::common::build::column(
            &c.grain,
            c.grains,
            width,
            &c.friction,
            c.seed,
            c.dt / c.deposit.substeps as f64,
        )?;
        let state = ColumnState {
            bottom: col.bottom,
            left: col.left,
            right: col.right,
            weight: grain_weight(&col.world),
            history: Vec::new(),
            vtk: VtkFrames::new(VTK_INTERVAL, c.analysis.vtk_frames.max(1)),
            deposit: PhaseStats::default(),
            relax: PhaseStats::default(),
            release: PhaseStats::default(),
            deposit_load: f64::NAN,
            relaxed_load: f64::NAN,
            measured: WindowStats::default(),
            window: MeasureWindow::default(),
            last_step_index: 0,
            measured_substeps: 0,
            resolved: MeasureWindow::default(),
            resolve_failed: 0,
            resolve_unavailable: 0,
            resolve_near: 0,
        };
        Ok((col.world, state))
    };
    drive(ctx, ctl, &Column { c, width }, fresh)
}

/// What the homogenisation of the measurement window gives ([`homogenise`]).
struct Homogenised {
    /// Mean grain diameter (m).
    d: f64,
    /// The wall stress profile.
    profile: ColumnProfile,
    /// Loads on the floor and the side walls (N per metre).
    loads: ColumnLoads,
    /// Solid fraction of the column away from its ends.
    phi: f64,
    /// Bulk density (kg/m²).
    rho_b: f64,
    /// Gravity (m/s²).
    g: f64,
    /// Share of the wall contacts at the Coulomb limit.
    sliding: f64,
    /// Mean mobilisation of the wall contacts.
    mean_mob: f64,
    /// Depth left out at the top of the column (m).
    top_skip: f64,
    /// Height left out at the bottom of the column (m).
    bottom_skip: f64,
}

/// Stage "measure": the profile, loads, solid fraction and wall mobilisation of the
/// measurement window `measure_window` of the column of `width` (m).
fn homogenise(
    c: &JanssenConfig,
    world: &dem::World,
    snap: &dem::snapshot::Snapshot,
    width: f64,
    measure_window: &MeasureWindow,
) -> Result<Homogenised> {
    let d = mean_diameter(world);
    let profile = measure_window.profile(c.analysis.depth_bins)?;
    let loads = measure_window.loads();
    let top_skip = c.analysis.skip_top_diameters * d;
    let bottom_skip = c.analysis.skip_bottom_diameters * d;
    let phi_region = Region::Rectangle {
        min: Vector::new(0.0, bottom_skip),
        max: Vector::new(width, (profile.surface - top_skip).max(bottom_skip + d)),
    };
    let phi = solid_fraction(snap, &phi_region)?;
    let rho_b = phi * c.grain.density;
    let g = world.params.gravity.norm();
    let (sliding, mean_mob) = measure_window.sliding();
    Ok(Homogenised {
        d,
        profile,
        loads,
        phi,
        rho_b,
        g,
        sliding,
        mean_mob,
        top_skip,
        bottom_skip,
    })
}

/// A Janssen fit or why it failed.
type Fitted = std::result::Result<JanssenOutcome, identify::IdentifyError>;

/// Stage "fit": the solver's effect on the fit, the measured steps solved again to 1e-8 and
/// fitted alike.
fn solver_sensitivity(
    c: &JanssenConfig,
    st: &ColumnState,
    fitted: &Fitted,
    setup: &JanssenSetup,
    window: (f64, f64),
) -> JanssenSensitivity {
    let (resolved, measure_window) = (&st.resolved, &st.window);
    let (resolve_failed, resolve_unavailable, resolve_near) =
        (st.resolve_failed, st.resolve_unavailable, st.resolve_near);
    let complete = resolved.samples > 0 && resolved.samples == measure_window.samples;
    let resolved_profile = complete
        .then(|| resolved.profile(c.analysis.depth_bins).ok())
        .flatten();
    JanssenSensitivity {
        resolved: resolved.samples,
        measured: measure_window.samples,
        failed: resolve_failed,
        unavailable: resolve_unavailable,
        near: resolve_near,
        fit: match (fitted, &resolved_profile) {
            (Ok(run), Some(p)) => {
                Some(fit_profile_like(p, setup, window, run).map_err(|e| e.to_string()))
            }
            _ => None,
        },
        tau_w_flipped: match (fitted, &resolved_profile) {
            (Ok(run), Some(p)) => p.negative_tau_w(window).is_empty() != run.uses_tau_w,
            _ => false,
        },
    }
}

/// Stage "measure → verdict": the measured step's numerics, the force balance of the column
/// (`balance`, the relative residual of the loads against the weight), the solid fraction,
/// the depth bins (`bin` thick, m), the fit's solver sensitivity.
fn judge(
    c: &JanssenConfig,
    measured: &WindowStats,
    h: &Homogenised,
    sensitivity: &JanssenSensitivity,
    fitted: &Fitted,
    (balance, bin): (f64, f64),
) -> Checks {
    let (phi, d) = (h.phi, h.d);
    // 5. Checks (crate::verdict): the measured step's numerics, the force balance of the
    // column, the solid fraction, the depth bins.
    let mut checks = Checks::new();
    // The fit's solver sensitivity is judged first (its reasons listed after the window's):
    // when it passes, it stands in for the window's loaded-contacts proxy.
    let mut sensitivity_checks = Checks::new();
    let sensitivity_passed = sensitivity.check(&mut sensitivity_checks, fitted.as_ref().ok());
    checks.window_measured("measurement window", measured, sensitivity_passed);
    checks.at_most(
        "janssen.force_balance",
        balance.abs(),
        FORCE_BALANCE_SUSPECT,
        Some(FORCE_BALANCE_REFUSED),
        |t| {
            format!(
                "floor and wall vertical loads carry {:.2} % of the weight (the column is accelerating, e.g. a slip event while measured: a longer release.floor_drop may measure it sliding steadily; limit ±{:.0} %)",
                100.0 * (1.0 + balance),
                100.0 * t
            )
        },
    );
    checks.solid_fraction(
        "janssen.solid_fraction",
        "the column's solid fraction",
        phi,
        max_solid_fraction(c.grain.radius_spread),
    );
    checks.at_most("janssen.bin_thickness", d / bin, 1.0, None, |_| {
        format!(
            "depth bins {:.2} mm thick, thinner than a mean diameter ({:.2} mm): lower analysis.depth_bins",
            bin * 1e3,
            d * 1e3
        )
    });
    checks.extend(&sensitivity_checks);
    checks
}

/// Stage "report": the fit's summary keys, law file and headline lines (or its refusal).
#[allow(clippy::too_many_arguments)]
fn report_fit(
    c: &JanssenConfig,
    ctx: &mut RunContext,
    ctl: &RunControl,
    fitted: &Fitted,
    profile: &ColumnProfile,
    window: (f64, f64),
    checks: &Checks,
    s: &mut Summary,
    verdict: &mut RunVerdict,
) -> Result<Vec<String>> {
    let mut headline = Vec::new();
    match fitted {
        Ok(o) => {
            let f = &o.fit;
            for (k, v) in f.summary_entries() {
                s.num(&k, v);
            }
            s.text("janssen_fit_mode", o.mode)
                .flag("janssen_fit_uses_tau_w", o.uses_tau_w)
                .int(
                    "tau_w_negative_bins",
                    profile.negative_tau_w(window).len() as u64,
                );
            let law = CalibratedLaw::from_janssen(f, ctl.law_provenance(ctx, "janssen", c.seed));
            let exported = export_law(&mut ctx.out, verdict, "janssen", &law, checks.clone())?;
            headline.extend(exported.heading("janssen"));
            headline.push(format!(
                "K    = {:.3}  (95 % CI {:.3} … {:.3})",
                f.k.value, f.k.ci_low, f.k.ci_high
            ));
            if o.mode == "joint" {
                headline.push(format!(
                    "μ_w  = {:.3}  (95 % CI {:.3} … {:.3}; wall friction μ = {})",
                    f.mu_w.value, f.mu_w.ci_low, f.mu_w.ci_high, c.friction.grain_wall
                ));
            } else {
                headline.push(format!(
                    "μ_w  = {:.3}  (at the wall friction: fitted with full mobilisation, K only)",
                    f.mu_w.value
                ));
            }
            headline.push(format!(
                "K μ_w = {:.3}  (95 % CI {:.3} … {:.3}), R² = {:.3}",
                f.k_mu_w.value, f.k_mu_w.ci_low, f.k_mu_w.ci_high, f.report.r_squared
            ));
            headline.push(fit_data_line(profile, window, o.uses_tau_w));
        }
        Err(e) => {
            warn(&format!("Janssen fit failed: {e}"));
            for k in ["janssen_K", "janssen_mu_w", "janssen_K_mu_w"] {
                s.num(k, f64::NAN)
                    .num(&format!("{k}_ci_low"), f64::NAN)
                    .num(&format!("{k}_ci_high"), f64::NAN);
            }
            s.text("janssen_fit_error", &e.to_string());
            headline.push(format!("Janssen fit failed: {e}"));
            crate::verdict::remove_stale_law(&ctx.out, "janssen")?;
            verdict.run.fail(
                "janssen.fit",
                Verdict::Refused,
                f64::NAN,
                f64::NAN,
                format!("the Janssen fit failed: {e}"),
            );
        }
    }
    Ok(headline)
}

/// The solve keys of one phase `phase` (`release`, `relax`) from its statistics `st`:
/// `PHASE_unconverged_steps`, `PHASE_energy_growth_steps`, `PHASE_worst_error` and
/// `PHASE_worst_error_without_gap_shifts`.
fn solve_keys<'s>(s: &'s mut Summary, phase: &str, st: &PhaseStats) -> &'s mut Summary {
    s.int(&format!("{phase}_unconverged_steps"), st.unconverged_steps)
        .int(
            &format!("{phase}_energy_growth_steps"),
            st.energy_growth_steps,
        )
        .num(&format!("{phase}_worst_error"), st.worst_error)
        .num(
            &format!("{phase}_worst_error_without_gap_shifts"),
            st.worst_error_without_gap_shifts,
        )
}

/// Stage "report": the summary keys of each phase (deposit, relaxation, release and
/// measurement) and of the last step.
fn phase_keys(
    s: &mut Summary,
    c: &JanssenConfig,
    st: &ColumnState,
    final_report: &dem::StepReport,
) {
    let (deposit, relax, release) = (st.deposit, st.relax, st.release);
    let (deposit_load, relaxed_load) = (st.deposit_load, st.relaxed_load);
    let (measure_window, measured_substeps) = (&st.window, st.measured_substeps);
    let mut all = deposit;
    all.merge(&release);
    all.merge(&relax);
    solver_keys(s, &all);
    s.int("deposit_steps", deposit.steps)
        .num("deposit_dt_s", c.dt / c.deposit.substeps as f64)
        .num("deposit_time_s", deposit.simulated_time)
        .int("deposit_unconverged_steps", deposit.unconverged_steps)
        .int("deposit_energy_growth_steps", deposit.energy_growth_steps)
        .num("deposit_bottom_load_over_weight", deposit_load)
        .num("relaxed_bottom_load_over_weight", relaxed_load)
        .num("release_floor_drop_m", c.release.floor_drop)
        .num("release_speed_m_s", c.release.speed)
        .int("release_steps", release.steps);
    solve_keys(s, "release", &release)
        .int("relax_steps", relax.steps)
        .num("relax_time_s", relax.simulated_time);
    solve_keys(s, "relax", &relax)
        .flag("relax_at_rest", relax.at_rest)
        .num("final_kinetic_energy_ratio", relax.final_energy_ratio)
        .num("final_solver_error", final_report.solver.error)
        .num(
            "final_solver_error_without_gap_shifts",
            final_report.solver.error_without_gap_shifts,
        )
        .int("final_solver_sweeps", final_report.solver.iterations as u64)
        .flag("final_solver_converged", final_report.solver.converged)
        .int("measure_steps", measure_window.samples)
        .int("measured_max_substeps", measured_substeps);
}

/// Stage "report": `wall_profile.csv`, the fit-ready profile with the fitted law and the
/// hydrostatic line.
fn write_profile(
    out: &mut OutputDir,
    c: &JanssenConfig,
    h: &Homogenised,
    fitted: &Fitted,
    width: f64,
    window: (f64, f64),
) -> Result<()> {
    let (profile, rho_b, g) = (&h.profile, h.rho_b, h.g);
    // τ_w is named `tau_w_Pa` (read by `grainlaw fit janssen`) only when the fit used it.
    let uses_tau = fitted.as_ref().map(|o| o.uses_tau_w).unwrap_or(false);
    let tau_header = if uses_tau {
        "tau_w_Pa"
    } else {
        "tau_w_measured_Pa"
    };
    let mut prof = CsvTable::new(&[
        "z_m",
        "sigma_v_Pa",
        "sigma_h_Pa",
        tau_header,
        "janssen_sigma_v_Pa",
        "janssen_sigma_h_Pa",
        "hydrostatic_Pa",
    ]);
    prof.comments.push("Janssen column: depth below the free surface, vertical stress (method of planes), wall normal and shear stress (mean of both walls); compressive positive. Fit again with: grainlaw fit janssen wall_profile.csv".into());
    prof.metadata = vec![
        ("width_m".into(), width),
        ("bulk_density_kg_m3".into(), rho_b),
        ("wall_friction".into(), c.friction.grain_wall),
        ("gravity_m_s2".into(), g),
        ("depth_min_m".into(), window.0),
        ("depth_max_m".into(), window.1),
    ];
    if let Ok(o) = fitted {
        if o.mode == "full_mobilisation" {
            prof.metadata.push(("full_mobilisation".into(), 1.0));
        }
    }
    for (i, &z) in profile.z.iter().enumerate() {
        let (jv, jh) = match fitted {
            Ok(o) => (o.fit.law.sigma_v(z), o.fit.law.sigma_h(z)),
            Err(_) => (f64::NAN, f64::NAN),
        };
        prof.push(vec![
            z,
            profile.sigma_v[i],
            profile.sigma_h[i],
            profile.tau_w[i],
            jv,
            jh,
            rho_b * g * z,
        ]);
    }
    prof.write(out, "wall_profile.csv")?;

    Ok(())
}

/// Runs the scenario: config, build and run (`simulate`), measure (`homogenise`), fit,
/// verdict (`judge`), report.
pub fn run(c: &JanssenConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let width = crate::scenarios::common::build::column_width(&c.grain, c.grains, c.column_aspect);
    announce(c, ctx.verbosity, width);
    let (world, st) = simulate(c, ctx, ctl, width)?;
    let world = &world;
    let (weight, measured) = (st.weight, st.measured);
    let final_report = world.last_report();
    if measured.unconverged > 0 {
        warn(&format!(
            "{} of the {} measured steps did not converge: worst error {:.2e} > {:.0e}",
            measured.unconverged, measured.steps, measured.worst_error, c.relax.solver.tolerance
        ));
    }
    let snap = world.snapshot();
    let frames = st.vtk.clone().finish(&mut ctx.out, world)?;
    let measure_window = &st.window;
    let h = homogenise(c, world, &snap, width, measure_window)?;
    let (d, profile, rho_b, g) = (h.d, &h.profile, h.rho_b, h.g);
    let bottom_load = h.loads.floor;
    let wall_load = h.loads.walls;

    let setup = JanssenSetup {
        width_m: width,
        bulk_density_kg_m3: rho_b,
        gravity_m_s2: g,
        wall_friction: c.friction.grain_wall,
    };
    let window = (h.top_skip, profile.surface - h.bottom_skip);
    let fitted = fit_profile(profile, &setup, window);
    let sensitivity = solver_sensitivity(c, &st, &fitted, &setup, window);

    let balance = (bottom_load + wall_load) / weight - 1.0;
    let bin = profile.surface / c.analysis.depth_bins as f64;
    let checks = judge(c, &measured, &h, &sensitivity, &fitted, (balance, bin));
    let mut verdict = RunVerdict {
        run: checks.clone(),
        ..Default::default()
    };
    verdict.allow_suspect = ctl.allow_suspect;

    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("box_width_m", width)
        .num("column_height_m", profile.surface)
        .num("column_height_over_width", profile.surface / width)
        .num("mean_diameter_m", d)
        .num("solid_fraction", h.phi)
        .num("bulk_density_kg_m3", rho_b)
        .num("weight_N", weight)
        .num("bottom_load_N", bottom_load)
        .num("bottom_load_over_weight", bottom_load / weight)
        .num("wall_load_N", wall_load)
        .num("force_balance_residual", balance)
        .num("depth_bin_thickness_m", bin)
        .num("wall_friction", c.friction.grain_wall)
        .num("grain_friction", c.friction.grain_grain);
    let mut headline = report_fit(
        c,
        ctx,
        ctl,
        &fitted,
        profile,
        window,
        &checks,
        &mut s,
        &mut verdict,
    )?;
    s.num("wall_sliding_fraction", h.sliding)
        .num("wall_mean_mobilisation", h.mean_mob)
        .num("wall_contacts", measure_window.wall_contacts());
    headline.push(format!(
        "bottom load / weight = {:.3}, wall contacts at the Coulomb limit: {:.0} %",
        bottom_load / weight,
        100.0 * h.sliding
    ));
    phase_keys(&mut s, c, &st, &final_report);
    measured.keys(&mut s, "measured");
    sensitivity.keys(&mut s, fitted.as_ref().ok());
    s.int("vtk_frames", frames as u64);

    // CSV: history and the fit-ready profile.
    rows::table(&st.history).write(&mut ctx.out, "history.csv")?;
    write_profile(&mut ctx.out, c, &h, &fitted, width, window)?;

    figures::draw(
        ctx,
        &figures::Inputs {
            profile,
            fitted: &fitted,
            rho_b,
            g,
            window,
            mu_wall: c.friction.grain_wall,
            mobilisations: measure_window.mobilisations(),
            samples: measure_window.samples,
            sliding: h.sliding,
            mean_mob: h.mean_mob,
            snap: &snap,
            grains: c.grains,
            history: &st.history,
            end_time: world.time,
        },
    )?;

    let mut lines = vec![format!("report: {}/", ctx.out.path().display())];
    lines.extend(headline);
    Ok(RunOutcome {
        summary: s,
        headline: lines,
        verdict,
    })
}

/// The headline line saying which data the Janssen fit used. τ_w is left out when a bin of the
/// window has τ_w < 0 (the wall holds the grains down there: a depth bin of a narrow column
/// holds a few wall contacts, and one grain stuck with reversed friction turns its mean); the
/// line names those bins and their values, so that the user can judge. It is a property of the
/// measured state, reported with the fit rather than as a warning: the fit to σ_v and σ_h
/// still separates K (σ_h = K σ_v) and μ_w (the curvature of σ_v), and its checks are the same.
fn fit_data_line(profile: &ColumnProfile, window: (f64, f64), uses_tau_w: bool) -> String {
    let n = profile
        .z
        .iter()
        .filter(|z| **z >= window.0 && **z <= window.1)
        .count();
    if uses_tau_w {
        return format!("fitted to σ_v, σ_h and τ_w in {n} depth bins");
    }
    let negative = profile.negative_tau_w(window);
    let (lo, hi) = profile
        .z
        .iter()
        .zip(&profile.tau_w)
        .filter(|(z, t)| **z >= window.0 && **z <= window.1 && **t >= 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, t)| {
            (a.min(*t), b.max(*t))
        });
    let others = if lo <= hi {
        format!(", the others {lo:.0}–{hi:.0} Pa")
    } else {
        String::new()
    };
    let named: Vec<String> = negative
        .iter()
        .map(|(z, t)| format!("{t:.0} Pa at z = {:.1} mm", z * 1e3))
        .collect();
    format!(
        "fitted to σ_v and σ_h in {n} depth bins; τ_w left out, < 0 in {} ({}{others})",
        if negative.len() == 1 {
            "one bin".to_string()
        } else {
            format!("{} bins", negative.len())
        },
        named.join(", ")
    )
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for JanssenConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "janssen"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        vec![LawNeed {
            law: "janssen",
            formula: "σ_v(z) of Janssen 1895, K and μ_w jointly",
            key: "",
            needs: 4,
            have: None,
            why: "depth bins of the wall profile in the fit window",
            instead_of: None,
        }]
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        let w = column_width(&self.grain, self.grains, self.column_aspect);
        let dt = self.dt / self.deposit.substeps as f64;
        column(&self.grain, self.grains, w, &self.friction, self.seed, dt).map(drop)
    }
}
