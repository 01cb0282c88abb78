//! The `step_down` class: the robot starts on a platform whose edge crosses the whole map
//! and must get down it; sometimes between corridor walls.

use super::course::{Course, Reject, Span, extent_in, sub};
use super::layout::{BEYOND_MAP_M, corridor_walls, edge_course};
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Height of the `step_down` platform, m (up to the paper's 0.3 m step limit).
pub const STEP_DOWN_HEIGHT_M: Span = Span::new(0.05, 0.30);

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::StepDown, name: "step_down", draw, models: None };

/// Draws the platform's height and an edge course behind whose first edge it lies.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let h = STEP_DOWN_HEIGHT_M.draw(rng, 3);
    let mut c = edge_course(rng, 0.0, [1.2, 2.5]);
    c.b.param("height_m", h);
    let map = c.b.map(&c.corners, 0.0);
    let corners = c.b.local_corners(&map);
    // The platform: everything behind the edge through the origin, across the map.
    let e = extent_in([0.0, 0.0], c.edge_yaw, &corners);
    let back = -e[0] + BEYOND_MAP_M;
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    c.b.add_box(
        "the platform the robot starts on; its edge crosses the map".into(),
        sub([0.0, 0.0], c.edge_yaw, [-back / 2.0, (lo + hi) / 2.0]),
        [back, hi - lo],
        h,
        c.edge_yaw,
    );
    if let Some(clear) = c.walls {
        corridor_walls(&mut c.b, &corners, clear, 0.8);
    }
    let start = c.b.pose([-c.d_start, c.start_y], c.start_yaw);
    let goal = c.b.pose([c.d_goal, c.goal_y], c.goal_yaw);
    let description = format!(
        "step down: {h:.3} m platform, edge at {:.1}° to the path, {}, heading {:.0}°",
        c.edge_yaw,
        c.walls.map_or("full width".to_owned(), |w| format!("walls {w:.2} m apart")),
        c.b.frame.yaw_deg()
    );
    let length = c.d_start + c.d_goal;
    Ok(c.b.finish(description, map, start, goal, Outcome::Reach, 1, length))
}

#[cfg(test)]
mod tests {
    use super::super::layout::EDGE_YAW_DEG;
    use super::super::test_support::{SEEDS, case, loaded, over_map};
    use super::*;

    #[test]
    fn step_down_stays_in_its_ranges_and_its_platform_blocks_the_whole_map() {
        for seed in SEEDS {
            let c = case(Class::StepDown, seed);
            let s = loaded(&c);
            let p = &c.parameters;
            let h = p["height_m"];
            assert!(STEP_DOWN_HEIGHT_M.contains(h));
            assert!(p["edge_yaw_deg"].abs() <= EDGE_YAW_DEG);
            assert_eq!(s.terrain_height(s.start.x, s.start.y), h, "{}", c.name);
            assert_eq!(s.terrain_height(s.goal.x, s.goal.y), 0.0, "{}", c.name);
            // The platform covers the whole map behind its edge and nothing beyond it (the
            // corridor walls, 0.8 m, aside): no way around.
            for (n, z) in over_map(&s, p["heading_deg"] + p["edge_yaw_deg"]) {
                if z != 0.8 && n.abs() > 0.01 {
                    assert_eq!(z, if n < 0.0 { h } else { 0.0 }, "{}: at {n:.3}", c.name);
                }
            }
        }
    }
}
