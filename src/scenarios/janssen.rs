//! The `janssen` scenario: deposit → relax → release → homogenise → fit → figures.
//!
//! 1. Grains rained without overlap into a box of two vertical walls and a floor fall under
//!    gravity (deposition, sub-stepped: `dt / deposit.substeps`, loose solver tolerance) until at
//!    rest; then the column is relaxed at the scenario's `dt` with a tight tolerance until at
//!    rest again. The static forces of a rigid column at rest are indeterminate (how much weight
//!    the walls carry depends on the solver's path), so the column is then released: the floor
//!    is lowered slowly (`release`), the grains slide along the walls and the wall contacts reach
//!    the Coulomb limit (the paper's "relâcher le système afin de se mettre dans les conditions
//!    de Coulomb"). The last step of the release is solved to the tight tolerance with a large
//!    sweep cap, and measured.
//! 2. On the measured state: the wall normal and shear stress by depth bin on both side walls
//!    (σ_h = −σ_nn, τ_w), the vertical stress across horizontal planes at the bins' middles
//!    (σ_v = −σ_yy, method of planes), the bulk density ρ_b = φ ρ, the load on the floor over the
//!    weight, and the friction mobilisation |f_t|/(μ f_n) of the side-wall contacts.
//! 3. Janssen's law `σ_v(z) = ρ_b g W/(2Kμ_w) (1 − exp(−2Kμ_w z/W))`, `σ_h = K σ_v`,
//!    `τ_w = μ_w σ_h` is fitted jointly for K and μ_w (bounded by the wall friction); if μ_w
//!    ends at that bound, the fit with μ_w = μ_wall (full mobilisation, Janssen's assumption)
//!    is reported instead and flagged.

use datasets::config::JanssenConfig;
use datasets::phases::RunUntilRest;
use dem::snapshot::Snapshot;
use dem::BodyKind;
use homogenise::depth::{DepthAxis, DepthBins};
use homogenise::mobilisation::{contact_mobilisations, ContactClass, COULOMB_LIMIT};
use homogenise::state::solid_fraction;
use homogenise::walls::{plane_stress_profile, wall_stress_profile};
use homogenise::Region;
use identify::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, JanssenFit, JanssenOptions, JanssenProfile,
    JanssenSetup,
};
use identify::{CalibratedLaw, IdentifyError};
use nalgebra::Vector2;

use datasets::phases::PhaseStats;
use serde::{Deserialize, Serialize};

use super::common::{grain_weight, mean_diameter, solver_keys, Stop, VtkFrames};
use super::phased::{drive, PhasedRun, RunControl};
use super::{PhaseEnv, RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::{CsvTable, OutputDir, Summary};
use crate::plot::histogram::{draw_histogram, HistogramPlot};
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_row, draw_xy, Axis, Band, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::progress::{info, warn};
use crate::verdict::{export_law, max_solid_fraction, Checks, RunVerdict, Verdict, WindowStats};

/// Simulated seconds between two VTK frames.
const VTK_INTERVAL: f64 = 0.02;

/// Relative imbalance `|(floor + walls vertical load)/weight − 1|` of the measured column above
/// which it is not at rest and its stresses are suspect (1).
pub const FORCE_BALANCE_SUSPECT: f64 = 0.01;
/// The same, above which the result is refused (1).
pub const FORCE_BALANCE_REFUSED: f64 = 0.05;

/// The measured profile of the relaxed column.
#[derive(Debug, Clone)]
pub struct ColumnProfile {
    /// Bin-middle depths (m).
    pub z: Vec<f64>,
    /// σ_v (Pa, compressive positive), method of planes.
    pub sigma_v: Vec<f64>,
    /// σ_h (Pa), mean of both side walls.
    pub sigma_h: Vec<f64>,
    /// τ_w (Pa), mean of both side walls.
    pub tau_w: Vec<f64>,
    /// Height of the free surface above the floor (m).
    pub surface: f64,
}

/// Height of the free surface: the mean over one-diameter-wide columns of the highest grain
/// top (m).
pub fn surface_height(snap: &Snapshot, width: f64, d: f64) -> f64 {
    let n = ((width / d).floor() as usize).max(1);
    let mut top = vec![f64::NAN; n];
    for b in snap.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        let k = ((b.position.x / width * n as f64).floor().max(0.0) as usize).min(n - 1);
        let t = b.position.y + b.radius;
        if top[k].is_nan() || top[k] < t {
            top[k] = t;
        }
    }
    let v: Vec<f64> = top.into_iter().filter(|t| t.is_finite()).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Measures the wall and vertical stress profiles of a column at rest.
pub fn measure_profile(snap: &Snapshot, width: f64, bins: usize) -> Result<ColumnProfile> {
    let d = {
        let g: Vec<f64> = snap
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| 2.0 * b.radius)
            .collect();
        g.iter().sum::<f64>() / g.len().max(1) as f64
    };
    let surface = surface_height(snap, width, d);
    let axis = DepthAxis::new(Vector2::new(0.0, -1.0), Vector2::new(0.0, surface))?;
    let db = DepthBins::new(axis, surface / bins as f64, bins)?;
    let left = wall_stress_profile(snap, "left", &db)?;
    let right = wall_stress_profile(snap, "right", &db)?;
    let z: Vec<f64> = left.iter().map(|b| b.depth()).collect();
    let levels: Vec<f64> = z.iter().map(|z| surface - z).collect();
    let planes = plane_stress_profile(snap, &levels, Some(width))?;
    Ok(ColumnProfile {
        sigma_v: planes.iter().map(|p| -p.sigma_yy).collect(),
        sigma_h: left
            .iter()
            .zip(&right)
            .map(|(l, r)| -0.5 * (l.normal_stress + r.normal_stress))
            .collect(),
        tau_w: left
            .iter()
            .zip(&right)
            .map(|(l, r)| 0.5 * (l.shear_stress + r.shear_stress))
            .collect(),
        z,
        surface,
    })
}

