//! `momaro plan`: the hybrid planner (`planner`) on one scenario, and the picture of where
//! its search went (`--expansions`), drawn whatever the outcome.

use crate::planner::plan::{ExpansionCounts, run_counted};
use crate::planner::{PlanError, PlanOptions, PlanSummary};
use crate::render::{ImageError, write_expansion_png};
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use std::path::Path;

/// Why `momaro plan` failed.
#[derive(Debug, thiserror::Error)]
pub enum PlanJobError {
    /// Planning failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The expansion image could not be written.
    #[error(transparent)]
    Image(#[from] ImageError),
}

/// Plans `scenario`; with `expansion_image`, writes a PNG of the expansions per base cell
/// over the height map ([`crate::render::expansion_image`]) whether a path was found or
/// not: a search that finds none shows where it spent its expansions.
///
/// # Errors
/// [`PlanJobError`]: planning failed, or the image could not be written (checked first).
pub fn run(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    expansion_image: Option<&Path>,
) -> Result<PlanSummary, PlanJobError> {
    let mut counts = None;
    let result = run_counted(
        scenario,
        robot,
        opts,
        &crate::motion::manoeuvres::ALL,
        expansion_image.map(|_| &mut counts),
    );
    write_counts(expansion_image, counts.as_ref())?;
    Ok(result?)
}

/// Writes `counts` to `path`, when both are given.
///
/// # Errors
/// [`ImageError`] naming the file.
pub fn write_counts(
    path: Option<&Path>,
    counts: Option<&ExpansionCounts>,
) -> Result<(), ImageError> {
    match (path, counts) {
        (Some(path), Some(c)) => write_expansion_png(&c.heights, &c.counts, path),
        _ => Ok(()),
    }
}
