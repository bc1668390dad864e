//! `grainlaw continuum inclined-plane`: the law's steady flow down a slope computed by Gerris
//! (a layer periodic along the slope), against the analytic Bagnold profile of the same law and
//! a DEM `inclined-flow` run's velocity profile (`docs/continuum.md` §7).
//!
//! Steady uniform flow of thickness `H` at angle `θ`: `τ = ρ_b g sin θ (H − z)`,
//! `P = ρ_b g cos θ (H − z)`, so `μ(I) = tan θ` fixes a uniform `I_θ` (`μ_s < tan θ < μ₂`;
//! `I_θ = I₀ (tan θ − μ_s)/(μ₂ − tan θ)` for the saturating law, `(tan θ − μ_s)/b` for the linear
//! one) and `u(z) = (2/3)(I_θ/d)√(φ g cos θ)(H^{3/2} − (H − z)^{3/2})` (GDR MiDi, Eur. Phys.
//! J. E 14, 2004; Jop, Forterre & Pouliquen, J. Fluid Mech. 541, 2005), evaluated by
//! [`identify::continuum::BagnoldFlow`]. In Gerris' units (`H = 1`, `g = 1`, `ρ_b = 1`):
//! `u = (2/3)(√φ I_θ/D)√(cos θ)(1 − (1 − z)^{3/2})`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use identify::continuum::BagnoldFlow;
use identify::law::CalibratedLaw;

