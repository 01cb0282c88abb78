//! `momaro plan --detailed`: plan, then expand the abstract path into stable keyframes
//! (step motion generation, Sec. VI) with MuJoCo's CoM.

use crate::closed_loop::mission::expand_mission_on;
use crate::motion::{DetailedPath, MotionError};
use crate::planner::{self, PlanError, PlanOptions, PlanSummary};
use crate::scenario::Scenario;
use crate::sim::Simulation;
use serde::Serialize;

/// Why a detailed plan failed.
#[derive(Debug, thiserror::Error)]
pub enum DetailedJobError {
    /// Planning failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The expansion image could not be written.
    #[error(transparent)]
    Image(#[from] crate::render::ImageError),
    /// The expansion failed.
    #[error("scenario {scenario}: step motion generation")]
    Motion {
        /// Scenario name.
        scenario: String,
        /// The cause.
        source: MotionError,
    },
}

/// A plan and its expansion: what `momaro plan --detailed --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct DetailedSummary {
    /// The abstract plan.
    pub plan: PlanSummary,
    /// The expanded path.
    pub detailed: DetailedPath,
}

/// Plans `scenario` and expands the path, with the CoM of `sim`'s model; with
/// `expansion_image`, writes where the search went as `momaro plan` does.
///
/// # Errors
/// [`DetailedJobError`] if planning or the expansion fails or the image cannot be written.
pub fn run(
    scenario: &Scenario,
    sim: &mut Simulation,
    opts: &PlanOptions,
    expansion_image: Option<&std::path::Path>,
) -> Result<DetailedSummary, DetailedJobError> {
    let robot = sim.robot().clone();
    let prep = planner::prepare_for(scenario, &robot, opts, &crate::motion::manoeuvres::ALL)?;
    let mut counts = None;
    let plan = planner::plan::run_on_counted(
        &prep,
        scenario,
        &robot,
        opts,
        expansion_image.map(|_| &mut counts),
    );
    super::plan::write_counts(expansion_image, counts.as_ref())?;
    let plan = plan?;
    let detailed = expand_mission_on(&prep, sim, &plan, plan.path.len())
        .map_err(|source| DetailedJobError::Motion { scenario: scenario.name.clone(), source })?;
    Ok(DetailedSummary { plan, detailed })
}

/// Writes a recording of the detailed plan: height map, abstract path and keyframes.
///
/// # Errors
/// If the map cannot be rebuilt or writing fails.
pub fn record(
    scenario: &Scenario,
    summary: &DetailedSummary,
    path: &std::path::Path,
) -> Result<(), super::plan_recording::PlanRecordingError> {
    let heights = super::costmap::rasterised_map(scenario)?;
    let rec = crate::viz::Recorder::create(path, "momaro plan --detailed")?;
    rec.log_height_map(&heights)?;
    let poses: Vec<_> = summary.plan.path.iter().map(|e| e.pose).collect();
    rec.log_plan(&poses)?;
    rec.log_keyframes(&summary.detailed.keyframes)?;
    rec.finish()?;
    Ok(())
}
