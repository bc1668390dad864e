//! The `shear-cell` scenario: steady plane shear without gravity of a periodic sample between
//! two rough walls; the top wall is pushed with the imposed pressure P and moved at the velocity
//! V that targets each inertial number `I = γ̇ d/√(P/ρ)` in turn (the runs follow each other,
//! lowest I first, each starting from the previous steady state).
//!
//! Per run, averaged over the last `average_strain` of shear in the bulk (two diameters away
//! from each wall): stress (μ = |σ_xy|/(−σ_yy), P = −σ_yy), solid fraction φ, shear rate γ̇ from
//! the affine fit of the grain velocities, hence the measured I; at each wall the slip velocity
//! of the first layer of grains and the effective friction τ_w/σ_w. Then μ(I) and φ(I) are fitted
//! (identify::mu_i), and the wall friction law against the slip velocity (identify::wall_law,
//! best of three forms by AIC).

pub mod build;
pub mod config;

use dem::math::{Tensor, Vector};
use dem::snapshot::Snapshot;
use homogenise::kinematics::{velocity_gradient, VelocityWeight};
use homogenise::state::solid_fraction;
use homogenise::walls::{near_wall_profile, NearWallSpec};
use homogenise::Region;
use identify::law::GrainScale;
use identify::mu_i::RheologySeries;
use identify::wall_law::{select_wall_law, WallSlipSeries};
use identify::{CalibratedLaw, FitOptions};

use serde::{Deserialize, Serialize};

use super::common::laws::LawNeed;
use super::common::{
    add_fitted_curve, delta_band, fit_keys, mean_diameter, parameter_lines, Stop, VtkFrames,
};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_rows, table_row, TableRow};
use super::sensitivity::{record, Resolved};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::{CsvTable, OutputDir, Summary};
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_row, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::progress::{info, warn};
use crate::verdict::{
    export_law, max_solid_fraction, Checks, RunVerdict, Sensitivity, Verdict, WindowStats,
    SENSITIVITY_MU_SUSPECT, SENSITIVITY_PRESSURE_SUSPECT, SENSITIVITY_TOLERANCE,
};
use build::shear_cell;
use config::ShearCellConfig;

/// Averages of one run (sums of finite samples).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct RunAverages {
    sxy: f64,
    syy: f64,
    phi: f64,
    gamma_dot: f64,
    samples: usize,
    walls: [(f64, f64, f64, usize); 2],
    profile: Vec<(f64, f64, f64)>,
    /// μ = |Σ_xy|/(−Σ_yy) and φ of each sample, in order (steady-state check).
    #[serde(default, with = "crate::floats::vec")]
    mu_samples: Vec<f64>,
    #[serde(default, with = "crate::floats::vec")]
    phi_samples: Vec<f64>,
}

/// What the checks of one run (one point of μ(I), φ(I)) need (crate::verdict); shared with
/// the `simple-shear` scenario.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub(crate) struct RunCheckData {
    /// Target inertial number.
    #[serde(with = "dem::serde_float")]
    pub(crate) i_target: f64,
    /// Measured inertial number.
    #[serde(with = "dem::serde_float")]
    pub(crate) i_measured: f64,
    /// Numerics of the averaging window.
    pub(crate) window: WindowStats,
    /// Samples of μ over the window.
    #[serde(with = "crate::floats::vec")]
    pub(crate) mu: Vec<f64>,
    /// Samples of φ over the window.
    #[serde(with = "crate::floats::vec")]
    pub(crate) phi: Vec<f64>,
}

/// The checks of the points of a rheology: those common to both laws (window numerics, `I`
/// against its target), those of μ(I) (steady μ) and of φ(I) (steady φ, φ below `phi_bound`),
/// each point's own verdict, and the merged window statistics. The checks are named after the
/// scenario that measured the points (`scenario` = `shear_cell`, `simple_shear`).
pub(crate) struct PointJudgement {
    pub(crate) common: Checks,
    pub(crate) mu: Checks,
    pub(crate) phi: Checks,
    pub(crate) points: Vec<Verdict>,
    pub(crate) windows: WindowStats,
}

impl PointJudgement {
    /// The checks of the μ(I) and of the φ(I) law, each with the common ones, and the run's
    /// verdict over the common checks and both laws' (`allow_suspect` as the run says).
    pub(crate) fn law_checks(&self, allow_suspect: bool) -> (Checks, Checks, RunVerdict) {
        let mut mu = self.mu.clone();
        mu.extend(&self.common);
        let mut phi = self.phi.clone();
        phi.extend(&self.common);
        let mut verdict = RunVerdict {
            run: self.common.clone(),
            allow_suspect,
            ..Default::default()
        };
        verdict.run.extend(&mu);
        verdict.run.extend(&phi);
        (mu, phi, verdict)
    }
}

/// [`judge_points`] of a scenario's own runs, with the bound of φ of its grains' radius spread
/// ([`max_solid_fraction`]), and the checks of both laws and the run's verdict
/// ([`PointJudgement::law_checks`], `allow_suspect` as the run says).
pub(crate) fn judge_runs(
    scenario: &str,
    run_checks: &[RunCheckData],
    radius_spread: f64,
    allow_suspect: bool,
) -> (PointJudgement, Checks, Checks, RunVerdict) {
    let judged = judge_points(scenario, run_checks, max_solid_fraction(radius_spread));
    let (mu, phi, verdict) = judged.law_checks(allow_suspect);
    (judged, mu, phi, verdict)
}

