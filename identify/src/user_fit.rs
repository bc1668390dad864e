//! Fitting a law by name from a user's CSV file (`grainlaw fit LAW DATA.csv [--out law.json]`).
//!
//! File format: see [`crate::data`] (header with units in the names, `# key = value`
//! metadata lines for set-up constants, `#` comments). Columns and metadata per law (headers
//! are matched case-insensitively; stresses are compressive-positive magnitudes unless said):
//!
//! | law | required columns | optional columns | metadata (`# key = value`) |
//! |---|---|---|---|
//! | `janssen` | `z_m`, `sigma_v_Pa`, `sigma_h_Pa` | `tau_w_Pa` | `width_m`, `bulk_density_kg_m3`, `wall_friction`; optional `gravity_m_s2` (9.81), `depth_min_m`, `depth_max_m`, `full_mobilisation` (1 = fix μ_w = μ_wall) |
//! | `janssen-kmu` | `z_m`, `sigma_v_Pa` | | `width_m`, `bulk_density_kg_m3`; optional `gravity_m_s2`, `depth_min_m`, `depth_max_m` |
//! | `wall-law` | `slip_velocity_m_s` and either `mu_eff` or both `tau_w_Pa`, `sigma_w_Pa` | | `grain_diameter_m`; optional `gravity_m_s2` |
//! | `mu-i` | `I`, `mu` | `P_Pa` | |
//! | `phi-i` | `I`, `phi` | `P_Pa` | |
//! | `mohr-coulomb` | one of: `p_Pa`, `q_Pa` (Mohr circles) · `sigma_xx_Pa`, `sigma_yy_Pa`, `sigma_xy_Pa` (2D tensors, **tension positive**) · `sigma_n_Pa`, `tau_Pa` (failure plane) | | |
//!
//! `z` is the depth below the free surface, `I` the inertial number, `mu = τ/P`, `phi` the solid
//! fraction, `p`/`q` the centre/radius of the Mohr circle at yield. `wall-law` fits the three
//! candidate forms and keeps the lowest AIC (the ranking is stored in the JSON).
//! Metadata given in [`CsvFitOptions::metadata`] override the file's.

use std::collections::BTreeMap;
use std::path::Path;

use crate::data::Table;
use crate::error::{IdentifyError, Result};
use crate::fit::FitOptions;
use crate::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, fit_janssen_k_mu, JanssenOptions, JanssenProfile,
    JanssenSetup,
};
use crate::law::{CalibratedLaw, Provenance};
use crate::laws::STANDARD_GRAVITY;
use crate::mohr_coulomb::{fit_mohr_coulomb, YieldData};
use crate::mu_i::{fit_mu_i, fit_phi_i, RheologySeries};
use crate::wall_law::{select_wall_law, WallSlipSeries};

/// Law names accepted by [`fit_csv_file`].
pub const LAW_NAMES: [&str; 6] = [
    "janssen",
    "janssen-kmu",
    "wall-law",
    "mu-i",
    "phi-i",
    "mohr-coulomb",
];

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
    let text = std::fs::read_to_string(path).map_err(|e| IdentifyError::Io {
        path: source.clone(),
        source: e,
    })?;
    let table = Table::parse_csv(&text, &source)?;
    let header = header_line(&text);
    check_unique_headers(&table, header)?;
    if table.rows() == 0 {
        return Err(IdentifyError::Csv {
            file: source,
            line: header,
            message: "no data rows after the header".into(),
        });
    }
    fit_table(law, &table, options)
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
    if !LAW_NAMES.contains(&law) {
        return Err(IdentifyError::UnknownLaw {
            name: law.to_string(),
            known: LAW_NAMES.join(", "),
        });
    }
    Ok(())
}

/// Fits `law` to an already-read table (see [`fit_csv_file`]).
pub fn fit_table(law: &str, table: &Table, options: &CsvFitOptions) -> Result<CalibratedLaw> {
    check_law_name(law)?;
    let mut table = table.clone();
    for (k, v) in &options.metadata {
        table.metadata.insert(k.clone(), *v);
    }
    let mut provenance = Provenance::new(&options.scenario, options.seed);
    provenance.source = Some(table.source.clone());
    match law {
        "janssen" | "janssen-kmu" => {
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
        "wall-law" => {
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
        "mu-i" | "phi-i" => {
            let mut series = RheologySeries {
                inertial_number: table.column("I")?,
                pressure_pa: table.optional_column("P_Pa")?,
                ..Default::default()
            };
            if law == "mu-i" {
                series.mu = Some(table.column("mu")?);
                let fit = fit_mu_i(&series, &options.fit)?;
                Ok(CalibratedLaw::from_mu_i(&fit, provenance))
            } else {
                series.phi = Some(table.column("phi")?);
                let fit = fit_phi_i(&series, &options.fit)?;
                Ok(CalibratedLaw::from_phi_i(&fit, provenance))
            }
        }
        _ => {
            // mohr-coulomb
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
                let tensors: Vec<[f64; 3]> =
                    (0..sxx.len()).map(|k| [sxx[k], syy[k], sxy[k]]).collect();
                YieldData::from_tension_positive_tensors(&tensors)
            };
            let fit = fit_mohr_coulomb(&data, options.fit.confidence)?;
            Ok(CalibratedLaw::from_mohr_coulomb(&fit, provenance))
        }
    }
}
