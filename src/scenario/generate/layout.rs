//! What several classes lay out alike: walls across the map (with or without a doorway),
//! corridor walls, scattered clutter, and the edge course of `step_down` and
//! `up_and_over`; with the ranges and clearances they share.

use super::Span;
use super::course::{Builder, extent_in, polyline_distance, quarter, rect, round_to, sub};
use crate::rng::Rng;

/// Largest angle between a platform or block edge and the perpendicular of the path, degrees.
pub const EDGE_YAW_DEG: f64 = 20.0;
/// Height of clutter obstacles (boxes and poles), m: up to 0.5 m.
pub const CLUTTER_HEIGHT_M: Span = Span::new(0.06, 0.50);
/// Largest wall yaw of `narrow` and `impossible` against the path's perpendicular, degrees.
pub const WALL_YAW_DEG: f64 = 30.0;
/// Height of walls with a doorway, m: well above anything steppable.
pub const WALL_HEIGHT_M: Span = Span::new(0.6, 1.2);

/// Wall thickness of stairwells and corridors, m.
pub(super) const WALL_THICKNESS_M: f64 = 0.15;
/// Half-width of the way kept free of clutter taller than a bump: the robot's half-width
/// over its wheels (0.46 m) plus the foot radius r_F (0.12 m) and a little.
const WAY_HALF_WIDTH_M: f64 = 0.7;
/// Clear radius around a start or goal on open ground: the driving footprint's wheels lie
/// within 0.6 m of the base centre; plus r_F. The job's check (`prepare`) is the judge.
pub(super) const POSE_CLEAR_M: f64 = 1.0;
/// How far blocking obstacles reach beyond the map, m.
pub(super) const BEYOND_MAP_M: f64 = 1.0;

/// Two walls along the course's x over the whole map and beyond, `clear` apart.
pub(super) fn corridor_walls(b: &mut Builder, map: &[[f64; 2]; 4], clear: f64, height: f64) {
    let e = extent_in([0.0, 0.0], 0.0, map);
    let (x0, x1) = (e[0] - BEYOND_MAP_M, e[1] + BEYOND_MAP_M);
    let t = WALL_THICKNESS_M;
    for (side, s) in [("left", 1.0), ("right", -1.0)] {
        b.add_box(
            format!("{side} corridor wall"),
            [(x0 + x1) / 2.0, s * (clear / 2.0 + t / 2.0)],
            [x1 - x0, t],
            height,
            0.0,
        );
    }
}

/// A wall through `origin` (course frame) whose face normal lies at `yaw_deg` from the
/// course's +x, crossing the whole map (`map`, its corners) and 1 m beyond; with a
/// doorway `door` m wide centred on `origin` (none for 0).
#[allow(clippy::too_many_arguments)]
pub(super) fn wall_across(
    b: &mut Builder,
    map: &[[f64; 2]; 4],
    origin: [f64; 2],
    yaw_deg: f64,
    thickness: f64,
    height: f64,
    door: f64,
    name: &str,
) {
    let e = extent_in(origin, yaw_deg, map);
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    if door <= 0.0 {
        b.add_box(
            name.to_owned(),
            sub(origin, yaw_deg, [0.0, (lo + hi) / 2.0]),
            [thickness, hi - lo],
            height,
            yaw_deg,
        );
        return;
    }
    for (side, from, to) in [("left", door / 2.0, hi), ("right", lo, -door / 2.0)] {
        b.add_box(
            format!("{name}, {side} of the doorway"),
            sub(origin, yaw_deg, [0.0, (from + to) / 2.0]),
            [thickness, to - from],
            height,
            yaw_deg,
        );
    }
}

/// One random clutter obstacle: (is a pole, size (a pole: radius twice), yaw, height,
/// radius of a disc covering its footprint).
fn clutter_obstacle(rng: &mut Rng) -> (bool, [f64; 2], f64, f64, f64) {
    let pole = rng.chance(0.4);
    let height = CLUTTER_HEIGHT_M.draw(rng, 3);
    if pole {
        let r = round_to(rng.range(0.03, 0.12), 3);
        (true, [r, r], 0.0, height, r)
    } else {
        let size = [round_to(rng.range(0.2, 0.8), 3), round_to(rng.range(0.2, 0.8), 3)];
        let yaw = round_to(rng.range(0.0, 180.0), 1);
        (false, size, yaw, height, size[0].hypot(size[1]) / 2.0)
    }
}