/// The Janssen fit of a column, with how it was obtained.
pub struct JanssenOutcome {
    /// The fit.
    pub fit: JanssenFit,
    /// `joint` (K and μ_w free) or `full_mobilisation` (μ_w = μ_wall).
    pub mode: &'static str,
    /// Whether τ_w entered the fit (left out when a bin in the window has τ_w < 0, i.e. the
    /// wall friction pushes the grains down there).
    pub uses_tau_w: bool,
}

/// Fits Janssen's law (joint; full mobilisation if μ_w reaches the wall friction).
pub fn fit_profile(
    p: &ColumnProfile,
    setup: &JanssenSetup,
    window: (f64, f64),
) -> std::result::Result<JanssenOutcome, IdentifyError> {
    let uses_tau_w =
        p.z.iter()
            .zip(&p.tau_w)
            .all(|(z, t)| *z < window.0 || *z > window.1 || *t >= 0.0);
    let profile = JanssenProfile {
        z_m: p.z.clone(),
        sigma_v_pa: p.sigma_v.clone(),
        sigma_h_pa: Some(p.sigma_h.clone()),
        tau_w_pa: uses_tau_w.then(|| p.tau_w.clone()),
    };
    let opts = JanssenOptions {
        depth_window: Some(window),
        ..Default::default()
    };
    match fit_janssen(&profile, setup, &opts) {
        Ok(fit) => Ok(JanssenOutcome {
            fit,
            mode: "joint",
            uses_tau_w,
        }),
        Err(IdentifyError::ParameterAtBound { name, bound, .. })
            if name == "mu_w"
                && (bound - setup.wall_friction).abs() <= 1e-12 * bound.abs().max(1.0) =>
        {
            let fit = fit_janssen_full_mobilisation(&profile, setup, &opts)?;
            Ok(JanssenOutcome {
                fit,
                mode: "full_mobilisation",
                uses_tau_w,
            })
        }
        Err(e) => Err(e),
    }
}

