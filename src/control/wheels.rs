//! Omnidirectional wheel kinematics: a body twist (v_x', v_y', ω) in the robot frame to a
//! steering angle and two wheel speeds per leg.
//!
//! Each leg's wheel pair sits at a point p = (x', y') of the base frame and moves with
//! v = (v_x' − ω·y', v_y' + ω·x'). Its steering angle is the direction of v; since the pair
//! turns with the base at ω, the left wheel (at +track/2 across the pair) rolls slower by
//! ω·track/2 and the right one faster. Steering takes the shortest way: a wheel pair never
//! turns by more than 90° when reversing its wheels does the same job (the "flip"), and its
//! wheels get no speed while the steering is still far from its target. While a pair
//! steers, its wheels roll differentially with the steering rate, as Momaro's directly
//! driven pairs do, instead of scrubbing over the ground.

use crate::geometry::wrap_angle;
use crate::robot::{Leg, RobotDescription};
use std::f64::consts::PI;

/// A velocity command in the robot frame: m/s, m/s, rad/s.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Twist {
    /// Forward velocity v_x', m/s.
    pub vx: f64,
    /// Leftward velocity v_y', m/s.
    pub vy: f64,
    /// Yaw rate ω, rad/s.
    pub wz: f64,
}

/// What to command one leg's steering and wheels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelPairCommand {
    /// Steering angle target, rad (0 = wheels rolling along x').
    pub steer: f64,
    /// Wheel angular speeds (left, right), rad/s; positive rolls toward the steering direction.
    pub wheel_speeds: [f64; 2],
}

/// Tuning of the wheel kinematics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelKinematics {
    /// Steering error beyond which the wheels are not driven, rad.
    pub steer_gate_rad: f64,
    /// Pair speed below which the steering holds its angle (direction undefined), m/s.
    pub min_speed: f64,
    /// Steering joint range, rad: targets stay inside it.
    pub steer_limit: f64,
}

impl Default for WheelKinematics {
    fn default() -> Self {
        Self { steer_gate_rad: 0.35, min_speed: 1e-3, steer_limit: 3.1 }
    }
}

impl WheelKinematics {
    /// Commands for one wheel pair at `foot` = (x', y') in the base frame, given the
    /// steering's measured angle `current_steer`.
    pub fn pair_command(
        &self,
        robot: &RobotDescription,
        twist: Twist,
        foot: [f64; 2],
        current_steer: f64,
    ) -> WheelPairCommand {
        let v = [twist.vx - twist.wz * foot[1], twist.vy + twist.wz * foot[0]];
        let speed = v[0].hypot(v[1]);
        let half_track_turn = twist.wz * robot.wheel_track / 2.0;
        if speed < self.min_speed {
            // Turning on the spot about this pair's centre, or standing: hold the steering.
            let s = [-half_track_turn, half_track_turn];
            return self.gated(robot, current_steer, current_steer, s);
        }
        let heading = v[1].atan2(v[0]);
        // Two ways to roll along v: steer to `heading` forwards, or to heading ± π backwards.
        let mut best = (f64::INFINITY, heading, 1.0);
        for (angle, sign) in [(heading, 1.0), (heading + PI, -1.0), (heading - PI, -1.0)] {
            // Express the candidate near the current angle (the joint is not continuous).
            let a = current_steer + wrap_angle(angle - current_steer);
            if a.abs() > self.steer_limit {
                continue;
            }
            let err = (a - current_steer).abs();
            if err < best.0 {
                best = (err, a, sign);
            }
        }
        let (_, steer, sign) = best;
        let s = [sign * speed - half_track_turn, sign * speed + half_track_turn];
        self.gated(robot, steer, current_steer, s)
    }

    fn gated(
        &self,
        robot: &RobotDescription,
        steer: f64,
        current: f64,
        linear: [f64; 2],
    ) -> WheelPairCommand {
        let err = (steer - current).abs();
        let gate = if err > self.steer_gate_rad { 0.0 } else { err.cos() };
        WheelPairCommand {
            steer,
            wheel_speeds: [
                gate * linear[0] / robot.wheel_radius,
                gate * linear[1] / robot.wheel_radius,
            ],
        }
    }

    /// Adds the differential wheel speeds that let a pair turn about its steering axis at
    /// `steer_rate` (rad/s) without scrubbing: left wheel backward, right wheel forward.
    pub fn with_steering_rate(
        &self,
        robot: &RobotDescription,
        cmd: WheelPairCommand,
        steer_rate: f64,
    ) -> WheelPairCommand {
        let roll = steer_rate * robot.wheel_track / 2.0 / robot.wheel_radius;
        WheelPairCommand {
            steer: cmd.steer,
            wheel_speeds: [cmd.wheel_speeds[0] - roll, cmd.wheel_speeds[1] + roll],
        }
    }

