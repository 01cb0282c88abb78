//! Sagittal-plane inverse and forward kinematics of one leg (hip, knee, ankle pitch).
//!
//! Coordinates are the base frame's (x', z') at the leg's hip: x' forward, z' up. All
//! three joints turn about the base's y' axis; a segment at angle `a` from straight down
//! points along u(a) = (−sin a, −cos a). The wheel is kept level: the foot segment points
//! straight down in the world, so the joint angles sum to −(base pitch). Knees point toward
//! the body centre: front knees backward (knee angle < 0), rear knees forward (> 0).

use super::{Leg, RobotDescription};

/// Why a foot position cannot be reached.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    /// The ankle is farther from the hip than the straight leg.
    #[error("leg {leg:?}: ankle {distance:.3} m from the hip, beyond the reach of {reach:.3} m")]
    OutOfReach {
        /// The leg.
        leg: Leg,
        /// Hip-to-ankle distance asked for, m.
        distance: f64,
        /// Thigh plus shin, m.
        reach: f64,
    },
    /// A joint would have to pass its limit.
    #[error("leg {leg:?}: {joint} angle {value:.3} rad outside [{min:.3}, {max:.3}]")]
    JointLimit {
        /// The leg.
        leg: Leg,
        /// hip, knee or ankle.
        joint: &'static str,
        /// The angle the solution needs.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// Non-finite input.
    #[error("leg {leg:?}: non-finite foot target")]
    NotFinite {
        /// The leg.
        leg: Leg,
    },
}

fn u(a: f64) -> [f64; 2] {
    [-a.sin(), -a.cos()]
}

/// World down in the base frame of a base pitched by `pitch`, (x', z'): the direction of
/// a level wheel's foot segment, and of its ground contact point from the axle.
pub fn world_down(pitch: f64) -> [f64; 2] {
    u(-pitch)
}

/// The ankle (x', z') relative to the hip for the wheel's ground contact point at
/// `contact`, in the base frame of a base pitched by `pitch`, the wheel level: the foot
/// segment and wheel radius straight up from the contact along [`world_down`].
pub fn ankle_of_contact(robot: &RobotDescription, contact: [f64; 2], pitch: f64) -> [f64; 2] {
    let down = world_down(pitch);
    let below = robot.foot_length + robot.wheel_radius;
    [contact[0] - below * down[0], contact[1] - below * down[1]]
}

/// Joint angles (hip, knee, ankle) that put the wheel's ground contact point at `contact`
/// = (x', z') relative to the hip, in the base frame of a base pitched by `pitch` (rad,
/// positive nose down), with the wheel level in the world.
///
/// # Errors
/// [`IkError`] if the point is out of reach or a joint limit would be passed.
pub fn leg_ik(
    robot: &RobotDescription,
    leg: Leg,
    contact: [f64; 2],
    pitch: f64,
) -> Result<[f64; 3], IkError> {
    if !(contact[0].is_finite() && contact[1].is_finite() && pitch.is_finite()) {
        return Err(IkError::NotFinite { leg });
    }
    let (l1, l2) = (robot.thigh_length, robot.shin_length);
    let ankle = ankle_of_contact(robot, contact, pitch);
    let d2 = ankle[0] * ankle[0] + ankle[1] * ankle[1];
    let d = d2.sqrt();
    if d > l1 + l2 || d < (l1 - l2).abs() {
        return Err(IkError::OutOfReach { leg, distance: d, reach: l1 + l2 });
    }
    let c2 = ((d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
    let knee_sign = if leg.is_front() { -1.0 } else { 1.0 };
    let q2 = knee_sign * c2.acos();
    let beta = (-ankle[0]).atan2(-ankle[1]);
    let q1 = beta - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
    let q3 = -pitch - q1 - q2;
    let q = [q1, q2, q3];
    for (k, name) in ["hip", "knee", "ankle"].iter().enumerate() {
        let r = robot.joint_ranges[k];
        if !r.contains(q[k]) {
            return Err(IkError::JointLimit {
                leg,
                joint: name,
                value: q[k],
                min: r.min,
                max: r.max,
            });
        }
    }
    Ok(q)
}

/// The knee and the ankle (x', z') relative to the hip, in the base frame, for joint
/// angles `q`: the thigh and shin segments of the sagittal chain.
pub fn knee_and_ankle(robot: &RobotDescription, q: [f64; 3]) -> [[f64; 2]; 2] {
    let (a1, a2) = (u(q[0]), u(q[0] + q[1]));
    let knee = [robot.thigh_length * a1[0], robot.thigh_length * a1[1]];
    [knee, [knee[0] + robot.shin_length * a2[0], knee[1] + robot.shin_length * a2[1]]]
}

/// Forward kinematics: the wheel's ground contact point (x', z') relative to the hip, in the
/// base frame of a base pitched by `pitch`, for joint angles `q`. The contact point is the
/// lowest point of the wheel in the world, assuming the wheel level.
pub fn leg_fk(robot: &RobotDescription, q: [f64; 3], pitch: f64) -> [f64; 2] {
    let [_, ankle] = knee_and_ankle(robot, q);
    let (a3, down) = (u(q[0] + q[1] + q[2]), u(-pitch));
    let (lf, r) = (robot.foot_length, robot.wheel_radius);
    [ankle[0] + lf * a3[0] + r * down[0], ankle[1] + lf * a3[1] + r * down[1]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot() -> RobotDescription {
        RobotDescription::reference()
    }

    #[test]
    fn hand_computed_driving_posture() {
        // Contact 0.27 m below the hip: ankle 0.09 m below; with 0.25 m segments the knee
        // angle is -(π - 2·asin(0.045/0.25)) and the hip the half of its magnitude.
        let q = leg_ik(&robot(), Leg::FrontLeft, [0.0, -0.27], 0.0).unwrap();
        let half = (0.045f64 / 0.25).asin();
        assert!((q[1] + (std::f64::consts::PI - 2.0 * half)).abs() < 1e-9, "{q:?}");
        assert!((q[0] - (std::f64::consts::FRAC_PI_2 - half)).abs() < 1e-9, "{q:?}");
        assert!((q[0] + q[1] + q[2]).abs() < 1e-12);
    }

    #[test]
    fn rear_knees_bend_the_other_way() {
        let f = leg_ik(&robot(), Leg::FrontLeft, [0.05, -0.4], 0.0).unwrap();
        let r = leg_ik(&robot(), Leg::RearLeft, [0.05, -0.4], 0.0).unwrap();
        assert!(f[1] < 0.0 && r[1] > 0.0);
    }

    #[test]
    fn ik_fk_round_trip_with_pitch() {
        let rb = robot();
        for leg in Leg::ALL {
            for &(x, z, pitch) in
                &[(0.0, -0.27, 0.0), (0.1, -0.5, 0.2), (-0.15, -0.45, -0.25), (0.2, -0.6, 0.1)]
            {
                let q = leg_ik(&rb, leg, [x, z], pitch).unwrap();
                let p = leg_fk(&rb, q, pitch);
                assert!((p[0] - x).abs() < 1e-9 && (p[1] - z).abs() < 1e-9, "{leg:?} {p:?}");
            }
        }
    }

    #[test]
    fn out_of_reach_and_nan_are_errors() {
        let rb = robot();
        assert!(matches!(
            leg_ik(&rb, Leg::RearRight, [0.0, -0.9], 0.0),
            Err(IkError::OutOfReach { .. })
        ));
        assert!(matches!(
            leg_ik(&rb, Leg::RearRight, [f64::NAN, -0.3], 0.0),
            Err(IkError::NotFinite { .. })
        ));
    }
}
