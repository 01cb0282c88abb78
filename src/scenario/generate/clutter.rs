//! The `clutter` class: random boxes and poles up to 0.5 m tall and low bumps a wheel
//! drives over, a way from start to goal (through a waypoint) kept free of the tall ones.

use super::course::{Builder, Course, Reject, Span, polyline_length, quarter, rect, round_to};
use super::layout::scatter;
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::Outcome;

/// Height of drivable bumps, m: below the 0.05 m a wheel drives over (eq. 2).
pub const BUMP_HEIGHT_M: Span = Span::new(0.01, 0.045);

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::Clutter, name: "clutter", draw, models: None };

/// Draws the course's size, start, goal and waypoint, the obstacles off the way, and the
/// bumps anywhere.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let l = round_to(rng.range(6.0, 9.0), 1);
    let w = round_to(rng.range(4.0, 6.0), 1);
    let lat = w / 2.0 - 1.0;
    let start = [1.0, round_to(rng.range(-lat, lat), 2)];
    let goal = [l - 1.0, round_to(rng.range(-lat, lat), 2)];
    let via = [round_to(l / 2.0 + rng.range(-0.5, 0.5), 2), round_to(rng.range(-lat, lat), 2)];
    let way = [start, via, goal];
    let start_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let goal_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let n = rng.int_range(6, 14);
    let n_bumps = rng.int_range(3, 8);
    let mut b = Builder::new(frame);
    b.param("length_m", l);
    b.param("width_m", w);
    let area = [0.3, l - 0.3, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, lo, hi) = scatter(&mut b, rng, n, area, &way, &[start, goal]);
    for k in 0..n_bumps {
        let h = BUMP_HEIGHT_M.draw(rng, 3);
        let size = [round_to(rng.range(0.3, 1.2), 3), round_to(rng.range(0.3, 1.2), 3)];
        let c =
            [round_to(rng.range(area[0], area[1]), 3), round_to(rng.range(area[2], area[3]), 3)];
        let yaw = round_to(rng.range(0.0, 180.0), 1);
        b.add_box(format!("bump {}: drivable", k + 1), c, size, h, yaw);
    }
    b.param("obstacles", f64::from(boxes + poles));
    b.param("bumps", f64::from(n_bumps));
    b.param("tallest_m", hi);
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let description = format!(
        "clutter: {} obstacles ({boxes} boxes, {poles} poles, {:.2}-{hi:.2} m tall), {n_bumps} bumps under 0.05 m, {l:.1} m x {w:.1} m",
        boxes + poles,
        if lo.is_finite() { lo } else { 0.0 }
    );
    let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
    Ok(b.finish(description, map, s, g, Outcome::Reach, 2, polyline_length(&way)))
}

#[cfg(test)]
mod tests {
    use super::super::layout::CLUTTER_HEIGHT_M;
    use super::super::test_support::{SEEDS, case};
    use super::*;

    #[test]
    fn clutter_stays_in_its_ranges() {
        for seed in SEEDS {
            let c = case(Class::Clutter, seed);
            for p in &c.terrain {
                let h = p.primitive.max_height();
                assert!(
                    CLUTTER_HEIGHT_M.contains(h) || BUMP_HEIGHT_M.contains(h),
                    "{}: {} at {h}",
                    c.name,
                    p.note
                );
                assert!(h <= 0.5);
            }
            assert!(c.parameters["obstacles"] >= 1.0, "{}", c.name);
        }
    }
}
