//! What every class draws with: the numbers as written (rounding to the millimetre and the
//! tenth of a degree), the course frame, and the builder that places primitives in it and
//! collects the drawn parameters; and what a class's drawing returns, a [`Course`] or a
//! [`Reject`].

use super::Placed;
use crate::rng::Rng;
use crate::scenario::terrain::{Block, Pole, Primitive, Stairs};
use crate::scenario::{MapExtent, Outcome, PoseSpec};
use serde::Serialize;
use std::collections::BTreeMap;

/// A closed interval a drawn parameter lies in.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Span {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Span {
    pub(super) const fn new(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }

    /// Whether `v` lies in the interval (1 µ of slack for the rounding of written values).
    pub fn contains(&self, v: f64) -> bool {
        v >= self.lo - 1e-6 && v <= self.hi + 1e-6
    }

    /// A uniform draw rounded to `decimals`, clamped into the interval.
    pub(super) fn draw(&self, rng: &mut Rng, decimals: i32) -> f64 {
        round_to(rng.range(self.lo, self.hi), decimals).clamp(self.lo, self.hi)
    }
}

/// Why a draw was rejected.
#[derive(Debug)]
pub(super) struct Reject(pub(super) String);

/// Rejects the draw with `reason` unless `ok`.
pub(super) fn reject_unless(ok: bool, reason: impl FnOnce() -> String) -> Result<(), Reject> {
    if ok { Ok(()) } else { Err(Reject(reason())) }
}

/// A drawn course before it becomes a case.
pub(super) struct Course {
    pub(super) description: String,
    pub(super) map: MapExtent,
    pub(super) start: PoseSpec,
    pub(super) goal: PoseSpec,
    pub(super) terrain: Vec<Placed>,
    pub(super) outcome: Outcome,
    /// Height edges a run must step, each four steps (for the timeout).
    pub(super) edges: u32,
    /// Length of the course, m (for the timeout).
    pub(super) length_m: f64,
    pub(super) parameters: BTreeMap<&'static str, f64>,
}

// ---------------------------------------------------------------------------------------
// Numbers.

/// `v` rounded to `decimals` decimal places.
pub(super) fn round_to(v: f64, decimals: i32) -> f64 {
    let f = 10f64.powi(decimals);
    // `+ 0.0` turns −0 into 0.
    (v * f).round() / f + 0.0
}

/// Positions and sizes are written to the millimetre.
pub(super) fn mm(v: f64) -> f64 {
    round_to(v, 3)
}

/// An angle in degrees wrapped to [−180, 180) and rounded to 0.1°.
pub(super) fn deg(v: f64) -> f64 {
    let w = round_to((v + 180.0).rem_euclid(360.0) - 180.0, 1);
    if w >= 180.0 { w - 360.0 } else { w }
}

// ---------------------------------------------------------------------------------------
// Geometry: the course frame and the builder of primitives in it.

/// Rotates `p` by `yaw_deg` and adds `origin` (a point of a sub-frame in its parent).
pub(super) fn sub(origin: [f64; 2], yaw_deg: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = yaw_deg.to_radians().sin_cos();
    [origin[0] + c * p[0] - s * p[1], origin[1] + s * p[0] + c * p[1]]
}

/// Coordinates of `p` in a sub-frame at `origin` turned by `yaw_deg`.
pub(super) fn in_sub(origin: [f64; 2], yaw_deg: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = yaw_deg.to_radians().sin_cos();
    let (dx, dy) = (p[0] - origin[0], p[1] - origin[1]);
    [c * dx + s * dy, -s * dx + c * dy]
}

