//! Time laws of the step executor: the smoothstep interpolation of keyframe segments and
//! its rate, the segment clock that slows down while the servos lag, and the duration of
//! a motion at bounded linear and angular speed (recovery, lower bound of a segment).

use crate::geometry::wrap_angle;
use crate::posture::kinematics::Posture;

/// `3s² − 2s³` on [0, 1]: zero velocity at both ends.
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// d smoothstep / ds.
pub fn smoothstep_rate(s: f64) -> f64 {
    if !(0.0..=1.0).contains(&s) {
        return 0.0;
    }
    6.0 * s * (1.0 - s)
}

/// Segment clock rate for a joint tracking error `err` (rad): 1 up to `start`, falling
/// linearly to `slowest` at `full`.
pub fn clock_rate(err: f64, start: f64, full: f64, slowest: f64) -> f64 {
    if err <= start {
        1.0
    } else if err >= full {
        slowest
    } else {
        1.0 - (1.0 - slowest) * (err - start) / (full - start)
    }
}

/// Time to move from `a` to `b` at `speed` (m/s, base and feet) and `angular` (rad/s).
pub fn motion_duration(a: &Posture, b: &Posture, speed: f64, angular: f64) -> f64 {
    let d = |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]);
    let lin =
        (0..4).map(|i| d(a.feet[i], b.feet[i])).fold(d(a.base_position, b.base_position), f64::max);
    let ang = (0..3).map(|k| wrap_angle(b.base_rpy[k] - a.base_rpy[k]).abs()).fold(0.0, f64::max);
    (lin / speed).max(ang / angular).max(0.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::step_executor::test_support::standing;

    #[test]
    fn smoothstep_by_hand() {
        assert_eq!(smoothstep(0.0), 0.0);
        assert_eq!(smoothstep(1.0), 1.0);
        assert!((smoothstep(0.5) - 0.5).abs() < 1e-12);
        // 3·0.25² − 2·0.25³ = 0.1875 − 0.03125.
        assert!((smoothstep(0.25) - 0.15625).abs() < 1e-12);
        assert_eq!(smoothstep(2.0), 1.0);
        // 6·0.5·0.5 = 1.5 at the middle, zero at the ends.
        assert!((smoothstep_rate(0.5) - 1.5).abs() < 1e-12);
        assert_eq!(smoothstep_rate(0.0), 0.0);
        assert_eq!(smoothstep_rate(1.0), 0.0);
    }

    #[test]
    fn clock_slows_linearly_between_the_error_bounds() {
        assert_eq!(clock_rate(0.01, 0.05, 0.2, 0.2), 1.0);
        // Half-way (0.125 rad): 1 − 0.8·0.5 = 0.6.
        assert!((clock_rate(0.125, 0.05, 0.2, 0.2) - 0.6).abs() < 1e-12);
        assert_eq!(clock_rate(0.5, 0.05, 0.2, 0.2), 0.2);
    }

    #[test]
    fn motion_duration_takes_the_slowest_part() {
        let a = standing();
        let mut b = a;
        b.feet[0][0] += 0.3; // 3 s at 0.1 m/s
        b.base_rpy[0] = 0.1; // 0.5 s at 0.2 rad/s
        assert!((motion_duration(&a, &b, 0.1, 0.2) - 3.0).abs() < 1e-12);
        assert!((motion_duration(&a, &a, 0.1, 0.2) - 0.1).abs() < 1e-12);
    }
}