/// 95 % band of `σ_v(z)` and `σ_h(z)` of a fit by the delta method on (K, μ_w):
/// rows `(z, σ_v, σ_v lo, σ_v hi, σ_h, σ_h lo, σ_h hi)`.
pub fn fit_band(fit: &JanssenFit, zs: &[f64]) -> Vec<[f64; 7]> {
    let law = fit.law;
    let cov = &fit.report.covariance;
    let t = fit.report.t_critical;
    let free_mu = cov.len() >= 2;
    let eval = |k: f64, mu: f64, z: f64| {
        let l = identify::laws::janssen::JanssenLaw { k, mu_w: mu, ..law };
        (l.sigma_v(z), l.sigma_h(z))
    };
    zs.iter()
        .map(|&z| {
            let (sv, sh) = eval(law.k, law.mu_w, z);
            let hk = 1e-6 * law.k.abs().max(1e-9);
            let hm = 1e-6 * law.mu_w.abs().max(1e-9);
            let (svk, shk) = eval(law.k + hk, law.mu_w, z);
            let (svm, shm) = eval(law.k, law.mu_w + hm, z);
            let gv = [(svk - sv) / hk, (svm - sv) / hm];
            let gh = [(shk - sh) / hk, (shm - sh) / hm];
            let var = |g: [f64; 2]| {
                let mut v = g[0] * g[0] * cov[0][0];
                if free_mu {
                    v += 2.0 * g[0] * g[1] * cov[0][1] + g[1] * g[1] * cov[1][1];
                }
                v.max(0.0)
            };
            let (ev, eh) = (t * var(gv).sqrt(), t * var(gh).sqrt());
            [z, sv, sv - ev, sv + ev, sh, sh - eh, sh + eh]
        })
        .collect()
}

/// The phases of the column: deposit, relax, release (floor lowered), measure (one step
/// solved tightly); the release and the measure are skipped when `floor_drop` is 0.
struct Column<'a> {
    c: &'a JanssenConfig,
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
    history: CsvTable,
    /// VTK frames.
    vtk: VtkFrames,
    deposit: PhaseStats,
    relax: PhaseStats,
    /// Release and measured step together.
    release: PhaseStats,
    /// Floor load over the weight at the end of the deposit and of the relaxation.
    #[serde(with = "dem::serde_float")]
    deposit_load: f64,
    #[serde(with = "dem::serde_float")]
    relaxed_load: f64,
    /// Numerics of the measured step (the last step of the relaxation without release).
    #[serde(default)]
    measured: WindowStats,
    /// World step index after the last step (the world counts sub-steps).
    #[serde(default)]
    last_step_index: u64,
    /// Sub-steps of the measured step (1 unless it was subdivided).
    #[serde(default)]
    measured_substeps: u64,
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

const DEPOSIT: usize = 0;
const RELAX: usize = 1;
const RELEASE: usize = 2;
const MEASURE: usize = 3;

impl PhasedRun for Column<'_> {
    type State = ColumnState;

    fn phase_count(&self) -> usize {
        4
    }

    fn enter(
        &self,
        k: usize,
        env: &PhaseEnv,
        world: &mut dem::World,
        st: &mut ColumnState,
        _out: &mut OutputDir,
    ) -> Result<Option<PhasePlan>> {
        let c = self.c;
        let plan = |name: &str, stop| {
            Some(PhasePlan {
                name: name.into(),
                stop,
            })
        };
        Ok(match k {
            DEPOSIT => {
                world.params.solver = c.deposit.solver.params();
                plan(
                    "deposit",
                    Stop::UntilRest(RunUntilRest {
                        min_time: 0.0,
                        max_time: c.deposit.max_time,
                        rest_energy: c.deposit.rest_energy,
                    }),
                )
            }
            // Relaxation at the scenario's time step, tight tolerance.
            RELAX => {
                world.params.dt = c.dt;
                world.params.solver = c.relax.solver.params();
                plan(
                    "relax",
                    Stop::UntilRest(RunUntilRest {
                        min_time: c.relax.min_time,
                        max_time: c.relax.max_time,
                        rest_energy: c.relax.rest_energy,
                    }),
                )
            }
            // Release: the floor is lowered slowly so that the column slides along the walls
            // (Coulomb conditions at the wall contacts).
            RELEASE if self.release_steps() > 0 => {
                world.bodies[st.bottom].velocity = Vector2::new(0.0, -c.release.speed);
                world.params.solver = c.release.solver.params();
                plan("release", Stop::Steps(self.release_steps()))
            }
            // The stresses are measured at the end of the release, on a step solved to the
            // tight tolerance while the floor still moves.
            MEASURE if self.release_steps() > 0 => {
                world.params.solver = dem::SolverParams {
                    tolerance: c.relax.solver.tolerance,
                    max_iterations: c.analysis.final_max_iterations,
                    method: c.relax.solver.method,
                    lemke_max_contacts: c.relax.solver.lemke_max_contacts,
                    max_halvings: c.release.solver.max_halvings,
                    // The whole step is tried with the method asked for (`auto`: Newton and
                    // the exact finish after the sweeps), sub-steps only if that fails.
                    gauss_seidel_attempts: false,
                    ..Default::default()
                };
                info(
                    env.verbosity,
                    &format!(
                        "     measure: one step solved to {:.0e} (at most {} sweeps)",
                        c.relax.solver.tolerance, c.analysis.final_max_iterations
                    ),
                );
                plan("measure", Stop::Steps(1))
            }
            _ => None,
        })
    }

    fn step(
        &self,
        k: usize,
        st: &mut ColumnState,
        out: &mut OutputDir,
        w: &dem::World,
        r: &dem::StepReport,
        p: &datasets::phases::PhaseProgress,
    ) -> Result<()> {
        // The measured step: the one step of `measure`, or the last of `relax` without release.
        let measured = if self.release_steps() > 0 {
            k == MEASURE
        } else {
            k == RELAX
        };
        if measured && k == RELAX {
            st.measured.restart();
        }
        st.measured.step(measured, w, r, &p.stats);
        if measured {
            st.measured_substeps = r.step.saturating_sub(st.last_step_index);
        }
        st.last_step_index = r.step;
        let load = Self::floor_load(w, st);
        st.history.push(vec![
            w.time,
            k as f64,
            w.kinetic_energy(),
            r.active_contacts as f64,
            r.solver.iterations as f64,
            r.solver.error,
            load,
        ]);
        st.vtk.maybe(out, w)
    }

    fn leave(
        &self,
        k: usize,
        st: &mut ColumnState,
        _out: &mut OutputDir,
        world: &mut dem::World,
        stats: &PhaseStats,
    ) -> Result<()> {
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
                world.params.solver = self.c.relax.solver.params();
            }
        }
        Ok(())
    }
}

