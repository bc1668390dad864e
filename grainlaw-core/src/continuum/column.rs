//! `grainlaw continuum column-collapse`: a calibrated μ(I) law run by Gerris on the 2D
//! collapse of a granular column, its front and profiles, the comparison with a DEM run, and
//! the band of the law's uncertainty (`docs/continuum.md`).

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde_json::{json, Value};

use identify::law::CalibratedLaw;

use super::band::{self, Band, ParameterSet};
use super::dem_column::{self, DemColumn, FrontRow, Profile, ProfileRow};
use super::gerris;
use super::gfs::{ColumnCase, ReferenceInstant, SNAPSHOT_DIR};
use super::inputs::CaseInputs;
use super::rheology::{load_continuum_law, GerrisRheology, LightPhase};
use super::snapshot::{self, InertialStatistics, Snapshot};
use crate::error::{CliError, Result};
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{draw_xy, Axis, Band as PlotBand, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::verdict::{Checks, RunVerdict, Verdict};

/// The reference instants `t*` of Lagrée, Staron & Popinet (2011) and the DEM contract.
pub const REFERENCE_INSTANTS: [f64; 5] = [0.66, 0.95, 1.24, 1.52, 2.28];
/// Aspect ratio without a DEM run or `--aspect-ratio`: the Gerris example's 6.26.
pub const DEFAULT_ASPECT_RATIO: f64 = 6.26;
/// `d/R₀` without a DEM run or `--half-width`: the Gerris example's 0.04623 (Staron's grains).
pub const DEFAULT_DIAMETER_OVER_HALF_WIDTH: f64 = 0.04623;
/// End of the run in `t*` without a DEM rest time or `--t-end`.
pub const DEFAULT_END_T_STAR: f64 = 4.0;
/// Interval of the front history in `t*`.
pub const HISTORY_INTERVAL_T_STAR: f64 = 0.02;
/// Default refinement level.
pub const DEFAULT_LEVEL: u32 = 8;
/// Default viscosity cap (Gerris units), the Gerris example's.
pub const DEFAULT_VISCOSITY_CAP: f64 = 10.0;
/// Change of the grains' area over the run above which the run is suspect (1).
pub const MASS_SUSPECT: f64 = 0.02;
/// Change of the grains' area above which the run is refused (1).
pub const MASS_REFUSED: f64 = 0.10;
/// Area fraction of the grains flowing above the law's calibrated `I` (at the worst instant)
/// above which the run is suspect: its result then rests on the law's extrapolation
/// (`docs/continuum.md` §6).
pub const VALIDITY_SUSPECT: f64 = 0.10;

/// What `grainlaw continuum column-collapse` runs.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnPlan {
    /// Law, output, DEM run (a `column-collapse` output directory), `φ` (default: the DEM's
    /// initial one), level, viscosity cap, Gerris command, suspect policy.
    pub inputs: CaseInputs,
    /// Aspect ratio `a` (default: the DEM's, else [`DEFAULT_ASPECT_RATIO`]).
    pub aspect_ratio: Option<f64>,
    /// Initial half-width `R₀` (m) (default: the DEM's, else `d/0.04623`).
    pub half_width_m: Option<f64>,
    /// Side of the square domain in units of `R₀` (default [`default_domain`]).
    pub domain: Option<f64>,
    /// End of the run in `t*` (default: the DEM's rest, else [`DEFAULT_END_T_STAR`]).
    pub end_t_star: Option<f64>,
    /// Also run the law's uncertainty band.
    pub band: bool,
    /// Gerris runs at once for the band (≥ 1).
    pub jobs: usize,
}

impl ColumnPlan {
    /// The plan with the defaults for `law` and `out`.
    pub fn new(law: PathBuf, out: PathBuf) -> Self {
        ColumnPlan {
            inputs: CaseInputs::new(law, out, DEFAULT_LEVEL, DEFAULT_VISCOSITY_CAP),
            aspect_ratio: None,
            half_width_m: None,
            domain: None,
            end_t_star: None,
            band: false,
            jobs: 1,
        }
    }
}

/// The side of the square domain for aspect ratio `a` (units of `R₀`): the smallest power of two
/// at least `max(2.5 a, 1.2 a, 4)`; the runout of a 2D column is about `1 + 2.5 a^{2/3}`
/// (Lube et al. 2005; Staron & Hinch 2005), below `2.5 a` for `a ≥ 1`, and the continuum's
/// thin front spreads further.
pub fn default_domain(a: f64) -> f64 {
    let need = (2.5 * a).max(4.0);
    2f64.powi(need.log2().ceil() as i32)
}

/// A finished continuum column run.
#[derive(Debug, Clone)]
pub struct ColumnOutcome {
    /// The report printed on stdout.
    pub lines: Vec<String>,
    /// Warnings (printed on stderr as `warning: …`).
    pub warnings: Vec<String>,
    /// The verdict.
    pub verdict: RunVerdict,
    /// `summary.json`'s content.
    pub summary: Value,
    /// The output directory.
    pub dir: PathBuf,
}

/// A height profile `(x, h)` at a labelled Gerris time.
type LabelledProfile = (String, f64, Vec<(f64, f64)>);

/// One Gerris run of the column, read back (Gerris units).
#[derive(Debug, Clone)]
struct CaseResult {
    /// `(t, x_f)` every history snapshot.
    front: Vec<(f64, f64)>,
    /// `(label, t, profile)` at the reference instants and `end`.
    profiles: Vec<LabelledProfile>,
    /// Area of the grains at the start and at the end.
    area: (f64, f64),
    /// The law's `I` at every history snapshot.
    inertial: Vec<InertialStatistics>,
    /// Largest speed in a cell full of grains at the end.
    end_speed: f64,
    /// The run.
    run: gerris::GerrisRun,
}

/// The resolved set-up of a run.
#[derive(Debug, Clone)]
struct Setup {
    aspect_ratio: f64,
    half_width_m: f64,
    domain: f64,
    end_t_star: f64,
    threshold: f64,
    references: Vec<(String, f64)>,
}

impl Setup {
    fn time_scale(&self) -> f64 {
        self.aspect_ratio.sqrt()
    }
}

/// The resolved inputs of a column run: the law, the DEM run, the set-up and the rheology.
struct ColumnConfig {
    /// The law file, as given.
    law_path: String,
    /// The law.
    law: CalibratedLaw,
    /// The DEM run to compare with.
    dem: Option<DemColumn>,
    /// The law's grain diameter `d` (m).
    d_m: f64,
    /// Gravity (m/s²).
    g: f64,
    /// Packing fraction `φ` of the continuum.
    phi: f64,
    /// Side of a cell (units of `R₀`).
    cell: f64,
    /// The law as Gerris runs it.
    rheology: GerrisRheology,
    /// The resolved set-up.
    setup: Setup,
    /// Warnings so far.
    warnings: Vec<String>,
}