/// Scatters `n` clutter obstacles over `area` (course frame), none within the way's
/// half-width of the polyline `way` nor within [`POSE_CLEAR_M`] of `poses`; returns the
/// boxes, poles and the lowest and highest placed.
pub(super) fn scatter(
    b: &mut Builder,
    rng: &mut Rng,
    n: u32,
    area: [f64; 4],
    way: &[[f64; 2]],
    poses: &[[f64; 2]],
) -> (u32, u32, f64, f64) {
    let (mut boxes, mut poles, mut lo, mut hi) = (0, 0, f64::INFINITY, 0.0f64);
    for k in 0..n {
        let (pole, size, yaw, height, radius) = clutter_obstacle(rng);
        for _ in 0..40 {
            let c = [
                round_to(rng.range(area[0], area[1]), 3),
                round_to(rng.range(area[2], area[3]), 3),
            ];
            let clear_way = way.len() < 2 || polyline_distance(c, way) >= WAY_HALF_WIDTH_M + radius;
            let clear_poses =
                poses.iter().all(|p| (c[0] - p[0]).hypot(c[1] - p[1]) >= POSE_CLEAR_M + radius);
            if clear_way && clear_poses {
                if pole {
                    b.add_pole(format!("clutter {}: pole", k + 1), c, size[0], height);
                    poles += 1;
                } else {
                    b.add_box(format!("clutter {}: box", k + 1), c, size, height, yaw);
                    boxes += 1;
                }
                lo = lo.min(height);
                hi = hi.max(height);
                break;
            }
        }
    }
    (boxes, poles, lo, hi)
}

/// The common layout of `step_down` and `up_and_over`: a quarter-turned course whose
/// edges cross the whole map at `edge_yaw` (degrees from the path's perpendicular),
/// optionally between corridor walls `walls` m apart; start `d_start` m before the first
/// edge, goal `d_goal` m beyond the last.
pub(super) struct EdgeCourse {
    pub(super) b: Builder,
    pub(super) corners: [[f64; 2]; 4],
    pub(super) edge_yaw: f64,
    pub(super) walls: Option<f64>,
    pub(super) d_start: f64,
    pub(super) d_goal: f64,
    pub(super) start_y: f64,
    pub(super) goal_y: f64,
    pub(super) start_yaw: f64,
    pub(super) goal_yaw: f64,
}

/// Draws an edge course whose far edge lies `far_edge` m beyond the first (along the
/// path, at the edge yaw 0), with the goal drawn in `d_goal` m beyond it.
pub(super) fn edge_course(rng: &mut Rng, far_edge: f64, d_goal: [f64; 2]) -> EdgeCourse {
    let frame = quarter(rng);
    let edge_yaw = round_to(rng.range(-EDGE_YAW_DEG, EDGE_YAW_DEG), 1);
    let w_map = round_to(rng.range(3.0, 5.0), 1);
    let walls = rng.chance(0.5).then(|| round_to(rng.range(1.8, (w_map - 0.6).min(3.0)), 2));
    let d_start = round_to(rng.range(1.1, 1.6), 2);
    let d_goal = round_to(rng.range(d_goal[0], d_goal[1]), 2);
    // Sideways room: the robot turns on the spot 0.75 m from a corridor wall.
    let lat = walls.map_or(0.6, |c| (c / 2.0 - 0.75).min(0.6));
    let start_y = round_to(rng.range(-lat, lat), 2);
    let goal_y = round_to(rng.range(-lat, lat), 2);
    let start_yaw = round_to(rng.range(-90.0, 90.0), 1);
    let goal_yaw = round_to(rng.range(-45.0, 45.0), 1);
    // The far edge's x at the course centre line, pushed out by its yaw.
    let far = far_edge / edge_yaw.to_radians().cos();
    let corners = rect(-d_start - 1.0, far + d_goal + 1.0, -w_map / 2.0, w_map / 2.0);
    let mut b = Builder::new(frame);
    b.param("edge_yaw_deg", edge_yaw);
    b.param("map_width_m", w_map);
    b.param("corridor_m", walls.unwrap_or(0.0));
    b.param("heading_deg", frame.yaw_deg());
    EdgeCourse {
        b,
        corners,
        edge_yaw,
        walls,
        d_start,
        d_goal,
        start_y,
        goal_y,
        start_yaw,
        goal_yaw,
    }
}