use super::column::interpolate;
use super::dem_column::{read_rows, write_rows};
use super::gerris;
use super::gfs::{InclinedCase, SNAPSHOT_DIR};
use super::inputs::CaseInputs;
use super::rheology::{load_continuum_law, GerrisRheology};
use super::snapshot::Snapshot;
use crate::error::{CliError, Result};
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{draw_xy, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::verdict::{Checks, RunVerdict, Verdict};

/// Default refinement level (`2^6 = 64` cells across the layer).
pub const DEFAULT_LEVEL: u32 = 6;
/// Default layer thickness without a DEM run or `--depth`, in grain diameters.
pub const DEFAULT_DEPTH_DIAMETERS: f64 = 20.0;
/// Largest number of Gerris time steps.
pub const MAX_STEPS: u64 = 4000;
/// Steady state: `U` changes by less than this fraction of the analytic surface velocity over
/// 10 steps.
pub const STEADY_TOLERANCE: f64 = 2e-6;
/// Default viscosity cap (Gerris units of the layer).
pub const DEFAULT_VISCOSITY_CAP: f64 = 1000.0;
/// Gravity of the DEM scenarios (m/s²).
pub const GRAVITY: f64 = 9.81;

/// What `grainlaw continuum inclined-plane` runs.
#[derive(Debug, Clone, PartialEq)]
pub struct InclinedPlan {
    /// Law, output, DEM run (an `inclined-flow` output directory), `φ` (default: the DEM
    /// layer's mean), level, viscosity cap, Gerris command, suspect policy.
    pub inputs: CaseInputs,
    /// Slope (degrees) (default: the DEM's).
    pub slope_deg: Option<f64>,
    /// Layer thickness `H` (m) (default: the DEM's flow height, else 20 d).
    pub depth_m: Option<f64>,
}

impl InclinedPlan {
    /// The plan with the defaults for `law` and `out`.
    pub fn new(law: PathBuf, out: PathBuf) -> Self {
        InclinedPlan {
            inputs: CaseInputs::new(law, out, DEFAULT_LEVEL, DEFAULT_VISCOSITY_CAP),
            slope_deg: None,
            depth_m: None,
        }
    }
}

/// A finished inclined-plane run.
#[derive(Debug, Clone)]
pub struct InclinedOutcome {
    /// The report printed on stdout.
    pub lines: Vec<String>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// The verdict.
    pub verdict: RunVerdict,
    /// `summary.json`'s content.
    pub summary: Value,
    /// `(z, u)` of Gerris (Gerris units, averaged along the slope).
    pub gerris_profile: Vec<(f64, f64)>,
    /// Largest `|u_Gerris − u_Bagnold|` over the analytic surface velocity.
    pub max_relative_error: f64,
}

/// A row of the DEM `inclined-flow` `profiles.csv`.
#[derive(Debug, Clone, Deserialize)]
struct DemFlowRow {
    height_m: f64,
    velocity_m_s: Option<f64>,
    solid_fraction: Option<f64>,
}

/// The DEM run's set-up and profile.
#[derive(Debug, Clone)]
struct DemFlow {
    dir: PathBuf,
    slope_deg: f64,
    depth_m: f64,
    diameter_m: f64,
    packing_fraction: f64,
    /// `(z, u)` (m, m/s) of the bins with grains up to the flow height.
    profile: Vec<(f64, f64)>,
}

fn read_dem(dir: &Path) -> Result<DemFlow> {
    let sp = dir.join("summary.json");
    let bad = |p: &Path, r: String| CliError::Input {
        path: p.display().to_string(),
        reason: r,
    };
    let text = std::fs::read_to_string(&sp).map_err(|e| bad(&sp, e.to_string()))?;
    let v: Value = serde_json::from_str(&text).map_err(|e| bad(&sp, e.to_string()))?;
    if v["scenario"].as_str() != Some("inclined-flow") {
        return Err(bad(
            &sp,
            format!(
                "scenario {}: not the output of an inclined-flow run",
                v["scenario"]
            ),
        ));
    }
    let num = |k: &str| -> Result<f64> {
        v[k].as_f64()
            .filter(|x| x.is_finite() && *x > 0.0)
            .ok_or_else(|| bad(&sp, format!("`{k}` missing or not a positive number")))
    };
    let (slope_deg, depth_m, diameter_m) = (
        num("slope_deg")?,
        num("flow_height_m")?,
        num("mean_diameter_m")?,
    );
    let rows: Vec<DemFlowRow> = read_rows(&dir.join("profiles.csv"))?;
    let inside: Vec<&DemFlowRow> = rows.iter().filter(|r| r.height_m <= depth_m).collect();
    let phis: Vec<f64> = inside.iter().filter_map(|r| r.solid_fraction).collect();
    let packing_fraction = phis.iter().sum::<f64>() / phis.len().max(1) as f64;
    let profile = inside
        .iter()
        .filter_map(|r| r.velocity_m_s.map(|u| (r.height_m, u)))
        .collect();
    Ok(DemFlow {
        dir: dir.to_path_buf(),
        slope_deg,
        depth_m,
        diameter_m,
        packing_fraction,
        profile,
    })
}

/// One row of `profile.csv`.
#[derive(Debug, Clone, Serialize)]
struct ProfileRow {
    height_m: f64,
    velocity_gerris_m_s: f64,
    velocity_bagnold_m_s: f64,
}

/// One row of `comparison.csv` (at the DEM's bins).
#[derive(Debug, Clone, Serialize)]
struct DemRow {
    height_m: f64,
    velocity_dem_m_s: f64,
    velocity_gerris_m_s: f64,
    velocity_bagnold_m_s: f64,
}

/// The resolved inputs of an inclined-plane run: the law, the DEM run, the layer and the
/// analytic Bagnold flow of the law on the slope.
struct InclinedConfig {
    /// The law file, as given.
    law_path: String,
    /// The law.
    law: CalibratedLaw,
    /// The DEM run to compare with.
    dem: Option<DemFlow>,
    /// Warnings so far.
    warnings: Vec<String>,
    /// The law's grain diameter `d` (m).
    d_m: f64,
    /// Slope (degrees).
    slope_deg: f64,
    /// Slope `θ` (radians).
    theta: f64,
    /// Depth of the layer `H` (m).
    depth: f64,
    /// Packing fraction `φ` of the layer.
    phi: f64,
    /// The law as Gerris runs it.
    rheology: GerrisRheology,
    /// The inertial number of steady flow on the slope, `μ(I_θ) = tan θ`.
    i_theta: f64,
    /// The analytic steady flow of the law.
    flow: BagnoldFlow,
    /// Velocity unit of the case (m/s).
    uv: f64,
    /// The analytic surface velocity (Gerris units).
    u_surface_g: f64,
}

/// The Gerris run of the layer, read back and set against the analytic profile.
struct InclinedRun {
    /// The run.
    run: gerris::GerrisRun,
    /// Gerris' last step, when its log gives one.
    steps: Option<u64>,
    /// `(z, u)` of Gerris (Gerris units, averaged along the slope).
    gerris_profile: Vec<(f64, f64)>,
    /// Largest `|u_Gerris − u_Bagnold|` over the analytic surface velocity.
    max_err: f64,
    /// RMS of `u_Gerris − u_Bagnold` over the analytic surface velocity.
    rms_err: f64,
    /// The rows of `profile.csv`.
    table: Vec<ProfileRow>,
}

impl InclinedRun {
    /// Gerris' surface velocity (m/s).
    fn surface_velocity(&self, uv: f64) -> f64 {
        self.gerris_profile.last().map_or(f64::NAN, |p| p.1) * uv
    }
}

/// Runs the inclined plane of `plan` (module documentation). Errors as
/// [`super::column::column_collapse`]; a slope without steady flow for the law is bad input.
///
/// Stages: config (`resolve_inclined`) → the Gerris run → its profile against Bagnold's →
/// checks → comparison with the DEM → figure → summary and report.
pub fn inclined_plane(plan: &InclinedPlan) -> Result<InclinedOutcome> {
    crate::plot::init_font();
    let mut cfg = resolve_inclined(plan)?;
    plan.inputs.check_out("continuum-inclined-plane")?;
    let mut out = OutputDir::create(&plan.inputs.out)?;
    let run = run_inclined_case(plan, &cfg)?;
    write_rows(
        &mut out,
        "profile.csv",
        &run.table,
        "steady flow down the slope: Gerris (averaged along the slope, cell centres) and the analytic Bagnold profile of the same law; height above the base",
    )?;
    let checks = inclined_checks(&mut cfg, run.steps);
    let (dem_rows, dem_json) = dem_comparison(&cfg, &run.gerris_profile);
    if !dem_rows.is_empty() {
        write_rows(
            &mut out,
            "comparison.csv",
            &dem_rows,
            "the DEM's time-averaged velocity profile against Gerris (interpolated) and the analytic Bagnold profile, at the DEM's bins",
        )?;
    }
    velocity_figure(&mut out, plan, &cfg, &run.table)?;
    let verdict = RunVerdict {
        run: checks,
        laws: Vec::new(),
        allow_suspect: plan.inputs.allow_suspect,
    };
    let s = inclined_summary(plan, &cfg, &run, dem_json.as_ref(), &verdict);
    out.write("summary.json", s.to_json().as_bytes())?;
    let lines = inclined_lines(plan, &cfg, &run, dem_json.as_ref(), &verdict);
    Ok(InclinedOutcome {
        lines,
        warnings: cfg.warnings,
        verdict,
        summary: serde_json::from_str(&s.to_json()).unwrap_or(Value::Null),
        gerris_profile: run.gerris_profile,
        max_relative_error: run.max_err,
    })
}

/// Reads the law and the DEM run and resolves the layer of `plan` (slope, depth, `φ`), the
/// rheology and the law's steady flow on the slope. Errors: [`CliError::Usage`] for a bad
/// setting, [`CliError::Input`] for a slope without steady flow.
fn resolve_inclined(plan: &InclinedPlan) -> Result<InclinedConfig> {
    let law_path = plan.inputs.law.display().to_string();
    let law = load_continuum_law(&plan.inputs.law)?;
    let dem = plan.inputs.dem.as_deref().map(read_dem).transpose()?;
    let mut warnings = Vec::new();
    if !(3..=10).contains(&plan.inputs.level) {
        return Err(CliError::Usage(format!(
            "--level must lie in 3..=10, got {}",
            plan.inputs.level
        )));
    }
    let d_m = law.constant("d").unwrap_or(f64::NAN);
    let slope_deg = plan
        .slope_deg
        .or(dem.as_ref().map(|d| d.slope_deg))
        .ok_or_else(|| CliError::Usage("the slope is needed: give --slope-deg or --dem".into()))?;
    if !(slope_deg > 0.0 && slope_deg < 90.0) {
        return Err(CliError::Usage(format!(
            "--slope-deg must lie in (0, 90), got {slope_deg}"
        )));
    }
    let depth = plan
        .depth_m
        .or(dem.as_ref().map(|d| d.depth_m))
        .unwrap_or(DEFAULT_DEPTH_DIAMETERS * d_m);
    let phi = plan
        .inputs
        .packing_fraction
        .or(dem.as_ref().map(|d| d.packing_fraction))
        .ok_or_else(|| {
            CliError::Usage(
                "the layer's packing fraction is needed (its density is φ ρ_s): give --packing-fraction or --dem".into(),
            )
        })?;
    if let Some(d) = &dem {
        if (d.diameter_m - d_m).abs() > 0.05 * d.diameter_m {
            warnings.push(format!(
                "the law's grain diameter d = {d_m:.4e} m differs from the DEM grains' {:.4e} m: the law is used with its own d",
                d.diameter_m
            ));
        }
    }
    let rheology = GerrisRheology::new(
        law.clone(),
        &law_path,
        depth,
        GRAVITY,
        phi,
        plan.inputs.viscosity_cap,
    )?;
    let theta = slope_deg.to_radians();
    let i_theta = rheology.inertial_number_for(theta.tan()).ok_or_else(|| CliError::Input {
        path: law_path.clone(),
        reason: format!(
            "no steady flow on a {slope_deg}° slope: tan θ = {:.4} is outside the law's range of friction (μ(0) = {:.4}{})",
            theta.tan(),
            rheology.mu(0.0),
            if law.law == "mu-i" { format!(", μ(∞) = {:.4}", law.parameter("mu_2").unwrap_or(f64::NAN)) } else { String::new() }
        ),
    })?;
    let flow = BagnoldFlow::with_inertial_number(i_theta, phi, theta, depth, d_m, GRAVITY)
        .map_err(|e| CliError::Input {
            path: law_path.clone(),
            reason: e.to_string(),
        })?;
    let uv = rheology.units.velocity_m_s();
    let u_surface_g = flow.surface_velocity() / uv;
    Ok(InclinedConfig {
        law_path,
        law,
        dem,
        warnings,
        d_m,
        slope_deg,
        theta,
        depth,
        phi,
        rheology,
        i_theta,
        flow,
        uv,
        u_surface_g,
    })
}

/// Writes the case into `OUT/gerris` (stale snapshots removed), runs Gerris to steady flow,
/// reads its end snapshot and sets its profile against the analytic one.
fn run_inclined_case(plan: &InclinedPlan, cfg: &InclinedConfig) -> Result<InclinedRun> {
    let case_dir = plan.inputs.out.join("gerris");
    let case = InclinedCase {
        rheology: cfg.rheology.clone(),
        slope_rad: cfg.theta,
        level: plan.inputs.level,
        initial_surface_velocity: 2.0 * cfg.u_surface_g,
        steady_tolerance: STEADY_TOLERANCE * cfg.u_surface_g,
        max_steps: MAX_STEPS,
        comments: vec![format!(
            "grainlaw {} continuum inclined-plane: the {} law of {}; slope {} deg, H = {} m, level {}",
            identify::law::GRAINLAW_VERSION,
            cfg.law.law,
            cfg.law_path,
            cfg.slope_deg,
            cfg.depth,
            plan.inputs.level
        )],
    };
    let snaps = case_dir.join(SNAPSHOT_DIR);
    if snaps.exists() {
        std::fs::remove_dir_all(&snaps).map_err(|e| CliError::io(&snaps, e))?;
    }
    std::fs::create_dir_all(&snaps).map_err(|e| CliError::io(&snaps, e))?;
    crate::output::dir::write_atomic(&case_dir.join("inclined.gfs"), case.to_gfs()?.as_bytes())?;
    let gerris_cmd = gerris::command(plan.inputs.gerris.as_deref());
    let run = gerris::run(&gerris_cmd, &case_dir, "inclined.gfs")?;
    let endp = snaps.join("end.txt");
    if !endp.is_file() {
        return Err(CliError::ExternalSolver {
            solver: gerris_cmd.display().to_string(),
            reason: "finished without its end snapshot".into(),
            dir: case_dir.display().to_string(),
            rerun: format!("{} inclined.gfs", gerris_cmd.display()),
        });
    }
    let snap = Snapshot::read(&endp)?;
    let steps = last_step(&case_dir.join("gerris.log"));
    let gerris_profile = along_slope_average(&snap);
    let (depth, uv, u_surface_g) = (cfg.depth, cfg.uv, cfg.u_surface_g);
    let analytic = |z: f64| cfg.flow.velocity(z * depth) / uv;
    let max_err = gerris_profile
        .iter()
        .map(|&(z, u)| (u - analytic(z)).abs())
        .fold(0.0, f64::max)
        / u_surface_g;
    let rms_err = (gerris_profile
        .iter()
        .map(|&(z, u)| (u - analytic(z)).powi(2))
        .sum::<f64>()
        / gerris_profile.len().max(1) as f64)
        .sqrt()
        / u_surface_g;
    let table: Vec<ProfileRow> = gerris_profile
        .iter()
        .map(|&(z, u)| ProfileRow {
            height_m: z * depth,
            velocity_gerris_m_s: u * uv,
            velocity_bagnold_m_s: cfg.flow.velocity(z * depth),
        })
        .collect();
    Ok(InclinedRun {
        run,
        steps,
        gerris_profile,
        max_err,
        rms_err,
        table,
    })
}

/// The snapshot's velocity averaged along the slope: one `(y, u)` per row of cells, by `y`.
fn along_slope_average(snap: &Snapshot) -> Vec<(f64, f64)> {
    let mut rows: Vec<(f64, f64, f64)> = Vec::new(); // (y, sum u, n)
    for c in &snap.cells {
        match rows.iter_mut().find(|r| (r.0 - c.y).abs() < 1e-9) {
            Some(r) => {
                r.1 += c.u;
                r.2 += 1.0;
            }
            None => rows.push((c.y, c.u, 1.0)),
        }
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    rows.iter().map(|r| (r.0, r.1 / r.2)).collect()
}

/// The checks of the run: steady flow reached, the slope's `I` inside the law's calibrated
/// range (a warning into `cfg` when not).
fn inclined_checks(cfg: &mut InclinedConfig, steps: Option<u64>) -> Checks {
    let mut checks = Checks::new();
    if steps.is_some_and(|s| s + 10 >= MAX_STEPS) {
        checks.fail(
            "continuum.steady",
            Verdict::Suspect,
            steps.unwrap_or(0) as f64,
            MAX_STEPS as f64,
            format!(
                "Gerris stopped at its step limit ({MAX_STEPS}) before U changed by less than {STEADY_TOLERANCE:e} of the surface velocity per 10 steps: not steady"
            ),
        );
    }
    let i_theta = cfg.i_theta;
    if let Some(limit) = cfg.rheology.validity_max() {
        if i_theta > limit {
            cfg.warnings.push(format!(
                "the slope's I = {i_theta:.3} is above the law's calibrated range (I ≤ {limit:.3}, {:.1} × the limit): the whole layer flows on the law's extrapolation",
                i_theta / limit
            ));
            checks.fail(
                "continuum.validity_range",
                Verdict::Suspect,
                1.0,
                super::column::VALIDITY_SUSPECT,
                format!("the whole layer flows at I = {i_theta:.3}, above the law's calibrated I = {limit:.3}"),
            );
        }
    }
    checks
}

/// The DEM's profile against Gerris' and Bagnold's: the rows of `comparison.csv` and the
/// summary's `dem` object (both empty without a DEM run).
fn dem_comparison(
    cfg: &InclinedConfig,
    gerris_profile: &[(f64, f64)],
) -> (Vec<DemRow>, Option<Value>) {
    let (depth, uv, flow) = (cfg.depth, cfg.uv, &cfg.flow);
    let dem_rows: Vec<DemRow> = cfg
        .dem
        .as_ref()
        .map(|d| {
            d.profile
                .iter()
                .map(|&(z, u)| DemRow {
                    height_m: z,
                    velocity_dem_m_s: u,
                    velocity_gerris_m_s: interpolate(gerris_profile, z / depth) * uv,
                    velocity_bagnold_m_s: flow.velocity(z),
                })
                .collect()
        })
        .unwrap_or_default();
    let dem_json = cfg.dem.as_ref().map(|d| {
        let us = d.profile.iter().map(|p| p.1).fold(f64::NAN, f64::max);
        let rms = (dem_rows
            .iter()
            .map(|r| (r.velocity_gerris_m_s - r.velocity_dem_m_s).powi(2))
            .sum::<f64>()
            / dem_rows.len().max(1) as f64)
            .sqrt();
        json!({
            "dir": d.dir.display().to_string(),
            "dem_surface_velocity_m_s": us,
            "gerris_surface_velocity_m_s": gerris_profile.last().map_or(f64::NAN, |p| p.1) * uv,
            "bagnold_surface_velocity_m_s": flow.surface_velocity(),
            "rms_difference_gerris_minus_dem_m_s": rms,
            "rms_difference_over_dem_surface_velocity": rms / us,
            "dem_packing_fraction": d.packing_fraction,
        })
    });
    (dem_rows, dem_json)
}

/// `velocity.png`: Bagnold's profile, Gerris' and the DEM's.
fn velocity_figure(
    out: &mut OutputDir,
    plan: &InclinedPlan,
    cfg: &InclinedConfig,
    table: &[ProfileRow],
) -> Result<()> {
    let (law, i_theta) = (&cfg.law, cfg.i_theta);
    let mut plot = XyPlot::new(
        &format!(
            "Steady flow down a {}° slope: μ(I) in Gerris, Bagnold, DEM",
            cfg.slope_deg
        ),
        Axis::new("velocity along the slope u (m/s)"),
        Axis::new("height above the base z (m)"),
    );
    plot.legend = LegendAt::LowerRight;
    plot.series.push(Series::new(
        &format!("Bagnold, analytic (I = {i_theta:.3})"),
        Style::Line,
        PALETTE[6],
        cfg.flow
            .profile(200)
            .into_iter()
            .map(|(z, u)| (u, z))
            .collect(),
    ));
    plot.series.push(Series::new(
        &format!(
            "Gerris, level {} ({} cells across)",
            plan.inputs.level,
            1u32 << plan.inputs.level
        ),
        Style::Circles,
        PALETTE[0],
        table
            .iter()
            .map(|r| (r.velocity_gerris_m_s, r.height_m))
            .collect(),
    ));
    if let Some(d) = &cfg.dem {
        plot.series.push(Series::new(
            "DEM (inclined-flow, time average)",
            Style::Points,
            PALETTE[1],
            d.profile.iter().map(|&(z, u)| (u, z)).collect(),
        ));
    }
    plot.notes.push(format!(
        "{}: {}; φ = {:.3}, H = {:.2} mm, d = {:.2} mm",
        law.law,
        law.parameters
            .iter()
            .map(|p| format!("{} = {:.3}", p.name, p.value))
            .collect::<Vec<_>>()
            .join(", "),
        cfg.phi,
        cfg.depth * 1e3,
        cfg.d_m * 1e3
    ));
    draw_xy(out, "velocity.png", &plot)
}

/// `summary.json` of the run.
fn inclined_summary(
    plan: &InclinedPlan,
    cfg: &InclinedConfig,
    run: &InclinedRun,
    dem_json: Option<&Value>,
    verdict: &RunVerdict,
) -> Summary {
    let rheology = &cfg.rheology;
    let mut s = gerris::summary_head(
        "continuum-inclined-plane",
        &run.run,
        &cfg.law_path,
        &cfg.law.law,
    );
    s.num("slope_deg", cfg.slope_deg)
        .num("depth_m", cfg.depth)
        .num("packing_fraction", cfg.phi)
        .num("inertial_number", cfg.i_theta)
        .num("bagnold_surface_velocity_m_s", cfg.flow.surface_velocity())
        .num("gerris_surface_velocity_m_s", run.surface_velocity(cfg.uv))
        .num("max_relative_error_vs_bagnold", run.max_err)
        .num("rms_relative_error_vs_bagnold", run.rms_err)
        .set(
            "gerris",
            json!({
                "case": "gerris/inclined.gfs",
                "level": plan.inputs.level,
                "cells_across": 1u32 << plan.inputs.level,
                "steps": run.steps,
                "units": rheology.units,
                "grain_diameter_over_H": rheology.grain_diameter(),
                "regularisation": rheology.regularisation,
            }),
        );
    if let Some(j) = dem_json {
        s.set("dem", j.clone());
    }
    verdict.keys(&mut s);
    s.set("warnings", Value::from(cfg.warnings.clone()));
    s.text("grainlaw_version", identify::law::GRAINLAW_VERSION);
    s
}

/// The report printed on stdout.
fn inclined_lines(
    plan: &InclinedPlan,
    cfg: &InclinedConfig,
    run: &InclinedRun,
    dem_json: Option<&Value>,
    verdict: &RunVerdict,
) -> Vec<String> {
    let mut lines = vec![
        format!("report: {}/", plan.inputs.out.display()),
        format!(
            "{} on a {}° slope (tan θ = {:.4}): I = {:.4}; layer H = {:.2} mm = {:.1} d, φ = {:.3}",
            cfg.law.law,
            cfg.slope_deg,
            cfg.theta.tan(),
            cfg.i_theta,
            cfg.depth * 1e3,
            cfg.depth / cfg.d_m,
            cfg.phi
        ),
        format!(
            "Gerris level {} ({} cells across), {} steps, {:.1} s: surface velocity {:.4} m/s, Bagnold {:.4} m/s; largest difference {:.2e} of it (RMS {:.2e})",
            plan.inputs.level,
            1u32 << plan.inputs.level,
            run.steps.map_or("?".into(), |s| s.to_string()),
            run.run.wall_seconds,
            run.surface_velocity(cfg.uv),
            cfg.flow.surface_velocity(),
            run.max_err,
            run.rms_err
        ),
    ];
    if let Some(j) = dem_json {
        lines.push(format!(
            "DEM surface velocity {:.4} m/s; RMS difference Gerris − DEM {:.4} m/s ({:.0} % of the DEM's surface velocity)",
            j["dem_surface_velocity_m_s"].as_f64().unwrap_or(f64::NAN),
            j["rms_difference_gerris_minus_dem_m_s"].as_f64().unwrap_or(f64::NAN),
            100.0 * j["rms_difference_over_dem_surface_velocity"].as_f64().unwrap_or(f64::NAN)
        ));
    }
    lines.extend(verdict.lines());
    lines
}

/// The last `step: N` of Gerris' progress lines in `log`.
fn last_step(log: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(log).ok()?;
    text.lines().rev().find_map(|l| {
        l.trim()
            .strip_prefix("step:")
            .and_then(|r| r.split_whitespace().next())
            .and_then(|n| n.parse().ok())
    })
}