/// Judges every point of a rheology ([`PointJudgement`]), its checks named after `scenario`. A
/// point whose `i_target` is not finite (another code's run, which has none) skips the check of
/// `I` against its target.
pub(crate) fn judge_points(
    scenario: &str,
    run_checks: &[RunCheckData],
    phi_bound: f64,
) -> PointJudgement {
    let mut j = PointJudgement {
        common: Checks::new(),
        mu: Checks::new(),
        phi: Checks::new(),
        points: Vec::with_capacity(run_checks.len()),
        windows: WindowStats::default(),
    };
    for rc in run_checks {
        // a run without a target (another code's run read by `grainlaw homogenise`: NaN) is
        // named by its measured I and has no target to miss
        let label = if rc.i_target.is_finite() {
            format!("I = {}", rc.i_target)
        } else {
            format!("I = {:.4e} (measured)", rc.i_measured)
        };
        let (mut pc, mut pm, mut pp) = (Checks::new(), Checks::new(), Checks::new());
        // A sample that is not a number (μ of a cell whose σ_yy went tensile: the grains lost
        // contact) leaves the point without a mean: refused, not an input error.
        let bad = rc
            .mu
            .iter()
            .chain(&rc.phi)
            .filter(|x| !x.is_finite())
            .count();
        if bad > 0 {
            pc.fail(
                &format!("{scenario}.finite_samples"),
                Verdict::Refused,
                bad as f64,
                0.0,
                format!(
                    "{label}: {bad} of the averaging window's {} samples of μ and φ are not finite (a tensile or vanishing σ_yy: the packing lost its contacts)",
                    rc.mu.len() + rc.phi.len()
                ),
            );
        }
        pc.window(&format!("{label}, averaging window"), &rc.window);
        j.windows.merge(&rc.window);
        if rc.i_target.is_finite() {
            let ratio = rc.i_measured / rc.i_target;
            let factor = if ratio >= 1.0 { ratio } else { 1.0 / ratio };
            pc.at_most(
                &format!("{scenario}.inertial_number_factor"),
                factor,
                I_FACTOR_SUSPECT,
                Some(I_FACTOR_REFUSED),
                |t| {
                    format!(
                        "{label}: measured I = {:.3e} is {factor:.2} times off its target (limit {t}×)",
                        rc.i_measured
                    )
                },
            );
        }
        pm.steady(
            &format!("{scenario}.steady_mu"),
            &format!("{label}: μ"),
            &rc.mu,
            STEADY_MU_TOLERANCE,
        );
        pp.steady(
            &format!("{scenario}.steady_phi"),
            &format!("{label}: φ"),
            &rc.phi,
            STEADY_PHI_TOLERANCE,
        );
        let phi = rc.phi.iter().sum::<f64>() / rc.phi.len().max(1) as f64;
        pp.solid_fraction(
            &format!("{scenario}.solid_fraction"),
            &format!("{label}: the bulk"),
            phi,
            phi_bound,
        );
        j.points
            .push(pc.verdict().max(pm.verdict()).max(pp.verdict()));
        j.common.extend(&pc);
        j.mu.extend(&pm);
        j.phi.extend(&pp);
    }
    j
}

/// The `point_verdict` column value of a point: 0 ok, 1 suspect, 2 refused (or unjudged).
pub(crate) fn point_verdict_code(v: Option<&Verdict>) -> f64 {
    match v {
        Some(Verdict::Ok) => 0.0,
        Some(Verdict::Suspect) => 1.0,
        Some(Verdict::Refused) | None => 2.0,
    }
}

/// Writes `rheology.csv`: `rows` under their headers and a last column `point_verdict`, filled
/// here from `point_verdicts`, the table's `description`, how to fit it again, the meaning of
/// `point_verdict` and the grain's diameter and density as metadata (the fits' `d`, `ρ_s`).
pub(crate) fn write_rheology_table<R: TableRow>(
    out: &mut OutputDir,
    rows: &[R],
    point_verdicts: &[Verdict],
    description: &str,
    grain: GrainScale,
) -> Result<()> {
    let mut headers = R::HEADERS.to_vec();
    headers.push("point_verdict");
    let mut table = CsvTable::new(&headers);
    for (k, r) in rows.iter().enumerate() {
        let mut r = r.to_values();
        r.push(point_verdict_code(point_verdicts.get(k)));
        table.push(r);
    }
    table.comments.push(format!(
        "{description}; fit again with grainlaw fit mu-i rheology.csv"
    ));
    table.comments.push("point_verdict: the point's own checks (averaging-window numerics, I against its target, steady state, solid fraction): 0 ok, 1 suspect, 2 refused".into());
    table.metadata = vec![
        ("grain_diameter_m".into(), grain.diameter_m),
        ("grain_density_kg_m3".into(), grain.density_kg_m3),
    ];
    table.write(out, "rheology.csv")
}

/// Measured inertial number over its target (or the inverse) above which a run is suspect: the
/// point then belongs to another part of μ(I) than planned (1).
pub const I_FACTOR_SUSPECT: f64 = 2.0;
/// The same, above which the run is refused (1).
pub const I_FACTOR_REFUSED: f64 = 10.0;
/// Difference of the window halves of μ that matters (absolute; [`crate::verdict::halves_drift`]).
pub const STEADY_MU_TOLERANCE: f64 = 0.02;
/// Difference of the window halves of φ that matters (absolute).
pub const STEADY_PHI_TOLERANCE: f64 = 0.005;

/// Bounds of one correction of the wall velocity,
/// `V ← V · clamp(√(I_target / I_measured), 1/2, 2)`: half the miss in log scale, because the
/// bulk answers a change of V with a lag of a strain of order one (a run starts from the
/// previous run's flow) and a shear localised at a slipping wall answers less than in
/// proportion; a full correction overshot (I = 0.2: V raised 2.5 times from a lagging
/// measurement, then the top wall slid at 4 m/s over the grains).
pub const VELOCITY_CORRECTION_BOUNDS: (f64, f64) = (0.5, 2.0);

/// A lead stage whose bulk I is within this factor of the target leaves V alone: the bulk I of
/// half a stage is a noisy measurement (a small cell shears intermittently), and correcting
/// within the noise drove the runs of a 120-grain cell away from their targets (I = 0.01
/// ended at 0.015, I = 0.04 at 0.024); the misses the correction is for are systematic and
/// larger (the default cell at I = 0.02: 2.3 times). Below the suspect limit
/// [`I_FACTOR_SUSPECT`].
pub const VELOCITY_DEAD_BAND: f64 = 1.5;

/// The phases: compression at zero shear, then per inertial number (lowest first, each from the
/// previous steady state) the lead stages, after each but the last of which the wall velocity
/// is corrected towards the target, and the averaged stage.
struct Shear<'a> {
    c: &'a ShearCellConfig,
    /// Target inertial numbers, sorted.
    targets: Vec<f64>,
}

