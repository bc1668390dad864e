//! `grainlaw fit LAW DATA.csv [MORE.csv ...] [--out law.json]`: fits a law to a user's CSV, or
//! to several tables of the same columns merged ([`fit_files`]).
//!
//! Exit status: 0 when the law passed every check of `identify::accept` and was written; 2 for
//! bad input (unreadable or malformed file, missing column or metadata, unknown metadata key,
//! value out of its domain, too few rows, unknown law); 3 when the data were read but the fit
//! was refused (not identifiable, a parameter at its bound or with a standard error above its
//! value, an interval crossing a physical bound, a scale outside the data, R² below the
//! threshold or below the simpler nested form's). Errors are one line on stderr, naming the file
//! first; a refusal ends with the simpler form to use when there is one.

use std::path::Path;

use identify::data::Table;
use identify::law::{CalibratedLaw, DerivedQuantity, LawParameter};
use identify::user_fit::{fit_csv_file, passed_points, CsvFitOptions, POINT_VERDICT};
use identify::IdentifyError;

use crate::error::{CliError, Result};
use crate::output::dir::write_atomic;

/// Fits `law` to `data`; prints every parameter with its 95 % interval (a parameter held at its
/// bound is printed as such, not as an estimate; angles also in degrees), then the derived
/// quantities, and writes the calibrated-law JSON to `out`. With `out` the lines go to stdout;
/// without it the JSON goes to stdout (so that it can be piped) and the lines to stderr.
/// Returns the law written.
pub fn fit(law: &str, data: &Path, out: Option<&Path>) -> Result<CalibratedLaw> {
    let cal =
        fit_csv_file(law, data, &CsvFitOptions::default()).map_err(|e| naming_file(data, e))?;
    let left_out = left_out_points(data);
    report(&cal, data, left_out, out)?;
    Ok(cal)
}

