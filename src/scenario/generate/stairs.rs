//! The `stairs` class: a flight of stairs, climbed or descended, at any yaw; sometimes
//! with an intermediate landing, sometimes between the walls of a stairwell.

use super::course::{Builder, Course, Frame, Reject, Span, deg, rect, round_to};
use super::layout::WALL_THICKNESS_M;
use super::{Class, ClassUnit, MAX_MAP_M};
use crate::params::{FootModel, StepModel};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Number of steps of a generated flight of stairs.
pub const STAIR_STEPS: [u32; 2] = [2, 8];
/// Riser height of generated stairs, m (IBC/IRC risers, plus steep old stairs).
pub const STAIR_RISE_M: Span = Span::new(0.10, 0.22);
/// Tread depth of generated stairs, m (IRC's 0.254 m minimum rounded down to 0.25).
pub const STAIR_TREAD_M: Span = Span::new(0.25, 0.40);
/// Clear width of generated stairs (between the walls, if any), m.
pub const STAIR_WIDTH_M: Span = Span::new(1.1, 2.0);
/// Depth of the top landing, where the robot stands at the top, m.
pub const STAIR_LANDING_M: Span = Span::new(1.3, 2.0);
/// Depth of an optional intermediate landing (flights of 4 steps or more), m.
pub const STAIR_MID_LANDING_M: Span = Span::new(0.9, 1.5);

/// The class. Its files name the stairs step model, since the treads (0.25–0.40 m) are
/// shorter than the robot's 0.7 m hip spacing, and the wheel pairs' footprint, which
/// keeps more of a tread than the paper's disc (README, "Step model" and "Foot model"),
/// as the repository's own stairs scenarios do.
pub(super) const UNIT: ClassUnit = ClassUnit {
    class: Class::Stairs,
    name: "stairs",
    draw,
    models: Some((StepModel::Stairs, FootModel::WheelPair)),
};

