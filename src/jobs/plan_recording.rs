//! `momaro plan --rerun`: the plan drawn over its maps — height map, foot-cost image, the
//! base path with headings, and each step as a line from the old foot position to its
//! foothold (front steps red, rear steps green, as in the paper's Fig. 11).

use super::costmap::{CostmapError, rasterised_map};
use crate::cost::CostMaps;
use crate::path::ManoeuvreKind;
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
    let maps = CostMaps::build(&heights, robot, &scenario.params)?;
    let rec = Recorder::create(path, "momaro plan")?;
    rec.log_height_map(&heights)?;
    let (nx, ny) = heights.dims();
    let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
    if let Some(img) = render::cost_layer_image(&foot, nx, ny, None) {
        rec.log_layer_image("foot_cost", &img, heights.origin(), heights.resolution())?;
    }
    let poses: Vec<_> = summary.path.iter().map(|e| e.pose).collect();
    rec.log_plan(&poses)?;
    rec.log_steps(&step_lines(summary))?;
    rec.finish()?;
    Ok(())
}

/// Each step of `summary`'s path as a line from the old foot position to its foothold, 2 cm
/// above the ground, and whether a front leg steps (red) or a rear one (green).
pub fn step_lines(summary: &PlanSummary) -> Vec<([f64; 3], [f64; 3], bool)> {
    let mut steps = Vec::new();
    for pair in summary.path.windows(2) {
        let (before, after) = (&pair[0], &pair[1]);
        if after.kind == ManoeuvreKind::Step
            && let Some(leg) = after.leg
        {
            let i = leg.index();
            let z = |h: Option<f64>| h.unwrap_or(0.0) + 0.02;
            steps.push((
                [before.feet[i][0], before.feet[i][1], z(before.foot_heights[i])],
                [after.feet[i][0], after.feet[i][1], z(after.foot_heights[i])],
                leg.is_front(),
            ));
        }
    }
    steps
}
