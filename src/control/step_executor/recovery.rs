//! Leaving the plan: on a failure a lifted foot is put down first, then the robot returns
//! to the driving posture at its pose (from the height map, feet rolled to the neutral
//! footprint) and stops, so that `closed_loop` can replan. Where a wheel would meet an edge
//! on its way back (a height change more than a driving wheel meets, as mid-flight on a
//! staircase, where feet stand a tread apart), the robot holds its stance instead and
//! reports itself stranded: rolling a wheel pair off a tread drops that corner, and on a
//! stair descent the CoM stood 0.41 m outside the support for a second. The wheels are
//! what meets an edge, not the foot's centre: each is the model's sphere, resting on the
//! height map where it stands ([`HeightMap::wheel_rest_height`], risers counted), so a
//! pair rolled toward a riser meets it a wheel radius before its centre's cell does. Checked
//! under the foot's centre alone, a rear pair on a 14-step descent was rolled 15 cm toward
//! a riser, to stop 0.7 cm short of it at a target height 7 cm up it, and the robot
//! bounced off its front pairs with the CoM 0.43 m outside the support.

use super::drive::WHEEL_REST_RANGE_M;
use super::timing::{motion_duration, smoothstep, smoothstep_rate};
use super::{
    AfterPutDown, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor, Stranding,
    planar,
};
use crate::posture::kinematics::{Posture, driving_posture, interpolate};
use crate::robot::{Leg, RobotDescription};
use crate::terrain::HeightMap;

impl StepExecutor {
    /// Puts a lifted foot down if there is one, then returns to the driving posture.
    pub(super) fn fail(&mut self, failure: ExecFailure, time: f64) {
        self.event(time, ExecEventKind::Failure { failure: failure.clone() });
        self.active = None;
        if let Some(leg) = Leg::ALL.into_iter().find(|l| !self.cmd.contact[l.index()]) {
            self.start_put_down(leg, AfterPutDown::Recover(failure));
        } else {
            self.start_recover(failure);
        }
    }

    pub(super) fn start_recover(&mut self, failure: ExecFailure) {
        let from = self.with_offsets(&self.cmd);
        let pose = planar(&from);
        let ground = &self.ground;
        let to = driving_posture(
            &self.robot,
            &pose,
            self.config.driving_leg_height_m,
            self.config.pitch_fraction,
            |x, y| ground.bilinear(x, y).or_else(|| ground.height_at_cell(x, y)),
        );
        self.foot_offset = [[0.0; 3]; 4];
        self.correction = [0.0; 2];
        self.fading = None;
        self.cmd = from;
        let to = match to {
            Ok(to) => to,
            Err(at) => {
                let reason = Stranding::OffMap { at };
                self.mode = Mode::Stranded(failure, reason);
                return;
            }
        };
        for leg in Leg::ALL {
            let i = leg.index();
            let height_change_m =
                wheel_rest_range_along(&self.robot, ground, from.feet[i], to.feet[i]);
            if height_change_m > WHEEL_REST_RANGE_M {
                let allowed_m = WHEEL_REST_RANGE_M;
                let reason = Stranding::Edge { leg, height_change_m, allowed_m };
                self.mode = Mode::Stranded(failure, reason);
                return;
            }
        }
        let c = &self.config;
        let duration = motion_duration(&from, &to, c.recover_speed_mps, c.recover_angular_speed);
        self.mode = Mode::Recover { from, to, elapsed: 0.0, duration, failure };
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn recover_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        from: Posture,
        to: Posture,
        mut elapsed: f64,
        duration: f64,
        failure: ExecFailure,
    ) -> Command {
        elapsed = (elapsed + dt).min(duration);
        let s = elapsed / duration;
        let w = smoothstep(s);
        let dw = smoothstep_rate(s) / duration;
        let p = interpolate(&from, &to, w);
        self.cmd = p;
        let legs = self.legs_or_hold(&p);
        let vel: [[f64; 2]; 4] = std::array::from_fn(|i| {
            [(to.feet[i][0] - from.feet[i][0]) * dw, (to.feet[i][1] - from.feet[i][1]) * dw]
        });
        let wheels = self.rolling(&p, &vel, obs);
        self.mode = if elapsed >= duration {
            Mode::Stopped(failure)
        } else {
            Mode::Recover { from, to, elapsed, duration, failure }
        };
        Command { legs, wheels }
    }
}