/// The bulk inertial number measured over the second half of a lead stage (sums).
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
struct LeadAverages {
    /// Σ γ̇ (1/s) and Σ P (Pa) of the bulk.
    gamma_dot: f64,
    pressure: f64,
    samples: u64,
}

/// The plan of the current stage of a shear run, fixed when the stage starts.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
struct ShearRun {
    /// Wall velocity V (m/s), gap H (m), time step (s).
    v: f64,
    h: f64,
    dt: f64,
    steps: u64,
    avg_steps: u64,
    /// Samples every this many steps over the last `avg_steps`.
    every: u64,
    /// Steps done.
    n: u64,
    /// The uniform-shear estimate of V, `γ̇_target H`, at the run's start (m/s).
    #[serde(default)]
    v_uniform: f64,
}

/// A run's mean velocity profile: heights above the bottom wall (m) and mean velocity (m/s,
/// NaN in an empty bin).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct MeanProfile {
    #[serde(with = "dem::serde_float")]
    i: f64,
    #[serde(with = "crate::floats::vec")]
    y: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    velocity: Vec<f64>,
    v: f64,
    h: f64,
}

table_row! {
    /// One shear run: a row of the shear cell's `rheology.csv` (without its `point_verdict`).
    struct CellRow {
        /// Target inertial number.
        i_target: "I_target",
        /// Bulk inertial number measured.
        i: "I",
        /// Bulk μ = |Σ_xy|/P.
        mu: "mu",
        /// Bulk solid fraction.
        phi: "phi",
        /// Bulk `P = −Σ_yy` (Pa).
        p: "P_Pa",
        /// Bulk shear rate (1/s).
        shear_rate: "shear_rate_1_s",
        /// Wall velocity V (m/s).
        wall_velocity: "wall_velocity_m_s",
        /// Gap H (m).
        height: "height_m",
        /// Time step (s).
        dt: "dt_s",
        /// Slip velocity at the bottom wall (m/s).
        slip_bottom: "slip_velocity_bottom_m_s",
        /// Effective friction of the bottom wall.
        mu_eff_bottom: "mu_eff_bottom",
        /// Slip velocity at the top wall (m/s).
        slip_top: "slip_velocity_top_m_s",
        /// Effective friction of the top wall.
        mu_eff_top: "mu_eff_top",
        /// Samples of the window.
        samples: "samples",
        /// V over the uniform-shear estimate γ̇_target H.
        wall_velocity_over_uniform: "wall_velocity_over_uniform",
        /// The solver's tolerance of the averaged stage.
        solver_tolerance: "solver_tolerance",
    }
}

table_row! {
    /// One wall-velocity correction: a row of `lead_stages.csv`.
    struct LeadRow {
        /// Target inertial number.
        i_target: "I_target",
        /// The lead stage after which V was corrected.
        lead_stage: "lead_stage",
        /// Bulk I over the stage's second half.
        i_measured: "I_measured",
        /// Factor applied to V.
        velocity_factor: "velocity_factor",
        /// V over the uniform-shear estimate after it.
        wall_velocity_over_uniform: "wall_velocity_over_uniform",
    }
}

/// What the phases collect.
#[derive(Serialize, Deserialize)]
struct ShearState {
    all: PhaseStats,
    /// One row per run: `rheology.csv`.
    #[serde(with = "serde_rows")]
    rows: Vec<CellRow>,
    profiles: Vec<MeanProfile>,
    run: ShearRun,
    acc: RunAverages,
    /// Numerics of the current run's averaging window.
    #[serde(default)]
    window: WindowStats,
    /// One per finished run.
    #[serde(default)]
    checks: Vec<RunCheckData>,
    /// The current lead stage's bulk measurement.
    #[serde(default)]
    lead: LeadAverages,
    /// One row per wall-velocity correction: `lead_stages.csv`.
    #[serde(default, with = "serde_rows")]
    lead_rows: Vec<LeadRow>,
    /// The current lead stage's solver sensitivity (its second half's samples, re-solved).
    #[serde(default)]
    lead_sensitivity: Sensitivity,
    /// Decades by which the lead stages have tightened the solver tolerance so far
    /// ([`config::ShearCellConfig::solver_tightenings`]).
    #[serde(default)]
    tightenings: u32,
    /// Mean cost per step of the last phase's solves, in sweeps
    /// ([`PhaseStats::mean_solve_cost`], `needs_tightening`).
    #[serde(default, alias = "lead_sweeps")]
    phase_cost: f64,
}

/// The correction of the wall velocity after a lead stage whose bulk measurement is `lead`:
/// `(I_measured, factor)` with `I_measured = |⟨γ̇⟩| d / √(⟨P⟩/ρ)` and
/// `factor = clamp(√(I_target / I_measured), 1/2, 2)` ([`VELOCITY_CORRECTION_BOUNDS`]), or 1
/// when `I_measured` is within [`VELOCITY_DEAD_BAND`] of the target or was not measured (NaN).
fn velocity_correction(i_target: f64, lead: &LeadAverages, d: f64, rho: f64) -> (f64, f64) {
    if lead.samples == 0 {
        return (f64::NAN, 1.0);
    }
    let m = lead.samples as f64;
    let i_measured = (lead.gamma_dot / m).abs() * d / (lead.pressure / m / rho).sqrt();
    let miss = i_target / i_measured;
    if !(i_measured.is_finite() && i_measured > 0.0)
        || (1.0 / VELOCITY_DEAD_BAND..=VELOCITY_DEAD_BAND).contains(&miss)
    {
        return (i_measured, 1.0);
    }
    let (lo, hi) = VELOCITY_CORRECTION_BOUNDS;
    (i_measured, miss.sqrt().clamp(lo, hi))
}

