//! `momaro plan --detailed`: plan, then expand the abstract path into stable keyframes
//! (step motion generation, Sec. VI) with MuJoCo's CoM.

use crate::feasibility::MotionOptions;
use crate::motion::{DetailedPath, MotionError, expand_path};
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
    let detailed = expand_prefix_on(&prep, scenario, sim, &plan, plan.path.len())?;
    Ok(DetailedSummary { plan, detailed })
}

/// Expands an existing plan of `scenario`.
///
/// # Errors
/// [`DetailedJobError`] if the maps cannot be built or the expansion fails.
pub fn expand(
    scenario: &Scenario,
    sim: &mut Simulation,
    plan: &PlanSummary,
) -> Result<DetailedPath, DetailedJobError> {
    expand_prefix(scenario, sim, plan, plan.path.len())
}

/// Expands the first `end` elements of `plan`'s path (the whole path for its length), on
/// the maps the plan was made on (its k12, step cost factor and models).
///
/// # Errors
/// [`DetailedJobError`] if the maps cannot be built or the expansion fails.
pub fn expand_prefix(
    scenario: &Scenario,
    sim: &mut Simulation,
    plan: &PlanSummary,
    end: usize,
) -> Result<DetailedPath, DetailedJobError> {
    let prep = planner::prepare(
        scenario,
        sim.robot(),
        planner::ParamOverrides::of_plan(plan),
        &crate::motion::manoeuvres::ALL,
    )?;
    expand_prefix_on(&prep, scenario, sim, plan, end)
}

/// [`expand_prefix`] on the world `prep` the plan was made on (`planner::run_on`).
///
/// # Errors
/// [`DetailedJobError::Motion`] if the expansion fails.
pub fn expand_prefix_on(
    prep: &planner::Prepared,
    scenario: &Scenario,
    sim: &mut Simulation,
    plan: &PlanSummary,
    end: usize,
) -> Result<DetailedPath, DetailedJobError> {
    let robot = sim.robot().clone();
    let options = MotionOptions::from_params(&prep.params);
    let end = end.min(plan.path.len());
    expand_path(&plan.path[..end], &robot, &prep.maps, sim, &options)
        .map_err(|source| DetailedJobError::Motion { scenario: scenario.name.clone(), source })
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