/// What the central run measured for the report and summary.
struct CentralMeasures {
    /// Relative change of the grains' area over the run.
    mass_change: f64,
    /// The front at the end (units of `R₀`).
    end_front: f64,
    /// The height at `x = 0` at the end (units of `R₀`).
    end_height: f64,
    /// Front speed at the end (`R₀` per unit `t*`).
    speed: f64,
}

/// Runs the column collapse of `plan` (module documentation). Errors: [`CliError::Input`] /
/// [`CliError::Usage`] for bad input (exit 2), [`CliError::ExternalSolver`] when Gerris is
/// missing or fails (exit 3, the case left in `OUT/gerris`), [`CliError::Io`] for files.
///
/// Stages: config (`resolve_config`) → the central Gerris run → its tables → checks →
/// comparison with the DEM → band → figures → summary and report.
pub fn column_collapse(plan: &ColumnPlan) -> Result<ColumnOutcome> {
    crate::plot::init_font();
    let mut cfg = resolve_config(plan)?;
    plan.inputs.check_out("continuum-column-collapse")?;
    let started = std::time::Instant::now();
    let mut out = OutputDir::create(&plan.inputs.out)?;
    let gerris_cmd = gerris::command(plan.inputs.gerris.as_deref());
    let comments = run_comments(plan, &cfg);
    let central = run_case(
        &cfg.rheology,
        &cfg.setup,
        plan.inputs.level,
        &comments,
        &plan.inputs.out.join("gerris"),
        &gerris_cmd,
    )?;
    let (front_rows, cont_profiles) = write_central(&mut out, &central, &cfg)?;
    let (checks, measures, validity) = check_central(&mut cfg, &central);
    let comparison = match &cfg.dem {
        Some(d) => Some(write_comparison(
            &mut out,
            compare(d, &front_rows, &cont_profiles, &cfg.setup),
        )?),
        None => None,
    };
    let band = if plan.band {
        Some(run_band(
            plan,
            &cfg.rheology,
            &cfg.setup,
            &central,
            &comments,
            &gerris_cmd,
            cfg.dem.as_ref(),
            &mut out,
        )?)
    } else {
        None
    };
    front_figure(
        &mut out,
        &front_rows,
        cfg.dem.as_ref(),
        band.as_ref(),
        &cfg.setup,
    )?;
    profiles_figure(&mut out, &cont_profiles, cfg.dem.as_ref(), &cfg.setup)?;
    let verdict = RunVerdict {
        run: checks,
        laws: Vec::new(),
        allow_suspect: plan.inputs.allow_suspect,
    };
    let report = ColumnReport {
        plan,
        cfg: &cfg,
        central: &central,
        measures: &measures,
        validity: &validity,
        comparison: comparison.as_ref(),
        band: band.as_ref(),
        verdict: &verdict,
    };
    let mut s = report.summary();
    s.num("wall_seconds", started.elapsed().as_secs_f64());
    s.text("grainlaw_version", identify::law::GRAINLAW_VERSION);
    out.write("summary.json", s.to_json().as_bytes())?;
    let lines = report.lines();
    Ok(ColumnOutcome {
        lines,
        warnings: cfg.warnings,
        verdict,
        summary: serde_json::from_str(&s.to_json()).unwrap_or(Value::Null),
        dir: plan.inputs.out.clone(),
    })
}

/// Reads the law and the DEM run and resolves the set-up of `plan` (aspect ratio, `R₀`, `φ`,
/// domain, end, reference instants) and the rheology. Errors: [`CliError::Usage`] for a bad
/// setting, those of the readers for bad files.
fn resolve_config(plan: &ColumnPlan) -> Result<ColumnConfig> {
    let law_path = plan.inputs.law.display().to_string();
    let law = load_continuum_law(&plan.inputs.law)?;
    let dem = plan
        .inputs
        .dem
        .as_deref()
        .map(DemColumn::read)
        .transpose()?;
    let mut warnings = Vec::new();
    if !(3..=12).contains(&plan.inputs.level) {
        return Err(CliError::Usage(format!(
            "--level must lie in 3..=12, got {}",
            plan.inputs.level
        )));
    }
    if plan.jobs == 0 {
        return Err(CliError::Usage("--jobs must be at least 1".into()));
    }
    let d_m = law.constant("d").unwrap_or(f64::NAN);
    let ds = dem.as_ref().map(|d| &d.summary);
    let a =
        match (plan.aspect_ratio, ds) {
            (Some(a), Some(s)) if (a - s.aspect_ratio).abs() > 1e-6 * s.aspect_ratio => {
                return Err(CliError::Usage(format!(
                "--aspect-ratio {a} differs from the DEM run's {} ({}): leave it out to compare",
                s.aspect_ratio,
                dem.as_ref().map(|d| d.dir.display().to_string()).unwrap_or_default()
            )))
            }
            (Some(a), _) => a,
            (None, Some(s)) => s.aspect_ratio,
            (None, None) => DEFAULT_ASPECT_RATIO,
        };
    positive("--aspect-ratio", a)?;
    let r0 = match (plan.half_width_m, ds) {
        (Some(r), _) => r,
        (None, Some(s)) => s.initial_half_width_m,
        (None, None) => d_m / DEFAULT_DIAMETER_OVER_HALF_WIDTH,
    };
    positive("--half-width", r0)?;
    let phi = plan
        .inputs
        .packing_fraction
        .or(ds.map(|s| s.initial_packing_fraction))
        .ok_or_else(|| {
            CliError::Usage(
                "the continuum's packing fraction is needed (its density is φ ρ_s, and I_Gerris = √φ I): give --packing-fraction or --dem".into(),
            )
        })?;
    let g = ds.map_or(9.81, |s| s.gravity_m_s2);
    if let Some(s) = ds {
        dem_grain_warnings(&law, s, d_m, r0, &mut warnings);
    }
    let domain = plan.domain.unwrap_or_else(|| default_domain(a));
    if !(domain.is_finite() && domain > 1.2 * a.max(1.0)) {
        return Err(CliError::Usage(format!(
            "--domain {domain} must exceed 1.2 × max(a, 1) = {} (units of R0)",
            1.2 * a.max(1.0)
        )));
    }
    let references: Vec<f64> = ds
        .map(|s| s.reference_instants_t_star.clone())
        .filter(|r| !r.is_empty())
        .unwrap_or_else(|| REFERENCE_INSTANTS.to_vec());
    let end_t_star = plan
        .end_t_star
        .or(ds.and_then(|s| s.rest_t_star()))
        .unwrap_or(DEFAULT_END_T_STAR);
    positive("--t-end", end_t_star)?;
    let rheology = GerrisRheology::new(
        law.clone(),
        &law_path,
        r0,
        g,
        phi,
        plan.inputs.viscosity_cap,
    )?;
    let cell = domain / f64::from(1u32 << plan.inputs.level);
    let setup = Setup {
        aspect_ratio: a,
        half_width_m: r0,
        domain,
        end_t_star,
        threshold: rheology.grain_diameter().max(cell),
        references: references
            .iter()
            .filter(|t| **t < end_t_star)
            .map(|t| (format!("t{t}"), *t))
            .collect(),
    };
    if setup.references.len() < references.len() {
        warnings.push(format!(
            "the run ends at t* = {end_t_star}: the reference instants after it are left out"
        ));
    }
    Ok(ColumnConfig {
        law_path,
        law,
        dem,
        d_m,
        g,
        phi,
        cell,
        rheology,
        setup,
        warnings,
    })
}

