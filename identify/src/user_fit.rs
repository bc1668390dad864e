//! Fitting a law by name from a user's CSV file (`grainlaw fit LAW DATA.csv [--out law.json]`).
//!
//! File format: see [`crate::data`] (header with units in the names, `# key = value`
//! metadata lines for set-up constants, other `#` lines comments). Columns and metadata per law
//! (headers are matched case-insensitively; stresses are compressive-positive magnitudes unless
//! said; columns in Pa are also read in kPa or MPa, in m in mm, in m/s in mm/s):
//!
//! | law | required columns | optional columns | metadata (`# key = value`) |
//! |---|---|---|---|
//! | `janssen` | `z_m`, `sigma_v_Pa`, `sigma_h_Pa` | `tau_w_Pa` | `width_m`, `bulk_density_kg_m3`, `wall_friction`; optional `gravity_m_s2` (9.81), `depth_min_m`, `depth_max_m`, `full_mobilisation` (1 = fix μ_w = μ_wall) |
//! | `janssen-kmu` | `z_m`, `sigma_v_Pa` | | `width_m`, `bulk_density_kg_m3`; optional `gravity_m_s2`, `depth_min_m`, `depth_max_m`; `wall_friction`, `full_mobilisation` accepted (a `janssen` file) and not used |
//! | `wall-law` | `slip_velocity_m_s` and either `mu_eff` or both `tau_w_Pa`, `sigma_w_Pa` | | `grain_diameter_m`; optional `gravity_m_s2` |
//! | `mu-i`, `mu-i-linear` | `I`, `mu` | `P_Pa`, `mu_std_error` (weights `1/σ`) | `grain_diameter_m`, `grain_density_kg_m3` (the law's `d`, `rho_s`) |
//! | `phi-i` | `I`, `phi` | `P_Pa`, `phi_std_error` (weights `1/σ`) | `grain_diameter_m`, `grain_density_kg_m3` |
//! | `mohr-coulomb` | one of: `p_Pa`, `q_Pa` (Mohr circles) · `sigma_xx_Pa`, `sigma_yy_Pa`, `sigma_xy_Pa` (2D tensors, **tension positive**) · `sigma_n_Pa`, `tau_Pa` (failure plane) | | optional `cohesion` (only `0`: fixes `c = 0`, and 3 states suffice) |
//!
//! `z` is the depth below the free surface, `I` the inertial number, `mu = τ/P`, `phi` the solid
//! fraction, `p`/`q` the centre/radius of the Mohr circle at yield. `wall-law` fits the three
//! candidate forms and keeps the lowest AIC among those accepted (the ranking is stored in the
//! JSON). A metadata key the law does not read is refused ([`IdentifyError::UnknownMetadata`],
//! with the keys it reads); so is a key it reads whose value is not a finite number. Metadata
//! given in [`CsvFitOptions::metadata`] override the file's and are recorded as overrides in the
//! provenance, with the date and the SHA-256 of the file.

use std::collections::BTreeMap;
use std::path::Path;

use crate::data::Table;
use crate::error::{IdentifyError, Result};
use crate::fit::FitOptions;
use crate::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, fit_janssen_k_mu, JanssenOptions, JanssenProfile,
    JanssenSetup,
};
use crate::law::{CalibratedLaw, GrainScale, Provenance};
use crate::laws::STANDARD_GRAVITY;
use crate::mohr_coulomb::{fit_mohr_coulomb_with, MohrCoulombOptions, YieldData};
use crate::mu_i::{fit_mu_i, fit_mu_i_linear, fit_phi_i, RheologySeries};
use crate::wall_law::{select_wall_law, WallSlipSeries};

/// Law names accepted by [`fit_csv_file`].
pub const LAW_NAMES: [&str; 7] = [
    "janssen",
    "janssen-kmu",
    "wall-law",
    "mu-i",
    "mu-i-linear",
    "phi-i",
    "mohr-coulomb",
];

/// The `# key = value` keys `law` reads (module documentation); any other key is refused.
pub fn metadata_keys(law: &str) -> &'static [&'static str] {
    const JANSSEN: &[&str] = &[
        "width_m",
        "bulk_density_kg_m3",
        "wall_friction",
        "gravity_m_s2",
        "depth_min_m",
        "depth_max_m",
        "full_mobilisation",
    ];
    match law {
        "janssen" | "janssen-kmu" => JANSSEN,
        "wall-law" => &["grain_diameter_m", "gravity_m_s2"],
        "mu-i" | "mu-i-linear" | "phi-i" => &["grain_diameter_m", "grain_density_kg_m3"],
        "mohr-coulomb" => &["cohesion"],
        _ => &[],
    }
}

