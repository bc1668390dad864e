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

use std::path::{Path, PathBuf};

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
/// `grainlaw campaign --collect` merges its runs' ([`merged_table`]: the rows
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
            let (text, left_out) = merged_table(&indexed, &name, "grainlaw fit")?;
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

/// A `# key = value` metadata line (`key` an identifier, as `grainlaw fit` reads it), or None
/// for a comment.
fn metadata_line(line: &str) -> Option<(String, String)> {
    let c = line.strip_prefix('#')?.trim();
    let (k, v) = c.split_once('=')?;
    let (k, v) = (k.trim(), v.trim());
    let ident = !k.is_empty()
        && k.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
        && !k.starts_with(|ch: char| ch.is_ascii_digit());
    (ident && !v.is_empty() && !v.contains(char::is_whitespace))
        .then(|| (k.to_string(), v.to_string()))
}

/// Largest relative spread of a numeric metadata value over the merged runs: the runs of one
/// campaign draw their grains from the same distribution, so their sample mean diameters differ
/// by sampling noise (about 1 % for a few hundred grains); beyond this the runs are not one
/// material and the merge is refused.
pub const MERGE_METADATA_SPREAD: f64 = 0.05;

/// The text of per-run CSV tables written by grainlaw (same header) concatenated, with a `run`
/// column (each file's index), and how many rows were left out: a table with a `point_verdict`
/// column keeps only its rows whose verdict is 0. Their `# key = value` metadata must agree: a
/// text value exactly, a number within [`MERGE_METADATA_SPREAD`] of the mean over the runs,
/// which the merged table carries (a fit over grains of different sizes would mix scales).
/// `name` names the merged table in messages, `by` the command merging (its first comment).
/// The merge of `campaign --collect` and of `grainlaw fit LAW A.csv B.csv ...`.
pub fn merged_table(files: &[(usize, PathBuf)], name: &str, by: &str) -> Result<(String, usize)> {
    let mut metas: Vec<(PathBuf, Vec<(String, String)>)> = Vec::new();
    let mut header: Option<String> = None;
    let mut rows = Vec::new();
    let mut dropped = 0usize;
    for (index, path) in files {
        let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        let mut meta = Vec::new();
        let mut this_header = None;
        let mut verdict_col = None;
        for line in text.lines() {
            let t = line.trim();
            if t.is_empty() {
                continue;
            }
            if t.starts_with('#') {
                if let Some(kv) = metadata_line(t) {
                    meta.push(kv);
                }
                continue;
            }
            if this_header.is_none() {
                this_header = Some(t.to_string());
                verdict_col = t.split(',').position(|h| h.trim() == "point_verdict");
            } else {
                let passed = verdict_col.is_none_or(|j| {
                    t.split(',')
                        .nth(j)
                        .and_then(|v| v.trim().parse::<f64>().ok())
                        == Some(0.0)
                });
                if passed {
                    rows.push(format!("{t},{index}"));
                } else {
                    dropped += 1;
                }
            }
        }
        match &header {
            None => header = this_header,
            Some(h) if Some(h) != this_header.as_ref() => {
                return Err(CliError::Input {
                    path: path.display().to_string(),
                    reason: "its columns differ from the first run's: the runs cannot be merged"
                        .into(),
                })
            }
            Some(_) => {}
        }
        metas.push((path.clone(), meta));
    }
    let first = &metas[0].1;
    let mut merged_meta = Vec::new();
    for (k, v0) in first {
        let values: Vec<(&PathBuf, Option<&String>)> = metas
            .iter()
            .map(|(p, m)| (p, m.iter().find(|(k2, _)| k2 == k).map(|(_, v)| v)))
            .collect();
        if let Some((p, _)) = values.iter().find(|(_, v)| v.is_none()) {
            return Err(CliError::Input {
                path: p.display().to_string(),
                reason: format!("metadata `{k}` is missing: the runs cannot be merged"),
            });
        }
        let nums: Option<Vec<f64>> = values
            .iter()
            .map(|(_, v)| v.and_then(|v| v.parse::<f64>().ok()))
            .collect();
        match nums {
            Some(xs) => {
                let mean = xs.iter().sum::<f64>() / xs.len() as f64;
                let spread = xs.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max);
                if spread > MERGE_METADATA_SPREAD * mean.abs() {
                    return Err(CliError::Input {
                        path: name.to_string(),
                        reason: format!(
                            "metadata `{k}` differs by {:.1} % between runs (more than {:.0} %): they are not one material and are not merged",
                            100.0 * spread / mean.abs(),
                            100.0 * MERGE_METADATA_SPREAD
                        ),
                    });
                }
                merged_meta.push(format!("# {k} = {mean:e}"));
            }
            None => {
                if let Some((p, _)) = values.iter().find(|(_, v)| *v != Some(v0)) {
                    return Err(CliError::Input {
                        path: p.display().to_string(),
                        reason: format!("metadata `{k}` differs from the first run's: the runs cannot be merged"),
                    });
                }
                merged_meta.push(format!("# {k} = {v0}"));
            }
        }
    }
    let mut text = format!(
        "# merged by {by}: the rows that passed their checks ({dropped} left out); column `run` is the run's index; numeric metadata are the means over the runs\n"
    );
    for m in merged_meta {
        text.push_str(&m);
        text.push('\n');
    }
    text.push_str(&header.unwrap_or_default());
    text.push_str(",run\n");
    for r in rows {
        text.push_str(&r);
        text.push('\n');
    }
    Ok((text, dropped))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metadata_lines_are_key_value_only() {
        assert_eq!(
            metadata_line("# grain_diameter_m = 2.9e-3"),
            Some(("grain_diameter_m".into(), "2.9e-3".into()))
        );
        assert_eq!(metadata_line("# steady shear (I, mu = |sigma_xy|/P)"), None);
        assert_eq!(metadata_line("# note: mu = tau / P"), None);
    }
}
