//! Leaving the plan: on a failure a lifted foot is put down first, then the robot returns
//! to the driving posture at its pose (from the height map, feet rolled to the neutral
//! footprint) and stops, so that `jobs::run` can replan.

use super::timing::{motion_duration, smoothstep, smoothstep_rate};
use super::{
    AfterPutDown, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor, planar,
};
use crate::motion::kinematics::{Posture, driving_posture, interpolate};
use crate::robot::Leg;

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
        match to {
            Ok(to) => {
                let c = &self.config;
                let duration =
                    motion_duration(&from, &to, c.recover_speed_mps, c.recover_angular_speed);
                self.mode = Mode::Recover { from, to, elapsed: 0.0, duration, failure };
            }
            Err(_) => self.mode = Mode::Stopped(failure),
        }
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