/// Options of [`fit_csv_file`].
#[derive(Debug, Clone, PartialEq)]
pub struct CsvFitOptions {
    /// Generic fit options (confidence level, bootstrap).
    pub fit: FitOptions,
    /// Metadata overriding the file's `# key = value` lines.
    pub metadata: BTreeMap<String, f64>,
    /// Scenario name recorded in the provenance (default `user-csv`).
    pub scenario: String,
    /// Seed recorded in the provenance (default none).
    pub seed: Option<u64>,
}

impl Default for CsvFitOptions {
    fn default() -> Self {
        CsvFitOptions {
            fit: FitOptions::default(),
            metadata: BTreeMap::new(),
            scenario: "user-csv".into(),
            seed: None,
        }
    }
}

/// Reads `path` and fits `law` (one of [`LAW_NAMES`]); returns the calibrated law for export.
/// Errors: [`IdentifyError::UnknownLaw`], the file errors of [`crate::data`], a header that
/// names a column twice or is followed by no data row ([`IdentifyError::Csv`] on the header
/// line; with a column twice, which of the two would be read is ambiguous), and the fit's.
pub fn fit_csv_file(law: &str, path: &Path, options: &CsvFitOptions) -> Result<CalibratedLaw> {
    check_law_name(law)?;
    let source = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| IdentifyError::Io {
        path: source.clone(),
        source: e,
    })?;
    let text = String::from_utf8(bytes.clone()).map_err(|_| IdentifyError::Io {
        path: source.clone(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        ),
    })?;
    let mut law = fit_csv_text(law, &text, &source, options)?;
    law.provenance = law.provenance.with_input(&source, &bytes);
    Ok(law)
}

/// [`fit_csv_file`] on the text of a table (`source` names it in messages and in the
/// provenance's `source`; the caller records the input files): e.g. several tables merged.
pub fn fit_csv_text(
    law: &str,
    text: &str,
    source: &str,
    options: &CsvFitOptions,
) -> Result<CalibratedLaw> {
    check_law_name(law)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let table = Table::parse_csv(text, source)?;
    let header = header_line(text);
    check_unique_headers(&table, header)?;
    if table.rows() == 0 {
        return Err(IdentifyError::Csv {
            file: source.to_string(),
            line: header,
            message: "no data rows after the header".into(),
        });
    }
    fit_table(law, &table, options)
}

/// The verdict of a law this module returns (`verdict` of the law JSON, as a `grainlaw run`
/// writes it, `docs/outputs.md` §2.1): `ok`, since every returned fit passed the checks of
/// [`crate::accept`]; a fit that does not is refused with an error, not returned.
pub const FIT_VERDICT: &str = "ok";

/// Name of the column in which grainlaw's scenarios judge each point of a table (0 passed its
/// checks, 1 suspect, 2 refused; `docs/outputs.md` §2.1).
pub const POINT_VERDICT: &str = "point_verdict";

/// The rows of `table` that may be fitted, and how many were left out: a table with a
/// [`POINT_VERDICT`] column keeps only its rows whose verdict is 0, so that a point measured on
/// unconverged steps or outside its steady state never enters a law; any other table is kept
/// whole. Errors: a verdict cell that is not a number ([`IdentifyError::NonNumericCell`]), and
/// the refusal [`IdentifyError::NotIdentifiable`] when no row passed.
pub fn passed_points(table: &Table) -> Result<(Table, usize)> {
    if !table.has_column(POINT_VERDICT) {
        return Ok((table.clone(), 0));
    }
    let keep: Vec<bool> = table
        .column(POINT_VERDICT)?
        .iter()
        .map(|v| *v == 0.0)
        .collect();
    let left_out = keep.iter().filter(|k| !**k).count();
    if left_out == keep.len() {
        return Err(IdentifyError::NotIdentifiable {
            reason: format!(
                "all {} rows of {} have {POINT_VERDICT} ≠ 0 (each failed its run's checks): \
                 nothing may be fitted",
                keep.len(),
                table.source
            ),
        });
    }
    Ok((table.with_rows(&keep), left_out))
}

