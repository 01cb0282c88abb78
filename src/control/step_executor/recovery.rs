//! Leaving the plan: on a failure a lifted foot is put down first, then the robot returns
//! to the driving posture at its pose (from the height map, feet rolled to the neutral
//! footprint) and stops, so that `jobs::run` can replan. Where a foot would roll over an
//! edge on its way back (a height change more than a driving wheel meets, as mid-flight
//! on a staircase, where feet stand a tread apart), the robot holds its stance instead
//! and reports itself stranded: rolling a wheel pair off a tread drops that corner, and
//! on a stair descent the CoM stood 0.41 m outside the support for a second.

use super::drive::WHEEL_REST_RANGE_M;
use super::timing::{motion_duration, smoothstep, smoothstep_rate};
use super::{
    AfterPutDown, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor, Stranding,
    planar,
};
use crate::motion::kinematics::{Posture, driving_posture, interpolate};
use crate::robot::Leg;
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
            let height_change_m = height_range_along(ground, from.feet[i], to.feet[i]);
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

/// Height range of the known terrain under a foot rolled in a straight line from `a` to
/// `b` (sampled every half cell, both ends included), m: zero on flat ground, a tread's
/// rise where the way crosses a stair edge.
fn height_range_along(ground: &HeightMap, a: [f64; 3], b: [f64; 3]) -> f64 {
    let length = (b[0] - a[0]).hypot(b[1] - a[1]);
    let samples = (length / (0.5 * ground.resolution())).ceil().max(1.0) as usize;
    let (lo, hi) = (0..=samples)
        .filter_map(|k| {
            let t = k as f64 / samples as f64;
            ground.height_at_cell(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
        })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| (lo.min(z), hi.max(z)));
    if lo <= hi { hi - lo } else { 0.0 }
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
    fn the_height_range_along_a_foot_s_way_counts_the_edges_it_crosses() {
        let step = map(Some(0.5));
        assert_eq!(height_range_along(&step, [0.0, 0.0, 0.0], [0.4, 0.0, 0.0]), 0.0);
        assert!((height_range_along(&step, [0.0, 0.0, 0.0], [1.0, 0.3, 0.0]) - 0.2).abs() < 1e-12);
        // No way at all: the cell under the foot.
        assert_eq!(height_range_along(&step, [0.6, 0.0, 0.2], [0.6, 0.0, 0.2]), 0.0);
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
    }
}