/// The larger of the height ranges over which each wheel of a pair rests while the foot
/// rolls in a straight line from `a` to `b` (sampled every half cell, both ends
/// included), m: zero on flat ground and for a foot that does not move, a tread's rise
/// where a wheel meets a stair edge. The pair rolls steered along its way, so its two
/// wheels (the model's spheres, `track` apart) sit across it; each rests where
/// [`HeightMap::wheel_rest_height`] puts it, with every cell counted (a riser is what the
/// check is for) but those above its own cell that the wheel already touches where it
/// stands: a pair that stepped up to a riser and rolls back from it leans on it, it does
/// not meet it. The range includes the height of the wheel's own cell where it starts,
/// so a wheel that starts at a drop and rolls off it counts the drop. Samples where the
/// map knows nothing under a wheel are left out.
fn wheel_rest_range_along(
    robot: &RobotDescription,
    ground: &HeightMap,
    a: [f64; 3],
    b: [f64; 3],
) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length = dx.hypot(dy);
    // Across the way (any direction for a foot that does not move).
    let (ux, uy) = if length > 0.0 { (-dy / length, dx / length) } else { (0.0, 1.0) };
    let (half, r) = (robot.wheel_track / 2.0, robot.wheel_radius);
    let samples = (length / (0.5 * ground.resolution())).ceil().max(1.0) as usize;
    [-half, half]
        .map(|o| {
            // Where the wheel stands: the height of its own cell, and the higher cells it
            // already touches there, which it leans on rather than meets.
            let (x0, y0) = (a[0] + o * ux, a[1] + o * uy);
            let start = ground.height_at_cell(x0, y0);
            let leaned_on = |i: usize, j: usize, h: f64| {
                start.is_some_and(|s| h > s) && ground.cell_within(i, j, x0, y0, r)
            };
            let (lo, hi) = (0..=samples)
                .filter_map(|k| {
                    let t = k as f64 / samples as f64;
                    let (x, y) = (x0 + t * dx, y0 + t * dy);
                    ground.wheel_rest_height_on(x, y, r, |i, j, h| !leaned_on(i, j, h))
                })
                .chain(start)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| (lo.min(z), hi.max(z)));
            if lo <= hi { hi - lo } else { 0.0 }
        })
        .into_iter()
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::step_executor::test_support::{config, ground, robot, standing, step_path};

    /// Flat ground, with a 0.2 m block over x ≥ `edge` if given (2.5 cm cells from −2 m).
    fn map(edge: Option<f64>) -> HeightMap {
        HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, _| {
            let x = -2.0 + (i as f64 + 0.5) * 0.025;
            if edge.is_some_and(|e| x >= e) { 0.2 } else { 0.0 }
        })
        .unwrap()
    }

    #[test]
    fn the_wheels_way_back_counts_the_edges_they_meet() {
        let (rb, step) = (robot(), map(Some(0.5)));
        let range = |a: [f64; 2], b: [f64; 2]| {
            wheel_rest_range_along(&rb, &step, [a[0], a[1], 0.0], [b[0], b[1], 0.0])
        };
        // Flat all the way: the wheels (radius 0.08 m) stop 0.02 m short of the edge.
        assert_eq!(range([0.0, 0.0], [0.4, 0.0]), 0.0);
        // Over the edge onto the 0.2 m block.
        assert!((range([0.0, 0.0], [1.0, 0.3]) - 0.2).abs() < 1e-12);
        // The foot's centre stops 0.03 m short of the edge, on the low cells all the way,
        // but its wheels meet the block: each rests on the block's first cell, 0.03 m
        // ahead, at 0.2 + √(0.08² − 0.03²) − 0.08 = 0.194162 m.
        let short = range([0.0, 0.0], [0.47, 0.0]);
        assert!(
            (short - (0.2 + (0.08f64.powi(2) - 0.03f64.powi(2)).sqrt() - 0.08)).abs() < 1e-9,
            "{short}"
        );
        // No way at all: where the wheels stand now.
        assert_eq!(range([0.7, 0.0], [0.7, 0.0]), 0.0);
        // Wheels 5 cm short of the block lean on it (a pair that stepped up to a riser):
        // rolled away from it they meet nothing.
        assert_eq!(range([0.45, 0.0], [0.2, 0.0]), 0.0);
        // Wheels 2 cm onto the block rolled off it: the drop counts from where they stand.
        assert!((range([0.52, 0.0], [0.2, 0.0]) - 0.2).abs() < 1e-12);
    }

    #[test]
    fn a_robot_whose_foot_would_roll_off_an_edge_holds_its_stance_stranded() {
        // FL stands 0.2 m ahead of its neutral place, on a 0.2 m block whose edge lies
        // 0.1 m ahead of that place: its way back rolls over the edge. On flat ground the
        // same stance returns to the driving posture.
        let neutral = robot().neutral_footprint()[Leg::FrontLeft.index()];
        let failure = ExecFailure::Drift { distance_m: 0.2, heading_rad: 0.0 };
        let stance = |ground: HeightMap, z: f64| {
            let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground);
            ex.cmd = standing();
            ex.cmd.feet[0] = [neutral[0] + 0.2, neutral[1], z];
            ex.start_recover(failure.clone());
            ex.mode
        };
        match stance(map(Some(neutral[0] + 0.1)), 0.2) {
            Mode::Stranded(f, Stranding::Edge { leg, height_change_m, allowed_m }) => {
                assert_eq!(f, failure);
                assert_eq!(leg, Leg::FrontLeft);
                assert!((height_change_m - 0.2).abs() < 1e-12, "{height_change_m}");
                assert_eq!(allowed_m, WHEEL_REST_RANGE_M);
            }
            m => panic!("{m:?}"),
        }
        assert!(matches!(stance(ground(), 0.0), Mode::Recover { .. }));

        // FL stands 0.1 m behind its neutral place, and a 0.2 m block's edge lies 3 to
        // 5.5 cm ahead of that place (the next cell border): the foot's centre never
        // leaves the low cells on its way back, but its wheels (radius 0.08 m) meet the
        // block's first cell, `gap` ahead, and rest on it at 0.2 + √(0.08² − gap²) − 0.08.
        let edge = ((neutral[0] + 2.03) / 0.025).ceil() * 0.025 - 2.0;
        let gap = edge - neutral[0];
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), map(Some(edge)));
        ex.cmd = standing();
        ex.cmd.feet[0] = [neutral[0] - 0.1, neutral[1], 0.0];
        ex.start_recover(failure.clone());
        match ex.mode {
            Mode::Stranded(_, Stranding::Edge { leg, height_change_m, .. }) => {
                assert_eq!(leg, Leg::FrontLeft);
                let rest = 0.2 + (0.08f64.powi(2) - gap * gap).sqrt() - 0.08;
                assert!((height_change_m - rest).abs() < 1e-9, "{height_change_m} {rest}");
            }
            m => panic!("{m:?}"),
        }
    }
}
