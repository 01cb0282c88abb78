//! Feet keeping and finding the ground: after the place keyframe, weight goes back onto
//! the foot only when MuJoCo reports contact (`ContactConfirm`, bounded extra lowering; no
//! contact fails the step); a foot put down in an emergency or before a recovery is
//! lowered until contact, then the step is retried from its lift or the robot recovers;
//! in a standing manoeuvre on four feet the diagonals share the weight (`load_sharing`),
//! and on fewer a stance foot that loses the ground is lowered until it touches again
//! (the stance compliance).

use super::{AfterPutDown, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor};
use crate::control::foot_contact::{ContactConfirm, ContactConfirmConfig, ContactStatus};
use crate::robot::Leg;

impl StepExecutor {
    /// The stance legs' compliance in the standing modes. On four feet (all four in
    /// contact in the commanded posture) the wheel loads are shared as in a drive run
    /// ([`StepExecutor::share_load`]: the light diagonal's feet lowered below their
    /// keyframes, the heavy one's raised back toward them): on a 6 × 0.165 m flight
    /// climbed 54° off its axis the front-left pair carried 42 N of 569 when a shift back
    /// began, lost the ground with the leg 13 cm short of its reach, and the robot went
    /// over backwards. With a leg stepping (waiting to lift included), or no loads
    /// measured, a leg the commanded posture has bearing weight whose wheels MuJoCo
    /// reports touching nothing is lowered at [`ExecutorConfig::leg_extend_speed_mps`], at
    /// most [`ExecutorConfig::max_leg_extension_m`], until they touch: the position-
    /// servoed legs give under the weight, most in front of a shifted CoM (on a stair
    /// descent a planned base shift pitched the base 2.2° past its keyframe, a rear pair on
    /// its tread rose 1 cm off it, and the lift that followed measured −6.4 cm of margin on
    /// the two legs left, 8.5 cm planned, and was aborted). Extensions are kept (as the
    /// placed foot's extra lowering is) until the next drive run takes them over. A leg a
    /// step has lifted, is confirming or is putting down is left to the step.
    pub(super) fn comply_stance(&mut self, obs: &Observation, dt: f64) {
        let stepping = match &self.mode {
            Mode::Segment { .. } | Mode::CheckStance { .. } | Mode::Slide { .. } => None,
            Mode::Guard { index, .. } | Mode::Confirm { index, .. } => self.keys[*index].leg,
            Mode::PutDown { leg, .. } => Some(*leg),
            _ => return,
        };
        if stepping.is_none() && self.cmd.contact.iter().all(|&on| on) {
            let mut extension = self.foot_offset.map(|o| -o[2]);
            if self.share_load(&self.cmd, obs, &mut extension, dt) {
                for (o, e) in self.foot_offset.iter_mut().zip(extension) {
                    o[2] = -e;
                }
                return;
            }
        }
        let c = &self.config;
        for leg in Leg::ALL {
            let i = leg.index();
            if !self.cmd.contact[i] || Some(leg) == stepping || obs.leg_in_contact(leg) {
                continue;
            }
            let z = &mut self.foot_offset[i][2];
            if *z > -c.max_leg_extension_m {
                *z = (*z - c.leg_extend_speed_mps * dt).max(-c.max_leg_extension_m);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn confirm_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        index: usize,
        mut confirm: ContactConfirm,
    ) -> Command {
        let time = obs.time;
        let leg = self.keys[index].leg.unwrap_or(Leg::FrontLeft);
        let status = confirm.update(obs.leg_in_contact(leg), dt);
        let i = leg.index();
        match status {
            ContactStatus::Pending { extra_m } | ContactStatus::Confirmed { extra_m } => {
                self.foot_offset[i][2] = -extra_m;
            }
            ContactStatus::Failed { .. } => {}
        }
        let p = self.with_offsets(&self.cmd);
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let wheels = self.rolling(&p, &[[0.0; 2]; 4], obs);
        match status {
            ContactStatus::Pending { .. } => {
                self.mode = Mode::Confirm { index, confirm };
            }
            ContactStatus::Confirmed { extra_m } => {
                self.steps_executed += 1;
                self.active = None;
                self.event(time, ExecEventKind::StepExecuted { leg, extra_m });
                self.fading = Some(self.correction);
                self.advance(index + 1, time);
            }
            ContactStatus::Failed { extra_m } => {
                self.steps_aborted += 1;
                self.cmd.contact[i] = false;
                self.fail(ExecFailure::NoContact { leg, extra_m }, time);
            }
        }
        Command { legs, wheels }
    }

    pub(super) fn start_put_down(&mut self, leg: Leg, then: AfterPutDown) {
        // Fold the offsets of this leg into the commanded posture and lower from there.
        let i = leg.index();
        let p = self.with_offsets(&self.cmd);
        self.cmd.feet[i] = p.feet[i];
        self.foot_offset[i] = [0.0; 3];
        // The lowest ground the foot was planned on or may stand over now (a foot put
        // down mid-swing can be above lower ground than either end of its step, e.g. the
        // floor before a platform edge), minus the extra lowering allowed. Over a ditch
        // this is its bottom: contact or the leg's reach stops the foot first.
        let [x, y, _] = self.cmd.feet[i];
        let cells = (self.robot.wheel_pair_radius() / self.ground.resolution()).ceil() as usize;
        let under = self.ground.min_around(x, y, cells).unwrap_or(f64::INFINITY);
        let floor = self
            .keys
            .iter()
            .filter(|k| k.leg == Some(leg))
            .map(|k| k.feet[i][2])
            .fold(self.cmd.feet[i][2].min(under), f64::min)
            - self.config.contact.max_extra_m;
        self.mode = Mode::PutDown {
            leg,
            lowered: 0.0,
            floor,
            confirm: ContactConfirm::new(ContactConfirmConfig {
                max_extra_m: f64::INFINITY,
                ..self.config.contact
            }),
            then,
        };
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn put_down_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        leg: Leg,
        mut lowered: f64,
        floor: f64,
        mut confirm: ContactConfirm,
        then: AfterPutDown,
    ) -> Command {
        let time = obs.time;
        let i = leg.index();
        let status = confirm.update(obs.leg_in_contact(leg), dt);
        if matches!(status, ContactStatus::Pending { .. }) {
            let z = self.cmd.feet[i][2] - lowered;
            if z > floor {
                lowered += self.config.put_down_speed_mps * dt;
            }
        }
        let mut p = self.cmd;
        p.feet[i][2] -= lowered;
        let p_off = self.with_offsets(&p);
        let legs = self.legs_or_hold(&p_off);
        let wheels = self.rolling(&p_off, &[[0.0; 2]; 4], obs);
        let at_floor = self.cmd.feet[i][2] - lowered <= floor;
        match status {
            ContactStatus::Confirmed { .. } => {
                self.cmd = p;
                self.cmd.contact[i] = true;
                match then {
                    AfterPutDown::Retry(lift) => self.start_guard(lift),
                    AfterPutDown::Recover(f) => self.start_recover(f),
                }
            }
            _ if at_floor => {
                let f = ExecFailure::NoContact { leg, extra_m: lowered };
                self.event(time, ExecEventKind::Failure { failure: f.clone() });
                self.mode = Mode::Stopped(f);
            }
            _ => self.mode = Mode::PutDown { leg, lowered, floor, confirm, then },
        }
        Command { legs, wheels }
    }
}

#[cfg(test)]
mod tests {
    use crate::control::step_executor::actuation::{REACH_SPARE_M, reach_excess};
    use crate::control::step_executor::test_support::{
        all_contacts, config, contacts_without, ground, key, obs, robot, standing, step_path,
    };
    use crate::control::step_executor::{
        ExecEventKind, ExecFailure, ExecStatus, ExecutorConfig, Mode, StepExecutor,
    };
    use crate::geometry::Pose2;
    use crate::motion::Phase;
    use crate::robot::Leg;

    #[test]
    fn a_step_lifts_after_the_margin_check_and_ends_only_on_contact() {
        let keys = step_path();
        let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
        let feet = keys[0].feet;
        // The CoM 0.14 m inside the FR–RL diagonal (which passes through the origin).
        let com = [-0.1, -0.1, 0.4];
        let without_fl = contacts_without(&feet, Leg::FrontLeft);
        let mut t = 0.0;
        let mut lifted_at = None;
        let mut status = ExecStatus::Running;
        // Until the foot is placed, MuJoCo reports no contact of FL.
        for _ in 0..1000 {
            t += 0.01;
            let (_, st) = ex.tick(&obs(t, &ex, &without_fl, com), 0.01);
            status = st;
            if lifted_at.is_none() && ex.active_step().is_some() {
                lifted_at = Some(t);
            }
        }
        // Lifted after the 0.3 s settle, the step not done without contact, the foot
        // lowered by the full extra distance (5 cm), then failed.
        let lifted_at = lifted_at.expect("lifted");
        assert!((lifted_at - 0.3).abs() < 0.02, "{lifted_at}");
        assert_eq!(ex.steps_executed, 0);
        assert_eq!(ex.steps_aborted, 1);
        assert!(ex.events.iter().any(|e| matches!(
            e.event,
            ExecEventKind::Failure { failure: ExecFailure::NoContact { leg: Leg::FrontLeft, .. } }
        )));
        assert!(
            matches!(status, ExecStatus::NeedsReplan(ExecFailure::NoContact { .. })),
            "{status:?}"
        );

        // The same with contact reported once the foot is down: the step is executed.
        let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
        let placed = keys[3].feet;
        let mut t = 0.0;
        for _ in 0..1000 {
            t += 0.01;
            // FL touches once it is being placed.
            let down = matches!(ex.phase(), Some(Phase::Place) | None);
            let c = if down { all_contacts(&placed) } else { without_fl.clone() };
            let (_, st) = ex.tick(&obs(t, &ex, &c, com), 0.01);
            if st == ExecStatus::Finished {
                break;
            }
        }
        assert_eq!(ex.steps_executed, 1, "{:?}", ex.events);
        assert_eq!(ex.steps_aborted, 0);
    }

    #[test]
    fn a_dip_shorter_than_the_monitors_hold_does_not_put_the_foot_down() {
        // 0.03 s of support memory + 0.05 s of margin hold.
        assert!((config().emergency_hold_s - 0.08).abs() < 1e-12);
        let keys = step_path();
        let feet = keys[0].feet;
        let without_fl = contacts_without(&feet, Leg::FrontLeft);
        // The CoM 0.14 m inside the FR–RL diagonal; a dip is the rear-left pair off the
        // ground (FR and RR left: the CoM is 0.22 m outside their line).
        let com = [-0.1, -0.1, 0.4];
        let dip: Vec<_> = without_fl.iter().copied().filter(|(l, _)| *l != Leg::RearLeft).collect();
        // Ticks of 10 ms: a dip of `n` ticks, starting `from` ticks after the lift; with
        // `stale`, the executor starts with the start of a low margin left over (as a
        // segment that ended while the margin was low leaves it: a drift failure, or a
        // Place that ended with the foot still in the air). The time of the put-down is
        // counted from the dip's start.
        let put_down_after_with = |n: usize, from: usize, stale: bool| {
            let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
            if stale {
                // Left by the segment before; then the step's guard starts (here anew:
                // `new` started it already, at the same time).
                ex.low_margin_since = Some(0.0);
                ex.start_guard(1);
            }
            let (mut t, mut lifted) = (0.0, None);
            for _ in 0..150 {
                t += 0.01;
                let k = lifted.map_or(0, |l: f64| ((t - l) / 0.01).round() as usize);
                let dipping = lifted.is_some() && (from..from + n).contains(&k);
                let c = if dipping { &dip } else { &without_fl };
                let o = obs(t, &ex, c, com);
                if dipping {
                    assert!(o.support_margin(Leg::FrontLeft) < 0.0);
                }
                ex.tick(&o, 0.01);
                if lifted.is_none() && ex.active_step().is_some() {
                    lifted = Some(t);
                }
            }
            let lifted = lifted.expect("lifted");
            ex.events.iter().find_map(|e| match e.event {
                ExecEventKind::FootPutDown { .. } => Some(e.time_s - (lifted + 0.01 * from as f64)),
                _ => None,
            })
        };
        let put_down_after = |n: usize| put_down_after_with(n, 20, false);
        // 70 ms below the emergency margin: the monitor does not count it, nor does the
        // executor.
        assert_eq!(put_down_after(7), None);
        // 80 ms and longer: put down on the dip's eighth sample, 70 ms after its first.
        for n in [8, 30] {
            let at = put_down_after(n).expect("put down");
            assert!((at - 0.07).abs() < 1e-6, "{n}: {at}");
        }
        // A low margin left over from before the lift counts for nothing, also where the
        // margin is low from the lift's first sample on: the guard starts the watch afresh
        // (it once put the foot down at that first sample).
        assert_eq!(put_down_after_with(3, 1, true), None);
        let at = put_down_after_with(8, 1, true).expect("put down");
        assert!((at - 0.07).abs() < 1e-6, "{at}");
    }

    #[test]
    fn the_base_height_hold_raises_a_sunken_base_up_to_its_cap() {
        // The keyframes stand the base 0.5 m up; MuJoCo measures it 2 cm lower. With the
        // gain 2/s the raise after 0.1 s of 10 ms ticks is 2 · 0.02 · 0.1 = 4 mm; 10 cm
        // low for 0.3 s would ask 6 cm, and it stops at the 4 cm cap; without a
        // measurement nothing is raised.
        let keys = step_path();
        let com = [-0.1, -0.1, 0.4];
        let contacts = all_contacts(&keys[0].feet);
        let run = |base_z: Option<f64>, ticks: usize| {
            let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
            for k in 0..ticks {
                let mut o = obs(0.01 * (k + 1) as f64, &ex, &contacts, com);
                o.base_z = base_z;
                ex.tick(&o, 0.01);
            }
            (ex.base_lift, ex.with_offsets(&ex.cmd).base_position[2] - ex.cmd.base_position[2])
        };
        let (lift, raised) = run(Some(0.48), 10);
        assert!((lift - 0.004).abs() < 1e-9, "{lift}");
        assert!((raised - lift).abs() < 1e-12, "the commanded base carries the raise");
        let (lift, _) = run(Some(0.40), 30);
        assert_eq!(lift, config().max_base_lift_m);
        assert_eq!(run(None, 10).0, 0.0);
        // A base standing higher than commanded is not lowered.
        assert_eq!(run(Some(0.52), 10).0, 0.0);
    }

    #[test]
    fn the_base_position_hold_integrates_the_lag_along_the_heading_within_reach() {
        // The keyframes stand the base at the origin facing +x; MuJoCo measures it `at`.
        // Returns the hold along x and y after `ticks` ticks of 10 ms.
        let keys = step_path();
        let com = [-0.1, -0.1, 0.4];
        let contacts = all_contacts(&keys[0].feet);
        let run = |config: ExecutorConfig, at: [f64; 2], ticks: usize| {
            let mut ex = StepExecutor::new(&robot(), config, keys.clone(), ground());
            for k in 0..ticks {
                let mut o = obs(0.01 * (k + 1) as f64, &ex, &contacts, com);
                o.base = Pose2::new(at[0], at[1], 0.0);
                ex.tick(&o, 0.01);
            }
            ex
        };
        // 2 cm behind: with the gain 2/s the legs are solved for a base 2 · 0.02 · 0.1 =
        // 4 mm ahead after 0.1 s.
        let ex = run(config(), [-0.02, 0.0], 10);
        assert!((ex.base_hold[0] - 0.004).abs() < 1e-9, "{:?}", ex.base_hold);
        assert!(ex.base_hold[1].abs() < 1e-12);
        let solved = ex.held(&ex.cmd);
        assert!((solved.base_position[0] - ex.cmd.base_position[0] - 0.004).abs() < 1e-9);
        // 10 cm behind for 0.3 s asks 6 cm: the cap, 4 cm.
        let ex = run(config(), [-0.1, 0.0], 30);
        assert!((ex.base_hold[0] - config().max_base_hold_m).abs() < 1e-12);
        // Sideways the sagittal legs cannot carry the base: no hold.
        assert_eq!(run(config(), [0.0, 0.05], 30).base_hold, [0.0, 0.0]);
        // Never past reach: with a high gain and no cap, the hold stops where the legs
        // (hips 0.45 m up, ankles 0.18 m above the ground, so 0.27 m below the hips) reach
        // 0.5 m less the executor's 1 mm spare: √(0.499² − 0.27²) = 0.419644 m.
        let wide = ExecutorConfig { base_hold_gain: 100.0, max_base_hold_m: 1.0, ..config() };
        let ex = run(wide, [-0.1, 0.0], 20);
        assert!((ex.base_hold[0] - 0.419644).abs() < 1e-4, "{:?}", ex.base_hold);
        let solved = ex.held(&ex.cmd);
        assert!(reach_excess(&ex.robot, &solved, REACH_SPARE_M, None) <= 1e-12);
        // Driving (or any mode but the standing ones) drops it.
        let mut ex = run(config(), [-0.02, 0.0], 10);
        ex.mode = Mode::Finished;
        ex.tick(&obs(0.2, &ex, &contacts, com), 0.01);
        assert_eq!(ex.base_hold, [0.0, 0.0]);
    }

    #[test]
    fn before_a_lift_the_foot_about_to_leave_the_ground_does_not_bound_the_hold() {
        // FL stands 0.40 m behind its hip (0.27 m below it): a base moved ahead by h
        // stretches it to √((0.40 + h)² + 0.27²), its 0.499 m reach at h = 0.0196 m; the
        // other feet under their hips allow 0.42 m. Waiting to lift FL (the guard, its
        // settle made long), the base measured 10 cm behind for 0.3 s asks 6 cm of hold:
        // the 4 cm cap, not FL's 1.96 cm, which would cancel the guard's corrections
        // (measured on a stair: the hold at its cap shrank by what each correction added,
        // the base did not move, the step was aborted at 4.92 of 5 cm).
        let r = robot();
        let mut keys = step_path();
        for k in &mut keys {
            k.feet[0][0] = r.hips[0][0] - 0.40;
            k.joints = crate::posture::kinematics::leg_joint_targets(&r, &k.posture()).unwrap();
        }
        let cfg = ExecutorConfig { lift_settle_s: 10.0, ..config() };
        let mut ex = StepExecutor::new(&r, cfg, keys.clone(), ground());
        let contacts = all_contacts(&keys[0].feet);
        for k in 0..30 {
            let mut o = obs(0.01 * (k + 1) as f64, &ex, &contacts, [-0.1, -0.1, 0.4]);
            o.base = Pose2::new(-0.1, 0.0, 0.0);
            ex.tick(&o, 0.01);
        }
        assert!(matches!(ex.mode, Mode::Guard { .. }), "{:?}", ex.mode);
        assert!((ex.base_hold[0] - config().max_base_hold_m).abs() < 1e-12, "{:?}", ex.base_hold);
        // FL would be pulled in (it is lifted next); the feet that stay are within reach.
        let solved = ex.held(&ex.cmd);
        assert!(reach_excess(&r, &solved, REACH_SPARE_M, None) > 0.0);
        assert!(reach_excess(&r, &solved, REACH_SPARE_M, Some(Leg::FrontLeft)) <= 0.0);
    }

    #[test]
    fn a_stance_foot_that_loses_the_ground_is_lowered_until_it_touches() {
        // Waiting to lift FL (the guard), MuJoCo reports no wheel of RR on the ground.
        // At 5 cm/s, 20 ticks of 10 ms lower RR 1 cm below its keyframe; FL (about to
        // lift), FR and RL (touching) stay; after 1 s the 3 cm cap holds; once RR
        // touches it keeps its extension (the weight stays on it).
        let keys = step_path();
        let com = [-0.1, -0.1, 0.4];
        let feet = keys[0].feet;
        let without_rr: Vec<_> =
            all_contacts(&feet).into_iter().filter(|(l, _)| *l != Leg::RearRight).collect();
        let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
        let mut t = 0.0;
        let mut tick = |ex: &mut StepExecutor, contacts: &[(Leg, [f64; 2])]| {
            t += 0.01;
            ex.tick(&obs(t, ex, contacts, com), 0.01);
        };
        for _ in 0..20 {
            tick(&mut ex, &without_rr);
        }
        assert!(matches!(ex.mode, Mode::Guard { .. }), "{:?}", ex.mode);
        let z = |ex: &StepExecutor| ex.foot_offset.map(|o| o[2]);
        let lowered = z(&ex);
        assert!((lowered[Leg::RearRight.index()] + 0.01).abs() < 1e-9, "{lowered:?}");
        for leg in [Leg::FrontLeft, Leg::FrontRight, Leg::RearLeft] {
            assert_eq!(lowered[leg.index()], 0.0, "{leg:?}");
        }
        // The commanded foot carries it.
        let p = ex.with_offsets(&ex.cmd);
        assert!((p.feet[3][2] - (feet[3][2] - 0.01)).abs() < 1e-9);
        // The cap, in a long planned base shift (no leg stepping), then kept while
        // touching.
        let a = standing();
        let shift =
            vec![key(0.0, Phase::Start, None, &a), key(100.0, Phase::PlannedBaseShift, None, &a)];
        let mut ex = StepExecutor::new(&robot(), config(), shift, ground());
        for _ in 0..100 {
            tick(&mut ex, &without_rr);
        }
        assert_eq!(z(&ex)[Leg::RearRight.index()], -config().max_leg_extension_m);
        for _ in 0..50 {
            tick(&mut ex, &all_contacts(&feet));
        }
        assert_eq!(z(&ex)[Leg::RearRight.index()], -config().max_leg_extension_m);
    }

    #[test]
    fn on_four_feet_the_light_diagonal_is_lowered_until_the_loads_balance() {
        // A long planned base shift on four feet (no leg stepping), the CoM over the
        // centre of the rectangle of feet (target warp zero). All the weight on front-right
        // and rear-left, a warp of −1: front-left and rear-right go down 0.25 m/s × 1 =
        // 2.5 mm per 10 ms tick, 1 cm in 4 ticks, though every wheel touches. Balanced
        // loads keep it; the weight on the other diagonal moves the centimetre to the
        // other diagonal in 4 ticks.
        let a = standing();
        let shift =
            vec![key(0.0, Phase::Start, None, &a), key(100.0, Phase::PlannedBaseShift, None, &a)];
        let mut ex = StepExecutor::new(&robot(), config(), shift, ground());
        let weight = robot().total_mass * 9.81;
        let contacts = all_contacts(&a.feet);
        let mut t = 0.0;
        let mut tick = |ex: &mut StepExecutor, loads: [f64; 4]| {
            t += 0.01;
            let mut o = obs(t, ex, &contacts, [0.0, 0.0, 0.4]);
            o.wheel_loads = loads.map(|f| f * weight);
            ex.tick(&o, 0.01);
            ex.foot_offset.map(|o| o[2])
        };
        let close = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let mut z = [0.0; 4];
        for _ in 0..4 {
            z = tick(&mut ex, [0.0, 0.5, 0.5, 0.0]);
        }
        assert!(matches!(ex.mode, Mode::Segment { .. }), "{:?}", ex.mode);
        assert!(close(z, [-0.01, 0.0, 0.0, -0.01]), "{z:?}");
        for _ in 0..10 {
            z = tick(&mut ex, [0.25; 4]);
        }
        assert!(close(z, [-0.01, 0.0, 0.0, -0.01]), "{z:?}");
        for _ in 0..4 {
            z = tick(&mut ex, [0.5, 0.0, 0.0, 0.5]);
        }
        assert!(close(z, [0.0, -0.01, -0.01, 0.0]), "{z:?}");
    }
}