/// Whether the re-solve of a lead stage's samples calls for a tighter tolerance: on at least
/// [`TIGHTEN_MIN_SAMPLES`] samples, the upper bound ([`Sensitivity::upper_bounds`],
/// [`TIGHTEN_Z`] standard errors) of μ's change exceeds
/// [`crate::verdict::SENSITIVITY_MU_SUSPECT`] or that of the pressure's
/// [`crate::verdict::SENSITIVITY_PRESSURE_SUSPECT`]: what the window, another set of samples of
/// the same flow, could show; and only where the stage's solves took at most
/// [`TIGHTEN_MAX_SWEEPS`] of the sweep cap `max_sweeps` on average (`sweeps`, Newton
/// iterations and Lemke pivots counted in sweeps, [`PhaseStats::mean_solve_cost`]). Where the
/// solves are loose against the contact forces (a rapid flow) the per-sample changes scatter
/// widely (±30–80 % of a sample's pressure at I = 0.2, at 13–40 sweeps a step); in the slow
/// dense shear (I = 0.005: 1.3 % ± 0.6 %, at 2100–2400 sweeps a step against a cap of 5000) a
/// tenth of the tolerance stalls: the default cell at 10⁻⁵ throughout left 32 of the 1896
/// window steps at I = 0.005 unconverged and took 12.4 min instead of 3.
fn needs_tightening(s: &Sensitivity, sweeps: f64, max_sweeps: usize) -> bool {
    let [mu, p] = s.upper_bounds(TIGHTEN_Z);
    s.samples >= TIGHTEN_MIN_SAMPLES
        && sweeps <= TIGHTEN_MAX_SWEEPS * max_sweeps as f64
        && (mu > SENSITIVITY_MU_SUSPECT || p > SENSITIVITY_PRESSURE_SUSPECT)
}

/// Largest mean sweeps per step of a lead stage, as a fraction of the sweep cap, after which
/// `needs_tightening` may tighten the tolerance.
pub const TIGHTEN_MAX_SWEEPS: f64 = 0.2;

/// Standard errors of the mean added to a lead stage's measured changes (`needs_tightening`).
pub const TIGHTEN_Z: f64 = 2.0;

/// Fewest re-solved samples of a lead stage on which `needs_tightening` decides.
pub const TIGHTEN_MIN_SAMPLES: u64 = 4;

/// Which part of which run phase `k ≥ 1` is.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stage {
    /// Index of the target inertial number.
    target: usize,
    /// Lead stage `0 … corrections`, or `None` for the averaged stage.
    lead: Option<usize>,
}

impl Shear<'_> {
    /// Lead stages of a run (the strain before the averaged part; one when it is not
    /// corrected).
    fn lead_stages(&self) -> usize {
        self.c.velocity_corrections + 1
    }

    /// Strain of lead stage `j`: with corrections, the correcting stages share the first half
    /// of the lead and the last stage, which lets the flow settle at the final V before the
    /// averaged part, the second half; without, one stage.
    fn lead_strain(&self, j: usize) -> f64 {
        let c = self.c;
        let lead = c.strain - c.average_strain;
        match c.velocity_corrections {
            0 => lead,
            n if j < n => 0.5 * lead / n as f64,
            _ => 0.5 * lead,
        }
    }

    fn stage(&self, k: usize) -> Stage {
        let per_run = self.lead_stages() + 1;
        let (target, j) = ((k - 1) / per_run, (k - 1) % per_run);
        Stage {
            target,
            lead: (j < self.lead_stages()).then_some(j),
        }
    }
}

const TOP: usize = 1;

