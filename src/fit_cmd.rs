//! `grainlaw fit LAW DATA.csv [--out law.json]`: fits a law to a user's CSV.

use std::path::Path;

use identify::user_fit::{fit_csv_file, CsvFitOptions};

use crate::error::Result;
use crate::output::dir::write_atomic;

/// Fits `law` to `data`; prints the parameters with their 95 % intervals, and writes the
/// calibrated-law JSON to `out` (or stdout without it).
pub fn fit(law: &str, data: &Path, out: Option<&Path>) -> Result<()> {
    let cal = fit_csv_file(law, data, &CsvFitOptions::default())?;
    let json = cal.to_json_string()? + "\n";
    let mut lines = vec![format!(
        "{} fitted to {} ({} points, R² = {:.4})",
        cal.law,
        data.display(),
        cal.fit.n,
        cal.fit.r_squared
    )];
    for p in &cal.parameters {
        lines.push(format!(
            "  {:<10} = {:.6e} {}  (95 % CI {:.6e} … {:.6e})",
            p.name, p.value, p.unit, p.ci_low, p.ci_high
        ));
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
