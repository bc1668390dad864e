//! `grainlaw fit LAW DATA.csv [--out law.json]`: fits a law to a user's CSV.

use std::path::Path;

use identify::user_fit::{fit_csv_file, CsvFitOptions};
use identify::{Estimate, IdentifyError};

use crate::error::{CliError, Result};
use crate::output::dir::write_atomic;

/// Fits `law` to `data`; prints the parameters with their 95 % intervals (a parameter held at
/// its bound is printed as such, not as an estimate), and writes the calibrated-law JSON to
/// `out` (or stdout without it). Every error about the data starts with the file's path.
pub fn fit(law: &str, data: &Path, out: Option<&Path>) -> Result<()> {
    let cal =
        fit_csv_file(law, data, &CsvFitOptions::default()).map_err(|e| naming_file(data, e))?;
    let json = cal.to_json_string()? + "\n";
    let mut lines = vec![format!(
        "{} fitted to {} ({} points, R² = {:.4})",
        cal.law,
        data.display(),
        cal.fit.n,
        cal.fit.r_squared
    )];
    lines.extend(cal.parameters.iter().map(parameter_line));
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

/// One printed parameter: `name = value unit (95 % CI low … high)`; a parameter on its bound
/// (`at_bound`, e.g. a Mohr–Coulomb cohesion held at `c = 0`, a Janssen `μ_w` fixed at
/// `μ_wall`) is `name = at its bound (value unit), not an estimate`, followed by the upper end
/// the data allow when its interval is one-sided and not empty.
fn parameter_line(p: &Estimate) -> String {
    if p.at_bound {
        let unit = if p.unit == "1" {
            String::new()
        } else {
            format!(" {}", p.unit)
        };
        let mut l = format!(
            "  {:<10} = at its bound ({}{unit}), not an estimate",
            p.name,
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
        format!(
            "  {:<10} = {:.6e} {}  (95 % CI {:.6e} … {:.6e})",
            p.name, p.value, p.unit, p.ci_low, p.ci_high
        )
    }
}

/// Puts the data file's path in front of a fit error whose message does not start with it (an
/// unknown law name is about the argument, not the file, and is left as it is).
fn naming_file(data: &Path, e: IdentifyError) -> CliError {
    let path = data.display().to_string();
    let message = e.to_string();
    if matches!(e, IdentifyError::UnknownLaw { .. }) || message.starts_with(&path) {
        CliError::Identify(e)
    } else {
        CliError::Input {
            path,
            reason: message,
        }
    }
}
