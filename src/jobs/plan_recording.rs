//! `momaro plan --rerun`: the plan drawn over its maps — height map, foot-cost image, the
//! base path with headings, and each step as a line from the old foot position to its
//! foothold (front steps red, rear steps green, as in the paper's Fig. 11).

use super::costmap::{CostmapError, rasterised_map};
use crate::cost::CostMaps;
use crate::planner::PlanSummary;
use crate::render;
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use crate::viz::{Recorder, VizError};
use std::path::Path;

/// Why a plan recording failed.
#[derive(Debug, thiserror::Error)]
pub enum PlanRecordingError {
    /// The maps could not be rebuilt.
    #[error(transparent)]
    Map(#[from] CostmapError),
    /// The cost layers could not be rebuilt.
    #[error(transparent)]
    Cost(#[from] crate::cost::CostError),
    /// Writing failed.
    #[error(transparent)]
    Viz(#[from] VizError),
}

/// Writes the recording of `summary` for `scenario` to `path`.
///
/// # Errors
/// [`PlanRecordingError`].
pub fn record(
    scenario: &Scenario,
    robot: &RobotDescription,
    summary: &PlanSummary,
    path: &Path,
) -> Result<(), PlanRecordingError> {
    let heights = rasterised_map(scenario)?;
    // The models the plan was made with.
    let params = crate::params::Params {
        foot_model: summary.foot_model,
        step_model: summary.step_model,
        ..scenario.params.clone()
    };
    let maps = CostMaps::build(&heights, robot, &params)?;
    let rec = Recorder::create(path, "momaro plan")?;
    rec.log_height_map(&heights)?;
    let (nx, ny) = heights.dims();
    let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
    if let Some(img) = render::cost_layer_image(&foot, nx, ny, None) {
        rec.log_layer_image("foot_cost", &img, heights.origin(), heights.resolution())?;
    }
    let poses: Vec<_> = summary.path.iter().map(|e| e.pose).collect();
    rec.log_plan(&poses)?;
    rec.log_steps(&crate::viz::step_lines(&summary.path))?;
    rec.finish()?;
    Ok(())
}