impl PhasedRun for Shear<'_> {
    type State = ShearState;

    fn phase_count(&self) -> usize {
        1 + self.targets.len() * (self.lead_stages() + 1)
    }

    fn enter(&self, st: &mut ShearState, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, env, world) = (at.k, at.env, at.world);
        let c = self.c;
        if k == 0 {
            world.params.dt = c.dt_max;
            return Ok(Some(PhasePlan::new(
                "compress",
                Stop::Steps((c.compression_time / c.dt_max).ceil() as u64),
            )));
        }
        let stage = self.stage(k);
        let i_target = self.targets[stage.target];
        let r = c.grain.radius_mean;
        let d = mean_diameter(world);
        let h = world.bodies[TOP].position.y - 2.0 * r;
        // V: the uniform-shear estimate γ̇ H at a run's start; then corrected after each lead
        // stage but the last by the bulk I it measured (its second half).
        let (v_uniform, mut v) = if stage.lead == Some(0) {
            let gamma_target = i_target * (c.pressure / c.grain.density).sqrt() / d;
            (gamma_target * h, gamma_target * h)
        } else {
            (st.run.v_uniform, st.run.v)
        };
        if let Some(j) = stage
            .lead
            .filter(|&j| j >= 1 && j <= c.velocity_corrections)
        {
            let (i_measured, factor) = velocity_correction(i_target, &st.lead, d, c.grain.density);
            v *= factor;
            st.lead_rows.push(LeadRow {
                i_target,
                lead_stage: j as f64,
                i_measured,
                velocity_factor: factor,
                wall_velocity_over_uniform: v / v_uniform,
            });
            if factor != 1.0 {
                info(
                    env.verbosity,
                    &format!(
                        "      I={i_target}: bulk I = {i_measured:.3e} over the lead's stage, wall velocity × {factor:.2} ({:.2} × uniform shear)",
                        v / v_uniform
                    ),
                );
            }
        }
        // The solver's accuracy: tightened after a lead stage whose samples' stress moved when
        // solved again to 1e-8 (`solver_tightenings`).
        if k >= 2 && self.stage(k - 1).lead.is_some() {
            let sens = std::mem::take(&mut st.lead_sensitivity);
            if st.tightenings < c.solver_tightenings
                && needs_tightening(&sens, st.phase_cost, c.solver.max_iterations)
            {
                st.tightenings += 1;
                let [mu_bound, p_bound] = sens.upper_bounds(TIGHTEN_Z);
                info(
                    env.verbosity,
                    &format!(
                        "      I={i_target}: the lead's samples move by Δμ = {:.4} (up to {mu_bound:.4}), ΔP/P = {:.2} % (up to {:.2} %) when solved to {SENSITIVITY_TOLERANCE:.0e}: solver tolerance → {:.0e}",
                        sens.mu_change(),
                        100.0 * sens.pressure_change(),
                        100.0 * p_bound,
                        c.solver.tolerance * 0.1f64.powi(st.tightenings as i32)
                    ),
                );
            }
        }
        world.params.solver.tolerance = c.solver.tolerance * 0.1f64.powi(st.tightenings as i32);
        let dt = c.dt_max.min(c.travel_per_step * r / v);
        let (strain, name) = match stage.lead {
            Some(j) => (
                self.lead_strain(j),
                format!("I={i_target} lead {}/{}", j + 1, self.lead_stages()),
            ),
            None => (c.average_strain, format!("I={i_target}")),
        };
        let steps = ((strain * h / (v * dt)).ceil() as u64).max(1);
        // The averaged stage samples all its steps; a lead stage, its second half.
        let avg_steps = if stage.lead.is_some() {
            steps / 2
        } else {
            steps
        };
        world.params.dt = dt;
        world.bodies[TOP].velocity.x = v;
        st.run = ShearRun {
            v,
            h,
            dt,
            steps,
            avg_steps,
            every: (avg_steps / 40).max(1),
            n: 0,
            v_uniform: if stage.lead == Some(0) {
                v_uniform
            } else {
                st.run.v_uniform
            },
        };
        st.acc = RunAverages::default();
        st.lead = LeadAverages::default();
        st.lead_sensitivity = Sensitivity::default();
        st.window.reset();
        Ok(Some(PhasePlan::new(name, Stop::Steps(steps))))
    }

    fn step(&self, st: &mut ShearState, at: Step<'_>) -> Result<()> {
        let (k, w, r, p) = (at.k, at.world, at.report, at.progress);
        if k == 0 {
            return Ok(());
        }
        let averaged = self.stage(k).lead.is_none();
        let run = &mut st.run;
        run.n += 1;
        let in_window = run.n + run.avg_steps > run.steps;
        st.window.step(averaged && in_window, w, r, &p.stats);
        if in_window && run.n.is_multiple_of(run.every) {
            let d = mean_diameter(w);
            if averaged {
                let (sxy, syy) = sample(w, &mut st.acc, self.c.grain.radius_mean, d)?;
                let resolved = resolved_stress(w, self.c.grain.radius_mean, d);
                record(&mut st.window.sensitivity, [sxy, syy], resolved);
            } else {
                let (gamma_dot, sym) = bulk_shear(w, self.c.grain.radius_mean, d)?;
                st.lead.gamma_dot += gamma_dot;
                st.lead.pressure += -sym[(1, 1)];
                st.lead.samples += 1;
                // Only where the rule could tighten: tightenings left, and the stage's solves
                // not already too costly for it, whatever its remaining steps cost (the cost so
                // far over all the stage's steps is a lower bound of its mean): the slow shear's
                // lead stages would spend some 35 s of the default run re-solving samples that
                // cannot change its tolerance.
                let cost_bound =
                    p.stats.mean_solve_cost() * p.stats.steps as f64 / st.run.steps.max(1) as f64;
                if st.tightenings < self.c.solver_tightenings
                    && cost_bound <= TIGHTEN_MAX_SWEEPS * self.c.solver.max_iterations as f64
                {
                    let resolved = resolved_stress(w, self.c.grain.radius_mean, d);
                    record(
                        &mut st.lead_sensitivity,
                        [sym[(0, 1)], sym[(1, 1)]],
                        resolved,
                    );
                }
            }
        }
        Ok(())
    }

    fn leave(&self, st: &mut ShearState, at: Leave<'_>) -> Result<()> {
        let (k, world, stats) = (at.k, at.world, at.stats);
        st.all.merge(stats);
        st.phase_cost = stats.mean_solve_cost();
        if k == 0 || self.stage(k).lead.is_some() {
            return Ok(());
        }
        let i_target = self.targets[self.stage(k).target];
        let rho = self.c.grain.density;
        let d = mean_diameter(world);
        let ShearRun {
            v,
            h,
            dt,
            v_uniform,
            ..
        } = st.run;
        let acc = std::mem::take(&mut st.acc);
        let m = acc.samples.max(1) as f64;
        let (sxy, syy, phi, gd) = (acc.sxy / m, acc.syy / m, acc.phi / m, acc.gamma_dot / m);
        let p = -syy;
        let mu = sxy.abs() / p;
        let i_meas = gd.abs() * d / (p / rho).sqrt();
        let wall = |j: usize| {
            let (vs, ft, fnn, cnt) = acc.walls[j];
            let cnt = cnt.max(1) as f64;
            (vs / cnt, if fnn > 0.0 { ft.abs() / fnn } else { f64::NAN })
        };
        let (vb, mub) = wall(0);
        let (vt, mut_) = wall(1);
        st.checks.push(RunCheckData {
            i_target,
            i_measured: i_meas,
            window: st.window,
            mu: acc.mu_samples.clone(),
            phi: acc.phi_samples.clone(),
        });
        st.rows.push(CellRow {
            i_target,
            i: i_meas,
            mu,
            phi,
            p,
            shear_rate: gd,
            wall_velocity: v,
            height: h,
            dt,
            slip_bottom: vb,
            mu_eff_bottom: mub,
            slip_top: vt,
            mu_eff_top: mut_,
            samples: acc.samples as f64,
            wall_velocity_over_uniform: v / v_uniform,
            solver_tolerance: world.params.solver.tolerance,
        });
        st.profiles.push(MeanProfile {
            i: i_meas,
            y: acc.profile.iter().map(|p| p.0).collect(),
            velocity: acc
                .profile
                .iter()
                .map(|&(_, s, c)| if c > 0.0 { s / c } else { f64::NAN })
                .collect(),
            v,
            h,
        });
        Ok(())
    }
}