/// 1-based line of the header: the first line that is neither blank nor a `#` comment.
fn header_line(text: &str) -> u64 {
    text.lines()
        .position(|l| {
            let l = l.trim();
            !l.is_empty() && !l.starts_with('#')
        })
        .map_or(0, |i| i as u64 + 1)
}

/// Refuses a header with the same column twice (headers are matched case-insensitively).
fn check_unique_headers(table: &Table, line: u64) -> Result<()> {
    for (j, h) in table.headers.iter().enumerate() {
        if let Some(k) = table.headers[..j]
            .iter()
            .position(|g| g.eq_ignore_ascii_case(h))
        {
            return Err(IdentifyError::Csv {
                file: table.source.clone(),
                line,
                message: format!(
                    "column '{h}' appears twice (fields {} and {})",
                    k + 1,
                    j + 1
                ),
            });
        }
    }
    Ok(())
}

fn check_law_name(law: &str) -> Result<()> {
    if law == "phi-i-linear" {
        return Err(IdentifyError::UnknownLaw {
            name: law.to_string(),
            known: format!(
                "{}; phi-i-linear was merged into phi-i, the same line φ_max − a I",
                LAW_NAMES.join(", ")
            ),
        });
    }
    if !LAW_NAMES.contains(&law) {
        return Err(IdentifyError::UnknownLaw {
            name: law.to_string(),
            known: LAW_NAMES.join(", "),
        });
    }
    Ok(())
}

/// Refuses metadata keys `law` does not read, and keys it reads whose value is not a finite
/// number.
fn check_metadata(law: &str, table: &Table, options: &CsvFitOptions) -> Result<()> {
    let known = metadata_keys(law);
    let unknown = |key: &str, line: u64| IdentifyError::UnknownMetadata {
        file: table.source.clone(),
        line,
        key: key.to_string(),
        law: law.to_string(),
        known: if known.is_empty() {
            "none".into()
        } else {
            known.join(", ")
        },
    };
    for (key, value) in &table.metadata {
        let line = table.metadata_lines.get(key).copied().unwrap_or(0);
        if !known.contains(&key.as_str()) {
            return Err(unknown(key, line));
        }
        if !value.is_finite() {
            return Err(IdentifyError::Metadata {
                file: table.source.clone(),
                message: format!("line {line}: metadata '{key}' is not finite"),
            });
        }
    }
    for (key, text, line) in &table.text_metadata {
        if known.contains(&key.as_str()) {
            return Err(IdentifyError::Metadata {
                file: table.source.clone(),
                message: format!("line {line}: metadata '{key}' = '{text}' is not a number"),
            });
        }
    }
    for (key, value) in &options.metadata {
        if !known.contains(&key.as_str()) {
            return Err(unknown(key, 0));
        }
        if !value.is_finite() {
            return Err(IdentifyError::Metadata {
                file: table.source.clone(),
                message: format!("metadata override '{key}' is not finite"),
            });
        }
    }
    Ok(())
}

/// `d` and `ρ_s` from the metadata, for a μ(I) or φ(I) law.
fn grain_scale(table: &Table) -> Result<GrainScale> {
    let d = table.metadata_value("grain_diameter_m")?;
    let rho = table.metadata_value("grain_density_kg_m3")?;
    crate::error::check_setup_positive("grain_diameter_m", d)?;
    crate::error::check_setup_positive("grain_density_kg_m3", rho)?;
    Ok(GrainScale {
        diameter_m: d,
        density_kg_m3: rho,
    })
}

/// Fits `law` to an already-read table (see [`fit_csv_file`]).
pub fn fit_table(law: &str, table: &Table, options: &CsvFitOptions) -> Result<CalibratedLaw> {
    check_law_name(law)?;
    check_metadata(law, table, options)?;
    let (passed, left_out) = passed_points(table)?;
    fit_rows(law, &passed, options)
        .map(|mut law| {
            // it passed every check of `crate::accept` (a refused fit returns no law): `ok`, as
            // a run marks the laws it exports
            law.verdict = Some(FIT_VERDICT.into());
            law
        })
        .map_err(|e| match e {
            IdentifyError::TooFewPoints { law, needed, got } if left_out > 0 => {
                IdentifyError::NotIdentifiable {
                    reason: format!(
                        "{law}: {got} points passed their run's checks ({left_out} left out for \
                     {POINT_VERDICT} ≠ 0), at least {needed} needed"
                    ),
                }
            }
            e => e,
        })
}

