//! How the command line reports: errors classed for exit codes ([`BadInput`]: 2), the one
//! JSON object a failed `run` or `plan --json` prints, and the shared loaders.

use crate::jobs;
use crate::scenario::{Scenario, ScenarioError};
use anyhow::Context as _;

/// Failure classes, for exit codes.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

pub fn plan_error(e: crate::planner::PlanError) -> anyhow::Error {
    use crate::planner::PlanError as E;
    match e {
        E::BadOption { .. } | E::Params { .. } | E::OffMap { .. } | E::Untraversable { .. } => {
            anyhow::Error::new(BadInput(e.to_string()))
        }
        other => anyhow::Error::new(other),
    }
}

pub fn run_error(e: crate::closed_loop::RunError) -> anyhow::Error {
    match e {
        crate::closed_loop::RunError::Plan(p) => plan_error(p),
        other => anyhow::Error::new(other),
    }
}

/// The JSON of a run that ended in an error rather than a summary: `run --json` always
/// prints one object, with the failure's kind (`invalid_input` or `error`).
pub fn error_summary(scenario: &std::path::Path, e: &anyhow::Error) -> serde_json::Value {
    let mut v = failure_object(scenario, e, input_or_error(e));
    if let Some(obj) = v.as_object_mut() {
        obj.insert("passed".into(), false.into());
        obj.insert("reached_goal".into(), false.into());
    }
    v
}

/// `invalid_input` for bad input (exit code 2), else `error`.
pub fn input_or_error(e: &anyhow::Error) -> &'static str {
    if e.chain().any(|c| c.is::<BadInput>()) { "invalid_input" } else { "error" }
}

/// The scenario, its path, the failure's kind and its message.
pub fn failure_object(
    scenario: &std::path::Path,
    e: &anyhow::Error,
    kind: &str,
) -> serde_json::Value {
    serde_json::json!({
        "scenario": scenario.file_stem().map(|s| s.to_string_lossy().into_owned()),
        "path": scenario.display().to_string(),
        "failure_kind": kind,
        "failure": format!("{e:#}"),
    })
}

/// With `--json`, the object `plan` prints when it ends without a plan (stdout stays
/// one JSON object whatever happens, as for `run`): `failure_kind` `no_path`,
/// `planning_time_limit`, `motion_generation` (`--detailed`), `invalid_input` or `error`,
/// and the message in `failure`. The exit code is the error's.
pub fn print_plan_failure(json: bool, scenario: &std::path::Path, e: &anyhow::Error) {
    if !json {
        return;
    }
    let kind = e.chain().find_map(|c| {
        if let Some(crate::planner::PlanError::NoPath { termination, .. }) = c.downcast_ref() {
            Some(match termination {
                crate::search::Termination::NoPath => "no_path",
                _ => "planning_time_limit",
            })
        } else if let Some(jobs::detailed::DetailedJobError::Motion { .. }) = c.downcast_ref() {
            Some("motion_generation")
        } else {
            None
        }
    });
    let v = failure_object(scenario, e, kind.unwrap_or_else(|| input_or_error(e)));
    // Printing can fail only on a closed stdout, where nobody reads the object.
    let _ = print_json(&v);
}

pub fn robot(model: &std::path::Path) -> anyhow::Result<crate::robot::RobotDescription> {
    Ok(crate::sim::Simulation::robot_only(model)?.robot().clone())
}

pub fn check_error(e: jobs::check::CheckError) -> anyhow::Error {
    use jobs::check::CheckError as E;
    match e {
        E::BadShard { .. } | E::NoWorkers | E::Io { .. } | E::EmptyDirectory { .. } => {
            anyhow::Error::new(BadInput(e.to_string()))
        }
        E::Spawn(_) => anyhow::Error::new(e),
    }
}

pub fn load(path: &std::path::Path) -> anyhow::Result<Scenario> {
    Scenario::load(path).map_err(|e: ScenarioError| anyhow::Error::new(BadInput(e.to_string())))
}

pub fn print_json<T: serde::Serialize>(value: &T) -> anyhow::Result<()> {
    say!("{}", serde_json::to_string_pretty(value).context("serialising the summary")?);
    Ok(())
}

/// One progress line on stderr, `[done/total] what`, the count padded to the total's
/// width (a bench's rows as they are done; a closed pipe is not an error).
pub fn progress_line(done: usize, total: usize, what: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let width = total.to_string().len();
    let _ = writeln!(std::io::stderr(), "[{done:>width$}/{total}] {what}");
}