/// Warnings when the law's grains (diameter `d_m`, density) differ from the DEM run's by more
/// than 5 %.
fn dem_grain_warnings(
    law: &CalibratedLaw,
    s: &dem_column::ColumnSummary,
    d_m: f64,
    r0: f64,
    warnings: &mut Vec<String>,
) {
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    if rel(d_m, s.mean_diameter_m) > 0.05 {
        warnings.push(format!(
            "the law's grain diameter d = {d_m:.4e} m differs from the DEM grains' {:.4e} m by {:.0} %: the law is used with its own d (D = d/R0 = {:.4})",
            s.mean_diameter_m,
            100.0 * rel(d_m, s.mean_diameter_m),
            d_m / r0
        ));
    }
    let rho = law.constant("rho_s").unwrap_or(f64::NAN);
    if rel(rho, s.grain_density_kg_m3) > 0.05 {
        warnings.push(format!(
            "the law's grain density {rho} kg/m³ differs from the DEM grains' {} kg/m³",
            s.grain_density_kg_m3
        ));
    }
}

/// The comment lines at the head of the Gerris case.
fn run_comments(plan: &ColumnPlan, cfg: &ColumnConfig) -> Vec<String> {
    vec![
        format!(
            "grainlaw {} continuum column-collapse: the {} law of {}",
            identify::law::GRAINLAW_VERSION,
            cfg.law.law,
            cfg.law_path
        ),
        format!(
            "column a = H0/R0 = {}, R0 = {} m, level {} in a domain of {} R0 (cells {} R0)",
            cfg.setup.aspect_ratio,
            cfg.setup.half_width_m,
            plan.inputs.level,
            cfg.setup.domain,
            cfg.cell
        ),
    ]
}

/// Writes the central run's `front.csv` and `profiles.csv` (SI units); returns the front rows
/// and the profiles by label.
fn write_central(
    out: &mut OutputDir,
    central: &CaseResult,
    cfg: &ColumnConfig,
) -> Result<(Vec<FrontRow>, std::collections::BTreeMap<String, Profile>)> {
    let setup = &cfg.setup;
    let r0 = setup.half_width_m;
    let ts = cfg.rheology.units.time_s();
    let front_rows: Vec<FrontRow> = central
        .front
        .iter()
        .map(|&(t, x)| FrontRow {
            t_s: t * ts,
            t_star: t / setup.time_scale(),
            x_f_m: x * r0,
        })
        .collect();
    let mut profile_rows = Vec::new();
    for (label, t, p) in &central.profiles {
        for &(x, h) in p {
            profile_rows.push(ProfileRow {
                label: label.clone(),
                t_star: t / setup.time_scale(),
                x_m: x * r0,
                h_m: h * r0,
            });
        }
    }
    dem_column::write_front(
        out,
        &front_rows,
        &format!(
            "continuum (Gerris) column collapse: front x_f where the height exceeds {:.4e} m (max(d, cell)); t* = t sqrt(g/H0)",
            setup.threshold * r0
        ),
    )?;
    dem_column::write_profiles(
        out,
        &profile_rows,
        "continuum (Gerris) column collapse: height of the grains h(x) = sum of T dy over each column of cells, at the reference instants and at the end (label end)",
    )?;
    let cont_profiles = dem_column::group_profiles(profile_rows.clone());
    Ok((front_rows, cont_profiles))
}

/// The checks of the central run (mass, domain, validity range; warnings into `cfg`), what
/// it measured, and the validity report.
fn check_central(cfg: &mut ColumnConfig, central: &CaseResult) -> (Checks, CentralMeasures, Value) {
    let (domain, cell, r0) = (cfg.setup.domain, cfg.cell, cfg.setup.half_width_m);
    let mut checks = Checks::new();
    let mass_change = (central.area.1 - central.area.0) / central.area.0;
    checks.at_most(
        "continuum.mass",
        mass_change.abs(),
        MASS_SUSPECT,
        Some(MASS_REFUSED),
        |t| {
            format!(
                "the grains' area changed by {:.2} % over the run (limit {:.0} %): the VOF tracer lost or gained mass",
                100.0 * mass_change,
                100.0 * t
            )
        },
    );
    let max_front = central.front.iter().map(|p| p.1).fold(0.0, f64::max);
    let wall_gap = (domain - max_front) / cell;
    if wall_gap < 4.0 {
        checks.fail(
            "continuum.domain",
            Verdict::Refused,
            max_front * r0,
            (domain - 4.0 * cell) * r0,
            format!(
                "the front reached x = {:.3} R0, within {wall_gap:.1} cells of the domain's wall at {domain} R0: rerun with a larger --domain",
                max_front
            ),
        );
    }
    let validity = validity_report(
        &cfg.rheology,
        &central.inertial,
        &cfg.setup,
        &mut checks,
        &mut cfg.warnings,
    );
    let measures = CentralMeasures {
        mass_change,
        end_front: central.front.last().map_or(f64::NAN, |p| p.1),
        end_height: central
            .profiles
            .iter()
            .find(|p| p.0 == "end")
            .and_then(|p| p.2.first())
            .map_or(f64::NAN, |p| p.1),
        speed: front_speed(&central.front, cfg.setup.time_scale()),
    };
    (checks, measures, validity)
}

