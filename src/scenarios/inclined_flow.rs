//! The `inclined_flow` scenario.

use datasets::config::InclinedFlowConfig;

use super::{RunContext, RunOutcome};
use crate::error::{CliError, Result};

/// Runs the scenario.
pub fn run(_c: &InclinedFlowConfig, _ctx: &mut RunContext) -> Result<RunOutcome> {
    Err(CliError::Usage("scenario not implemented yet".into()))
}
