//! The `up_and_over` class: a block across the whole map; the robot steps up, drives
//! across and steps down; sometimes between corridor walls.

use super::course::{Course, Reject, Span, extent_in, sub};
use super::layout::{BEYOND_MAP_M, corridor_walls, edge_course};
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Height of the `up_and_over` block, m.
pub const UP_AND_OVER_HEIGHT_M: Span = Span::new(0.08, 0.25);
/// Depth of the `up_and_over` block along the path, m.
pub const UP_AND_OVER_DEPTH_M: Span = Span::new(0.8, 2.0);

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::UpAndOver, name: "up_and_over", draw, models: None };

/// Draws the block's height and depth and an edge course whose two edges are its sides.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let h = UP_AND_OVER_HEIGHT_M.draw(rng, 3);
    let depth = UP_AND_OVER_DEPTH_M.draw(rng, 2);
    let mut c = edge_course(rng, depth, [1.0, 2.0]);
    c.b.param("height_m", h);
    c.b.param("depth_m", depth);
    let map = c.b.map(&c.corners, 0.0);
    let corners = c.b.local_corners(&map);
    let e = extent_in([0.0, 0.0], c.edge_yaw, &corners);
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    c.b.add_box(
        "the block across the path".into(),
        sub([0.0, 0.0], c.edge_yaw, [depth / 2.0, (lo + hi) / 2.0]),
        [depth, hi - lo],
        h,
        c.edge_yaw,
    );
    if let Some(clear) = c.walls {
        corridor_walls(&mut c.b, &corners, clear, 0.8);
    }
    let far = depth / c.edge_yaw.to_radians().cos();
    let start = c.b.pose([-c.d_start, c.start_y], c.start_yaw);
    let goal = c.b.pose([far + c.d_goal, c.goal_y], c.goal_yaw);
    let description = format!(
        "up and over: {h:.3} m block, {depth:.2} m deep, edges at {:.1}° to the path, {}, heading {:.0}°",
        c.edge_yaw,
        c.walls.map_or("full width".to_owned(), |w| format!("walls {w:.2} m apart")),
        c.b.frame.yaw_deg()
    );
    let length = c.d_start + far + c.d_goal;
    Ok(c.b.finish(description, map, start, goal, Outcome::Reach, 2, length))
}

#[cfg(test)]
mod tests {
    use super::super::layout::EDGE_YAW_DEG;
    use super::super::test_support::{SEEDS, case, loaded, over_map};
    use super::*;

    #[test]
    fn up_and_over_stays_in_its_ranges_and_its_block_crosses_the_whole_map() {
        for seed in SEEDS {
            let c = case(Class::UpAndOver, seed);
            let s = loaded(&c);
            let p = &c.parameters;
            let (h, d) = (p["height_m"], p["depth_m"]);
            assert!(UP_AND_OVER_HEIGHT_M.contains(h) && UP_AND_OVER_DEPTH_M.contains(d));
            assert!(p["edge_yaw_deg"].abs() <= EDGE_YAW_DEG);
            assert_eq!(s.terrain_height(s.start.x, s.start.y), 0.0);
            assert_eq!(s.terrain_height(s.goal.x, s.goal.y), 0.0);
            for (n, z) in over_map(&s, p["heading_deg"] + p["edge_yaw_deg"]) {
                if z != 0.8 && n.abs() > 0.01 && (n - d).abs() > 0.01 {
                    assert_eq!(z, if n > 0.0 && n < d { h } else { 0.0 }, "{}: at {n:.3}", c.name);
                }
            }
        }
    }
}