/// Draws a flight: up or down, its steps, rise, tread, width and landings, walls or not,
/// and a yaw whose map fits.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let up = rng.chance(0.5);
    let steps = rng.int_range(STAIR_STEPS[0], STAIR_STEPS[1]);
    let rise = STAIR_RISE_M.draw(rng, 3);
    let tread = STAIR_TREAD_M.draw(rng, 3);
    let width = STAIR_WIDTH_M.draw(rng, 2);
    let landing = STAIR_LANDING_M.draw(rng, 2);
    let walls = rng.chance(0.5);
    let mid = if steps >= 4 && rng.chance(0.5) {
        Some((rng.int_range(2, steps - 2), STAIR_MID_LANDING_M.draw(rng, 2)))
    } else {
        None
    };
    let ground_d = round_to(rng.range(0.9, 1.3), 2);
    let ground_y = round_to(rng.range(-0.2, 0.2), 2);
    let ground_yaw = round_to(rng.range(-30.0, 30.0), 1);
    let landing_yaw = round_to(rng.range(-10.0, 10.0), 1);
    let mid_depth = mid.map_or(0.0, |m| m.1);
    let run = f64::from(steps) * tread + mid_depth + landing;
    let t = WALL_THICKNESS_M;
    let half = width / 2.0 + if walls { t } else { 0.0 };
    let back = run + if walls { t } else { 0.0 };
    let mut corners = rect(0.0, back, -half, half).to_vec();
    corners.extend(rect(-ground_d - 0.8, -ground_d + 0.8, ground_y - 0.8, ground_y + 0.8));
    // The flight's direction: any yaw whose map fits; after 32 tries the nearest quarter
    // turn (every course fits along an axis).
    let mut yaw = 0.0;
    let mut fits = false;
    for _ in 0..32 {
        yaw = round_to(rng.range(-180.0, 180.0), 1);
        let map = Builder::new(Frame::Yaw(yaw)).map(&corners, 0.3);
        let (a, b) = (map.x_max - map.x_min, map.y_max - map.y_min);
        if a.max(b) <= MAX_MAP_M[0] && a.min(b) <= MAX_MAP_M[1] {
            fits = true;
            break;
        }
    }
    if !fits {
        yaw = deg((yaw / 90.0).round() * 90.0);
    }
    let frame = if yaw.rem_euclid(90.0) == 0.0 {
        Frame::Quarter(((yaw / 90.0).round() as i32).rem_euclid(4) as u8)
    } else {
        Frame::Yaw(yaw)
    };
    let mut b = Builder::new(frame);
    b.param("up", if up { 1.0 } else { 0.0 });
    b.param("steps", f64::from(steps));
    b.param("rise_m", rise);
    b.param("tread_m", tread);
    b.param("width_m", width);
    b.param("top_landing_m", landing);
    b.param("mid_landing_m", mid_depth);
    b.param("mid_landing_after", mid.map_or(0.0, |m| f64::from(m.0)));
    b.param("walls", if walls { 1.0 } else { 0.0 });
    b.param("yaw_deg", yaw);
    let (label, start) = match mid {
        Some((k1, depth)) => {
            b.add_stairs(
                format!("lower flight: steps 1 to {k1}, then the intermediate landing"),
                [0.0, 0.0],
                width,
                k1,
                tread,
                rise,
                depth,
                0.0,
            );
            // Steps 1..k1 of the full flight below lie under the lower flight (lower
            // than it), so the union is the lower flight, the landing, then steps k1+1.. .
            (format!("upper flight: steps {} to {steps} and the top landing", k1 + 1), [depth, 0.0])
        }
        None => ("the flight and its top landing".into(), [0.0, 0.0]),
    };
    b.add_stairs(label, start, width, steps, tread, rise, landing, 0.0);
    let top = f64::from(steps) * rise;
    if walls {
        let h = round_to(top + 0.6, 2);
        for (side, s) in [("left", 1.0), ("right", -1.0)] {
            b.add_box(
                format!("{side} stairwell wall"),
                [back / 2.0, s * (width / 2.0 + t / 2.0)],
                [back, t],
                h,
                0.0,
            );
        }
        b.add_box(
            "back wall of the top landing".into(),
            [run + t / 2.0, 0.0],
            [t, width + 2.0 * t],
            h,
            0.0,
        );
    }
    let map = b.map(&corners, 0.3);
    let ground = [-ground_d, ground_y];
    let top_pose = [run - landing / 2.0, 0.0];
    let (start, goal) = if up {
        (b.pose(ground, ground_yaw), b.pose(top_pose, landing_yaw))
    } else {
        (b.pose(top_pose, 180.0 + landing_yaw), b.pose(ground, 180.0 + ground_yaw))
    };
    let mut description = format!(
        "stairs {}: {steps} steps of {rise:.3} m rise on {tread:.3} m tread, {width:.2} m wide",
        if up { "up" } else { "down" }
    );
    if let Some((k1, depth)) = mid {
        description += &format!(", {depth:.2} m landing after step {k1}");
    }
    description += &format!(
        ", {landing:.2} m top landing, {}, yaw {:.1}°",
        if walls { "walls" } else { "open sides" },
        yaw
    );
    let length = ground_d + run - landing / 2.0;
    Ok(b.finish(description, map, start, goal, Outcome::Reach, steps, length))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{SEEDS, case, loaded};
    use super::super::{GeneratedCase, course::sub};
    use super::*;
    use crate::scenario::Primitive;

    fn stairs_of(c: &GeneratedCase) -> Vec<(u32, f64, f64, f64, f64)> {
        c.terrain
            .iter()
            .filter_map(|p| match p.primitive {
                Primitive::Stairs(s) => {
                    Some((s.steps, s.step_depth, s.step_height, s.width, s.landing_depth))
                }
                _ => None,
            })
            .collect()
    }

    #[test]
    fn stairs_parameters_stay_in_their_ranges() {
        let (mut up, mut walls, mut mid) = (0, 0, 0);
        for seed in SEEDS {
            let c = case(Class::Stairs, seed);
            let p = &c.parameters;
            let steps = p["steps"] as u32;
            assert!((STAIR_STEPS[0]..=STAIR_STEPS[1]).contains(&steps));
            assert!(STAIR_RISE_M.contains(p["rise_m"]), "{}", c.name);
            assert!(STAIR_TREAD_M.contains(p["tread_m"]), "{}", c.name);
            assert!(STAIR_WIDTH_M.contains(p["width_m"]));
            assert!(STAIR_LANDING_M.contains(p["top_landing_m"]));
            let flights = stairs_of(&c);
            let (n, tread, rise, width, landing) = *flights.last().unwrap();
            assert_eq!(n, steps);
            assert_eq!(
                (tread, rise, width, landing),
                (p["tread_m"], p["rise_m"], p["width_m"], p["top_landing_m"])
            );
            if p["mid_landing_m"] > 0.0 {
                mid += 1;
                assert!(STAIR_MID_LANDING_M.contains(p["mid_landing_m"]));
                assert_eq!(flights.len(), 2);
                assert!(steps >= 4);
            }
            up += p["up"] as u32;
            walls += p["walls"] as u32;
            // The top of the flight: the goal going up, the start going down.
            let s = loaded(&c);
            let top = f64::from(steps) * rise;
            let (hi, lo) = if p["up"] == 1.0 { (s.goal, s.start) } else { (s.start, s.goal) };
            assert!((s.terrain_height(hi.x, hi.y) - top).abs() < 1e-9, "{}", c.name);
            assert_eq!(s.terrain_height(lo.x, lo.y), 0.0, "{}", c.name);
            assert!(
                c.description.starts_with("stairs up:")
                    || c.description.starts_with("stairs down:")
            );
        }
        assert!(up > 10 && up < 40 && walls > 10 && walls < 40 && mid > 3, "{up} {walls} {mid}");
    }

    #[test]
    fn two_flights_make_one_staircase() {
        let c = (1..200)
            .map(|s| case(Class::Stairs, s))
            .find(|c| c.parameters["mid_landing_m"] > 0.0 && c.parameters["yaw_deg"] != 0.0)
            .unwrap();
        let s = loaded(&c);
        let p = &c.parameters;
        let (k1, tread, rise, mid) =
            (p["mid_landing_after"], p["tread_m"], p["rise_m"], p["mid_landing_m"]);
        let Primitive::Stairs(lower) = c.terrain[0].primitive else { panic!() };
        let at = |x: f64| {
            let w = sub(lower.start, lower.yaw_deg, [x, 0.0]);
            s.terrain_height(w[0], w[1])
        };
        for k in 1..=(p["steps"] as u32) {
            let k = f64::from(k);
            let x = if k <= k1 { (k - 0.5) * tread } else { (k - 0.5) * tread + mid };
            assert!((at(x) - k * rise).abs() < 1e-9, "{}: step {k}", c.name);
        }
        assert!((at(k1 * tread + mid / 2.0) - k1 * rise).abs() < 1e-9, "mid landing");
    }
}
