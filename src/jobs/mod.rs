//! What the CLI's commands do, as library functions returning serialisable summaries, so
//! tests call exactly what users run.

pub mod bench;
pub mod check;
pub mod costmap;
pub mod detailed;
pub mod envelope;
pub mod generate;
pub mod plan;
pub mod plan_recording;
pub mod run;
pub mod sim;

use crate::posture::neutral_posture;
use crate::robot::ik::IkError;
use crate::scenario::Scenario;
use crate::sim::Simulation;

/// Places the robot at the scenario's start in the neutral driving posture, its wheels on
/// the terrain; returns the posture's joint targets and the base height above the ground.
///
/// # Errors
/// [`IkError`] if the driving leg height is out of the legs' reach.
pub fn stand_at_start(
    sim: &mut Simulation,
    scenario: &Scenario,
) -> Result<([[f64; 3]; 4], f64), IkError> {
    let robot = sim.robot().clone();
    let leg_height = scenario.params.driving_leg_height_m;
    let posture = neutral_posture(&robot, leg_height)?;
    let base_height = leg_height - robot.hips[0][2];
    let start = scenario.start;
    let ground = scenario.terrain_height(start.x, start.y);
    sim.place_robot([start.x, start.y, ground + base_height], start.theta, &posture);
    Ok((posture, base_height))
}
