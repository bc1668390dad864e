//! What both continuum cases take (the column collapse and the inclined plane): the law, the
//! output directory, the DEM run to compare with, the continuum's packing fraction, the Gerris
//! resolution and viscosity cap, the Gerris command and the suspect policy.

use std::path::{Path, PathBuf};

use crate::error::{CliError, Result};

/// The inputs shared by [`super::ColumnPlan`] and [`super::InclinedPlan`].
#[derive(Debug, Clone, PartialEq)]
pub struct CaseInputs {
    /// The μ(I) law JSON.
    pub law: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// A DEM output directory of the case's scenario to compare with (and take the set-up
    /// from).
    pub dem: Option<PathBuf>,
    /// Packing fraction `φ` of the continuum (default: the DEM's; required without).
    pub packing_fraction: Option<f64>,
    /// Refinement level.
    pub level: u32,
    /// Viscosity cap (Gerris units).
    pub viscosity_cap: f64,
    /// The Gerris command (default `gerris2D`).
    pub gerris: Option<PathBuf>,
    /// A suspect run exits 0.
    pub allow_suspect: bool,
}

impl CaseInputs {
    /// The inputs for `law` and `out` with refinement `level` and viscosity cap
    /// `viscosity_cap` (the case's defaults), no DEM run, `φ` unset, `gerris2D`.
    pub fn new(law: PathBuf, out: PathBuf, level: u32, viscosity_cap: f64) -> Self {
        CaseInputs {
            law,
            out,
            dem: None,
            packing_fraction: None,
            level,
            viscosity_cap,
            gerris: None,
            allow_suspect: false,
        }
    }

    /// Refuses an output directory that is the DEM run's (its files would be replaced) or that
    /// holds another scenario's run than `kind` (`continuum-column-collapse`, ...).
    pub(crate) fn check_out(&self, kind: &str) -> Result<()> {
        if let Some(d) = &self.dem {
            if same_dir(d, &self.out) {
                return Err(CliError::Usage(format!(
                    "--out {}: is the DEM run's directory (--dem): choose another",
                    self.out.display()
                )));
            }
        }
        crate::output::dir::check_out_dir(&self.out, kind)
    }
}

/// Whether `a` and `b` name the same directory (both canonicalised when they exist).
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}