/// [`fit_table`] on rows that may all be fitted: the overrides applied to the table's metadata,
/// the provenance, and the law's own reading of columns and metadata and its fit.
fn fit_rows(law: &str, table: &Table, options: &CsvFitOptions) -> Result<CalibratedLaw> {
    let mut table = table.clone();
    for (k, v) in &options.metadata {
        table.metadata.insert(k.clone(), *v);
    }
    let provenance = rows_provenance(&table, options);
    match law {
        "janssen" | "janssen-kmu" => fit_janssen_rows(law, &table, options, provenance),
        "wall-law" => fit_wall_law_rows(&table, options, provenance),
        "mu-i" | "mu-i-linear" | "phi-i" => fit_rheology_rows(law, &table, options, provenance),
        // mohr-coulomb
        _ => fit_mohr_coulomb_rows(&table, options, provenance),
    }
}

/// The provenance of a fit from `table`: the scenario and seed of `options`, its metadata
/// overrides (`key=value`), the date, and the table's source.
fn rows_provenance(table: &Table, options: &CsvFitOptions) -> Provenance {
    let mut provenance = Provenance::new(&options.scenario, options.seed)
        .with_overrides(
            options
                .metadata
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect(),
        )
        .with_date_now();
    provenance.source = Some(table.source.clone());
    provenance
}

/// `janssen` (`σ_v`, `σ_h` and the optional `τ_w`; `wall_friction` required, full mobilisation
/// on `full_mobilisation ≠ 0`) or `janssen-kmu` (`σ_v` only) from the table.
fn fit_janssen_rows(
    law: &str,
    table: &Table,
    options: &CsvFitOptions,
    provenance: Provenance,
) -> Result<CalibratedLaw> {
    let profile = JanssenProfile {
        z_m: table.column("z_m")?,
        sigma_v_pa: table.column("sigma_v_Pa")?,
        sigma_h_pa: if law == "janssen" {
            Some(table.column("sigma_h_Pa")?)
        } else {
            None
        },
        tau_w_pa: if law == "janssen" {
            table.optional_column("tau_w_Pa")?
        } else {
            None
        },
    };
    let setup = JanssenSetup {
        width_m: table.metadata_value("width_m")?,
        bulk_density_kg_m3: table.metadata_value("bulk_density_kg_m3")?,
        gravity_m_s2: table.metadata_or("gravity_m_s2", STANDARD_GRAVITY),
        wall_friction: if law == "janssen" {
            table.metadata_value("wall_friction")?
        } else {
            table.metadata_or("wall_friction", f64::INFINITY)
        },
    };
    let window = match (
        table.metadata.get("depth_min_m"),
        table.metadata.get("depth_max_m"),
    ) {
        (None, None) => None,
        (lo, hi) => Some((
            lo.copied().unwrap_or(f64::NEG_INFINITY),
            hi.copied().unwrap_or(f64::INFINITY),
        )),
    };
    let jopts = JanssenOptions {
        depth_window: window,
        use_tau_w: true,
        fit: options.fit.clone(),
    };
    if law == "janssen" {
        let fit = if table.metadata_or("full_mobilisation", 0.0) != 0.0 {
            fit_janssen_full_mobilisation(&profile, &setup, &jopts)?
        } else {
            fit_janssen(&profile, &setup, &jopts)?
        };
        Ok(CalibratedLaw::from_janssen(&fit, provenance))
    } else {
        let fit = fit_janssen_k_mu(&profile, &setup, &jopts)?;
        Ok(CalibratedLaw::from_janssen_k_mu(&fit, provenance))
    }
}

/// `wall-law` from the table: the slip velocity and `μ_eff`, read or formed as `|τ_w| / σ_w`
/// (`σ_w > 0`); the best of the candidate forms ([`select_wall_law`]) with its ranking.
fn fit_wall_law_rows(
    table: &Table,
    options: &CsvFitOptions,
    provenance: Provenance,
) -> Result<CalibratedLaw> {
    let vs = table.column("slip_velocity_m_s")?;
    let mu = if table.has_column("mu_eff") {
        table.column("mu_eff")?
    } else if table.has_column("tau_w_Pa") || table.has_column("sigma_w_Pa") {
        let tau = table.column("tau_w_Pa")?;
        let sigma = table.column("sigma_w_Pa")?;
        if let Some(k) = sigma.iter().position(|s| *s <= 0.0) {
            return Err(IdentifyError::NegativePressure {
                column: "sigma_w_Pa".into(),
                index: k,
                value: sigma[k],
            });
        }
        tau.iter().zip(&sigma).map(|(t, s)| t.abs() / s).collect()
    } else {
        table.column("mu_eff")?
    };
    let d = table.metadata_value("grain_diameter_m")?;
    let g = table.metadata_or("gravity_m_s2", STANDARD_GRAVITY);
    let series = WallSlipSeries {
        slip_velocity_m_s: vs,
        mu_eff: mu,
        grain_diameter_m: d,
        gravity_m_s2: g,
    };
    let sel = select_wall_law(&series, &options.fit)?;
    Ok(CalibratedLaw::from_wall_law(
        sel.best(),
        d,
        g,
        Some(sel.comparison.clone()),
        provenance,
    ))
}