    /// Commands for all four legs with wheel pairs at `feet` (base frame).
    pub fn commands(
        &self,
        robot: &RobotDescription,
        twist: Twist,
        feet: &[[f64; 2]; 4],
        current_steer: &[f64; 4],
    ) -> [WheelPairCommand; 4] {
        Leg::ALL.map(|leg| {
            let i = leg.index();
            self.pair_command(robot, twist, feet[i], current_steer[i])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round numbers for hand-computed speeds: r = 0.1 m, track 0.2 m.
    fn robot() -> RobotDescription {
        RobotDescription { wheel_radius: 0.1, wheel_track: 0.2, ..RobotDescription::reference() }
    }

    const K: WheelKinematics =
        WheelKinematics { steer_gate_rad: 0.35, min_speed: 1e-3, steer_limit: 3.1 };

    #[test]
    fn pure_translation_steers_all_pairs_alike() {
        let rb = robot();
        let feet = [[0.35, 0.32], [0.35, -0.32], [-0.35, 0.32], [-0.35, -0.32]];
        let twist = Twist { vx: 0.3, vy: 0.3, wz: 0.0 };
        let current = [std::f64::consts::FRAC_PI_4; 4];
        for c in K.commands(&rb, twist, &feet, &current) {
            assert!((c.steer - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
            let expected = 0.3 * 2f64.sqrt() / 0.1;
            assert!(
                (c.wheel_speeds[0] - expected).abs() < 1e-9
                    && (c.wheel_speeds[1] - expected).abs() < 1e-9
            );
        }
    }

    #[test]
    fn pure_rotation_steers_tangentially() {
        // ω = 1 rad/s at foot (0.3, 0.4): v = (-0.4, 0.3), |v| = 0.5, heading atan2(0.3, -0.4).
        let rb = robot();
        let heading = 0.3f64.atan2(-0.4);
        let c = K.pair_command(&rb, Twist { vx: 0.0, vy: 0.0, wz: 1.0 }, [0.3, 0.4], heading);
        assert!((c.steer - heading).abs() < 1e-12);
        // Left wheel 0.5 − 1·0.1, right 0.5 + 1·0.1, over r = 0.1.
        assert!(
            (c.wheel_speeds[0] - 4.0).abs() < 1e-9 && (c.wheel_speeds[1] - 6.0).abs() < 1e-9,
            "{c:?}"
        );
    }

    #[test]
    fn mixed_twist_adds_velocities() {
        // v = (0.5 − 1·0.0, 0 + 1·0.5) at foot (0.5, 0): heading 45°, |v| = 0.5·√2.
        let rb = robot();
        let c = K.pair_command(
            &rb,
            Twist { vx: 0.5, vy: 0.0, wz: 1.0 },
            [0.5, 0.0],
            std::f64::consts::FRAC_PI_4,
        );
        assert!((c.steer - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        let s = 0.5 * 2f64.sqrt();
        assert!((c.wheel_speeds[0] - (s - 0.1) / 0.1).abs() < 1e-9);
    }

    #[test]
    fn backwards_flips_the_wheels_instead_of_turning() {
        let rb = robot();
        let c = K.pair_command(&rb, Twist { vx: -0.4, vy: 0.0, wz: 0.0 }, [0.35, 0.32], 0.0);
        assert!(c.steer.abs() < 1e-12, "steering stays at 0, got {}", c.steer);
        assert!((c.wheel_speeds[0] + 4.0).abs() < 1e-9 && (c.wheel_speeds[1] + 4.0).abs() < 1e-9);
    }

    #[test]
    fn steering_rolls_the_pair_differentially() {
        let rb = robot();
        let c = WheelPairCommand { steer: 0.0, wheel_speeds: [1.0, 1.0] };
        // 2 rad/s steering, half track 0.1 m, r = 0.1 m: ±2 rad/s on the wheels.
        let d = K.with_steering_rate(&rb, c, 2.0);
        assert_eq!(d.wheel_speeds, [-1.0, 3.0]);
    }

    #[test]
    fn no_wheel_speed_while_steering_is_far_off() {
        let rb = robot();
        let c = K.pair_command(&rb, Twist { vx: 0.0, vy: 0.4, wz: 0.0 }, [0.35, 0.32], 0.0);
        assert!((c.steer.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(c.wheel_speeds, [0.0, 0.0]);
    }
}
