//! The standing posture: leg joint targets that hold the neutral footprint at a given leg
//! height with a level base (Sec. VI-B: 0.27 m while driving).

use crate::robot::ik::{IkError, leg_ik};
use crate::robot::{Leg, RobotDescription};

/// Joint targets (hip, knee, ankle per leg) for the neutral footprint with every wheel's
/// ground contact `leg_height` below its hip and the base level.
///
/// # Errors
/// [`IkError`] if the height is out of the legs' reach.
pub fn neutral_posture(
    robot: &RobotDescription,
    leg_height: f64,
) -> Result<[[f64; 3]; 4], IkError> {
    let mut q = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let i = leg.index();
        q[i] = leg_ik(robot, leg, [robot.neutral_foot_offset_x[i], -leg_height], 0.0)?;
    }
    Ok(q)
}
