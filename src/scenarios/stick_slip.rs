//! The `stick_slip` scenario.

use datasets::config::StickSlipConfig;

use super::{RunContext, RunOutcome};
use crate::error::{CliError, Result};

/// Runs the scenario.
pub fn run(_c: &StickSlipConfig, _ctx: &mut RunContext) -> Result<RunOutcome> {
    Err(CliError::Usage("scenario not implemented yet".into()))
}