/// `mu-i`, `mu-i-linear` or `phi-i` from the table (`I`, `mu` or `phi`, the optional `P` and
/// standard errors); the grain scale is read after the fit.
fn fit_rheology_rows(
    law: &str,
    table: &Table,
    options: &CsvFitOptions,
    provenance: Provenance,
) -> Result<CalibratedLaw> {
    let mut series = RheologySeries {
        inertial_number: table.column("I")?,
        pressure_pa: table.optional_column("P_Pa")?,
        ..Default::default()
    };
    // The constants are asked for after the fit, so that an error in the data is
    // reported first.
    let o = &options.fit;
    if law.starts_with("mu") {
        series.mu = Some(table.column("mu")?);
        series.mu_std_error = table.optional_column("mu_std_error")?;
    } else {
        series.phi = Some(table.column("phi")?);
        series.phi_std_error = table.optional_column("phi_std_error")?;
    }
    Ok(match law {
        "mu-i" => {
            let fit = fit_mu_i(&series, o)?;
            CalibratedLaw::from_mu_i(&fit, grain_scale(table)?, provenance)
        }
        "mu-i-linear" => {
            let fit = fit_mu_i_linear(&series, o)?;
            CalibratedLaw::from_mu_i_linear(&fit, grain_scale(table)?, provenance)
        }
        _ => {
            let fit = fit_phi_i(&series, o)?;
            CalibratedLaw::from_phi_i(&fit, grain_scale(table)?, provenance)
        }
    })
}

/// `mohr-coulomb` from the table: Mohr circles (`p`, `q`), failure-plane tractions (`σ_n`, `τ`)
/// or 2D tension-positive tensors, in that order of precedence, and `# cohesion = 0`.
fn fit_mohr_coulomb_rows(
    table: &Table,
    options: &CsvFitOptions,
    provenance: Provenance,
) -> Result<CalibratedLaw> {
    let data = if table.has_column("p_Pa") || table.has_column("q_Pa") {
        YieldData::Circles {
            p_pa: table.column("p_Pa")?,
            q_pa: table.column("q_Pa")?,
        }
    } else if table.has_column("sigma_n_Pa") || table.has_column("tau_Pa") {
        YieldData::FailurePlane {
            sigma_n_pa: table.column("sigma_n_Pa")?,
            tau_pa: table.column("tau_Pa")?,
        }
    } else {
        let sxx = table.column("sigma_xx_Pa")?;
        let syy = table.column("sigma_yy_Pa")?;
        let sxy = table.column("sigma_xy_Pa")?;
        let tensors: Vec<[f64; 3]> = (0..sxx.len()).map(|k| [sxx[k], syy[k], sxy[k]]).collect();
        YieldData::from_tension_positive_tensors(&tensors)
    };
    let cohesion_fixed_zero = match table.metadata.get("cohesion") {
        None => false,
        Some(c) if *c == 0.0 => true,
        Some(c) => {
            return Err(IdentifyError::Metadata {
                file: table.source.clone(),
                message: format!(
                    "line {}: '# cohesion = {c}': only '# cohesion = 0' is read (it fixes c = 0); remove the line to fit c",
                    table.metadata_lines.get("cohesion").copied().unwrap_or(0)
                ),
            })
        }
    };
    let fit = fit_mohr_coulomb_with(
        &data,
        &MohrCoulombOptions {
            confidence: options.fit.confidence,
            cohesion_fixed_zero,
            min_r_squared: options.fit.min_r_squared,
            ..MohrCoulombOptions::default()
        },
    )?;
    Ok(CalibratedLaw::from_mohr_coulomb(&fit, provenance))
}
