//! The `narrow` class: a wall across the whole map with a doorway the robot fits
//! through, at an angle to the path; sometimes a corridor through the doorway.

use super::course::{Builder, Course, Reject, Span, quarter, rect, round_to, sub};
use super::layout::{POSE_CLEAR_M, WALL_HEIGHT_M, WALL_YAW_DEG, wall_across};
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Doorway width of `narrow`, m: the robot is 0.92 m wide over its wheels.
pub const DOOR_WIDTH_M: Span = Span::new(1.0, 1.5);

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::Narrow, name: "narrow", draw, models: None };

/// Draws the doorway, its wall and corridor, and a start and goal on either side.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let door = DOOR_WIDTH_M.draw(rng, 2);
    let wall_yaw = round_to(rng.range(-WALL_YAW_DEG, WALL_YAW_DEG), 1);
    let thickness = round_to(rng.range(0.1, 0.3), 2);
    let height = WALL_HEIGHT_M.draw(rng, 2);
    let corridor = rng.chance(0.35).then(|| round_to(rng.range(1.0, 2.0), 2));
    let w = round_to(rng.range(3.5, 5.0), 1);
    let door_y = round_to(rng.range(-0.5, 0.5), 2);
    let reach = corridor.map_or(0.0, |c| c / 2.0) + thickness / 2.0;
    // Start and goal anywhere across the map, 1.0-1.6 m before and behind the wall (and
    // the corridor), measured along the wall's normal.
    let origin = [0.0, door_y];
    let lat = w / 2.0 - POSE_CLEAR_M;
    let (sin, cos) = wall_yaw.to_radians().sin_cos();
    let place = |rng: &mut Rng, side: f64| {
        let y = round_to(rng.range(-lat, lat), 2);
        let normal = side * (reach + rng.range(1.0, 1.6));
        [round_to((normal - (y - door_y) * sin) / cos, 2), y]
    };
    let s = place(rng, -1.0);
    let g = place(rng, 1.0);
    let corners = rect(s[0] - POSE_CLEAR_M, g[0] + POSE_CLEAR_M, -w / 2.0, w / 2.0);
    let mut b = Builder::new(frame);
    b.param("door_m", door);
    b.param("wall_yaw_deg", wall_yaw);
    b.param("wall_height_m", height);
    b.param("wall_thickness_m", thickness);
    b.param("corridor_m", corridor.unwrap_or(0.0));
    let map = b.map(&corners, 0.0);
    let corners = b.local_corners(&map);
    wall_across(&mut b, &corners, origin, wall_yaw, thickness, height, door, "wall");
    if let Some(len) = corridor {
        for (side, sgn) in [("left", 1.0), ("right", -1.0)] {
            b.add_box(
                format!("{side} corridor wall through the doorway"),
                sub(origin, wall_yaw, [0.0, sgn * (door / 2.0 + thickness / 2.0)]),
                [len, thickness],
                height,
                wall_yaw,
            );
        }
    }
    let start = b.pose(s, wall_yaw + round_to(rng.range(-45.0, 45.0), 1));
    let goal = b.pose(g, wall_yaw + round_to(rng.range(-45.0, 45.0), 1));
    let description = format!(
        "narrow: {door:.2} m doorway in a {height:.2} m wall at {wall_yaw:.1}° to the path{}",
        corridor.map_or(String::new(), |c| format!(", a {c:.2} m corridor through it"))
    );
    let length = (g[0] - s[0]).hypot(g[1] - s[1]);
    Ok(b.finish(description, map, start, goal, Outcome::Reach, 0, length + 3.0))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{SEEDS, case};
    use super::*;

    #[test]
    fn narrow_stays_in_its_ranges() {
        for seed in SEEDS {
            let c = case(Class::Narrow, seed);
            assert!(DOOR_WIDTH_M.contains(c.parameters["door_m"]));
            assert!(c.parameters["wall_yaw_deg"].abs() <= WALL_YAW_DEG);
            assert!(WALL_HEIGHT_M.contains(c.parameters["wall_height_m"]));
        }
    }
}