/// Distance of `p` from the polyline `way`.
pub(super) fn polyline_distance(p: [f64; 2], way: &[[f64; 2]]) -> f64 {
    way.windows(2)
        .map(|w| crate::geometry::segment_distance(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Length of the polyline `way`.
pub(super) fn polyline_length(way: &[[f64; 2]]) -> f64 {
    way.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
}

/// The course frame in the world: its origin is the world origin, turned by a whole
/// number of quarter turns (exact) or by any yaw.
#[derive(Debug, Clone, Copy)]
pub(super) enum Frame {
    /// Turned by this many quarter turns.
    Quarter(u8),
    /// Turned by this yaw, degrees.
    Yaw(f64),
}

impl Frame {
    /// The frame's yaw in the world, degrees.
    pub(super) fn yaw_deg(self) -> f64 {
        match self {
            Frame::Quarter(q) => 90.0 * f64::from(q),
            Frame::Yaw(y) => y,
        }
    }

    /// A point of the course frame in the world.
    pub(super) fn point(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Frame::Quarter(q) => match q % 4 {
                0 => p,
                1 => [-p[1], p[0]],
                2 => [-p[0], -p[1]],
                _ => [p[1], -p[0]],
            },
            Frame::Yaw(y) => sub([0.0, 0.0], y, p),
        }
    }

    /// The inverse of [`Frame::point`]: a world point in the course frame.
    pub(super) fn local(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Frame::Quarter(q) => Frame::Quarter((4 - q % 4) % 4).point(p),
            Frame::Yaw(y) => in_sub([0.0, 0.0], y, p),
        }
    }
}

/// Builds a course in its local frame; writes world coordinates, rounded as written.
pub(super) struct Builder {
    pub(super) frame: Frame,
    terrain: Vec<Placed>,
    parameters: BTreeMap<&'static str, f64>,
}

impl Builder {
    /// An empty course in `frame`.
    pub(super) fn new(frame: Frame) -> Self {
        Self { frame, terrain: Vec::new(), parameters: BTreeMap::new() }
    }

    /// Records the drawn parameter `name` (for the file's comment and the tests).
    pub(super) fn param(&mut self, name: &'static str, v: f64) -> f64 {
        self.parameters.insert(name, v);
        v
    }

    /// A point of the course frame in the world, to the millimetre.
    pub(super) fn at(&self, p: [f64; 2]) -> [f64; 2] {
        let w = self.frame.point(p);
        [mm(w[0]), mm(w[1])]
    }

    /// A pose of the course frame in the world, as written.
    pub(super) fn pose(&self, p: [f64; 2], local_yaw_deg: f64) -> PoseSpec {
        let [x, y] = self.at(p);
        PoseSpec { x, y, yaw_deg: deg(self.frame.yaw_deg() + local_yaw_deg) }
    }

    /// Places a box (centre, size and yaw in the course frame).
    pub(super) fn add_box(
        &mut self,
        note: String,
        center: [f64; 2],
        size: [f64; 2],
        height: f64,
        yaw: f64,
    ) {
        let primitive = Primitive::Box(Block {
            center: self.at(center),
            size: [mm(size[0]), mm(size[1])],
            height: mm(height),
            yaw_deg: deg(self.frame.yaw_deg() + yaw),
        });
        self.terrain.push(Placed { note, primitive });
    }

    /// Places a pole (centre in the course frame).
    pub(super) fn add_pole(&mut self, note: String, center: [f64; 2], radius: f64, height: f64) {
        let primitive = Primitive::Pole(Pole {
            center: self.at(center),
            radius: mm(radius),
            height: mm(height),
        });
        self.terrain.push(Placed { note, primitive });
    }

    /// Places a flight of stairs (start and yaw in the course frame).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_stairs(
        &mut self,
        note: String,
        start: [f64; 2],
        width: f64,
        steps: u32,
        tread: f64,
        rise: f64,
        landing: f64,
        yaw: f64,
    ) {
        let primitive = Primitive::Stairs(Stairs {
            start: self.at(start),
            width: mm(width),
            steps,
            step_depth: mm(tread),
            step_height: mm(rise),
            landing_depth: mm(landing),
            yaw_deg: deg(self.frame.yaw_deg() + yaw),
        });
        self.terrain.push(Placed { note, primitive });
    }

    /// The world map covering the local points `corners` (their bounding box after the
    /// frame's turn) plus `margin`, rounded outward to 0.1 m.
    pub(super) fn map(&self, corners: &[[f64; 2]], margin: f64) -> MapExtent {
        let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for &p in corners {
            let [x, y] = self.frame.point(p);
            b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
        }
        let down = |v: f64| round_to(((v - margin) * 10.0 + 1e-6).floor() / 10.0, 1);
        let up = |v: f64| round_to(((v + margin) * 10.0 - 1e-6).ceil() / 10.0, 1);
        MapExtent { x_min: down(b[0]), y_min: down(b[1]), x_max: up(b[2]), y_max: up(b[3]) }
    }

    /// The corners of a world map in the course frame.
    pub(super) fn local_corners(&self, map: &MapExtent) -> [[f64; 2]; 4] {
        rect(map.x_min, map.x_max, map.y_min, map.y_max).map(|p| self.frame.local(p))
    }

    /// The course the builder placed, with what the class drew around it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn finish(
        self,
        description: String,
        map: MapExtent,
        start: PoseSpec,
        goal: PoseSpec,
        outcome: Outcome,
        edges: u32,
        length_m: f64,
    ) -> Course {
        Course {
            description,
            map,
            start,
            goal,
            terrain: self.terrain,
            outcome,
            edges,
            length_m,
            parameters: self.parameters,
        }
    }
}

/// A rectangle of the course frame: `[x0, x1] × [y0, y1]` as its corners.
pub(super) fn rect(x0: f64, x1: f64, y0: f64, y1: f64) -> [[f64; 2]; 4] {
    [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// The extent of `corners` in a sub-frame at `origin` turned by `yaw_deg`:
/// `[x_min, x_max, y_min, y_max]`.
pub(super) fn extent_in(origin: [f64; 2], yaw_deg: f64, corners: &[[f64; 2]]) -> [f64; 4] {
    let mut e = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
    for &c in corners {
        let [x, y] = in_sub(origin, yaw_deg, c);
        e = [e[0].min(x), e[1].max(x), e[2].min(y), e[3].max(y)];
    }
    e
}

/// A course frame turned by a random quarter turn.
pub(super) fn quarter(rng: &mut Rng) -> Frame {
    Frame::Quarter(rng.below(4) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_rounded_as_written() {
        assert_eq!(deg(180.0), -180.0);
        assert_eq!(deg(-180.04), -180.0);
        assert_eq!(deg(359.96), 0.0);
        assert_eq!(mm(1.23456), 1.235);
        // −0 is written as 0.
        assert!(round_to(-0.0001, 2).is_sign_positive());
    }

    #[test]
    fn frames_turn_and_turn_back() {
        for frame in [Frame::Quarter(0), Frame::Quarter(1), Frame::Quarter(3), Frame::Yaw(33.0)] {
            let p = [1.25, -0.5];
            let back = frame.local(frame.point(p));
            assert!((back[0] - p[0]).abs() < 1e-12 && (back[1] - p[1]).abs() < 1e-12);
        }
        assert_eq!(Frame::Quarter(1).point([1.0, 2.0]), [-2.0, 1.0]);
    }
}