/// Writes `comparison.csv` and `comparison.json` of `c`; returns it.
fn write_comparison(out: &mut OutputDir, c: Comparison) -> Result<Comparison> {
    dem_column::write_rows(
        out,
        "comparison.csv",
        &c.rows,
        "continuum minus DEM at each reference instant and at rest (rest: DEM at rest, continuum at its end); x_f where the height exceeds the threshold; h differences over the DEM's bins up to the larger front",
    )?;
    out.write(
        "comparison.json",
        (serde_json::to_string_pretty(&c.to_json())
            .map_err(|e| CliError::io(out.file("comparison.json"), e))?
            + "\n")
            .as_bytes(),
    )?;
    Ok(c)
}

/// Everything the summary and the report of a column run draw on.
struct ColumnReport<'a> {
    /// The plan run.
    plan: &'a ColumnPlan,
    /// Its resolved inputs.
    cfg: &'a ColumnConfig,
    /// The central Gerris run.
    central: &'a CaseResult,
    /// What the central run measured.
    measures: &'a CentralMeasures,
    /// The validity report ([`validity_report`]).
    validity: &'a Value,
    /// The comparison with the DEM run, if any.
    comparison: Option<&'a Comparison>,
    /// The band of the law's uncertainty, if run.
    band: Option<&'a BandResult>,
    /// The verdict.
    verdict: &'a RunVerdict,
}

impl ColumnReport<'_> {
    /// `summary.json` without its wall time and version.
    fn summary(&self) -> Summary {
        let (cfg, central, m) = (self.cfg, self.central, self.measures);
        let (rheology, setup) = (&cfg.rheology, &cfg.setup);
        let (a, r0, domain, cell) = (
            setup.aspect_ratio,
            setup.half_width_m,
            setup.domain,
            cfg.cell,
        );
        let ts = rheology.units.time_s();
        let mut s = gerris::summary_head(
            "continuum-column-collapse",
            &central.run,
            &cfg.law_path,
            &cfg.law.law,
        );
        s.set("law_parameters", parameters_json(&cfg.law))
            .set(
                "column",
                json!({
                    "initial_half_width_m": r0,
                    "initial_height_m": a * r0,
                    "aspect_ratio": a,
                    "mean_diameter_m": cfg.d_m,
                    "gravity_m_s2": cfg.g,
                    "grain_density_kg_m3": rheology.grain_density_kg_m3(),
                    "initial_packing_fraction": cfg.phi,
                    "runout_m": m.end_front * r0,
                    "final_height_m": m.end_height * r0,
                    "end_time_s": setup.end_t_star * a.sqrt() * ts,
                    "end_t_star": setup.end_t_star,
                    "front_speed_at_end_m_s": m.speed * r0 / ts / a.sqrt(),
                    "reference_instants_t_star": setup.references.iter().map(|r| r.1).collect::<Vec<_>>(),
                }),
            )
            .set(
                "gerris",
                json!({
                    "case": "gerris/column.gfs",
                    "level": self.plan.inputs.level,
                    "domain_R0": domain,
                    "cell_R0": cell,
                    "cell_over_d": cell / rheology.grain_diameter(),
                    "front_threshold_m": setup.threshold * r0,
                    "units": rheology.units,
                    "grain_diameter_over_R0": rheology.grain_diameter(),
                    "regularisation": rheology.regularisation,
                    "light_phase": LightPhase::default(),
                    "grain_area_change": m.mass_change,
                    "max_speed_at_end_m_s": central.end_speed * rheology.units.velocity_m_s(),
                }),
            )
            .set("validity", self.validity.clone());
        if let Some(c) = self.comparison {
            s.set("comparison", c.to_json());
            s.text(
                "dem_dir",
                &cfg.dem
                    .as_ref()
                    .map(|d| d.dir.display().to_string())
                    .unwrap_or_default(),
            );
        }
        if let Some(b) = self.band {
            s.set("band", b.json.clone());
        }
        self.verdict.keys(&mut s);
        s.set("warnings", Value::from(cfg.warnings.clone()));
        s
    }

    /// The report printed on stdout.
    fn lines(&self) -> Vec<String> {
        let (plan, cfg, central, m) = (self.plan, self.cfg, self.central, self.measures);
        let (law, rheology, setup) = (&cfg.law, &cfg.rheology, &cfg.setup);
        let (a, domain, cell) = (setup.aspect_ratio, setup.domain, cfg.cell);
        let mut lines = vec![format!("report: {}/", plan.inputs.out.display())];
        lines.push(format!(
            "law {} of {}: {}",
            law.law,
            cfg.law_path,
            law.parameters
                .iter()
                .map(|p| format!("{} = {:.4}", p.name, p.value))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        lines.push(format!(
            "column a = {a}, R0 = {:.4} m, φ = {:.3}, d/R0 = {:.4}; Gerris level {} in {domain} R0 (cell {cell:.4} R0 = {:.2} d), {:.1} s",
            setup.half_width_m,
            cfg.phi,
            rheology.grain_diameter(),
            plan.inputs.level,
            cell / rheology.grain_diameter(),
            central.run.wall_seconds
        ));
        lines.push(format!(
            "front x_f/R0 at t* = {}: {}",
            setup
                .references
                .iter()
                .map(|r| format!("{}", r.1))
                .collect::<Vec<_>>()
                .join(", "),
            setup
                .references
                .iter()
                .map(|r| format!(
                    "{:.2}",
                    interpolate(&central.front, r.1 * setup.time_scale())
                ))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        lines.push(format!(
            "at t* = {}: x_f = {:.3} R0, h(0) = {:.3} R0, front speed {:.3} R0 per unit t*",
            setup.end_t_star, m.end_front, m.end_height, m.speed
        ));
        if let Some(c) = self.comparison {
            lines.extend(c.lines());
        }
        if let Some(b) = self.band {
            lines.extend(b.lines.clone());
        }
        lines.extend(self.verdict.lines());
        lines
    }
}

fn positive(name: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "{name} must be a finite number > 0, got {v}"
        )))
    }
}

