//! The `simple-shear` scenario: a representative volume without walls or gravity, a
//! biperiodic deformable cell (`dem::cell`, Lees–Edwards 1972 / Parrinello–Rahman 1981). A
//! loose polydisperse packing is compressed isotropically under stress control
//! (σ_xx = σ_yy = −P), then sheared at the imposed rate `γ̇ = I √(P/ρ)/d` of each target
//! inertial number (lowest first, each from the previous state) with σ_yy = −P imposed and
//! L_xx = 0 (`docs/physics.md` §6).
//!
//! Per run, the whole-cell state (`homogenise::cell`) is recorded every step into
//! `history_I{k}.csv`; over the last `average_strain`, the means and block-averaged standard
//! errors of μ = |Σ_xy|/(−Σ_yy), φ, p_n = −Σ_yy give the run's point
//! `I = γ̇ d / √(p_n/ρ)`. μ(I) and φ(I) are fitted by `identify::mu_i` (which refuses what the
//! data cannot support).

pub mod build;
pub mod config;

use dem::cell::{CellControl, Imposed};
use dem::math::Tensor as Mat;
use homogenise::averaging::block_average;
use homogenise::cell::cell_state;
use identify::law::GrainScale;
use identify::mu_i::RheologySeries;

use serde::{Deserialize, Serialize};

use super::cell_base::{cell_history_row, CellRecord, ControlPlan, GAIN_FRACTION, MIN_BLOCKS};
use super::common::laws::LawNeed;
use super::common::{mean_diameter, strain_bins, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::rows::{self, table_row};
use super::shear_cell::{judge_runs, RunCheckData};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::Summary;
use crate::plot::xy::{draw_row, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use config::SimpleShearConfig;

/// Whether window step `j` (0-based) of a window of `len` steps is re-solved: `samples`
/// (`sensitivity_samples`, 20 by default) spread evenly over the window, the last step of each
/// stride (every step of a shorter window). Each such step is solved again to
/// [`crate::verdict::SENSITIVITY_TOLERANCE`] with the cell's stress-controlled component
/// (`dem::World::last_step_problem`) and the cell's stress taken both ways: the window's solver
/// sensitivity of μ = |Σσ_xy| / (−Σσ_yy) and of σ_yy ([`crate::verdict::Sensitivity`]), judged
/// against a quarter of their statistical errors ([`crate::verdict::SENSITIVITY_SE_FRACTION`]).
/// A fixed number, not a fraction of the steps: a re-solve of a dense step costs hundreds of the
/// run's own loose solves.
fn resolves(j: u64, len: u64, samples: u64) -> bool {
    let every = (len / samples.max(1)).max(1);
    j % every == every - 1
}

cell_history_row! {
    /// One step of a shear run: a row of `history_I{k}.csv`.
    struct HistoryRow {
        head {
            /// Time (s).
            t: "t_s",
            /// Shear strain γ of the run.
            shear_strain: "shear_strain",
        }
        tail {
            /// Solid fraction.
            phi: "phi",
            /// Coordination.
            z: "Z",
            /// Fabric F_xx.
            fabric_xx: "fabric_xx",
            /// Fabric F_yy.
            fabric_yy: "fabric_yy",
            /// Fabric F_xy.
            fabric_xy: "fabric_xy",
            /// `γ̇ d / √(−Σ_yy/ρ)` (NaN without normal stress).
            inertial: "I",
            /// `|Σ_xy|/(−Σ_yy)`.
            mu: "mu",
            /// Re-solves of the step by the cell control.
            cell_corrections: "cell_corrections",
        }
    }
}

/// The samples of a biperiodic cell's state over an averaging window, one per step (this
/// scenario) or per snapshot (another code's run, `grainlaw homogenise`): `−Σ_yy` and
/// μ = |Σ_xy|/(−Σ_yy) of the symmetric mean stress, solid fraction φ, mean pressure `−tr Σ/2`,
/// coordination Z.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct CellSamples {
    pub(crate) normal_stress: Vec<f64>,
    pub(crate) mu: Vec<f64>,
    pub(crate) phi: Vec<f64>,
    pub(crate) pressure: Vec<f64>,
    pub(crate) coordination: Vec<f64>,
}

impl CellSamples {
    /// Adds the state of one step or snapshot.
    pub(crate) fn push(&mut self, cs: &homogenise::cell::CellState) {
        let s = cs.stress;
        let pn = -s[(1, 1)];
        self.normal_stress.push(pn);
        self.mu.push(if pn > 0.0 {
            s[(0, 1)].abs() / pn
        } else {
            f64::NAN
        });
        self.phi.push(cs.solid_fraction);
        self.pressure.push(cs.pressure);
        self.coordination.push(cs.coordination);
    }
}

/// One point of μ(I), φ(I): means over the window with their block-averaged standard errors
/// ([`block_average`], at least [`MIN_BLOCKS`] blocks; NaN with fewer than `2 · MIN_BLOCKS`
/// samples), `P = ⟨−Σ_yy⟩` and `I = |γ̇| d / √(P/ρ)` with `SE_I = I SE_P / (2P)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RheologyPoint {
    pub(crate) i: f64,
    pub(crate) i_se: f64,
    pub(crate) mu: f64,
    pub(crate) mu_se: f64,
    pub(crate) phi: f64,
    pub(crate) phi_se: f64,
    pub(crate) pn: f64,
    pub(crate) pn_se: f64,
    pub(crate) p: f64,
    pub(crate) z: f64,
}

