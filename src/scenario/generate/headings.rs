//! The `headings` class: start and goal on open ground (sometimes a few obstacles), their
//! headings off the planner's lattice of 64 headings.

use super::course::{Builder, Course, Frame, Reject, deg, rect, reject_unless, round_to};
use super::layout::scatter;
use super::{Class, ClassUnit};
use crate::rng::Rng;
use crate::scenario::{Outcome, PoseSpec};

/// Spacing of the planner's headings (64 per turn), degrees; `headings` avoids them.
pub const LATTICE_STEP_DEG: f64 = 5.625;
/// Smallest distance of a `headings` yaw from the nearest lattice heading, degrees.
pub const MIN_OFF_LATTICE_DEG: f64 = 0.5;

/// The class; its files name no model.
pub(super) const UNIT: ClassUnit =
    ClassUnit { class: Class::Headings, name: "headings", draw, models: None };

/// Distance of a yaw from the nearest multiple of [`LATTICE_STEP_DEG`], degrees.
pub fn off_lattice_deg(yaw_deg: f64) -> f64 {
    let r = yaw_deg.rem_euclid(LATTICE_STEP_DEG);
    r.min(LATTICE_STEP_DEG - r)
}

/// A yaw uniform over the turn and at least [`MIN_OFF_LATTICE_DEG`] from the lattice.
fn off_lattice_yaw(rng: &mut Rng) -> f64 {
    let k = rng.below(64) as f64;
    let off = rng.range(MIN_OFF_LATTICE_DEG + 0.05, LATTICE_STEP_DEG - MIN_OFF_LATTICE_DEG - 0.05);
    deg(-180.0 + k * LATTICE_STEP_DEG + off)
}

/// Draws a start and goal at least 2 m apart, their off-lattice headings, and up to 4
/// obstacles off the straight way between them.
fn draw(rng: &mut Rng) -> Result<Course, Reject> {
    let l = round_to(rng.range(5.0, 8.0), 1);
    let w = round_to(rng.range(4.0, 6.0), 1);
    let pick = |rng: &mut Rng| {
        [
            round_to(rng.range(1.0, l - 1.0), 2),
            round_to(rng.range(-w / 2.0 + 1.0, w / 2.0 - 1.0), 2),
        ]
    };
    let start = pick(rng);
    let mut goal = pick(rng);
    let dist = |g: [f64; 2]| (g[0] - start[0]).hypot(g[1] - start[1]);
    for _ in 0..20 {
        if dist(goal) >= 2.0 {
            break;
        }
        goal = pick(rng);
    }
    let apart = dist(goal);
    reject_unless(apart >= 2.0, || format!("start and goal only {apart:.2} m apart"))?;
    let start_yaw = off_lattice_yaw(rng);
    let goal_yaw = off_lattice_yaw(rng);
    let obstacles = if rng.chance(0.5) { rng.int_range(1, 4) } else { 0 };
    let mut b = Builder::new(Frame::Quarter(0));
    b.param("start_yaw_deg", start_yaw);
    b.param("goal_yaw_deg", goal_yaw);
    b.param("distance_m", round_to(apart, 2));
    let area = [0.3, l - 0.3, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, _, _) =
        scatter(&mut b, rng, obstacles, area, &[start, goal], &[start, goal]);
    b.param("obstacles", f64::from(boxes + poles));
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let [sx, sy] = b.at(start);
    let [gx, gy] = b.at(goal);
    let s = PoseSpec { x: sx, y: sy, yaw_deg: start_yaw };
    let g = PoseSpec { x: gx, y: gy, yaw_deg: goal_yaw };
    let description = format!(
        "headings: start yaw {start_yaw:.1}°, goal yaw {goal_yaw:.1}° (off the {LATTICE_STEP_DEG}° lattice), {apart:.2} m apart, {}",
        match boxes + poles {
            0 => "open ground".to_owned(),
            n => format!("{n} obstacles"),
        }
    );
    Ok(b.finish(description, map, s, g, Outcome::Reach, 0, apart + 2.0))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{SEEDS, case};
    use super::*;

    #[test]
    fn headings_are_off_the_lattice() {
        for seed in SEEDS {
            let c = case(Class::Headings, seed);
            for yaw in [c.start.yaw_deg, c.goal.yaw_deg] {
                assert!((-180.0..180.0).contains(&yaw), "{yaw}");
                assert!(off_lattice_deg(yaw) >= MIN_OFF_LATTICE_DEG - 1e-9, "{}: {yaw}", c.name);
            }
        }
        assert_eq!(off_lattice_deg(11.25), 0.0);
        assert!((off_lattice_deg(-3.0) - 2.625).abs() < 1e-12);
    }
}