/// Writes the case into `dir` (stale snapshots removed), runs Gerris, reads the snapshots.
fn run_case(
    rheology: &GerrisRheology,
    setup: &Setup,
    level: u32,
    comments: &[String],
    dir: &Path,
    gerris_cmd: &Path,
) -> Result<CaseResult> {
    let k = setup.time_scale();
    let case = ColumnCase {
        rheology: rheology.clone(),
        light: LightPhase::default(),
        aspect_ratio: setup.aspect_ratio,
        domain: setup.domain,
        level,
        end: setup.end_t_star * k,
        history_interval: HISTORY_INTERVAL_T_STAR * k,
        references: setup
            .references
            .iter()
            .map(|(l, t)| ReferenceInstant {
                label: l.clone(),
                time: t * k,
            })
            .collect(),
        comments: comments.to_vec(),
    };
    let snaps = dir.join(SNAPSHOT_DIR);
    if snaps.exists() {
        std::fs::remove_dir_all(&snaps).map_err(|e| CliError::io(&snaps, e))?;
    }
    std::fs::create_dir_all(&snaps).map_err(|e| CliError::io(&snaps, e))?;
    crate::output::dir::write_atomic(&dir.join("column.gfs"), case.to_gfs()?.as_bytes())?;
    let run = gerris::run(gerris_cmd, dir, "column.gfs")?;
    read_case(&case, dir, run)
}

/// Reads a finished case's snapshots.
fn read_case(case: &ColumnCase, dir: &Path, run: gerris::GerrisRun) -> Result<CaseResult> {
    let cell = case.cell_size();
    let threshold = case.rheology.grain_diameter().max(cell);
    let limit = case.rheology.validity_max().unwrap_or(f64::INFINITY);
    let snaps = dir.join(SNAPSHOT_DIR);
    let mut history: Vec<(f64, PathBuf)> = Vec::new();
    for e in std::fs::read_dir(&snaps).map_err(|e| CliError::io(&snaps, e))? {
        let p = e.map_err(|e| CliError::io(&snaps, e))?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if let Some(step) = name
            .strip_prefix("history-")
            .and_then(|n| n.strip_suffix(".txt"))
            .and_then(|n| n.parse::<u64>().ok())
        {
            history.push((step as f64, p));
        }
    }
    history.sort_by(|a, b| a.0.total_cmp(&b.0));
    if history.is_empty() {
        return Err(missing(dir, "no history snapshot"));
    }
    let mut front = Vec::new();
    let mut inertial = Vec::new();
    let mut area = (f64::NAN, f64::NAN);
    for (i, (_, p)) in history.iter().enumerate() {
        let s = Snapshot::read(p)?;
        let prof = s.height_profile(cell, &p.display().to_string())?;
        front.push((
            s.time,
            snapshot::front(&prof, threshold, cell).unwrap_or(0.0),
        ));
        if let Some(st) = s.inertial_statistics(cell, limit) {
            inertial.push(st);
        }
        if i == 0 {
            area.0 = s.grain_area(cell);
        }
    }
    let mut profiles = Vec::new();
    for r in &case.references {
        let p = dir.join(SNAPSHOT_DIR).join(format!("ref-{}.txt", r.label));
        if !p.is_file() {
            return Err(missing(dir, &format!("no snapshot {}", p.display())));
        }
        let s = Snapshot::read(&p)?;
        profiles.push((
            r.label.clone(),
            s.time,
            s.height_profile(cell, &p.display().to_string())?,
        ));
    }
    let endp = dir.join(SNAPSHOT_DIR).join("end.txt");
    if !endp.is_file() {
        return Err(missing(dir, "no end snapshot"));
    }
    let end = Snapshot::read(&endp)?;
    let end_profile = end.height_profile(cell, &endp.display().to_string())?;
    area.1 = end.grain_area(cell);
    // the front at the very end, if the last history snapshot is earlier
    if front.last().is_none_or(|f| f.0 < end.time - 1e-9) {
        front.push((
            end.time,
            snapshot::front(&end_profile, threshold, cell).unwrap_or(0.0),
        ));
    }
    let end_speed = end
        .cells
        .iter()
        .filter(|c| c.fraction > 0.999)
        .map(|c| c.u.hypot(c.v))
        .fold(0.0, f64::max);
    profiles.push(("end".to_string(), end.time, end_profile));
    Ok(CaseResult {
        front,
        profiles,
        area,
        inertial,
        end_speed,
        run,
    })
}

fn missing(dir: &Path, what: &str) -> CliError {
    CliError::ExternalSolver {
        solver: "gerris2D".into(),
        reason: format!("finished without its outputs ({what})"),
        dir: dir.display().to_string(),
        rerun: "gerris2D column.gfs".into(),
    }
}

/// `y(x)` of a polyline `(x, y)` sorted by `x`, linear between points, clamped at the ends.
pub fn interpolate(points: &[(f64, f64)], x: f64) -> f64 {
    match points.iter().position(|p| p.0 >= x) {
        None => points.last().map_or(f64::NAN, |p| p.1),
        Some(0) => points[0].1,
        Some(i) => {
            let (a, b) = (points[i - 1], points[i]);
            if b.0 == a.0 {
                b.1
            } else {
                a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
            }
        }
    }
}

/// Speed of the front over the last 0.2 of `t*` (units of `R₀` per unit `t*`).
fn front_speed(front: &[(f64, f64)], k: f64) -> f64 {
    let Some(&(t1, x1)) = front.last() else {
        return f64::NAN;
    };
    let t0 = t1 - 0.2 * k;
    let x0 = interpolate(front, t0);
    (x1 - x0) / 0.2
}

/// The validity check (`docs/continuum.md` §6): where and how far the run's `I` leaves the
/// law's calibrated range, a warning, and a suspect verdict above [`VALIDITY_SUSPECT`].
fn validity_report(
    r: &GerrisRheology,
    stats: &[InertialStatistics],
    setup: &Setup,
    checks: &mut Checks,
    warnings: &mut Vec<String>,
) -> Value {
    let k = setup.time_scale();
    let Some(limit) = r.validity_max() else {
        return json!({"calibrated_I_max": null, "note": "the law records no validity range in I"});
    };
    let top = stats.iter().max_by(|a, b| a.max.total_cmp(&b.max)).copied();
    let worst = stats
        .iter()
        .max_by(|a, b| a.fraction_above.total_cmp(&b.fraction_above))
        .copied();
    let (Some(top), Some(worst)) = (top, worst) else {
        return json!({"calibrated_I_max": limit, "note": "no cell full of grains"});
    };
    if top.max > limit {
        warnings.push(format!(
            "the run's inertial number leaves the law's calibrated range (I ≤ {limit:.3}): it reaches I = {:.3} ({:.1} × the limit) at x = {:.2} R0, y = {:.2} R0, t* = {:.2}; at worst {:.1} % of the grains' area flows above it (t* = {:.2})",
            top.max,
            top.max / limit,
            top.at.0,
            top.at.1,
            top.time / k,
            100.0 * worst.fraction_above,
            worst.time / k
        ));
    }
    checks.at_most(
        "continuum.validity_range",
        worst.fraction_above,
        VALIDITY_SUSPECT,
        None,
        |t| {
            format!(
                "{:.1} % of the grains' area flows above the law's calibrated I = {limit:.3} at t* = {:.2} (limit {:.0} %): the result rests on the law's extrapolation",
                100.0 * worst.fraction_above,
                worst.time / k,
                100.0 * t
            )
        },
    );
    json!({
        "calibrated_I_min": r.validity_min(),
        "calibrated_I_max": limit,
        "max_I": top.max,
        "max_I_over_calibrated": top.max / limit,
        "max_I_at_m": [top.at.0 * setup.half_width_m, top.at.1 * setup.half_width_m],
        "max_I_t_star": top.time / k,
        "worst_fraction_above": worst.fraction_above,
        "worst_fraction_t_star": worst.time / k,
        "fraction_above_history": stats.iter().map(|s| json!([s.time / k, s.fraction_above])).collect::<Vec<_>>(),
    })
}