impl RheologyPoint {
    /// The point of the samples at the shear rate `gamma_dot` (1/s), mean diameter `d` (m) and
    /// grain density `rho` (kg/m³). Errors: a non-finite sample (a tensile `Σ_yy` makes μ NaN).
    pub(crate) fn of(s: &CellSamples, gamma_dot: f64, d: f64, rho: f64) -> Result<Self> {
        let avg = |v: &[f64]| -> Result<(f64, f64)> {
            if v.len() < 2 * MIN_BLOCKS {
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(homogenise::HomogeniseError::InvalidParameter {
                        name: "series",
                        reason: format!("sample {i} is not finite"),
                    }
                    .into());
                }
                return Ok((v.iter().sum::<f64>() / v.len().max(1) as f64, f64::NAN));
            }
            let a = block_average(v, MIN_BLOCKS)?;
            Ok((a.mean, a.std_error))
        };
        let (pn, pn_se) = avg(&s.normal_stress)?;
        let (mu, mu_se) = avg(&s.mu)?;
        let (phi, phi_se) = avg(&s.phi)?;
        let (p, _) = avg(&s.pressure)?;
        let (z, _) = avg(&s.coordination)?;
        let i = gamma_dot.abs() * d / (pn / rho).sqrt();
        Ok(RheologyPoint {
            i,
            i_se: 0.5 * i * pn_se / pn,
            mu,
            mu_se,
            phi,
            phi_se,
            pn,
            pn_se,
            p,
            z,
        })
    }

    /// [`RheologyPoint::of`] for grainlaw's own run: a window with a sample that is not
    /// finite gives a point of NaN means and errors (its verdict refuses it:
    /// `simple_shear.finite_samples`), not an error of the run.
    pub(crate) fn of_run(s: &CellSamples, gamma_dot: f64, d: f64, rho: f64) -> Result<Self> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if [
            &s.normal_stress,
            &s.mu,
            &s.phi,
            &s.pressure,
            &s.coordination,
        ]
        .iter()
        .all(|v| finite(v))
        {
            return Self::of(s, gamma_dot, d, rho);
        }
        Ok(RheologyPoint {
            i: f64::NAN,
            i_se: f64::NAN,
            mu: f64::NAN,
            mu_se: f64::NAN,
            phi: f64::NAN,
            phi_se: f64::NAN,
            pn: f64::NAN,
            pn_se: f64::NAN,
            p: f64::NAN,
            z: f64::NAN,
        })
    }

    /// The row of `rheology.csv` (without its `point_verdict`).
    pub(crate) fn row(
        &self,
        i_target: f64,
        gamma_dot: f64,
        dt: f64,
        samples: usize,
        corrections_per_step: f64,
    ) -> RheologyRow {
        RheologyRow {
            i_target,
            i: self.i,
            i_se: self.i_se,
            mu: self.mu,
            mu_se: self.mu_se,
            phi: self.phi,
            phi_se: self.phi_se,
            pn: self.pn,
            pn_se: self.pn_se,
            p: self.p,
            z: self.z,
            shear_rate: gamma_dot,
            dt,
            samples: samples as f64,
            corrections_per_step,
        }
    }
}

