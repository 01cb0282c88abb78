//! What passes between the simulation and the controllers each control tick: the
//! executor's observation read from MuJoCo, its command sent to the actuators, and the
//! robot placed at the scenario's start.

use crate::control::step_executor::{Command, Observation};
use crate::geometry::Pose2;
use crate::posture::neutral_posture;
use crate::robot::Leg;
use crate::robot::ik::IkError;
use crate::scenario::Scenario;
use crate::sim::{BaseState, Simulation, TOUCHING_M};

/// Sends the executor's command to the simulated actuators.
pub fn actuate(sim: &mut Simulation, cmd: &Command) {
    for leg in Leg::ALL {
        let i = leg.index();
        sim.set_leg_joint_targets(leg, cmd.legs[i]);
        sim.set_steering_target(leg, cmd.wheels[i].steer);
        sim.set_wheel_speeds(leg, cmd.wheels[i].wheel_speeds);
    }
}

/// What the executor sees of the simulation, with `measured` as the planar base pose and
/// the height of `base` (the simulated base, read once per tick); wheels within
/// `support_gap_m` of the terrain support it, as they do for the monitor.
pub fn observe(
    sim: &Simulation,
    base: &BaseState,
    measured: Pose2,
    support_gap_m: f64,
) -> Observation {
    let wheels = sim.wheel_contacts();
    let within = |gap: f64| -> Vec<(Leg, [f64; 2])> {
        wheels
            .iter()
            .filter(|c| c.distance <= gap)
            .map(|c| (c.leg, [c.position[0], c.position[1]]))
            .collect()
    };
    Observation {
        time: sim.time(),
        base: measured,
        base_z: Some(base.position[2]),
        joints: Leg::ALL.map(|l| sim.leg_joints(l)),
        steering: Leg::ALL.map(|l| sim.steering_angle(l)),
        steering_rate: Leg::ALL.map(|l| sim.steering_rate(l)),
        com: sim.center_of_mass(),
        wheel_contacts: within(TOUCHING_M),
        support_contacts: within(support_gap_m),
        wheel_loads: sim.wheel_loads(),
    }
}

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