/// One row of `comparison.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonRow {
    /// `t0.66`, …, `rest`.
    pub label: String,
    /// `t*` (the DEM's).
    pub t_star: f64,
    /// Continuum front (m).
    pub x_f_continuum_m: f64,
    /// DEM front (m).
    pub x_f_dem_m: f64,
    /// Continuum minus DEM (m).
    pub x_f_difference_m: f64,
    /// Difference over the DEM's front (1).
    pub x_f_relative_difference: f64,
    /// Root-mean-square height difference over the DEM's points up to the larger front (m).
    pub h_rms_difference_m: f64,
    /// Largest height difference there, continuum minus DEM (m, signed).
    pub h_max_difference_m: f64,
    /// Height at `x = 0`, continuum minus DEM (m).
    pub h0_difference_m: f64,
}

/// The comparison with a DEM run.
#[derive(Debug, Clone)]
struct Comparison {
    rows: Vec<ComparisonRow>,
    half_width_m: f64,
}

impl Comparison {
    fn to_json(&self) -> Value {
        json!({
            "rows": self.rows,
            "normalised_by": "R0",
            "initial_half_width_m": self.half_width_m,
        })
    }

    fn lines(&self) -> Vec<String> {
        let r0 = self.half_width_m;
        let mut v = vec![
            "vs DEM: label, t*, x_f/R0 continuum, DEM, difference; h RMS difference/R0".to_string(),
        ];
        for r in &self.rows {
            v.push(format!(
                "  {:<6} {:>5.2}  {:>6.2} {:>6.2} {:>+6.2} ({:+.0} %)  {:.3}",
                r.label,
                r.t_star,
                r.x_f_continuum_m / r0,
                r.x_f_dem_m / r0,
                r.x_f_difference_m / r0,
                100.0 * r.x_f_relative_difference,
                r.h_rms_difference_m / r0
            ));
        }
        v
    }
}

fn compare(
    dem: &DemColumn,
    cont_front: &[FrontRow],
    cont: &std::collections::BTreeMap<String, Profile>,
    setup: &Setup,
) -> Comparison {
    let cf: Vec<(f64, f64)> = cont_front.iter().map(|r| (r.t_star, r.x_f_m)).collect();
    let df: Vec<(f64, f64)> = dem.front.iter().map(|r| (r.t_star, r.x_f_m)).collect();
    let mut rows = Vec::new();
    let mut labels: Vec<(String, String, f64, f64)> = setup
        .references
        .iter()
        .map(|(l, t)| (l.clone(), l.clone(), *t, interpolate(&df, *t)))
        .collect();
    if dem.profiles.contains_key("rest") || dem.summary.runout_m.is_some() {
        labels.push((
            "rest".into(),
            "end".into(),
            dem.summary
                .rest_t_star()
                .or(dem.profiles.get("rest").map(|p| p.t_star))
                .unwrap_or(setup.end_t_star),
            dem.summary.runout_m.unwrap_or(f64::NAN),
        ));
    }
    for (dl, cl, t, xf_dem) in labels {
        let xf_c = if cl == "end" {
            cf.last().map_or(f64::NAN, |p| p.1)
        } else {
            interpolate(&cf, t)
        };
        let (rms, maxd, h0) = match (dem.profiles.get(&dl), cont.get(&cl)) {
            (Some(d), Some(c)) => profile_difference(&d.points, &c.points, xf_c.max(xf_dem)),
            _ => (f64::NAN, f64::NAN, f64::NAN),
        };
        rows.push(ComparisonRow {
            label: dl,
            t_star: t,
            x_f_continuum_m: xf_c,
            x_f_dem_m: xf_dem,
            x_f_difference_m: xf_c - xf_dem,
            x_f_relative_difference: (xf_c - xf_dem) / xf_dem,
            h_rms_difference_m: rms,
            h_max_difference_m: maxd,
            h0_difference_m: h0,
        });
    }
    Comparison {
        rows,
        half_width_m: setup.half_width_m,
    }
}

/// RMS and largest (signed) difference of `cont − dem` over the DEM's points with `x ≤ upto`
/// (continuum interpolated, 0 beyond its last column), and the difference at the first point.
fn profile_difference(dem: &[(f64, f64)], cont: &[(f64, f64)], upto: f64) -> (f64, f64, f64) {
    let last_x = cont.last().map_or(0.0, |p| p.0);
    let hc = |x: f64| {
        if x > last_x {
            0.0
        } else {
            interpolate(cont, x)
        }
    };
    let diffs: Vec<f64> = dem
        .iter()
        .filter(|p| p.0 <= upto)
        .map(|&(x, h)| hc(x) - h)
        .collect();
    if diffs.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    let maxd = diffs
        .iter()
        .copied()
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(f64::NAN);
    (rms, maxd, diffs[0])
}

fn parameters_json(law: &CalibratedLaw) -> Value {
    Value::Array(
        law.parameters
            .iter()
            .map(|p| json!({"name": p.name, "value": p.value, "ci_low": p.ci_low, "ci_high": p.ci_high}))
            .collect(),
    )
}

/// The band's runs and result.
#[derive(Debug, Clone)]
struct BandResult {
    /// `(t*, band of x_f (m))` on the central run's history.
    front: Vec<(f64, Band)>,
    json: Value,
    lines: Vec<String>,
}

/// What the band's Gerris runs gave: the central run and the others by label.
struct BandRuns<'a> {
    /// The central run.
    central: &'a CaseResult,
    /// The other runs by their set's label (`axis{k}±`).
    by_label: std::collections::BTreeMap<String, CaseResult>,
    /// Number of principal axes.
    n_axes: usize,
}

