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
    ankle_above(robot, contact, world_down(pitch))
}

/// [`ankle_of_contact`] with world down in the base frame (`down`, [`world_down`]) given.
fn ankle_above(robot: &RobotDescription, contact: [f64; 2], down: [f64; 2]) -> [f64; 2] {
    let below = robot.foot_length + robot.wheel_radius;
    [contact[0] - below * down[0], contact[1] - below * down[1]]
}

/// One leg solved by the sagittal IK ([`leg_chain`]): the joint angles and the points of
/// its chain, which the posture checks (thigh and shin clearance, the lumped CoM) need and
/// would otherwise recompute from the angles with six sines and cosines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegChain {
    /// Joint angles (hip, knee, ankle), rad.
    pub joints: [f64; 3],
    /// The knee (x', z') relative to the hip in the base frame, m.
    pub knee: [f64; 2],
    /// The ankle (x', z') relative to the hip in the base frame, m.
    pub ankle: [f64; 2],
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
    leg_chain(robot, leg, contact, pitch, world_down(pitch)).map(|c| c.joints)
}

/// [`leg_ik`] with the knee and the ankle it solves for: `down` is [`world_down`]`(pitch)`,
/// which a posture computes once for its four legs. The knee comes without trigonometry:
/// it lies `l1` from the hip and `l2` from the ankle, on the side of the hip–ankle line
/// its leg's knees point to, so it is the hip–ankle direction turned by γ with
/// cos γ = (l1² + d² − l2²)/(2·l1·d), d the hip–ankle distance; the hip angle is the
/// knee's direction from the hip (β less γ, β the hip–ankle direction's angle, in one
/// arctangent: the IK runs in every posture check the planner makes). The knee equals
/// [`knee_and_ankle`] of the joint angles to rounding (about 1e-16 m), as the angles do
/// the textbook solution's (q1 = β − atan2(l2·sin q2, l1 + l2·cos q2)).
///
/// # Errors
/// [`IkError`] as [`leg_ik`].
pub fn leg_chain(
    robot: &RobotDescription,
    leg: Leg,
    contact: [f64; 2],
    pitch: f64,
    down: [f64; 2],
) -> Result<LegChain, IkError> {
    if !(contact[0].is_finite() && contact[1].is_finite() && pitch.is_finite()) {
        return Err(IkError::NotFinite { leg });
    }
    let (l1, l2) = (robot.thigh_length, robot.shin_length);
    let ankle = ankle_above(robot, contact, down);
    let d2 = ankle[0] * ankle[0] + ankle[1] * ankle[1];
    let d = d2.sqrt();
    if d > l1 + l2 || d < (l1 - l2).abs() {
        return Err(IkError::OutOfReach { leg, distance: d, reach: l1 + l2 });
    }
    let c2 = ((d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
    let knee_sign = if leg.is_front() { -1.0 } else { 1.0 };
    let q2 = knee_sign * c2.acos();
    let (q1, knee) = if d > 0.0 {
        // The thigh leaves the hip–ankle line by γ towards the side the knee points to:
        // cos γ = (l1² + d² − l2²)/(2·l1·d) by the law of cosines. The knee is the unit
        // vector hip → ankle turned by γ; the thigh's angle from straight down is the hip
        // angle (one arctangent where β − γ takes two).
        let cos_g = ((l1 * l1 + d2 - l2 * l2) / (2.0 * l1 * d)).clamp(-1.0, 1.0);
        let sin_g = knee_sign * (1.0 - cos_g * cos_g).sqrt();
        let e = [ankle[0] / d, ankle[1] / d];
        let knee = [l1 * (cos_g * e[0] - sin_g * e[1]), l1 * (sin_g * e[0] + cos_g * e[1])];
        ((-knee[0]).atan2(-knee[1]), knee)
    } else {
        // The ankle on the hip (equal segments folded flat): every knee on the circle of
        // radius l1 solves it; the thigh along β, the hip–ankle direction's angle.
        let q1 = (-ankle[0]).atan2(-ankle[1]);
        let a = u(q1);
        (q1, [l1 * a[0], l1 * a[1]])
    };
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
    Ok(LegChain { joints: q, knee, ankle })
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
    fn leg_chain_knee_by_hand() {
        // Contact 0.27 m below the hip, level base: the ankle 0.09 m below the hip, the
        // knee halfway down (z' = −0.045) and √(0.25² − 0.045²) to the side its knees
        // point to, backward for a front leg, forward for a rear one.
        let rb = robot();
        let side = (0.25f64 * 0.25 - 0.045 * 0.045).sqrt();
        for (leg, x) in [(Leg::FrontLeft, -side), (Leg::RearRight, side)] {
            let c = leg_chain(&rb, leg, [0.0, -0.27], 0.0, world_down(0.0)).unwrap();
            assert!((c.knee[0] - x).abs() < 1e-12 && (c.knee[1] + 0.045).abs() < 1e-12, "{c:?}");
            assert!(c.ankle[0].abs() < 1e-12 && (c.ankle[1] + 0.09).abs() < 1e-12, "{c:?}");
            assert_eq!(c.joints, leg_ik(&rb, leg, [0.0, -0.27], 0.0).unwrap());
        }
    }

    #[test]
    fn leg_chain_equals_forward_kinematics_of_its_angles() {
        // Over a grid of contacts and pitches, every reachable one: the chain's knee and
        // ankle are those the joint angles give, to rounding.
        let rb = robot();
        let mut solved = 0;
        for leg in Leg::ALL {
            for i in 0..=30 {
                for j in 0..=30 {
                    for pitch in [-0.4, -0.2, -0.05, 0.0, 0.1, 0.3] {
                        let contact = [-0.6 + 0.04 * f64::from(i), -0.8 + 0.02 * f64::from(j)];
                        let Ok(c) = leg_chain(&rb, leg, contact, pitch, world_down(pitch)) else {
                            continue;
                        };
                        assert_eq!(c.joints, leg_ik(&rb, leg, contact, pitch).unwrap());
                        // The textbook hip angle, from the knee angle's sine and cosine.
                        let [_, q2, _] = c.joints;
                        let ankle = ankle_of_contact(&rb, contact, pitch);
                        let (l1, l2) = (rb.thigh_length, rb.shin_length);
                        let q1 = (-ankle[0]).atan2(-ankle[1])
                            - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
                        let q3 = -pitch - q1 - q2;
                        for (k, q) in [q1, q2, q3].into_iter().enumerate() {
                            assert!((c.joints[k] - q).abs() < 1e-12, "{leg:?} {c:?} {q1}");
                        }
                        let [knee, ankle] = knee_and_ankle(&rb, c.joints);
                        for k in 0..2 {
                            assert!((c.knee[k] - knee[k]).abs() < 1e-12, "{leg:?} {c:?} {knee:?}");
                            assert!((c.ankle[k] - ankle[k]).abs() < 1e-12, "{c:?} {ankle:?}");
                        }
                        solved += 1;
                    }
                }
            }
        }
        assert!(solved > 4 * 1000, "{solved}");
    }

    #[test]
    fn leg_chain_with_the_ankle_on_the_hip() {
        // Joint limits wide enough to fold the equal segments flat: the ankle on the hip
        // has no direction to turn, the knee comes from the angles.
        let mut rb = robot();
        rb.joint_ranges = [crate::robot::Range { min: -3.5, max: 3.5 }; 3];
        let below = rb.foot_length + rb.wheel_radius;
        let c = leg_chain(&rb, Leg::RearLeft, [0.0, -below], 0.0, world_down(0.0)).unwrap();
        assert_eq!(c.ankle, [0.0, 0.0]);
        assert_eq!(c.knee, knee_and_ankle(&rb, c.joints)[0]);
        assert!((c.knee[0].hypot(c.knee[1]) - 0.25).abs() < 1e-12, "{c:?}");
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