table_row! {
    /// A point of the `rheology.csv` of a biperiodic cell (`RheologyPoint::row`; the table
    /// adds the point's verdict, `shear_cell::write_rheology_table`).
    pub struct RheologyRow {
        /// Target inertial number (NaN: none).
        i_target: "I_target",
        /// Measured I.
        i: "I",
        /// Its standard error.
        i_se: "I_std_error",
        /// μ = |Σ_xy|/P.
        mu: "mu",
        /// Its block standard error.
        mu_se: "mu_std_error",
        /// Solid fraction.
        phi: "phi",
        /// Its block standard error.
        phi_se: "phi_std_error",
        /// `P = ⟨−Σ_yy⟩` (Pa).
        pn: "P_Pa",
        /// Its block standard error (Pa).
        pn_se: "P_std_error_Pa",
        /// Mean pressure `−tr Σ/2` (Pa).
        p: "p_mean_Pa",
        /// Coordination.
        z: "Z",
        /// Shear rate γ̇ (1/s).
        shear_rate: "shear_rate_1_s",
        /// Time step (s).
        dt: "dt_s",
        /// Samples of the window.
        samples: "samples",
        /// Mean re-solves per step by the cell control (NaN: not known).
        corrections_per_step: "cell_corrections_per_step",
    }
}

/// The plan of the current shear run.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
struct RunPlan {
    gamma_dot: f64,
    dt: f64,
    steps: u64,
    avg_steps: u64,
    n: u64,
}

/// What the phases collect.
#[derive(Serialize, Deserialize)]
struct State {
    /// Solver statistics, one row per run (`rheology.csv`), the current run's history, the
    /// frames, the numerics of the current run's averaging window.
    #[serde(flatten)]
    cell: CellRecord<HistoryRow, RheologyRow>,
    /// Strain histories of μ of the finished runs, for the figure: (I, [(γ, μ)]).
    curves: Vec<(f64, Vec<(f64, f64)>)>,
    run: RunPlan,
    /// The checks of the finished runs (crate::verdict).
    #[serde(default)]
    checks: Vec<RunCheckData>,
    /// Peak of the stress ratio of each finished run ([`peak_mu`]).
    #[serde(default, with = "crate::floats::vec")]
    peaks: Vec<f64>,
}

/// Width of the shear-strain bins of the peak stress ratio of a run.
const PEAK_BIN_STRAIN: f64 = 0.1;

/// The peak stress ratio of a run's history: the largest mean of μ over bins of
/// [`PEAK_BIN_STRAIN`] of shear strain ([`strain_bins`]; NaN without data).
fn peak_mu(history: &[HistoryRow]) -> f64 {
    strain_bins(
        history,
        |r| r.shear_strain,
        PEAK_BIN_STRAIN,
        [|r: &HistoryRow| r.mu],
        |r| r.mu.is_finite() && r.shear_strain.is_finite(),
    )
    .iter()
    .map(|[mu]| *mu)
    .fold(f64::NAN, f64::max)
}

struct Shear<'a> {
    c: &'a SimpleShearConfig,
    targets: Vec<f64>,
}

impl Shear<'_> {
    /// The control of the cell for time step `dt`, shear rate `gamma_dot` (None: the
    /// isotropic compression), with the diameter `d`.
    fn control(&self, dt: f64, d: f64, gamma_dot: Option<f64>) -> CellControl {
        let c = self.c;
        let (p, rho) = (c.pressure, c.grain.density);
        let rate_cap = c.control_inertial_number * (p / rho).sqrt() / d;
        let (xx, xy, max_rate) = match gamma_dot {
            None => (Imposed::Stress(-p), Imposed::Rate(0.0), rate_cap),
            // A sheared packing dilates at up to about γ̇: the cap must allow it.
            Some(g) => (Imposed::Rate(0.0), Imposed::Rate(g), rate_cap.max(g)),
        };
        ControlPlan {
            mode: c.cell_control,
            xx,
            yy: Imposed::Stress(-p),
            xy,
            max_rate,
            pressure: p,
            compressing: gamma_dot.is_none(),
            gain_fraction: GAIN_FRACTION,
            filter_steps: 0.0,
            affine: c.cell_affine,
        }
        .control(dt, rho, d)
    }
}