impl BandRuns<'_> {
    /// The band of the quantity `f` of a run (`None` when the central value is not finite).
    fn band_of(&self, f: &dyn Fn(&CaseResult) -> f64) -> Option<Band> {
        let value_of = |label: &str| -> Option<f64> { self.by_label.get(label).map(f) };
        let pairs: Vec<(Option<f64>, Option<f64>)> = (0..self.n_axes)
            .map(|a| {
                (
                    value_of(&format!("axis{}+", a + 1)),
                    value_of(&format!("axis{}-", a + 1)),
                )
            })
            .collect();
        Band::of(f(self.central), &pairs)
    }
}

/// Runs the band of the law's uncertainty: the sets along the covariance's principal axes
/// (stages: the runs → the front's band → the instants → `band.csv` → the report).
#[allow(clippy::too_many_arguments)]
fn run_band(
    plan: &ColumnPlan,
    rheology: &GerrisRheology,
    setup: &Setup,
    central: &CaseResult,
    comments: &[String],
    gerris_cmd: &Path,
    dem: Option<&DemColumn>,
    out: &mut OutputDir,
) -> Result<BandResult> {
    let sets = band::parameter_sets(&rheology.law, &rheology.law_path)?;
    let (by_label, skipped) = run_band_cases(plan, rheology, setup, comments, gerris_cmd, &sets)?;
    let runs = BandRuns {
        central,
        by_label,
        n_axes: sets
            .iter()
            .skip(1)
            .filter_map(|s| s.axis.map(|a| a.0))
            .max()
            .map_or(0, |m| m + 1),
    };
    let k = setup.time_scale();
    let r0 = setup.half_width_m;
    let front: Vec<(f64, Band)> = central
        .front
        .iter()
        .filter_map(|&(t, _)| {
            runs.band_of(&|c: &CaseResult| interpolate(&c.front, t) * r0)
                .map(|b| (t / k, b))
        })
        .collect();
    let (rows, inside_count) = band_instants(&runs, setup, dem);
    write_band_csv(out, &front)?;
    let run_list: Vec<Value> = sets
        .iter()
        .map(|s| {
            let r = if s.label == "central" {
                Some(central)
            } else {
                runs.by_label.get(&s.label)
            };
            json!({
                "label": s.label,
                "parameters": s.values,
                "run": r.is_some(),
                "runout_m": r.map(|c| c.front.last().map_or(f64::NAN, |p| p.1) * r0),
            })
        })
        .collect();
    let verdict_line = band_verdict_line(dem, inside_count);
    let mut lines = vec![format!(
        "band of the law's uncertainty: {} runs ({} sets, {} skipped as unphysical) along the covariance's principal axes at the law's {:.0} % interval",
        runs.by_label.len() + 1,
        sets.len(),
        skipped.len(),
        100.0 * rheology.law.fit.confidence
    )];
    lines.extend(rows.iter().map(|r| band_row_line(r, r0)));
    lines.push(verdict_line.clone());
    Ok(BandResult {
        front,
        json: json!({
            "method": "2p+1 runs: the law's estimate and ± t sqrt(lambda_k) e_k along the covariance's principal axes (t of the law's intervals); band = central ± sqrt(sum_k ((f+ - f-)/2)^2)",
            "confidence": rheology.law.fit.confidence,
            "runs": run_list,
            "skipped": skipped,
            "instants": rows,
            "dem_inside": inside_count.0,
            "dem_compared": inside_count.1,
            "verdict": verdict_line,
        }),
        lines,
    })
}

/// Runs the band's sets other than the central one, `plan.jobs` Gerris runs at once, each in
/// `OUT/band/LABEL`; returns the runs and the sets skipped as unphysical. The first failed
/// run's error is returned.
fn run_band_cases(
    plan: &ColumnPlan,
    rheology: &GerrisRheology,
    setup: &Setup,
    comments: &[String],
    gerris_cmd: &Path,
    sets: &[ParameterSet],
) -> Result<(std::collections::BTreeMap<String, CaseResult>, Vec<String>)> {
    let others: Vec<&ParameterSet> = sets.iter().skip(1).collect();
    let mut skipped = Vec::new();
    let mut jobs: Vec<(&ParameterSet, GerrisRheology)> = Vec::new();
    for s in &others {
        match rheology.with_parameter_values(&s.values) {
            Ok(r) => jobs.push((s, r)),
            Err(e) => skipped.push(format!("{}: {}", s.label, e.one_line())),
        }
    }
    let results: Vec<(String, Result<CaseResult>)> = {
        let queue = std::sync::Mutex::new(jobs.iter().collect::<Vec<_>>());
        let done = std::sync::Mutex::new(Vec::new());
        std::thread::scope(|sc| {
            for _ in 0..plan.jobs.min(jobs.len()).max(1) {
                sc.spawn(|| loop {
                    let next = queue.lock().map(|mut q| q.pop()).unwrap_or(None);
                    let Some((set, r)) = next else { break };
                    let dir = plan.inputs.out.join("band").join(&set.label);
                    let mut c = comments.to_vec();
                    c.push(format!(
                        "band run {}: parameters {:?}",
                        set.label, set.values
                    ));
                    let res = std::fs::create_dir_all(&dir)
                        .map_err(|e| CliError::io(&dir, e))
                        .and_then(|_| run_case(r, setup, plan.inputs.level, &c, &dir, gerris_cmd));
                    if let Ok(mut d) = done.lock() {
                        d.push((set.label.clone(), res));
                    }
                });
            }
        });
        done.into_inner().unwrap_or_default()
    };
    let mut by_label = std::collections::BTreeMap::new();
    for (label, r) in results {
        by_label.insert(label, r?);
    }
    Ok((by_label, skipped))
}

