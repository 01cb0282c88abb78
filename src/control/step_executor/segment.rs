//! Keyframe segments other than drive runs: the smoothstep interpolation between two
//! keyframes on a segment clock that slows down while the servos lag, the stepping leg's
//! offsets (lift offset faded out, landing offset faded in), the drift check, and the
//! support margin watch while a foot is in the air (below the emergency margin the foot
//! is put down, see `contact`).

use super::timing::{clock_rate, motion_duration, smoothstep, smoothstep_rate};
use super::{
    AfterPutDown, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor, planar,
};
use crate::control::foot_contact::ContactConfirm;
use crate::geometry::wrap_angle;
use crate::motion::Phase;
use crate::posture::kinematics::{Posture, interpolate};
use crate::robot::Leg;

impl StepExecutor {
    pub(super) fn start_segment(&mut self, i: usize) {
        let from = self.cmd;
        let to = self.keys[i].posture();
        let planned = self.keys[i].time_s - self.keys[i - 1].time_s;
        let c = &self.config;
        let duration =
            planned.max(motion_duration(&from, &to, c.recover_speed_mps, c.recover_angular_speed));
        self.mode = Mode::Segment { from, index: i, elapsed: 0.0, duration, settle: 0.0 };
    }

    /// Largest |commanded − measured| joint angle, rad.
    fn tracking_error(&self, obs: &Observation) -> f64 {
        let mut e: f64 = 0.0;
        for (c, m) in self.last_legs.iter().zip(&obs.joints) {
            for k in 0..3 {
                e = e.max((c[k] - m[k]).abs());
            }
        }
        e
    }

    fn drift(&self, obs: &Observation, commanded: &Posture) -> Option<ExecFailure> {
        let c = planar(commanded);
        let distance_m = (obs.base.x - c.x).hypot(obs.base.y - c.y);
        let heading_rad = wrap_angle(obs.base.theta - c.theta);
        (distance_m > self.config.drift_tolerance_m
            || heading_rad.abs() > self.config.drift_tolerance_rad)
            .then_some(ExecFailure::Drift { distance_m, heading_rad })
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn segment_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        from: Posture,
        index: usize,
        mut elapsed: f64,
        duration: f64,
        mut settle: f64,
    ) -> Command {
        let time = obs.time;
        let c = &self.config;
        let rate = clock_rate(
            self.tracking_error(obs),
            c.slowdown_start_rad,
            c.slowdown_full_rad,
            c.slowest_rate,
        );
        let k = &self.keys[index];
        let (phase, leg) = (k.phase, k.leg);
        let to = k.posture();
        elapsed = (elapsed + dt * rate).min(duration);
        let s = elapsed / duration;
        let w = smoothstep(s);
        let dw = smoothstep_rate(s) * rate / duration;
        let mut p = interpolate(&from, &to, w);
        p.contact = std::array::from_fn(|i| from.contact[i] && to.contact[i]);
        // Offsets of the stepping leg: faded out during the lift, the landing
        // offset faded in during the swing.
        if let Some(l) = leg {
            let i = l.index();
            match phase {
                Phase::Lift => {
                    self.foot_offset[i] = self.lift_offset.map(|o| o * (1.0 - w));
                }
                Phase::Swing => {
                    self.foot_offset[i] = [self.landing[0] * w, self.landing[1] * w, 0.0];
                }
                Phase::Place => {
                    self.foot_offset[i] = [self.landing[0], self.landing[1], 0.0];
                }
                _ => {}
            }
        }
        if let Some(c0) = self.fading {
            self.correction = c0.map(|v| v * (1.0 - w));
        }
        let commanded = self.with_offsets(&p);
        self.cmd = p;
        if let Some(f) = self.drift(obs, &commanded) {
            self.fail(f, time);
            return self.hold();
        }
        // A foot in the air: watch the support margin.
        if let Some(l) = leg
            && matches!(phase, Phase::Lift | Phase::Swing | Phase::Place)
        {
            let m = obs.support_margin(l);
            let airborne = phase != Phase::Place || !obs.leg_in_contact(l);
            let low = airborne && m < self.config.emergency_margin_m;
            self.low_margin_since = if low { self.low_margin_since.or(Some(time)) } else { None };
            let held = self
                .low_margin_since
                .is_some_and(|since| time - since + dt >= self.config.emergency_hold_s - 1e-9);
            if held {
                self.low_margin_since = None;
                self.event(time, ExecEventKind::FootPutDown { leg: l, margin_m: m });
                let lift = self.lift_index(index);
                let then = if self.retries < self.config.max_step_retries {
                    self.retries += 1;
                    AfterPutDown::Retry(lift)
                } else {
                    self.steps_aborted += 1;
                    self.active = None;
                    AfterPutDown::Recover(ExecFailure::StepAborted {
                        leg: l,
                        margin_m: m,
                        required_m: self.config.min_lift_margin_m,
                        planned_m: self.keys[lift].margin_m,
                    })
                };
                self.start_put_down(l, then);
                return self.hold();
            }
        }
        let Some(legs) = self.legs_for(&commanded, time) else { return self.hold() };
        let vel: [[f64; 2]; 4] = std::array::from_fn(|i| {
            [(to.feet[i][0] - from.feet[i][0]) * dw, (to.feet[i][1] - from.feet[i][1]) * dw]
        });
        let wheels = self.rolling(&p, &vel, obs);
        if elapsed >= duration {
            settle += dt;
            if self.tracking_error(obs) < self.config.settle_tolerance_rad
                || settle >= self.config.max_settle_s
            {
                self.finish_segment(index, phase, leg);
                return Command { legs, wheels };
            }
        }
        self.mode = Mode::Segment { from, index, elapsed, duration, settle };
        Command { legs, wheels }
    }

    fn finish_segment(&mut self, index: usize, phase: Phase, leg: Option<Leg>) {
        self.cmd = self.keys[index].posture();
        if phase == Phase::Place && leg.is_some() {
            self.mode = Mode::Confirm { index, confirm: ContactConfirm::new(self.config.contact) };
            return;
        }
        if self.fading.is_some() {
            self.fading = None;
            self.correction = [0.0; 2];
        }
        self.advance(index + 1, self.now);
    }
}