impl PhasedRun for Shear<'_> {
    type State = State;

    fn phase_count(&self) -> usize {
        1 + self.targets.len()
    }

    fn enter(&self, st: &mut State, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, world) = (at.k, at.world);
        let c = self.c;
        let d = mean_diameter(world);
        if k == 0 {
            let dt = c.compression_dt(d);
            world.params.dt = dt;
            world.cell_control = Some(self.control(dt, d, None));
            world.validate(1e-9)?;
            return Ok(Some(PhasePlan::new(
                "compress",
                Stop::Steps(c.compression_steps(d)),
            )));
        }
        let i = self.targets[k - 1];
        let gamma_dot = i * (c.pressure / c.grain.density).sqrt() / d;
        let dt = c.shear_dt(gamma_dot, d);
        let steps = config::whole_steps(c.strain / (gamma_dot * dt));
        let avg_steps = config::whole_steps(c.average_strain / (gamma_dot * dt)).min(steps);
        world.params.dt = dt;
        let l = world.cell().map_or_else(Mat::zeros, |cell| cell.l);
        world.set_velocity_gradient(Mat::new(0.0, gamma_dot, 0.0, l[(1, 1)]));
        world.cell_control = Some(self.control(dt, d, Some(gamma_dot)));
        st.run = RunPlan {
            gamma_dot,
            dt,
            steps,
            avg_steps,
            n: 0,
        };
        st.cell.history.clear();
        st.cell.window.reset();
        Ok(Some(PhasePlan::new(format!("I={i}"), Stop::Steps(steps))))
    }

    fn step(&self, st: &mut State, at: Step<'_>) -> Result<()> {
        let (k, out, w, r, p) = (at.k, at.out, at.world, at.report, at.progress);
        st.cell.frames.maybe(out, w)?;
        if k == 0 {
            return Ok(());
        }
        st.run.n += 1;
        let averaged = st.run.n + st.run.avg_steps > st.run.steps;
        st.cell.window.step(averaged, w, r, &p.stats);
        let snap = w.snapshot();
        let cs = cell_state(&snap)?;
        let s = cs.stress;
        if averaged
            && resolves(
                st.run.n + st.run.avg_steps - st.run.steps - 1,
                st.run.avg_steps,
                self.c.sensitivity_samples,
            )
        {
            st.cell.resolve_sample(w, [s[(0, 1)], s[(1, 1)]], |snap| {
                let s = cell_state(snap).ok()?.stress;
                Some([s[(0, 1)], s[(1, 1)]])
            });
        }
        let d = mean_diameter(w);
        let pn = -s[(1, 1)];
        let i = if pn > 0.0 {
            st.run.gamma_dot * d / (pn / self.c.grain.density).sqrt()
        } else {
            f64::NAN
        };
        let mu = if pn > 0.0 {
            s[(0, 1)].abs() / pn
        } else {
            f64::NAN
        };
        st.cell.history.push(HistoryRow {
            t: w.time,
            shear_strain: st.run.gamma_dot * st.run.dt * st.run.n as f64,
            phi: cs.solid_fraction,
            z: cs.coordination,
            fabric_xx: cs.fabric[(0, 0)],
            fabric_yy: cs.fabric[(1, 1)],
            fabric_xy: cs.fabric[(0, 1)],
            inertial: i,
            mu,
            cell_corrections: r.cell_corrections as f64,
            ..HistoryRow::of_cell(&cs)
        });
        Ok(())
    }

    fn settle(&self, st: &mut State) {
        st.cell.settle();
    }

    fn leave(&self, st: &mut State, at: Leave<'_>) -> Result<()> {
        let (k, out, world, stats) = (at.k, at.out, at.world, at.stats);
        st.cell.all.merge(stats);
        if k == 0 {
            return Ok(());
        }
        let target = self.targets[k - 1];
        let mut table = rows::table(&st.cell.history);
        table.comments.push(format!(
            "simple shear at target I {target}: whole-cell mean stress (tension positive, kinetic stress of the fluctuations included), strain rate D of the cell (1/s), p is -tr(sigma)/2, q, solid fraction, coordination Z and fabric over force-carrying contacts, I is gamma_dot d / sqrt(-sigma_yy/rho), mu is |sigma_xy|/(-sigma_yy), cell_corrections counts the re-solves of the step by the cell control"
        ));
        table.write(out, &format!("history_I{k}.csv"))?;
        let tail = &st.cell.history
            [st.cell.history.len() - (st.run.avg_steps as usize).min(st.cell.history.len())..];
        let col = |f: fn(&HistoryRow) -> f64| -> Vec<f64> { tail.iter().map(f).collect() };
        let samples = CellSamples {
            normal_stress: col(|r| r.syy).iter().map(|s| -s).collect(),
            mu: col(|r| r.mu),
            phi: col(|r| r.phi),
            pressure: col(|r| r.p),
            coordination: col(|r| r.z),
        };
        let d = mean_diameter(world);
        let gd = st.run.gamma_dot;
        let point = RheologyPoint::of_run(&samples, gd, d, self.c.grain.density)?;
        let corrections: f64 = col(|r| r.cell_corrections).iter().sum();
        // what the solver's measured effect is judged against (0: not known)
        let known = |x: f64| if x.is_finite() { x } else { 0.0 };
        st.cell.window.statistical_errors = [known(point.mu_se), known(point.pn_se / point.pn)];
        st.checks.push(RunCheckData {
            i_target: target,
            i_measured: point.i,
            window: st.cell.window,
            mu: samples.mu,
            phi: samples.phi,
        });
        st.cell.rows.push(point.row(
            target,
            gd,
            st.run.dt,
            tail.len(),
            corrections / tail.len().max(1) as f64,
        ));
        st.peaks.push(peak_mu(&st.cell.history));
        st.curves.push((
            point.i,
            st.cell
                .history
                .iter()
                .step_by((st.cell.history.len() / 200).max(1))
                .map(|r| (r.shear_strain, r.mu))
                .collect(),
        ));
        Ok(())
    }
}