/// Stages "build" and "run": the cell compressed, then sheared at each target inertial number
/// (or resumed from a checkpoint).
fn simulate(
    c: &ShearCellConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<(dem::World, ShearState)> {
    let mut targets = c.inertial_numbers.clone();
    targets.sort_by(f64::total_cmp);
    let shear = Shear { c, targets };
    let fresh = || -> Result<(dem::World, ShearState)> {
        let (world, _) = build::shear_cell(c)?;
        let state = ShearState {
            all: PhaseStats::default(),
            rows: Vec::new(),
            profiles: Vec::new(),
            run: ShearRun::default(),
            acc: RunAverages::default(),
            window: WindowStats::default(),
            checks: Vec::new(),
            lead: LeadAverages::default(),
            lead_rows: Vec::new(),
            lead_sensitivity: Sensitivity::default(),
            tightenings: 0,
            phase_cost: 0.0,
        };
        Ok((world, state))
    };
    drive(ctx, ctl, &shear, fresh)
}

/// Stage "fit": the wall law over the slip of both walls of every run (`rows`, `d` the mean
/// diameter); the figure of the wall friction against the slip.
#[allow(clippy::too_many_arguments)]
fn fit_wall_law(
    c: &ShearCellConfig,
    rows: &[CellRow],
    d: f64,
    common: &Checks,
    provenance: &identify::law::Provenance,
    out: &mut OutputDir,
    s: &mut Summary,
    verdict: &mut RunVerdict,
    headline: &mut Vec<String>,
) -> Result<XyPlot> {
    let opts = FitOptions::default();
    let prov = || provenance.clone();
    let mut vs = Vec::new();
    let mut mus = Vec::new();
    for r in rows {
        for (v, m) in [(r.slip_bottom, r.mu_eff_bottom), (r.slip_top, r.mu_eff_top)] {
            if v.is_finite() && m.is_finite() {
                vs.push(v.abs());
                mus.push(m);
            }
        }
    }
    let ws = WallSlipSeries::new(vs.clone(), mus.clone(), d);
    let scale = (9.81 * d).sqrt();
    let mut pw = XyPlot::new(
        "Wall friction vs slip",
        Axis::new("slip velocity V_s / √(g d)"),
        Axis::new("μ_eff = τ_w / σ_w"),
    );
    pw.series.push(Series::new(
        "DEM (both walls)",
        Style::Points,
        PALETTE[3],
        vs.iter().zip(&mus).map(|(v, m)| (v / scale, *m)).collect(),
    ));
    let wall_left_out = c.leave_out.iter().any(|l| l == "wall-law");
    match (!wall_left_out).then(|| select_wall_law(&ws, &opts)) {
        // left out by the plan (said at the start)
        None => crate::verdict::remove_stale_law(out, "wall")?,
        Some(Ok(sel)) => {
            let best = sel.best();
            // over the measured slips only: the law is not drawn beyond its data
            let (vmin, vmax) = super::rheology_fit::finite_range(vs.iter().map(|v| v / scale))
                .unwrap_or((0.0, 0.0));
            let vx = super::rheology_fit::curve_abscissae(vmin, vmax, false);
            let p = best.report.values();
            let form = best.form;
            let band = delta_band(
                &p,
                &best.report.covariance,
                best.report.t_critical,
                &vx,
                |p, v| {
                    use identify::laws::wall_friction::WallFrictionLaw as W;
                    let law = match form {
                        identify::wall_law::WallLawForm::Exponential => W::Exponential {
                            mu_0: p[0],
                            mu_inf: p[1],
                            v_star: p[2],
                        },
                        identify::wall_law::WallLawForm::Hyperbolic => W::Hyperbolic {
                            mu_0: p[0],
                            mu_inf: p[1],
                            v_star: p[2],
                        },
                        identify::wall_law::WallLawForm::PowerLaw => W::PowerLaw {
                            mu_0: p[0],
                            k: p[1],
                            n: p[2],
                        },
                    };
                    law.mu_eff(v)
                },
            );
            add_fitted_curve(
                &mut pw,
                &format!("{} (best AIC)", form.law_name()),
                PALETTE[3],
                PALETTE[1],
                &band,
            );
            s.text("wall_law_form", form.law_name());
            fit_keys(s, "wall_law", &best.report.parameters);
            let law =
                CalibratedLaw::from_wall_law(best, d, 9.81, Some(sel.comparison.clone()), prov());
            let exported = export_law(out, verdict, "wall", &law, common.clone())?;
            headline.extend(exported.heading(&law.law));
            headline.extend(parameter_lines(
                &format!("wall law: {} chosen by AIC", form.law_name()),
                best.report.r_squared,
                &best.report.parameters,
            ));
        }
        Some(Err(e)) => {
            warn(&format!("wall-law fit failed: {e}"));
            s.text("wall_law_fit_error", &e.to_string());
            headline.push(format!("wall law not identified: {e}"));
            crate::verdict::remove_stale_law(out, "wall")?;
            verdict.run.fail(
                "shear_cell.wall_law_fit",
                Verdict::Refused,
                f64::NAN,
                f64::NAN,
                format!("no wall law could be fitted: {e}"),
            );
        }
    }
    pw.legend = LegendAt::LowerRight;
    Ok(pw)
}

/// Stage "report": `velocity_profiles.png` (each run's mean profile, normalised) and
/// `force_chains.png` (the last state, at the last inertial number of `is`).
fn profile_figures(
    out: &mut OutputDir,
    world: &dem::World,
    profiles: &[MeanProfile],
    is: &[f64],
) -> Result<()> {
    let mut pv = XyPlot::new(
        "Velocity profiles",
        Axis::new("velocity / wall velocity v_x / V"),
        Axis::new("height / gap y / H"),
    );
    for (k, mp) in profiles.iter().enumerate() {
        pv.series.push(Series::new(
            &format!("I = {:.3}", mp.i),
            Style::LinePoints,
            PALETTE[k % PALETTE.len()],
            mp.y.iter()
                .zip(&mp.velocity)
                .filter(|p| p.1.is_finite())
                .map(|(y, u)| (u / mp.v, y / mp.h))
                .collect(),
        ));
    }
    pv.legend = LegendAt::UpperLeft;
    crate::plot::xy::draw_xy(out, "velocity_profiles.png", &pv)?;
    let snap = world.snapshot();
    draw_particles(
        out,
        "force_chains.png",
        &ParticleView {
            snap: &snap,
            title: format!(
                "Shear cell at I = {:.3}: normal forces",
                is.last().copied().unwrap_or(0.0)
            ),
            fill: GrainFill::Plain,
            forces: true,
            axis_labels: ("x (m)".into(), "y (m)".into()),
            width_px: 700,
            overlays: Vec::new(),
        },
    )?;
    Ok(())
}

/// Runs the scenario: build and run (`simulate`), verdict (`judge_points`), report and
/// fits (μ(I), φ(I), `fit_wall_law`), figures (`profile_figures`).
pub fn run(c: &ShearCellConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let (
        world,
        ShearState {
            all,
            rows,
            profiles,
            checks: run_checks,
            lead_rows,
            ..
        },
    ) = simulate(c, ctx, ctl)?;
    // Checks (crate::verdict): per run, the numerics of its averaging window and the measured
    // I against its target (all laws); the steady state of μ (μ(I)) and of φ with its bound
    // (φ(I)).
    let (judged, mu_checks, phi_checks, mut verdict) = judge_runs(
        "shear_cell",
        &run_checks,
        c.grain.radius_spread,
        ctl.allow_suspect,
    );
    let (common, point_verdicts, windows) = (judged.common, judged.points, judged.windows);
    let d = mean_diameter(&world);
    VtkFrames::new(f64::INFINITY, 1).finish(&mut ctx.out, &world)?;
    let grain = GrainScale {
        diameter_m: d,
        density_kg_m3: c.grain.density,
    };
    write_rheology_table(
        &mut ctx.out,
        &rows,
        &point_verdicts,
        "steady plane shear: bulk averages per run (I, mu = |sigma_xy|/P, phi, P) and wall slip",
        grain,
    )?;
    if c.velocity_corrections > 0 {
        let mut lead = rows::table(&lead_rows);
        lead.comments.push("wall-velocity corrections: bulk I over the second half of each correcting lead stage, the factor applied to V after it (1 within the dead band), and V over the uniform-shear estimate after it".into());
        lead.write(&mut ctx.out, "lead_stages.csv")?;
    }

    // Fits.
    let series = RheologySeries {
        inertial_number: rows.iter().map(|r| r.i).collect(),
        mu: Some(rows.iter().map(|r| r.mu).collect()),
        phi: Some(rows.iter().map(|r| r.phi).collect()),
        pressure_pa: Some(rows.iter().map(|r| r.p).collect()),
        // the wall-bounded cell measures no standard error per point: unweighted fits
        mu_std_error: None,
        phi_std_error: None,
    };
    let provenance = ctl.law_provenance(ctx, "shear-cell", c.seed);
    let prov = || provenance.clone();
    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("pressure_Pa", c.pressure)
        .num("mean_diameter_m", d)
        .int("runs", rows.len() as u64)
        .num("I_min", rows.iter().map(|r| r.i).fold(f64::MAX, f64::min))
        .num("I_max", rows.iter().map(|r| r.i).fold(f64::MIN, f64::max));
    let mut headline = vec![format!("report: {}/", ctx.out.path().display())];
    let is: Vec<f64> = rows.iter().map(|r| r.i).collect();
    let (pmu, pphi) = super::rheology_fit::fit_mu_phi(
        &mut ctx.out,
        &series,
        &super::rheology_fit::RheologyFit {
            check_prefix: "shear_cell",
            title_suffix: "",
            dem_label: "DEM",
            grain,
            provenance: prov(),
            mu_checks: mu_checks.clone(),
            phi_checks: phi_checks.clone(),
            // the wall-bounded cell measures no standard error per point
            std_errors: Default::default(),
            point_verdicts: &point_verdicts,
            leave_out: &c.leave_out,
        },
        &mut verdict,
        &mut s,
        &mut headline,
    )?;
    let pw = fit_wall_law(
        c,
        &rows,
        d,
        &common,
        &provenance,
        &mut ctx.out,
        &mut s,
        &mut verdict,
        &mut headline,
    )?;
    draw_row(&mut ctx.out, "rheology.png", &[pmu, pphi, pw], (1950, 650))?;
    profile_figures(&mut ctx.out, &world, &profiles, &is)?;
    Ok(RunOutcome::windowed(s, &all, &windows, headline, verdict))
}

/// The bulk of the cell: the slice two diameters away from each wall.
fn bulk_region(w: &dem::World, r: f64, d: f64) -> Region {
    let top_y = w.bodies[TOP].position.y;
    let (lo, hi) = (r + 2.0 * d, top_y - r - 2.0 * d);
    Region::Slice {
        y_min: lo,
        y_max: hi.max(lo + d),
    }
}

/// Symmetric mean stress of the bulk (Pa, tension positive, inertia included).
fn bulk_stress(snap: &Snapshot, region: &Region) -> Result<Tensor> {
    let gs = homogenise::grain_stresses(snap)?;
    let st = homogenise::mean_stress(snap, &gs, region)?;
    Ok((st.total + st.total.transpose()) * 0.5)
}

/// The bulk shear rate `γ̇ = ∂v_x/∂y` (1/s, mass-weighted affine fit of the grain velocities)
/// and symmetric stress (Pa) of one state: what the wall-velocity correction measures
/// (`P = −σ_yy`).
fn bulk_shear(w: &dem::World, r: f64, d: f64) -> Result<(f64, Tensor)> {
    let snap = w.snapshot();
    let region = bulk_region(w, r, d);
    let sym = bulk_stress(&snap, &region)?;
    let g = velocity_gradient(&snap, &region, VelocityWeight::Mass)?.gradient[(0, 1)];
    Ok((g, sym))
}

/// The bulk `[σ_xy, σ_yy]` (Pa) of the world with its last step's contact problem solved to
/// [`crate::verdict::SENSITIVITY_TOLERANCE`] (the solver-sensitivity measure,
/// [`crate::verdict::Sensitivity`]), or why there is none.
fn resolved_stress(w: &dem::World, r: f64, d: f64) -> Resolved<([f64; 2], bool)> {
    super::sensitivity::resolved_pair(w, |snap| {
        let sym = bulk_stress(snap, &bulk_region(w, r, d)).ok()?;
        Some([sym[(0, 1)], sym[(1, 1)]])
    })
}

/// Adds one sample of the bulk and wall quantities to `acc`; returns its bulk
/// `(σ_xy, σ_yy)` (Pa).
fn sample(w: &dem::World, acc: &mut RunAverages, r: f64, d: f64) -> Result<(f64, f64)> {
    let snap = w.snapshot();
    let top_y = w.bodies[TOP].position.y;
    let region = bulk_region(w, r, d);
    let sym = bulk_stress(&snap, &region)?;
    acc.sxy += sym[(0, 1)];
    acc.syy += sym[(1, 1)];
    let phi = solid_fraction(&snap, &region)?;
    acc.phi += phi;
    acc.phi_samples.push(phi);
    acc.mu_samples.push(sym[(0, 1)].abs() / -sym[(1, 1)]);
    acc.gamma_dot += velocity_gradient(&snap, &region, VelocityWeight::Mass)?.gradient[(0, 1)];
    for (j, wall) in ["bottom", "top"].iter().enumerate() {
        let h = top_y - 2.0 * r;
        let spec = NearWallSpec {
            wall: wall.to_string(),
            flow_direction: Vector::new(1.0, 0.0),
            normal: Some(Vector::new(0.0, if j == 0 { 1.0 } else { -1.0 })),
            bin_width: 0.5 * d,
            bins: ((h / (0.5 * d)).ceil() as usize).max(1),
            first_layer: d,
        };
        let p = near_wall_profile(&snap, &spec)?;
        if let Some(v) = p.slip_velocity {
            acc.walls[j].0 += v.abs();
            acc.walls[j].1 += p.tangential_force;
            acc.walls[j].2 += p.normal_force;
            acc.walls[j].3 += 1;
        }
        if j == 0 {
            if acc.profile.is_empty() {
                acc.profile = p.distance.iter().map(|&y| (y, 0.0, 0.0)).collect();
            }
            for (k, v) in p.velocity.iter().enumerate() {
                if let (Some(v), Some(e)) = (v, acc.profile.get_mut(k)) {
                    e.1 += v;
                    e.2 += 1.0;
                }
            }
        }
    }
    acc.samples += 1;
    Ok((sym[(0, 1)], sym[(1, 1)]))
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for ShearCellConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "shear-cell"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        ShearCellConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        shear_cell(self).map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bulk sums giving `I = i` for `d = 1`, `ρ = 1`, `P = 4` over `n` samples.
    fn lead_at(i: f64, n: u64) -> LeadAverages {
        LeadAverages {
            gamma_dot: -(i * 2.0) * n as f64,
            pressure: 4.0 * n as f64,
            samples: n,
        }
    }

    /// The control law: half the miss in log scale beyond the dead band, bounded, none within
    /// it or without a measurement (exact to rounding).
    #[test]
    fn velocity_correction_law() {
        let (i, f) = velocity_correction(0.02, &lead_at(0.008, 10), 1.0, 1.0);
        assert!((i - 0.008).abs() < 1e-15);
        assert!((f - 2.5f64.sqrt()).abs() < 1e-12, "{f}");
        // Within the dead band: 0.02 / 0.015 = 1.33 < 1.5.
        assert_eq!(
            velocity_correction(0.02, &lead_at(0.015, 10), 1.0, 1.0).1,
            1.0
        );
        assert_eq!(
            velocity_correction(0.02, &lead_at(0.027, 10), 1.0, 1.0).1,
            1.0
        );
        // Too fast: 0.02 / 0.05 = 0.4 → √0.4.
        let f = velocity_correction(0.02, &lead_at(0.05, 3), 1.0, 1.0).1;
        assert!((f - 0.4f64.sqrt()).abs() < 1e-12, "{f}");
        // Bounded: a bulk 100 times too slow or too fast.
        assert_eq!(
            velocity_correction(0.02, &lead_at(0.0002, 3), 1.0, 1.0).1,
            2.0
        );
        assert_eq!(velocity_correction(0.02, &lead_at(2.0, 3), 1.0, 1.0).1, 0.5);
        // No sample, a bulk at rest: V unchanged (a jammed bulk says nothing of the V needed).
        let (i, f) = velocity_correction(0.02, &LeadAverages::default(), 1.0, 1.0);
        assert!(i.is_nan() && f == 1.0);
        assert_eq!(velocity_correction(0.02, &lead_at(0.0, 3), 1.0, 1.0).1, 1.0);
    }

    /// `n` lead samples at P = 100 Pa, μ = 0.3, whose pressure moves by `mean ± spread` (Pa,
    /// alternately) when re-solved, σ_xy unchanged (μ moves with P) or, with `keep_mu`, moving
    /// in proportion (μ unchanged).
    fn lead_samples(n: usize, mean: f64, spread: f64, keep_mu: bool) -> Sensitivity {
        let mut s = Sensitivity::default();
        for i in 0..n {
            let d = mean + if i % 2 == 0 { spread } else { -spread };
            let xy = if keep_mu {
                -30.0 * (1.0 + d / 100.0)
            } else {
                -30.0
            };
            s.add([-30.0, -100.0], Some([xy, -100.0 - d]));
        }
        s
    }

    fn lead_sensitivity(n: usize, mean: f64, spread: f64) -> Sensitivity {
        lead_samples(n, mean, spread, false)
    }

    /// The tightening rule: the measured change plus two standard errors against the suspect
    /// limits, on at least four samples, where the stage's solves take at most a fifth of the
    /// cap.
    #[test]
    fn the_tolerance_is_tightened_where_the_samples_could_move_and_sweeps_are_cheap() {
        let cheap = (100.0, 5000);
        let t = |s: &Sensitivity, (sweeps, cap): (f64, usize)| needs_tightening(s, sweeps, cap);
        // P moves by 3 % on every sample: beyond 2.5 %.
        assert!(t(&lead_sensitivity(20, 3.0, 0.0), cheap));
        // ... but not where the stage's solves took 2300 sweeps a step against 5000.
        assert!(!t(&lead_sensitivity(20, 3.0, 0.0), (2300.0, 5000)));
        // 1.3 % on average within ±0.3 %: bound 1.3 + 2·0.3·√(20/19)/√20 = 1.44 %, kept.
        assert!(!t(&lead_sensitivity(20, 1.3, 0.3), cheap));
        // 1.3 % on average within ±10 % a sample: the bound, 5.9 %, could be suspect.
        assert!(t(&lead_sensitivity(20, 1.3, 10.0), cheap));
        // Too few samples to decide.
        assert!(!t(&lead_sensitivity(3, 30.0, 0.0), cheap));
        // μ unchanged: the pressure alone decides, 3 % beyond its limit, 2 % within it.
        assert!(t(&lead_samples(20, 3.0, 0.0, true), cheap));
        assert!(!t(&lead_samples(20, 2.0, 0.0, true), cheap));
        // μ = 0.3 moving by 0.006 at P unchanged (σ_xy by 0.6 Pa): beyond 0.005.
        let mut s = Sensitivity::default();
        for _ in 0..20 {
            s.add([-30.0, -100.0], Some([-30.6, -100.0]));
        }
        assert!(t(&s, cheap));
    }
}