/// [`fit`] on several tables of the same columns (e.g. the `rheology.csv` of one run per
/// inertial number, grainlaw's or another code's read by `grainlaw homogenise`), merged as
/// `grainlaw campaign --collect` merges its runs' ([`crate::campaign::merged_table`]: the rows
/// whose `point_verdict` is 0, a `run` column numbering the files from 0, metadata that must
/// agree within 5 %); the provenance records every file with its SHA-256. One file is [`fit`].
pub fn fit_files(law: &str, data: &[std::path::PathBuf], out: Option<&Path>) -> Result<()> {
    match data {
        [] => Err(CliError::Usage("fit: no data file".into())),
        [one] => fit(law, one, out).map(|_| ()),
        _ => {
            let name = format!(
                "merged({})",
                data.iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            let indexed: Vec<(usize, std::path::PathBuf)> =
                data.iter().cloned().enumerate().collect();
            let (text, left_out) = crate::campaign::merged_table(&indexed, &name, "grainlaw fit")?;
            let label = Path::new(&name);
            let mut cal =
                identify::user_fit::fit_csv_text(law, &text, &name, &CsvFitOptions::default())
                    .map_err(|e| naming_file(label, e))?;
            for p in data {
                let bytes = std::fs::read(p).map_err(|e| CliError::io(p, e))?;
                cal.provenance = cal.provenance.with_input(&p.display().to_string(), &bytes);
            }
            report(&cal, label, left_out, out)
        }
    }
}

/// Prints the report of a fitted law and writes it (see [`fit`]).
fn report(cal: &CalibratedLaw, data: &Path, left_out: usize, out: Option<&Path>) -> Result<()> {
    let json = cal.to_json_string()? + "\n";
    let mut lines = report_lines(cal, data);
    if left_out > 0 {
        lines.insert(
            1,
            format!(
                "{left_out} rows left out: their {POINT_VERDICT} is not 0 (the run judged them \
                 suspect or refused)"
            ),
        );
    }
    match out {
        Some(path) => {
            write_atomic(path, json.as_bytes())?;
            for l in lines {
                println!("{l}");
            }
            println!("law written to {}", path.display());
        }
        None => {
            for l in lines {
                eprintln!("{l}");
            }
            print!("{json}");
        }
    }
    Ok(())
}

/// Rows of `data` that the fit left out for their `point_verdict` (0 when the file has no such
/// column; the fit has already read the file, so a read error here cannot happen and counts 0).
fn left_out_points(data: &Path) -> usize {
    let Ok(text) = std::fs::read_to_string(data) else {
        return 0;
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    Table::parse_csv(text, &data.display().to_string())
        .and_then(|t| passed_points(&t))
        .map_or(0, |(_, n)| n)
}

/// The printed report: a title line, one line per parameter (in the registry's order), one per
/// derived quantity, and the verdict.
fn report_lines(cal: &CalibratedLaw, data: &Path) -> Vec<String> {
    let mut lines = vec![format!(
        "{} fitted to {} ({} points, R² = {:.4})",
        cal.law,
        data.display(),
        cal.fit.n,
        cal.fit.r_squared
    )];
    for p in &cal.parameters {
        lines.push(parameter_line(p));
    }
    for d in &cal.derived {
        lines.push(derived_line(d));
    }
    lines.push(format!(
        "verdict: {} (every check of the fit passed; the law's `verdict` key)",
        cal.verdict.as_deref().unwrap_or("ok")
    ));
    lines
}

/// ` unit` for a unit other than `1`.
fn unit_suffix(unit: &str) -> String {
    if unit == "1" {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// One printed parameter: `name = value unit (95 % CI low … high)`, with `= value° (95 % CI
/// low° … high°)` for an angle; a parameter on its bound (`at_bound`, e.g. a Mohr–Coulomb
/// cohesion held at `c = 0`, a Janssen `μ_w` fixed at `μ_wall`) is
/// `name = at its bound (value unit), not an estimate`, followed by the upper end the data allow
/// when its interval is one-sided and not empty.
fn parameter_line(p: &LawParameter) -> String {
    let name = &p.name;
    let unit = unit_suffix(&p.unit);
    if p.at_bound {
        let mut l = format!(
            "  {name:<10} = at its bound ({}{unit}), not an estimate",
            identify::error::short(p.value),
        );
        if p.ci_high > p.value {
            l.push_str(&format!(
                " (the data allow up to {:.6e}{unit} at 95 %)",
                p.ci_high
            ));
        }
        l
    } else {
        let mut l = format!(
            "  {name:<10} = {:.6e}{unit}  (95 % CI {:.6e} … {:.6e})",
            p.value, p.ci_low, p.ci_high
        );
        if let Some(d) = &p.deg {
            l.push_str(&format!(
                " = {:.4}°  (95 % CI {:.4}° … {:.4}°)",
                d.value, d.ci_low, d.ci_high
            ));
        }
        l
    }
}

/// One derived quantity: `name = value unit (95 % CI low … high), derived: formula`.
fn derived_line(d: &DerivedQuantity) -> String {
    let name = &d.name;
    let unit = unit_suffix(&d.unit);
    if d.at_bound {
        format!(
            "  {name:<10} = {}{unit}, fixed (derived: {})",
            identify::error::short(d.value),
            d.formula
        )
    } else {
        format!(
            "  {name:<10} = {:.6e}{unit}  (95 % CI {:.6e} … {:.6e}; derived: {})",
            d.value, d.ci_low, d.ci_high, d.formula
        )
    }
}

/// Puts the data file's path in front of a fit error whose message does not start with it (an
/// unknown law name is about the argument, not the file, and is left as it is); a refusal
/// ([`IdentifyError::is_refusal`]) becomes [`CliError::FitRefused`] (exit code 3).
fn naming_file(data: &Path, e: IdentifyError) -> CliError {
    let path = data.display().to_string();
    let message = e.to_string();
    if e.is_refusal() {
        let reason = message
            .strip_prefix(&path)
            .map(|m| m.trim_start_matches(':').trim_start().to_string())
            .unwrap_or(message);
        return CliError::FitRefused { path, reason };
    }
    if matches!(e, IdentifyError::UnknownLaw { .. }) || message.starts_with(&path) {
        CliError::Identify(e)
    } else {
        CliError::Input {
            path,
            reason: message,
        }
    }
}