/// Stages "build" and "run": the cell compressed, then sheared at each target inertial number
/// (or resumed from a checkpoint).
fn simulate(
    c: &SimpleShearConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<(dem::World, State)> {
    let mut targets = c.inertial_numbers.clone();
    targets.sort_by(f64::total_cmp);
    let shear = Shear { c, targets };
    let fresh = || -> Result<(dem::World, State)> {
        let world = build::simple_shear(c)?;
        let t_total = c.compression_duration * c.grain_time()
            + shear
                .targets
                .iter()
                .map(|i| {
                    c.strain * c.grain.radius_mean * 2.0
                        / (i * (c.pressure / c.grain.density).sqrt())
                })
                .sum::<f64>();
        Ok((
            world,
            State {
                cell: CellRecord::new(VtkFrames::new(t_total / 40.0, 41)),
                curves: Vec::new(),
                run: RunPlan::default(),
                checks: Vec::new(),
                peaks: Vec::new(),
            },
        ))
    };
    drive(ctx, ctl, &shear, fresh)
}

/// Stage "report": the summary keys of the run and of each point (`rows`, with the peak
/// stress ratio of each run in `peaks`), `d` the mean diameter (m).
fn run_summary(c: &SimpleShearConfig, d: f64, rows: &[RheologyRow], peaks: &[f64]) -> Summary {
    let is: Vec<f64> = rows.iter().map(|r| r.i).collect();
    let mut s = Summary::new();
    let imin = is.iter().cloned().fold(f64::MAX, f64::min);
    let imax = is.iter().cloned().fold(f64::MIN, f64::max);
    s.int("grains", c.grains as u64)
        .text("cell_control", c.cell_control.as_str())
        .num("pressure_Pa", c.pressure)
        .num("mean_diameter_m", d)
        .int("runs", rows.len() as u64)
        .num("I_min", imin)
        .num("I_max", imax)
        .num(
            "cell_corrections_per_step",
            rows.iter().map(|r| r.corrections_per_step).sum::<f64>() / rows.len().max(1) as f64,
        );
    for (k, r) in rows.iter().enumerate() {
        s.num(&format!("run{}_I", k + 1), r.i)
            .num(&format!("run{}_mu", k + 1), r.mu)
            .num(&format!("run{}_mu_std_error", k + 1), r.mu_se)
            .num(&format!("run{}_phi", k + 1), r.phi)
            .num(&format!("run{}_phi_std_error", k + 1), r.phi_se)
            .num(&format!("run{}_P_Pa", k + 1), r.pn)
            // the steady state of the run: its critical state at that I
            .num(&format!("run{}_friction_critical_mu", k + 1), r.mu)
            .num(&format!("run{}_solid_fraction_critical", k + 1), r.phi);
        if let Some(&peak) = peaks.get(k) {
            s.num(&format!("run{}_friction_peak_mu", k + 1), peak);
        }
    }
    // The first run starts from the isotropically compressed sample: its transient peak is the
    // sample's peak friction (the later runs start from the previous steady state).
    if let Some(&peak) = peaks.first() {
        s.num("friction_peak_mu", peak);
    }
    s
}

/// Runs the scenario: build and run (`simulate`), verdict (`judge_points`), report
/// (`rheology.csv`, `run_summary`), fits (μ(I), φ(I)), figures.
pub fn run(
    c: &SimpleShearConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<RunOutcome> {
    let (world, state) = simulate(c, ctx, ctl)?;
    let State {
        cell: CellRecord {
            all, rows, frames, ..
        },
        curves,
        checks: run_checks,
        peaks,
        ..
    } = state;
    // Checks (crate::verdict), as in the shear cell: per point, the numerics of its averaging
    // window, I against its target, steady μ and φ, φ below its bound.
    let (judged, mu_checks, phi_checks, mut verdict) = judge_runs(
        "simple_shear",
        &run_checks,
        c.grain.radius_spread,
        ctl.allow_suspect,
    );
    let (point_verdicts, windows) = (judged.points, judged.windows);
    frames.finish(&mut ctx.out, &world)?;
    let d = mean_diameter(&world);
    let grain = GrainScale {
        diameter_m: d,
        density_kg_m3: c.grain.density,
    };
    super::shear_cell::write_rheology_table(
        &mut ctx.out,
        &rows,
        &point_verdicts,
        "Lees-Edwards simple shear at imposed normal stress: means over the last average_strain with block-averaged standard errors; P is -sigma_yy, I is gamma_dot d / sqrt(P/rho), mu is |sigma_xy|/P",
        grain,
    )?;

    // The points the laws are fitted to: those with a mean (a window with a sample that is
    // not finite has none, and is refused by its own checks: simple_shear.finite_samples).
    let kept: Vec<usize> = (0..rows.len())
        .filter(|&k| {
            [rows[k].i, rows[k].mu, rows[k].phi]
                .iter()
                .all(|x| x.is_finite())
        })
        .collect();
    let fit_verdicts: Vec<_> = kept.iter().map(|&k| point_verdicts[k]).collect();
    let fit =
        |f: fn(&RheologyRow) -> f64| -> Vec<f64> { kept.iter().map(|&k| f(&rows[k])).collect() };
    let series = RheologySeries {
        inertial_number: fit(|r| r.i),
        mu: Some(fit(|r| r.mu)),
        phi: Some(fit(|r| r.phi)),
        pressure_pa: Some(fit(|r| r.pn)),
        // each point weighted by its block-averaged standard error (unweighted when one is
        // not a positive number, e.g. a window too short for its blocks)
        mu_std_error: weights_if_usable(fit(|r| r.mu_se)),
        phi_std_error: weights_if_usable(fit(|r| r.phi_se)),
    };
    let provenance = ctl.law_provenance(ctx, "simple-shear", c.seed);
    let prov = || provenance.clone();
    let mut s = run_summary(c, d, &rows, &peaks);
    let mut headline = vec![format!("report: {}/", ctx.out.path().display())];
    let (pmu, pphi) = super::rheology_fit::fit_mu_phi(
        &mut ctx.out,
        &series,
        &super::rheology_fit::RheologyFit {
            check_prefix: "simple_shear",
            title_suffix: ", biperiodic cell",
            dem_label: "DEM (Lees–Edwards)",
            grain,
            provenance: prov(),
            mu_checks: mu_checks.clone(),
            phi_checks: phi_checks.clone(),
            std_errors: super::rheology_fit::PointStdErrors {
                i: Some(fit(|r| r.i_se)),
                mu: Some(fit(|r| r.mu_se)),
                phi: Some(fit(|r| r.phi_se)),
            },
            point_verdicts: &fit_verdicts,
            leave_out: &c.leave_out,
        },
        &mut verdict,
        &mut s,
        &mut headline,
    )?;
    let mut ph = XyPlot::new(
        "Stress ratio during each run",
        Axis::new("shear strain γ"),
        Axis::new("μ = |σ_xy| / (−σ_yy)"),
    );
    for (k, (i, pts)) in curves.iter().enumerate() {
        ph.series.push(Series::new(
            &format!("I = {i:.3}"),
            Style::Line,
            PALETTE[k % PALETTE.len()],
            pts.iter().filter(|p| p.1.is_finite()).cloned().collect(),
        ));
    }
    ph.legend = LegendAt::UpperRight;
    draw_row(&mut ctx.out, "rheology.png", &[pmu, pphi, ph], (1950, 650))?;
    Ok(RunOutcome::windowed(s, &all, &windows, headline, verdict))
}

/// Standard errors usable as fit weights: all finite and positive, or `None` (unweighted).
fn weights_if_usable(se: Vec<f64>) -> Option<Vec<f64>> {
    se.iter().all(|s| s.is_finite() && *s > 0.0).then_some(se)
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for SimpleShearConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "simple-shear"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        SimpleShearConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    /// `plan: about N time steps (compression …; I = …: …), bound max_steps = …`.
    fn plan_note(&self) -> Option<String> {
        let (compression, runs) = self.planned_steps();
        let total = compression + runs.iter().sum::<u64>();
        Some(format!(
            "plan: about {total} time steps (compression {compression}; {}), bound max_steps = {}",
            self.inertial_numbers
                .iter()
                .zip(&runs)
                .map(|(i, n)| format!("I = {i}: {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            self.max_steps
        ))
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        build::simple_shear(self).map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenarios::shear_cell::judge_points;
    use crate::verdict::{Verdict, WindowStats};

    /// A history whose μ is 0.6 over the first bin of shear strain, 0.8 over the second and
    /// 0.4 after (steps every 0.01 of strain), with a non-finite row: the peak is the second
    /// bin's mean, 0.8 (to rounding), not the largest step value 1.0 of a spike in the third bin.
    #[test]
    fn peak_is_the_largest_bin_mean() {
        let mut h = Vec::new();
        for n in 0..40 {
            let g = 0.005 + 0.01 * n as f64;
            let mu = match n {
                0..=9 => 0.6,
                10..=19 => 0.8,
                25 => 1.0,
                _ => 0.4,
            };
            h.push(HistoryRow {
                shear_strain: g,
                mu,
                ..Default::default()
            });
        }
        h.push(HistoryRow {
            shear_strain: 0.5,
            mu: f64::NAN,
            ..Default::default()
        });
        let p = peak_mu(&h);
        assert!((p - 0.8).abs() < 1e-12, "{p}");
        assert!(peak_mu(&[]).is_nan());
    }

    /// A window with a sample that is not finite (μ of a step whose σ_yy went tensile) is a
    /// refused point of NaN means, not an error of the run (before: "homogenise: invalid
    /// parameter `series`: sample N is not finite", exit 2); the same window read from another
    /// code (`RheologyPoint::of`) is still an input error.
    #[test]
    fn a_window_with_a_sample_that_is_not_finite_is_a_refused_point() {
        let n = 40;
        let mut samples = CellSamples {
            normal_stress: vec![1000.0; n],
            mu: (0..n).map(|k| 0.3 + 0.001 * (k % 3) as f64).collect(),
            phi: vec![0.8; n],
            pressure: vec![1000.0; n],
            coordination: vec![3.5; n],
        };
        let good = RheologyPoint::of_run(&samples, 2.0, 3e-3, 2500.0).unwrap();
        assert!((good.mu - 0.301).abs() < 1e-3, "{}", good.mu);
        samples.mu[15] = f64::NAN;
        assert!(RheologyPoint::of(&samples, 2.0, 3e-3, 2500.0).is_err());
        let bad = RheologyPoint::of_run(&samples, 2.0, 3e-3, 2500.0).unwrap();
        assert!(bad.mu.is_nan() && bad.i.is_nan());
        let check = |mu: Vec<f64>| RunCheckData {
            i_target: 0.01,
            i_measured: 0.01,
            window: WindowStats::default(),
            mu,
            phi: samples.phi.clone(),
        };
        let fine = judge_points("simple_shear", &[check(good_mu(n))], 0.9);
        assert_eq!(fine.points, vec![Verdict::Ok]);
        let j = judge_points("simple_shear", &[check(samples.mu.clone())], 0.9);
        assert_eq!(j.points, vec![Verdict::Refused]);
        let r = j
            .common
            .reasons
            .iter()
            .find(|r| r.check == "simple_shear.finite_samples")
            .expect("the finite-samples reason");
        assert_eq!(r.value, 1.0);
        assert!(
            r.message.contains("1 of the averaging window's 80 samples"),
            "{}",
            r.message
        );
    }

    fn good_mu(n: usize) -> Vec<f64> {
        (0..n).map(|k| 0.3 + 0.001 * (k % 3) as f64).collect()
    }
}
