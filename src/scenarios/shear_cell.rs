//! The `shear_cell` scenario.

use datasets::config::ShearCellConfig;

use super::{RunContext, RunOutcome};
use crate::error::{CliError, Result};

/// Runs the scenario.
pub fn run(_c: &ShearCellConfig, _ctx: &mut RunContext) -> Result<RunOutcome> {
    Err(CliError::Usage("scenario not implemented yet".into()))
}
