//! The `mixed` class: clutter, then a climb (a block, or 2–3 steps to a plateau) across
//! the whole map, whose far edge is a step down, on one course.

use super::course::{Builder, Course, Reject, quarter, rect, round_to};
use super::layout::{BEYOND_MAP_M, scatter};
use super::stairs::{STAIR_RISE_M, STAIR_TREAD_M};
use super::up_and_over::UP_AND_OVER_HEIGHT_M;
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// The class; its files name no model (a climb of 2–3 steps gets the wheel pair from the
/// scenario's defaults for its terrain).
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::Mixed, name: "mixed", draw, models: None };

/// Draws the clutter before the climb, the climb and the goal beyond its far edge.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let w = round_to(rng.range(3.5, 5.0), 1);
    let lat = w / 2.0 - 1.0;
    let start = [1.0, round_to(rng.range(-0.6, 0.6), 2)];
    let lane = round_to(rng.range(-lat, lat), 2);
    let climb_at = round_to(rng.range(4.0, 4.6), 2);
    let n_clutter = rng.int_range(2, 4);
    let block = rng.chance(0.5);
    // Across the map (its half-width as written, rounded up to 0.1 m) and 1 m beyond.
    let across = 2.0 * ((w / 2.0 * 10.0 - 1e-6).ceil() / 10.0 + BEYOND_MAP_M);
    let mut b = Builder::new(frame);
    b.param("map_width_m", w);
    b.param("heading_deg", frame.yaw_deg());
    let (plateau_end, drop, edges, climb) = if block {
        let h = UP_AND_OVER_HEIGHT_M.draw(rng, 3);
        let depth = round_to(rng.range(1.5, 2.3), 2);
        b.param("block_height_m", h);
        b.param("block_depth_m", depth);
        b.add_box(
            "the block to climb, across the map; its far edge is the step down".into(),
            [climb_at + depth / 2.0, 0.0],
            [depth, across],
            h,
            0.0,
        );
        (climb_at + depth, h, 2, format!("a {h:.3} m block {depth:.2} m deep"))
    } else {
        let steps = rng.int_range(2, 3);
        let rise = round_to(rng.range(STAIR_RISE_M.lo, (0.3 / f64::from(steps)).min(0.15)), 3);
        let tread = round_to(rng.range(0.30, STAIR_TREAD_M.hi), 3);
        let plateau = round_to(rng.range(1.2, 1.8), 2);
        b.param("steps", f64::from(steps));
        b.param("rise_m", rise);
        b.param("tread_m", tread);
        b.param("plateau_m", plateau);
        b.add_stairs(
            "stairs up to a plateau, across the map; its far edge is the step down".into(),
            [climb_at, 0.0],
            across,
            steps,
            tread,
            rise,
            plateau,
            0.0,
        );
        let top = f64::from(steps) * rise;
        (
            climb_at + f64::from(steps) * tread + plateau,
            top,
            steps + 1,
            format!(
                "{steps} steps of {rise:.3} m on {tread:.3} m tread to a {plateau:.2} m plateau"
            ),
        )
    };
    let goal = [round_to(plateau_end + rng.range(1.1, 1.4), 2), round_to(rng.range(-0.6, 0.6), 2)];
    let l = goal[0] + 1.0;
    let way = [start, [1.9, lane], [3.6, lane], [climb_at, lane]];
    let area = [1.9, 3.6, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, _, _) = scatter(&mut b, rng, n_clutter, area, &way, &[start]);
    b.param("obstacles", f64::from(boxes + poles));
    b.param("step_down_m", drop);
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let s = b.pose(start, round_to(rng.range(-45.0, 45.0), 1));
    let g = b.pose(goal, round_to(rng.range(-45.0, 45.0), 1));
    let description = format!(
        "mixed: {} clutter obstacles, then {climb}, step down {drop:.3} m, {l:.1} m course, heading {:.0}°",
        boxes + poles,
        frame.yaw_deg()
    );
    Ok(b.finish(description, map, s, g, Outcome::Reach, edges, goal[0] - start[0]))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{SEEDS, case, loaded};
    use super::*;

    #[test]
    fn mixed_courses_are_long_and_step_down() {
        for seed in SEEDS {
            let c = case(Class::Mixed, seed);
            let drop = c.parameters["step_down_m"];
            assert!(drop > 0.05 && drop <= 0.3 + 1e-9, "{}: {drop}", c.name);
            let s = loaded(&c);
            assert!((s.goal.x - s.start.x).hypot(s.goal.y - s.start.y) >= 5.5, "{}", c.name);
            let long = (s.map.x_max - s.map.x_min).max(s.map.y_max - s.map.y_min);
            assert!(long >= 7.5, "{}: {long}", c.name);
        }
    }
}
