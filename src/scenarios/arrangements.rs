//! The `arrangements` scenario.

use datasets::config::ArrangementsConfig;

use super::{RunContext, RunOutcome};
use crate::error::{CliError, Result};

/// Runs the scenario.
pub fn run(_c: &ArrangementsConfig, _ctx: &mut RunContext) -> Result<RunOutcome> {
    Err(CliError::Usage("scenario not implemented yet".into()))
}
