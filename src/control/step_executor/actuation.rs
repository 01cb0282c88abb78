//! From a commanded posture to actuator targets: leg joint targets by the sagittal IK
//! (pulling a foot just beyond reach back in), and wheel commands (pairs in contact roll
//! at their foot's speed along the heading, steering straight, with the steering-rate
//! feed-forward of the wheel kinematics). An IK failure here fails the step.

use super::{Command, ExecFailure, Observation, StepExecutor};
use crate::control::wheels::WheelPairCommand;
use crate::posture::kinematics::{Posture, contacts_in_base};
use crate::robot::ik::{IkError, ankle_of_contact, leg_ik, world_down};
use crate::robot::{Leg, RobotDescription};

/// Wheel speed (rad/s) that rolls a pair steered straight along a base heading `yaw` at
/// the foot's world velocity `v` (only the component along the heading can roll).
pub fn rolling_wheel_speed(robot: &RobotDescription, v: [f64; 2], yaw: f64) -> f64 {
    let (s, c) = yaw.sin_cos();
    (c * v[0] + s * v[1]) / robot.wheel_radius
}

/// Where each wheel pair stands in the base's plane (x', y', m) for posture `p`: its
/// contact under the base plus the hip's offset, what the wheel kinematics take.
pub(super) fn pairs_in_base(robot: &RobotDescription, p: &Posture) -> [[f64; 2]; 4] {
    let local = contacts_in_base(robot, p);
    std::array::from_fn(|i| [local[i][0] + robot.hips[i][0], local[i][1] + robot.hips[i][1]])
}

/// Spare reach the executor keeps when it has to pull a foot in, m.
pub(super) const REACH_SPARE_M: f64 = 0.001;

/// Joint targets for `p` like `posture::kinematics::leg_joint_targets`, except that a foot
/// beyond a leg's reach is pulled toward its hip (along the hip–ankle line) until the leg
/// has `spare` m of reach left, and a foot closer to its hip than the knee folds is pushed
/// out along the same line until the knee has `spare` m of fold left: the executor's
/// corrections (landing offset, stabilising shift, wheels resting on the height map under
/// a driving posture whose knees fold nearly to their limit) may ask a few millimetres
/// more than a posture planned at either limit has.
///
/// # Errors
/// [`IkError`] for a joint limit or non-finite input.
pub fn reachable_leg_targets(
    robot: &RobotDescription,
    p: &Posture,
    spare: f64,
) -> Result<[[f64; 3]; 4], IkError> {
    let local = contacts_in_base(robot, p);
    let pitch = p.base_rpy[1];
    let below = robot.foot_length + robot.wheel_radius;
    let (l1, l2) = (robot.thigh_length, robot.shin_length);
    let reach = l1 + l2 - spare;
    // Hip-to-ankle distance with the knee folded to its limit (law of cosines).
    let knee_max = robot.joint_ranges[1].min.abs().min(robot.joint_ranges[1].max.abs());
    let folded = (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * knee_max.cos()).max(0.0).sqrt() + spare;
    let down = world_down(pitch);
    let mut q = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let c = local[leg.index()];
        let mut contact = [c[0], c[2]];
        let ankle = ankle_of_contact(robot, contact, pitch);
        let d = ankle[0].hypot(ankle[1]);
        let target = if d > reach {
            reach
        } else if d < folded && d > 1e-9 {
            folded
        } else {
            d
        };
        if target != d {
            let k = target / d;
            contact = [ankle[0] * k + below * down[0], ankle[1] * k + below * down[1]];
        }
        q[leg.index()] = leg_ik(robot, leg, contact, pitch)?;
    }
    Ok(q)
}