/// Runs the scenario.
pub fn run(c: &JanssenConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let width = datasets::build::column_width(&c.grain, c.grains, c.column_aspect);
    info(
        ctx.verbosity,
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
    let fresh = || -> Result<(dem::World, ColumnState)> {
        let col = datasets::build::column(
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
            history: CsvTable::new(&[
                "time_s",
                "phase_0deposit_1relax_2release_3measure",
                "kinetic_energy_J",
                "contacts",
                "sweeps",
                "solver_error",
                "bottom_load_over_weight",
            ]),
            vtk: VtkFrames::new(VTK_INTERVAL, c.analysis.vtk_frames.max(1)),
            deposit: PhaseStats::default(),
            relax: PhaseStats::default(),
            release: PhaseStats::default(),
            deposit_load: f64::NAN,
            relaxed_load: f64::NAN,
            measured: WindowStats::default(),
            last_step_index: 0,
            measured_substeps: 0,
        };
        Ok((col.world, state))
    };
    let (world, st) = drive(ctx, ctl, &Column { c }, fresh)?;
    let world = &world;
    let ColumnState {
        bottom,
        left,
        right,
        weight,
        history,
        vtk,
        deposit,
        relax,
        release,
        deposit_load,
        relaxed_load,
        measured,
        measured_substeps,
        ..
    } = st;
    let final_report = world.last_report();
    if !final_report.solver.converged {
        warn(&format!(
            "the measured (last) step did not converge: error {:.2e} > {:.0e} after {} sweeps",
            final_report.solver.error, c.relax.solver.tolerance, final_report.solver.iterations
        ));
    }
    let snap = world.snapshot();
    let frames = vtk.finish(&mut ctx.out, world)?;

    // 3. Homogenisation.
    let d = mean_diameter(world);
    let profile = measure_profile(&snap, width, c.analysis.depth_bins)?;
    let bottom_load = -world.contact_force(bottom).0.y;
    let top_skip = c.analysis.skip_top_diameters * d;
    let bottom_skip = c.analysis.skip_bottom_diameters * d;
    let phi_region = Region::Rectangle {
        min: Vector2::new(0.0, bottom_skip),
        max: Vector2::new(width, (profile.surface - top_skip).max(bottom_skip + d)),
    };
    let phi = solid_fraction(&snap, &phi_region)?;
    let rho_b = phi * c.grain.density;
    let g = world.params.gravity.norm();
    let mut mob = Vec::new();
    for wall in ["left", "right"] {
        mob.extend(
            contact_mobilisations(&snap, &ContactClass::WallNamed(wall.into()))?
                .into_iter()
                .map(|(_, m)| m),
        );
    }
    let sliding = if mob.is_empty() {
        f64::NAN
    } else {
        mob.iter().filter(|&&m| m >= COULOMB_LIMIT).count() as f64 / mob.len() as f64
    };
    let mean_mob = mob.iter().sum::<f64>() / mob.len().max(1) as f64;

    // 4. Fit.
    let setup = JanssenSetup {
        width_m: width,
        bulk_density_kg_m3: rho_b,
        gravity_m_s2: g,
        wall_friction: c.friction.grain_wall,
    };
    let window = (top_skip, profile.surface - bottom_skip);
    let fitted = fit_profile(&profile, &setup, window);

    // 5. Checks (crate::verdict): the measured step's numerics, the force balance of the
    // column, the solid fraction, the depth bins.
    let mut checks = Checks::new();
    checks.window("measured step", &measured);
    let wall_load = -(world.contact_force(left).0.y + world.contact_force(right).0.y);
    let balance = (bottom_load + wall_load) / weight - 1.0;
    checks.at_most(
        "janssen.force_balance",
        balance.abs(),
        FORCE_BALANCE_SUSPECT,
        Some(FORCE_BALANCE_REFUSED),
        |t| {
            format!(
                "floor and wall vertical loads carry {:.2} % of the weight (the column is not at rest; limit ±{:.0} %)",
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
    let bin = profile.surface / c.analysis.depth_bins as f64;
    checks.at_most("janssen.bin_thickness", d / bin, 1.0, None, |_| {
        format!(
            "depth bins {:.2} mm thick, thinner than a mean diameter ({:.2} mm): lower analysis.depth_bins",
            bin * 1e3,
            d * 1e3
        )
    });
    let mut verdict = RunVerdict {
        run: checks.clone(),
        ..Default::default()
    };
    verdict.allow_suspect = ctl.allow_suspect;

    // 6. Outputs.
    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("box_width_m", width)
        .num("column_height_m", profile.surface)
        .num("column_height_over_width", profile.surface / width)
        .num("mean_diameter_m", d)
        .num("solid_fraction", phi)
        .num("bulk_density_kg_m3", rho_b)
        .num("weight_N", weight)
        .num("bottom_load_N", bottom_load)
        .num("bottom_load_over_weight", bottom_load / weight)
        .num("wall_load_N", wall_load)
        .num("force_balance_residual", balance)
        .num("depth_bin_thickness_m", bin)
        .num("wall_friction", c.friction.grain_wall)
        .num("grain_friction", c.friction.grain_grain);
    let mut headline = Vec::new();
    match &fitted {
        Ok(o) => {
            let f = &o.fit;
            for (k, v) in f.summary_entries() {
                s.num(&k, v);
            }
            s.text("janssen_fit_mode", o.mode)
                .flag("janssen_fit_uses_tau_w", o.uses_tau_w);
            if !o.uses_tau_w {
                // Which bins, so the user can judge (a few wall contacts per bin in a narrow
                // column: one slipping grain can turn a bin's mean).
                let bins: Vec<String> = profile
                    .z
                    .iter()
                    .zip(&profile.tau_w)
                    .filter(|(z, t)| **z >= window.0 && **z <= window.1 && **t < 0.0)
                    .map(|(z, t)| format!("{t:.0} Pa at z = {:.1} mm", z * 1e3))
                    .collect();
                warn(&format!(
                    "τ_w < 0 in the fit window ({}): Janssen fitted to σ_v and σ_h only",
                    bins.join(", ")
                ));
            }
            let law = CalibratedLaw::from_janssen(
                f,
                crate::provenance::of_run(ctx, ctl, "janssen", c.seed),
            );
            export_law(&mut ctx.out, &mut verdict, "janssen", &law, checks.clone())?;
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
    s.num("wall_sliding_fraction", sliding)
        .num("wall_mean_mobilisation", mean_mob)
        .int("wall_contacts", mob.len() as u64);
    headline.push(format!(
        "bottom load / weight = {:.3}, wall contacts at the Coulomb limit: {:.0} %",
        bottom_load / weight,
        100.0 * sliding
    ));
    let mut all = deposit;
    all.merge(&release);
    all.merge(&relax);
    solver_keys(&mut s, &all);
    s.int("deposit_steps", deposit.steps)
        .num("deposit_dt_s", c.dt / c.deposit.substeps as f64)
        .num("deposit_time_s", deposit.simulated_time)
        .int("deposit_unconverged_steps", deposit.unconverged_steps)
        .int("deposit_energy_growth_steps", deposit.energy_growth_steps)
        .num("deposit_bottom_load_over_weight", deposit_load)
        .num("relaxed_bottom_load_over_weight", relaxed_load)
        .num("release_floor_drop_m", c.release.floor_drop)
        .num("release_speed_m_s", c.release.speed)
        .int("release_steps", release.steps)
        .int("release_unconverged_steps", release.unconverged_steps)
        .int("release_energy_growth_steps", release.energy_growth_steps)
        .num("release_worst_error", release.worst_error)
        .int("relax_steps", relax.steps)
        .num("relax_time_s", relax.simulated_time)
        .int("relax_unconverged_steps", relax.unconverged_steps)
        .int("relax_energy_growth_steps", relax.energy_growth_steps)
        .num("relax_worst_error", relax.worst_error)
        .flag("relax_at_rest", relax.at_rest)
        .num("final_kinetic_energy_ratio", relax.final_energy_ratio)
        .num("final_solver_error", final_report.solver.error)
        .int("final_solver_sweeps", final_report.solver.iterations as u64)
        .flag("final_solver_converged", final_report.solver.converged)
        .int("final_step_substeps", measured_substeps);
    measured.keys(&mut s, "measured");
    s.int("vtk_frames", frames as u64);

    // CSV: history and the fit-ready profile.
    history.write(&mut ctx.out, "history.csv")?;
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
    if let Ok(o) = &fitted {
        if o.mode == "full_mobilisation" {
            prof.metadata.push(("full_mobilisation".into(), 1.0));
        }
    }
    for (i, &z) in profile.z.iter().enumerate() {
        let (jv, jh) = match &fitted {
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
    prof.write(&mut ctx.out, "wall_profile.csv")?;

    // Figures.
    figure_profile(
        ctx,
        &profile,
        &fitted,
        rho_b,
        g,
        window,
        c.friction.grain_wall,
    )?;
    let hist = homogenise::mobilisation::Histogram::new(&mob, 0.0, 1.0, 20)?;
    draw_histogram(
        &mut ctx.out,
        "wall_mobilisation.png",
        &HistogramPlot {
            title: "Friction mobilisation of the side-wall contacts".into(),
            x_label: "mobilisation |f_t| / (μ f_n)".into(),
            y_label: "fraction of wall contacts".into(),
            edges: hist.edges.clone(),
            values: hist.fractions(),
            color: PALETTE[0],
            markers: vec![(1.0, "Coulomb limit ".into())],
            notes: vec![
                format!(
                    "{} wall contacts, μ_wall = {}",
                    mob.len(),
                    c.friction.grain_wall
                ),
                format!(
                    "at the Coulomb limit (≥ {COULOMB_LIMIT}): {:.0} %",
                    100.0 * sliding
                ),
                format!("mean mobilisation: {mean_mob:.2}"),
            ],
        },
    )?;
    draw_particles(
        &mut ctx.out,
        "force_chains.png",
        &ParticleView {
            snap: &snap,
            title: format!("Relaxed column, {} grains: normal contact forces", c.grains),
            fill: GrainFill::Plain,
            forces: true,
            axis_labels: ("x (m)".into(), "y (m)".into()),
            width_px: if c.grains > 3000 { 900 } else { 520 },
        },
    )?;
    let t: Vec<(f64, f64)> = history.rows.iter().map(|r| (r[0], r[2])).collect();
    let l: Vec<(f64, f64)> = history.rows.iter().map(|r| (r[0], r[6])).collect();
    let mut ke = XyPlot::new(
        "Kinetic energy",
        Axis::new("time t (s)"),
        Axis::new("kinetic energy (J)").log(),
    );
    ke.series.push(Series::new(
        "",
        Style::Thin,
        PALETTE[0],
        t.into_iter().filter(|p| p.1 > 0.0).collect(),
    ));
    let mut bl = XyPlot::new(
        "Load on the floor",
        Axis::new("time t (s)"),
        Axis::new("bottom load / weight").range(0.0, 1.5),
    );
    bl.series.push(Series::new("", Style::Thin, PALETTE[1], l));
    bl.series.push(Series::new(
        "weight",
        Style::Dashed,
        PALETTE[6],
        vec![(0.0, 1.0), (world.time, 1.0)],
    ));
    // Phase boundaries (history column 1 holds the phase code).
    let starts: Vec<(f64, f64)> = history
        .rows
        .windows(2)
        .filter(|w| w[1][1] != w[0][1])
        .map(|w| (w[1][1], w[0][0]))
        .collect();
    let names = ["deposit", "relax", "release", "measure"];
    let mut note = String::from("phases: deposit from 0 s");
    for (code, t) in &starts {
        if let Some(n) = names.get(*code as usize) {
            note.push_str(&format!(", {n} from {t:.3} s"));
        }
    }
    bl.notes.push(note);
    bl.legend = LegendAt::LowerRight;
    for (_, t) in &starts {
        bl.series.push(Series::new(
            "",
            Style::Dashed,
            PALETTE[4],
            vec![(*t, 0.0), (*t, 1.5)],
        ));
    }
    draw_row(&mut ctx.out, "history.png", &[ke, bl], (1600, 600))?;

    let mut lines = vec![format!("report: {}/", ctx.out.path().display())];
    lines.extend(headline);
    Ok(RunOutcome {
        summary: s,
        headline: lines,
        verdict,
    })
}

fn figure_profile(
    ctx: &mut RunContext,
    p: &ColumnProfile,
    fitted: &std::result::Result<JanssenOutcome, IdentifyError>,
    rho_b: f64,
    g: f64,
    window: (f64, f64),
    mu_wall: f64,
) -> Result<()> {
    let mut plot = XyPlot::new(
        "Stresses in the column vs depth",
        Axis::new("stress (Pa)"),
        Axis::new("depth below the free surface z (m)").reversed(),
    );
    let zmax = p.surface;
    let zs: Vec<f64> = (0..=120).map(|k| zmax * k as f64 / 120.0).collect();
    if let Ok(o) = fitted {
        let band = fit_band(&o.fit, &zs);
        plot.bands.push(Band::between_x(
            "",
            PALETTE[0],
            &band.iter().map(|r| (r[0], r[2], r[3])).collect::<Vec<_>>(),
        ));
        plot.bands.push(Band::between_x(
            "95 % confidence band",
            PALETTE[1],
            &band.iter().map(|r| (r[0], r[5], r[6])).collect::<Vec<_>>(),
        ));
    }
    plot.series.push(Series::new(
        "hydrostatic ρ_b g z",
        Style::Dashed,
        PALETTE[6],
        vec![(0.0, 0.0), (rho_b * g * zmax, zmax)],
    ));
    if let Ok(o) = fitted {
        let f = &o.fit;
        plot.series.push(Series::new(
            "Janssen σ_v",
            Style::Line,
            PALETTE[0],
            zs.iter().map(|&z| (f.law.sigma_v(z), z)).collect(),
        ));
        plot.series.push(Series::new(
            "Janssen σ_h = K σ_v",
            Style::Line,
            PALETTE[1],
            zs.iter().map(|&z| (f.law.sigma_h(z), z)).collect(),
        ));
        plot.series.push(Series::new(
            "Janssen τ_w = μ_w σ_h",
            Style::Line,
            PALETTE[2],
            zs.iter().map(|&z| (f.law.tau_w(z), z)).collect(),
        ));
        let kmu = if o.mode == "joint" {
            format!(
                "K = {:.2} ± {:.2}, μ_w = {:.3} ± {:.3} (μ_wall = {mu_wall})",
                f.k.value,
                f.k.ci_high - f.k.value,
                f.mu_w.value,
                f.mu_w.ci_high - f.mu_w.value
            )
        } else {
            format!(
                "K = {:.2} ± {:.2}, μ_w = μ_wall = {mu_wall} (full mobilisation)",
                f.k.value,
                f.k.ci_high - f.k.value
            )
        };
        plot.notes.push(kmu);
        plot.notes.push(format!(
            "fitted over z ∈ [{:.3}, {:.3}] m",
            window.0, window.1
        ));
    }
    plot.series.push(Series::new(
        "DEM σ_v (planes)",
        Style::Points,
        PALETTE[0],
        p.z.iter().zip(&p.sigma_v).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.series.push(Series::new(
        "DEM σ_h (walls)",
        Style::Points,
        PALETTE[1],
        p.z.iter().zip(&p.sigma_h).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.series.push(Series::new(
        "DEM τ_w (walls)",
        Style::Circles,
        PALETTE[2],
        p.z.iter().zip(&p.tau_w).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.legend = LegendAt::UpperRight;
    let _ = &plot;
    draw_xy(&mut ctx.out, "wall_stress_profile.png", &plot)
}
