//! Frames and planar poses shared by every module.
//!
//! World frame: x forward, y left, z up, metres. Yaw θ counter-clockwise from +x,
//! radians. The base frame moves with the robot: x' forward, y' left. Grid and cell
//! conventions live with the height map (`terrain::heightmap`), nowhere else.

use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// A planar pose: position (m) and yaw (rad) in the world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose2 {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Yaw, rad, counter-clockwise from +x.
    pub theta: f64,
}

impl Pose2 {
    /// A pose from its parts.
    pub const fn new(x: f64, y: f64, theta: f64) -> Self {
        Self { x, y, theta }
    }

    /// A point given in this pose's frame, in world coordinates.
    pub fn transform(&self, local: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.theta.sin_cos();
        [self.x + c * local[0] - s * local[1], self.y + s * local[0] + c * local[1]]
    }

    /// A world point in this pose's frame.
    pub fn inverse_transform(&self, world: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.theta.sin_cos();
        let (dx, dy) = (world[0] - self.x, world[1] - self.y);
        [c * dx + s * dy, -s * dx + c * dy]
    }

    /// Euclidean distance between the positions, m.
    pub fn distance(&self, other: &Pose2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// `√(x² + y²)`: libm's `hypot` guards against overflow and underflow that metre-scale
/// geometry never reaches, at several times the cost; the posture checks run this in
/// their innermost loops.
#[inline]
pub fn norm2(x: f64, y: f64) -> f64 {
    (x * x + y * y).sqrt()
}

/// Wraps an angle to (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// Distance from `p` to the segment from `a` to `b` in the plane.
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm2(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_round_trip() {
        let p = Pose2::new(1.0, 2.0, 0.5);
        let w = p.transform([0.3, -0.2]);
        let l = p.inverse_transform(w);
        assert!((l[0] - 0.3).abs() < 1e-12 && (l[1] + 0.2).abs() < 1e-12);
    }

    #[test]
    fn quarter_turn_maps_x_to_y() {
        let p = Pose2::new(0.0, 0.0, PI / 2.0);
        let w = p.transform([1.0, 0.0]);
        assert!(w[0].abs() < 1e-12 && (w[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn wrap_angle_range() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.1) - 0.1).abs() < 1e-12);
    }
}