/// How far the furthest-reaching leg in contact of posture `p`, `except` left out, asks
/// beyond its reach (thigh plus shin, less `spare`), m; zero or less when every such foot
/// is reached. [`reachable_leg_targets`] would pull such a foot in, off the ground.
pub fn reach_excess(robot: &RobotDescription, p: &Posture, spare: f64, except: Option<Leg>) -> f64 {
    let local = contacts_in_base(robot, p);
    let reach = robot.thigh_length + robot.shin_length - spare;
    Leg::ALL
        .into_iter()
        .filter(|&leg| p.contact[leg.index()] && Some(leg) != except)
        .map(|leg| {
            let c = local[leg.index()];
            let ankle = ankle_of_contact(robot, [c[0], c[2]], p.base_rpy[1]);
            ankle[0].hypot(ankle[1]) - reach
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The largest fraction `a` in [0, 1] of a move at which `excess(a)`, the reach excess
/// ([`reach_excess`]) of the posture that far along the move, stays within `allowed`: 1 if
/// the whole move does, else found by bisection. `excess(0) <= allowed` is assumed, so the
/// answer is always within reach even where the excess is not monotonic along the move.
pub(super) fn reachable_fraction(excess: impl Fn(f64) -> f64, allowed: f64) -> f64 {
    if excess(1.0) <= allowed {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) <= allowed { lo = mid } else { hi = mid }
    }
    lo
}

/// `p` with its base moved by `hold` in the plane.
pub(super) fn held_by(p: &Posture, hold: [f64; 2]) -> Posture {
    let mut q = *p;
    q.base_position[0] += hold[0];
    q.base_position[1] += hold[1];
    q
}

fn straight(speed: f64) -> WheelPairCommand {
    WheelPairCommand { steer: 0.0, wheel_speeds: [speed, speed] }
}

impl StepExecutor {
    /// `p` with the base moved by the position hold (`ExecutorConfig::max_base_hold_m`):
    /// the posture the legs are solved for, so the compliant robot stands at `p`.
    pub(super) fn held(&self, p: &Posture) -> Posture {
        held_by(p, self.base_hold)
    }

    pub(super) fn legs_for(&mut self, p: &Posture, time: f64) -> Option<[[f64; 3]; 4]> {
        match reachable_leg_targets(&self.robot, &self.held(p), REACH_SPARE_M) {
            Ok(q) => {
                self.last_legs = q;
                Some(q)
            }
            Err(e) => {
                self.fail(ExecFailure::Ik { message: e.to_string() }, time);
                None
            }
        }
    }

    /// Joint targets for `p`, or the last ones if `p` cannot be solved (while already
    /// recovering, a failure must not start another recovery).
    pub(super) fn legs_or_hold(&mut self, p: &Posture) -> [[f64; 3]; 4] {
        if let Ok(q) = reachable_leg_targets(&self.robot, &self.held(p), REACH_SPARE_M) {
            self.last_legs = q;
        }
        self.last_legs
    }

    pub(super) fn hold(&self) -> Command {
        Command { legs: self.last_legs, wheels: [straight(0.0); 4] }
    }

    pub(super) fn with_steer_rate(
        &self,
        cmd: [WheelPairCommand; 4],
        obs: &Observation,
    ) -> [WheelPairCommand; 4] {
        std::array::from_fn(|i| {
            self.config.wheels.with_steering_rate(&self.robot, cmd[i], obs.steering_rate[i])
        })
    }

    /// Wheel commands for a posture moving at `velocity` (world feet velocities): pairs in
    /// contact roll at their foot's speed along the heading, steering straight.
    pub(super) fn rolling(
        &self,
        p: &Posture,
        velocity: &[[f64; 2]; 4],
        obs: &Observation,
    ) -> [WheelPairCommand; 4] {
        let yaw = p.base_rpy[2];
        let cmd = std::array::from_fn(|i| {
            if p.contact[i] {
                straight(rolling_wheel_speed(&self.robot, velocity[i], yaw))
            } else {
                straight(0.0)
            }
        });
        self.with_steer_rate(cmd, obs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::step_executor::test_support::{robot, standing};
    use crate::posture::kinematics::leg_joint_targets;
    use crate::robot::ik::leg_fk;

    #[test]
    fn wheel_speed_is_the_foot_speed_along_the_heading_over_the_radius() {
        // r = 0.08 m: 0.1 m/s straight ahead is 1.25 rad/s; heading 90° sees only v_y.
        let r = robot();
        assert!((rolling_wheel_speed(&r, [0.1, 0.0], 0.0) - 1.25).abs() < 1e-12);
        assert!((rolling_wheel_speed(&r, [0.1, 0.0], std::f64::consts::FRAC_PI_2)).abs() < 1e-12);
        assert!(
            (rolling_wheel_speed(&r, [0.0, -0.04], std::f64::consts::FRAC_PI_2) + 0.5).abs()
                < 1e-12
        );
        // 60°: 0.1·cos 60° = 0.05 m/s → 0.625 rad/s.
        assert!(
            (rolling_wheel_speed(&r, [0.1, 0.0], std::f64::consts::FRAC_PI_3) - 0.625).abs()
                < 1e-12
        );
    }

    #[test]
    fn a_foot_closer_than_the_folded_knee_is_pushed_out_along_the_hip_ankle_line() {
        let r = robot();
        let mut p = standing();
        // Hip 0.45 m above the ground, ankle 0.27 m below the hip; raising the foot by
        // 0.22 m puts the ankle 0.05 m below it. The knee folds to ±2.9 rad at most:
        // hip to ankle √(2 · 0.25² · (1 + cos 2.9)) = 0.060251 m, so 0.05 is too close.
        p.feet[0][2] += 0.22;
        assert!(leg_joint_targets(&r, &p).is_err());
        let q = reachable_leg_targets(&r, &p, 0.001).unwrap();
        let c = leg_fk(&r, q[0], 0.0);
        let ankle = [c[0], c[1] + r.foot_length + r.wheel_radius];
        let folded = (2.0 * 0.0625 * (1.0 + 2.9f64.cos())).sqrt();
        assert!((folded - 0.060251).abs() < 1e-6);
        assert!((ankle[0].hypot(ankle[1]) - (folded + 0.001)).abs() < 1e-9, "{ankle:?}");
        // Along the line: straight down, as the foot was.
        assert!(ankle[0].abs() < 1e-9 && ankle[1] < 0.0, "{ankle:?}");
    }

    #[test]
    fn a_foot_beyond_reach_is_pulled_in_along_the_hip_ankle_line() {
        let r = robot();
        let mut p = standing();
        // Hip 0.45 m above the ground: the ankle (0.18 m above the contact) 0.27 m below
        // the hip, reachable. Moving the front-left foot 0.45 m forward puts the ankle
        // √(0.45² + 0.27²) = 0.525 m from the hip, beyond 0.5.
        p.feet[0][0] += 0.45;
        assert!(leg_joint_targets(&r, &p).is_err());
        let q = reachable_leg_targets(&r, &p, 0.001).unwrap();
        let c = leg_fk(&r, q[0], 0.0);
        let ankle = [c[0], c[1] + r.foot_length + r.wheel_radius];
        assert!((ankle[0].hypot(ankle[1]) - 0.499).abs() < 1e-9);
        // Along the line: the ankle direction is unchanged.
        let want = 0.45f64.atan2(0.27);
        assert!((ankle[0].atan2(-ankle[1]) - want).abs() < 1e-9);
        // Reachable feet are untouched.
        let local = contacts_in_base(&r, &p);
        for i in 1..4 {
            let f = leg_fk(&r, q[i], 0.0);
            assert!((f[0] - local[i][0]).abs() < 1e-9 && (f[1] - local[i][2]).abs() < 1e-9);
        }
    }
}
