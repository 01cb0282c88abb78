//! The `impossible` class: no way exists, the planner must answer "no path": the goal
//! walled in, a wall across the map too high to step, or a doorway narrower than the
//! robot.

use super::course::{
    Builder, Course, Reject, Span, in_sub, quarter, rect, reject_unless, round_to, sub,
};
use super::layout::{WALL_HEIGHT_M, WALL_YAW_DEG, wall_across};
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Height of `impossible`'s wall across the map, m: above the 0.3 m step limit.
pub const HIGH_WALL_HEIGHT_M: Span = Span::new(0.36, 0.8);
/// Doorway width of `impossible`, m: narrower than the robot.
pub const TIGHT_DOOR_WIDTH_M: Span = Span::new(0.3, 0.55);
/// Height of the walls enclosing `impossible`'s goal, m: above 0.5 m.
pub const ENCLOSURE_HEIGHT_M: Span = Span::new(0.55, 1.0);

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::Impossible, name: "impossible", draw, models: None };

/// Draws one of the three variants (0: walled-in goal, 1: high wall, 2: tight doorway).
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let variant = rng.below(3);
    let mut b = Builder::new(frame);
    b.param("variant", variant as f64);
    let start_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let goal_yaw = round_to(rng.range(-180.0, 180.0), 1);
    match variant {
        0 => {
            let inner = round_to(rng.range(1.6, 2.2), 2);
            let t = round_to(rng.range(0.15, 0.3), 2);
            let height = ENCLOSURE_HEIGHT_M.draw(rng, 2);
            let turn = round_to(rng.range(0.0, 90.0), 1);
            let radius = (inner / 2.0 + t) * std::f64::consts::SQRT_2;
            // Room for the start 1.6 m before the enclosure's circle.
            let l = (rng.range(5.5, 7.0).max(3.0 + 2.0 * radius) * 10.0).ceil() / 10.0;
            let w = ((2.0 * radius + 0.8).max(rng.range(3.5, 5.0)) * 10.0).ceil() / 10.0;
            let goal = [round_to(l - 0.4 - radius, 2), 0.0];
            let start = [1.0, round_to(rng.range(-0.6, 0.6), 2)];
            b.param("room_m", inner);
            b.param("wall_height_m", height);
            let o = inner / 2.0 + t / 2.0;
            for (name, c, size) in [
                ("front", [-o, 0.0], [t, inner + 2.0 * t]),
                ("back", [o, 0.0], [t, inner + 2.0 * t]),
                ("left", [0.0, o], [inner + 2.0 * t, t]),
                ("right", [0.0, -o], [inner + 2.0 * t, t]),
            ] {
                b.add_box(
                    format!("{name} wall around the goal"),
                    sub(goal, turn, c),
                    size,
                    height,
                    turn,
                );
            }
            let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
            let description = format!(
                "impossible: the goal is walled in by {height:.2} m walls ({inner:.2} m room)"
            );
            let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
            Ok(b.finish(description, map, s, g, Outcome::NoPath, 0, 0.0))
        }
        _ => {
            let l = round_to(rng.range(6.0, 8.0), 1);
            let w = round_to(rng.range(3.5, 5.0), 1);
            let wall_yaw = round_to(rng.range(-WALL_YAW_DEG, WALL_YAW_DEG), 1);
            let (thickness, height, door) = if variant == 1 {
                (round_to(rng.range(0.15, 0.8), 2), HIGH_WALL_HEIGHT_M.draw(rng, 3), 0.0)
            } else {
                (
                    round_to(rng.range(0.1, 0.3), 2),
                    WALL_HEIGHT_M.draw(rng, 2),
                    TIGHT_DOOR_WIDTH_M.draw(rng, 2),
                )
            };
            let origin =
                [l / 2.0, if door > 0.0 { round_to(rng.range(-0.5, 0.5), 2) } else { 0.0 }];
            let start = [1.0, round_to(rng.range(-0.5, 0.5), 2)];
            let goal = [l - 1.0, round_to(rng.range(-0.5, 0.5), 2)];
            for p in [start, goal] {
                let x = in_sub(origin, wall_yaw, p)[0].abs() - thickness / 2.0;
                reject_unless(x >= 0.8, || format!("a pose only {x:.2} m from the wall"))?;
            }
            b.param("wall_yaw_deg", wall_yaw);
            b.param("wall_height_m", height);
            b.param("wall_thickness_m", thickness);
            b.param("door_m", door);
            let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
            let corners = b.local_corners(&map);
            wall_across(
                &mut b,
                &corners,
                origin,
                wall_yaw,
                thickness,
                height,
                door,
                "wall across the map",
            );
            let description = if door > 0.0 {
                format!(
                    "impossible: a {door:.2} m doorway, narrower than the robot, in a {height:.2} m wall at {wall_yaw:.1}°"
                )
            } else {
                format!(
                    "impossible: a {height:.3} m wall, {thickness:.2} m thick, across the map at {wall_yaw:.1}° (steps reach 0.3 m)"
                )
            };
            let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
            Ok(b.finish(description, map, s, g, Outcome::NoPath, 0, 0.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{SEEDS, case, loaded};
    use super::*;
    use crate::scenario::Primitive;

    #[test]
    fn impossible_stays_in_its_ranges() {
        for seed in SEEDS {
            let c = case(Class::Impossible, seed);
            let p = &c.parameters;
            match p["variant"] as u32 {
                0 => assert!(ENCLOSURE_HEIGHT_M.contains(p["wall_height_m"])),
                1 => {
                    assert!(HIGH_WALL_HEIGHT_M.contains(p["wall_height_m"]));
                    assert!(p["wall_height_m"] > 0.35);
                    // One box whose length reaches 1 m past every map corner.
                    let Primitive::Box(wall) = c.terrain[0].primitive else {
                        panic!("{}: {:?}", c.name, c.terrain[0])
                    };
                    let m = c.map;
                    for q in [
                        [m.x_min, m.y_min],
                        [m.x_max, m.y_min],
                        [m.x_min, m.y_max],
                        [m.x_max, m.y_max],
                    ] {
                        let along = in_sub(wall.center, wall.yaw_deg, q)[1].abs();
                        assert!(along <= wall.size[1] / 2.0 - 0.999, "{}", c.name);
                    }
                }
                _ => {
                    assert!(TIGHT_DOOR_WIDTH_M.contains(p["door_m"]));
                    assert!(p["door_m"] < 0.6);
                }
            }
        }
    }

    #[test]
    fn walled_in_goal_is_enclosed_on_every_side() {
        let c = (1..200)
            .map(|s| case(Class::Impossible, s))
            .find(|c| c.parameters["variant"] == 0.0)
            .unwrap();
        let s = loaded(&c);
        let h = c.parameters["wall_height_m"];
        // Every ray from the goal meets a wall before 2 m.
        for k in 0..72 {
            let a = f64::from(k) * 5f64.to_radians();
            let hit = (1..=80).any(|i| {
                let r = f64::from(i) * 0.025;
                s.terrain_height(s.goal.x + r * a.cos(), s.goal.y + r * a.sin()) == h
            });
            assert!(hit, "{}: ray {k}", c.name);
        }
    }
}