/// The band of the front at the reference instants and at the end, with the DEM's front
/// placed in it: the rows of `band.json`'s `instants` and `(inside, compared)`.
fn band_instants(
    runs: &BandRuns,
    setup: &Setup,
    dem: Option<&DemColumn>,
) -> (Vec<Value>, (usize, usize)) {
    let k = setup.time_scale();
    let r0 = setup.half_width_m;
    let mut rows = Vec::new();
    let mut inside_count = (0usize, 0usize);
    let dem_front: Vec<(f64, f64)> = dem
        .map(|d| d.front.iter().map(|r| (r.t_star, r.x_f_m)).collect())
        .unwrap_or_default();
    let mut instants: Vec<(String, f64, Option<f64>)> = setup
        .references
        .iter()
        .map(|(l, t)| (l.clone(), *t, dem.map(|_| interpolate(&dem_front, *t))))
        .collect();
    instants.push((
        "end".into(),
        setup.end_t_star,
        dem.and_then(|d| d.summary.runout_m),
    ));
    for (label, t, dem_x) in &instants {
        let f = |c: &CaseResult| -> f64 {
            if label == "end" {
                c.front.last().map_or(f64::NAN, |p| p.1) * r0
            } else {
                interpolate(&c.front, t * k) * r0
            }
        };
        if let Some(b) = runs.band_of(&f) {
            let inside = dem_x.map(|x| b.contains(x));
            if let Some(i) = inside {
                inside_count.1 += 1;
                if i {
                    inside_count.0 += 1;
                }
            }
            rows.push(json!({
                "label": label, "t_star": t, "x_f_central_m": b.central, "x_f_low_m": b.low,
                "x_f_high_m": b.high, "envelope_low_m": b.envelope_low, "envelope_high_m": b.envelope_high,
                "x_f_dem_m": dem_x, "dem_inside": inside,
            }));
        }
    }
    (rows, inside_count)
}

/// Writes `band.csv`: `t*`, central, low, high and envelope of `x_f` on the central run's
/// history.
fn write_band_csv(out: &mut OutputDir, front: &[(f64, Band)]) -> Result<()> {
    let mut table = crate::output::CsvTable::new(&[
        "t_star",
        "x_f_central_m",
        "x_f_low_m",
        "x_f_high_m",
        "x_f_envelope_low_m",
        "x_f_envelope_high_m",
    ]);
    table.comments.push(
        "band of the front from the law's covariance: central ± sqrt(sum over principal axes of ((x_f(+) - x_f(-))/2)^2) (docs/continuum.md §5)".into(),
    );
    for (t, b) in front {
        table.push(vec![
            *t,
            b.central,
            b.low,
            b.high,
            b.envelope_low,
            b.envelope_high,
        ]);
    }
    table.write(out, "band.csv")
}

/// The band's verdict: at how many instants the DEM front lies inside the band.
fn band_verdict_line(dem: Option<&DemColumn>, inside_count: (usize, usize)) -> String {
    if dem.is_some() {
        format!(
            "band verdict: the DEM front lies inside the law's band at {} of {} instants compared (the reference instants{}){}",
            inside_count.0,
            inside_count.1,
            if dem.and_then(|d| d.summary.runout_m).is_some() { ", and r∞ at rest" } else { "; the DEM run gives no r∞" },
            if inside_count.0 == inside_count.1 { ": consistent with the law within its uncertainty" } else { ": the DEM is NOT explained by the law's uncertainty alone" }
        )
    } else {
        "band: no DEM run given (--dem) to place in it".to_string()
    }
}

/// The report line of one instant of the band (`r` a row of [`band_instants`]).
fn band_row_line(r: &Value, r0: f64) -> String {
    format!(
        "  {:<9} x_f/R0 {:.2} [{:.2}, {:.2}]{}",
        match r["label"].as_str().unwrap_or("") {
            "end" => "r∞ (end)",
            l => l,
        },
        r["x_f_central_m"].as_f64().unwrap_or(f64::NAN) / r0,
        r["x_f_low_m"].as_f64().unwrap_or(f64::NAN) / r0,
        r["x_f_high_m"].as_f64().unwrap_or(f64::NAN) / r0,
        match (r["x_f_dem_m"].as_f64(), r["dem_inside"].as_bool()) {
            (Some(x), Some(i)) => format!(
                "; DEM {:.2} {}",
                x / r0,
                if i { "inside" } else { "OUTSIDE" }
            ),
            _ => String::new(),
        }
    )
}

fn front_figure(
    out: &mut OutputDir,
    rows: &[FrontRow],
    dem: Option<&DemColumn>,
    band: Option<&BandResult>,
    setup: &Setup,
) -> Result<()> {
    let r0 = setup.half_width_m;
    let mut plot = XyPlot::new(
        &format!("Column collapse, a = {}: front", setup.aspect_ratio),
        Axis::new("t* = t √(g/H₀)"),
        Axis::new("front x_f / R₀"),
    );
    plot.legend = LegendAt::LowerRight;
    if let Some(b) = band {
        plot.bands.push(PlotBand::between(
            "continuum, band of the law's uncertainty",
            PALETTE[0],
            &b.front
                .iter()
                .map(|(t, b)| (*t, b.low / r0, b.high / r0))
                .collect::<Vec<_>>(),
        ));
    }
    plot.series.push(Series::new(
        "continuum (Gerris, μ(I))",
        Style::Line,
        PALETTE[0],
        rows.iter().map(|r| (r.t_star, r.x_f_m / r0)).collect(),
    ));
    if let Some(d) = dem {
        plot.series.push(Series::new(
            "DEM",
            Style::Points,
            PALETTE[1],
            d.front.iter().map(|r| (r.t_star, r.x_f_m / r0)).collect(),
        ));
        if let Some(x) = d.summary.runout_m {
            plot.series.push(Series::new(
                "DEM at rest (r∞)",
                Style::Circles,
                PALETTE[2],
                vec![(d.summary.rest_t_star().unwrap_or(setup.end_t_star), x / r0)],
            ));
        }
    }
    draw_xy(out, "front.png", &plot)
}

fn profiles_figure(
    out: &mut OutputDir,
    cont: &std::collections::BTreeMap<String, Profile>,
    dem: Option<&DemColumn>,
    setup: &Setup,
) -> Result<()> {
    let r0 = setup.half_width_m;
    let mut plot = XyPlot::new(
        &format!(
            "Column collapse, a = {}: height profiles",
            setup.aspect_ratio
        ),
        Axis::new("x / R₀"),
        Axis::new("h / R₀"),
    );
    let mut labels: Vec<(String, String, String)> = setup
        .references
        .iter()
        .map(|(l, t)| (l.clone(), l.clone(), format!("t* = {t}")))
        .collect();
    labels.push(("end".into(), "rest".into(), "end / rest".into()));
    for (i, (cl, dl, text)) in labels.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        if let Some(c) = cont.get(cl) {
            plot.series.push(Series::new(
                &format!("{text} continuum"),
                Style::Line,
                color,
                c.points.iter().map(|p| (p.0 / r0, p.1 / r0)).collect(),
            ));
        }
        if let Some(d) = dem.and_then(|d| d.profiles.get(dl)) {
            plot.series.push(Series::new(
                &format!("{text} DEM"),
                Style::Dashed,
                color,
                d.points.iter().map(|p| (p.0 / r0, p.1 / r0)).collect(),
            ));
        }
    }
    draw_xy(out, "profiles.png", &plot)
}
