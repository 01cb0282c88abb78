//! `momaro run`: one scenario in closed loop (`closed_loop::run`), its summary the
//! command's output and its expectations the command's verdict.

use crate::closed_loop::{RunError, RunOptions, RunSummary};
use crate::scenario::Scenario;

/// Plans, expands and executes `scenario` in closed loop.
///
/// # Errors
/// [`RunError`] if the world cannot be built or the simulation fails.
pub fn run(scenario: &Scenario, opts: &RunOptions) -> Result<RunSummary, RunError> {
    crate::closed_loop::run(scenario, opts)
}
