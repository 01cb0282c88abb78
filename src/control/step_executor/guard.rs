//! The lift margin guard: before a foot is lifted, the support margin measured from
//! MuJoCo must reach the lift threshold plus reserve (more per retry); if it does not, the
//! base is moved toward the support centroid in bounded increments (a base shift
//! longitudinally, a roll about the ground laterally: [`correction_roll`]) as far as the
//! planted legs reach (`StepExecutor::within_reach`), without the roll where the wheels
//! it tilts the pairs onto are predicted to lose margin (`StepExecutor::predicted_margin`).
//! Increments go on while they pay: the step is aborted after
//! `ExecutorConfig::max_correction_attempts` increments that each raised the measured
//! margin by less than [`MIN_CORRECTION_GAIN_M`] ([`Corrections`]), or when the legs'
//! reach or `ExecutorConfig::max_correction_m` leaves no increment. At the lift the
//! landing offset ([`landing_offset`]) of the swing foot is frozen.

use super::actuation::{REACH_SPARE_M, reach_excess, reachable_fraction};
use super::timing::smoothstep;
use super::{
    ActiveStep, Command, ExecEventKind, ExecFailure, Mode, Observation, StepExecutor, planar,
};
use crate::geometry::{Pose2, wrap_angle};
use crate::posture::kinematics::{Posture, rotation, wheel_support};
use crate::robot::Leg;
use crate::support::stability_margin;

/// The planar offset (m) to add to a world foothold `foothold` so that, with the robot
/// displaced from its commanded base `commanded` to the measured `measured`, a foot
/// commanded there relative to the commanded base lands on the foothold.
pub fn landing_offset(commanded: Pose2, measured: Pose2, foothold: [f64; 2]) -> [f64; 2] {
    let dth = wrap_angle(measured.theta - commanded.theta);
    let (s, c) = (-dth).sin_cos();
    let rel = [foothold[0] - measured.x, foothold[1] - measured.y];
    let p = [commanded.x + c * rel[0] - s * rel[1], commanded.y + s * rel[0] + c * rel[1]];
    [p[0] - foothold[0], p[1] - foothold[1]]
}

/// The roll that goes with a stabilising base offset `correction` (world x, y) of posture
/// `p`: the legs only move in their sagittal planes, so the base can move sideways over
/// planted feet only by rolling about the ground under it (as the roll of eqs. 6–8 does):
/// a lateral offset `lat` (along the base's y') at a height `h` of the base above the mean
/// ground of the feet in contact is a roll of −lat/h (roll positive: left side up).
pub fn correction_roll(p: &Posture, correction: [f64; 2]) -> f64 {
    let (s, c) = p.base_rpy[2].sin_cos();
    let lat = -s * correction[0] + c * correction[1];
    if lat == 0.0 {
        return 0.0;
    }
    let feet: Vec<f64> = (0..4).filter(|&i| p.contact[i]).map(|i| p.feet[i][2]).collect();
    let ground = if feet.is_empty() { 0.0 } else { feet.iter().sum::<f64>() / feet.len() as f64 };
    let h = (p.base_position[2] - ground).max(0.1);
    -lat / h
}

/// The fraction of a base correction the CoM follows: the base and the upper legs move
/// with it, the feet stay planted.
const CORRECTION_COM_FRACTION: f64 = 0.8;

/// The smallest correction increment worth making, m: below it the legs' reach has
/// stopped the base.
const MIN_CORRECTION_M: f64 = 0.002;

/// The smallest rise of the measured margin for which an increment counts as paying, m:
/// half of what the smallest increment moves the CoM ([`MIN_CORRECTION_M`] ·
/// [`CORRECTION_COM_FRACTION`]).
pub(super) const MIN_CORRECTION_GAIN_M: f64 = 0.5 * MIN_CORRECTION_M * CORRECTION_COM_FRACTION;

/// The increments the guard has made before a lift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Corrections {
    /// Increments made.
    pub made: usize,
    /// Increments after which the measured margin rose by less than
    /// [`MIN_CORRECTION_GAIN_M`]: a count that stops the guard where the CoM no longer
    /// follows the base, while a margin that rises slowly (measured on a rear step: 3.95,
    /// 4.65, 4.92 cm after three increments, 5 cm asked) is followed up.
    pub fruitless: usize,
    /// The margin measured at the last check, m (−∞ before the first).
    pub measured_m: f64,
}

impl Corrections {
    /// No increment yet.
    pub const NONE: Self = Self { made: 0, fruitless: 0, measured_m: f64::NEG_INFINITY };

    /// After a check that measured `margin_m`: whether the increment before it paid.
    fn checked(self, margin_m: f64) -> Self {
        let paid = self.made == 0 || margin_m - self.measured_m >= MIN_CORRECTION_GAIN_M;
        Self {
            made: self.made,
            fruitless: self.fruitless + usize::from(!paid),
            measured_m: margin_m,
        }
    }
}

impl StepExecutor {
    /// Starts the lift guard of keyframe `index` from its beginning: no wait yet, no
    /// correction attempted, the correction faded from where it stands, no low margin
    /// being timed.
    pub(super) fn start_guard(&mut self, index: usize) {
        // A low margin watched in an earlier segment is not this step's: a segment left
        // while it was low (a drift failure, a Place ended in the air) kept its start.
        self.low_margin_since = None;
        self.mode = Mode::Guard {
            index,
            wait: 0.0,
            corrections: Corrections::NONE,
            corr_from: self.correction,
        };
    }

    /// The correction on the way from `from` to `to` that goes furthest while no support
    /// leg in contact (all but `lifting`, whose foot leaves the ground anyway) asks more
    /// reach than it does at `from` (or than it has): a base moved over planted feet
    /// beyond a leg's reach would have that foot pulled in, off the ground, and the
    /// support the correction was meant to widen would shrink instead (measured on a step
    /// down: a rear wheel lifted, the margin fell from 2.6 cm to −24.5 cm).
    fn within_reach(&self, from: [f64; 2], to: [f64; 2], lifting: Leg) -> [f64; 2] {
        let excess = |c: [f64; 2]| {
            reach_excess(
                &self.robot,
                &self.with_correction(&self.cmd, c),
                REACH_SPARE_M,
                Some(lifting),
            )
        };
        let allowed = excess(from).max(0.0);
        let at = |a: f64| [from[0] + a * (to[0] - from[0]), from[1] + a * (to[1] - from[1])];
        let a = reachable_fraction(|a| excess(at(a)), allowed);
        if a >= 1.0 { to } else { at(a) }
    }

    /// The support margin predicted with the correction `c` and foot `lifting` up: the
    /// measured CoM `com` moves by [`CORRECTION_COM_FRACTION`] of the base's move from the
    /// current correction, and the support is the wheels the corrected posture stands on
    /// ([`wheel_support`]: rolled, each pair on its lower wheel). Compared with the
    /// current correction's prediction, it gives what a correction gains.
    fn predicted_margin(&self, com: [f64; 3], c: [f64; 2], lifting: Leg) -> f64 {
        let mut q = self.with_correction(&self.cmd, c);
        q.contact[lifting.index()] = false;
        let support = wheel_support(&self.robot, &rotation(q.base_rpy), &q);
        let f = CORRECTION_COM_FRACTION;
        let d = [c[0] - self.correction[0], c[1] - self.correction[1]];
        stability_margin(&support, [com[0] + f * d[0], com[1] + f * d[1]])
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn guard_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        index: usize,
        mut wait: f64,
        corrections: Corrections,
        corr_from: [f64; 2],
    ) -> Command {
        let time = obs.time;
        let leg = self.keys[index].leg.unwrap_or(Leg::FrontLeft);
        let c = self.config.clone();
        wait += dt;
        let ramp = if corrections.made == 0 { 1.0 } else { smoothstep(wait / c.correction_time_s) };
        let target = self.correction;
        let applied = [
            corr_from[0] + (target[0] - corr_from[0]) * ramp,
            corr_from[1] + (target[1] - corr_from[1]) * ramp,
        ];
        let p = self.with_correction(&self.cmd, applied);
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let ready =
            wait >= c.lift_settle_s + if corrections.made == 0 { 0.0 } else { c.correction_time_s };
        if !ready {
            self.mode = Mode::Guard { index, wait, corrections, corr_from };
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let m = obs.support_margin(leg);
        let planned_m = self.keys[index].margin_m;
        let required = c.min_lift_margin_m
            + c.lift_margin_reserve_m
            + self.retries as f64 * c.retry_margin_increment_m;
        if m >= required {
            self.event(time, ExecEventKind::Lift { leg, margin_m: m, planned_m });
            if self.retries == 0 {
                self.steps_started += 1;
            }
            self.active = Some(ActiveStep { number: self.steps_started, leg });
            self.lift_offset = self.foot_offset[leg.index()];
            // Landing: the drift of the measured base from the base the legs are solved
            // for (the position hold's included: with the base held 3 cm off its
            // keyframes, a foot aimed from the keyframes' base landed 3 cm off its
            // foothold), frozen now.
            let place = self.place_index(index);
            let foothold = self.keys[place].feet[leg.index()];
            let solved = planar(&self.held(&p));
            self.landing = landing_offset(solved, obs.base, [foothold[0], foothold[1]]);
            self.fading = None;
            self.start_segment(index);
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let corrections = corrections.checked(m);
        let centroid = obs.support_centroid(leg);
        let total = self.correction[0].hypot(self.correction[1]);
        if corrections.fruitless < c.max_correction_attempts
            && total < c.max_correction_m - 1e-6
            && let Some(cen) = centroid
        {
            let dir = [cen[0] - obs.com[0], cen[1] - obs.com[1]];
            let n = dir[0].hypot(dir[1]).max(1e-9);
            let want = (required + 0.01 - m) / CORRECTION_COM_FRACTION;
            let step = [want * dir[0] / n, want * dir[1] / n];
            // The same increment without its lateral part (no roll): a roll can tilt
            // the wheel pairs onto their lower wheels and narrow the support it meant to
            // widen.
            let (sy, cy) = self.cmd.base_rpy[2].sin_cos();
            let along = step[0] * cy + step[1] * sy;
            let from = self.correction;
            let now = self.predicted_margin(obs.com, from, leg);
            let best = [step, [along * cy, along * sy]]
                .into_iter()
                .map(|d| {
                    let mut next = [from[0] + d[0], from[1] + d[1]];
                    let len = next[0].hypot(next[1]);
                    if len > c.max_correction_m {
                        next = next.map(|v| v * c.max_correction_m / len);
                    }
                    let next = self.within_reach(from, next, leg);
                    (self.predicted_margin(obs.com, next, leg) - now, next)
                })
                .max_by(|a, b| a.0.total_cmp(&b.0));
            // Below the smallest increment the legs in contact reach no further, and a
            // correction predicted to lose margin does not help: the step cannot be
            // stabilised and is aborted below.
            if let Some((gain, next)) = best
                && gain > 0.0
                && (next[0] - from[0]).hypot(next[1] - from[1]) >= MIN_CORRECTION_M
            {
                self.correction = next;
                self.event(
                    time,
                    ExecEventKind::Correction {
                        leg,
                        margin_m: m,
                        correction_m: next[0].hypot(next[1]),
                    },
                );
                let corrections = Corrections { made: corrections.made + 1, ..corrections };
                self.mode = Mode::Guard { index, wait: 0.0, corrections, corr_from: from };
                return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
            }
        }
        self.steps_aborted += 1;
        self.fail(
            ExecFailure::StepAborted { leg, margin_m: m, required_m: required, planned_m },
            time,
        );
        Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::step_executor::test_support::{
        config, contacts_without, ground, obs, robot, standing, step_path,
    };
    use crate::control::step_executor::{ExecStatus, ExecutorConfig};

    #[test]
    fn a_lateral_correction_is_a_roll_about_the_ground() {
        // Base 0.5 m above flat ground facing +y (yaw 90°): a world offset of −0.05 m in x
        // is 0.05 m to the base's left, a roll of −0.05 / 0.5 = −0.1 rad (right side up);
        // an offset along the heading needs no roll.
        let mut p = standing();
        p.base_rpy[2] = std::f64::consts::FRAC_PI_2;
        assert!((correction_roll(&p, [-0.05, 0.0]) + 0.1).abs() < 1e-12);
        assert!(correction_roll(&p, [0.0, 0.03]).abs() < 1e-12);
        // Only the feet in contact set the ground: FL lifted to 0.1 m changes nothing.
        p.feet[0][2] = 0.1;
        p.contact[0] = false;
        assert!((correction_roll(&p, [-0.05, 0.0]) + 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_correction_stops_where_a_planted_leg_would_leave_the_ground() {
        // Standing 0.5 m high, every leg in contact: a 0.6 m shift of the base over the
        // planted feet asks the rear legs for more than thigh + shin (0.4 m still
        // reaches), and the actuation would pull those feet in, off the ground. The
        // correction stops where the furthest leg just reaches (on a step down a rear
        // wheel lifted this way and the margin fell from 2.6 to −24.5 cm).
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        ex.cmd = standing();
        let excess = |ex: &StepExecutor, c: [f64; 2]| {
            reach_excess(
                &ex.robot,
                &ex.with_correction(&ex.cmd, c),
                REACH_SPARE_M,
                Some(Leg::FrontLeft),
            )
        };
        assert!(excess(&ex, [0.0, 0.0]) < 0.0);
        assert!(excess(&ex, [0.6, 0.0]) > 0.0);
        let c = ex.within_reach([0.0, 0.0], [0.6, 0.0], Leg::FrontLeft);
        assert!(c[0] > 0.4 && c[0] < 0.6 && c[1] == 0.0, "{c:?}");
        assert!(excess(&ex, c) <= 0.0);
        assert!(excess(&ex, [c[0] + 0.001, 0.0]) > 0.0);
        // Within reach, the whole correction is taken.
        assert_eq!(ex.within_reach([0.0, 0.0], [0.02, 0.01], Leg::FrontLeft), [0.02, 0.01]);
    }

    #[test]
    fn landing_offset_undoes_the_drift() {
        // Pure translation: the robot stands 2 cm ahead and 1 cm left of its command; the
        // foot must be commanded 2 cm behind and 1 cm right of the foothold.
        let o = landing_offset(Pose2::new(1.0, 0.0, 0.0), Pose2::new(1.02, 0.01, 0.0), [1.4, 0.3]);
        assert!((o[0] + 0.02).abs() < 1e-12 && (o[1] + 0.01).abs() < 1e-12);
        // Pure rotation by +0.1 rad about the base: the foothold 0.4 m ahead is commanded
        // at 0.4·(cos 0.1, −sin 0.1) relative to the base.
        let o = landing_offset(Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.0, 0.0, 0.1), [0.4, 0.0]);
        assert!((o[0] - (0.4 * 0.1f64.cos() - 0.4)).abs() < 1e-12);
        assert!((o[1] + 0.4 * 0.1f64.sin()).abs() < 1e-12);
    }

    #[test]
    fn a_foot_lands_on_its_foothold_with_the_base_held_off_its_keyframes() {
        // The base stands 2 cm behind its keyframes (x = −0.02): the position hold
        // integrates, and at the lift the legs are solved for a base h ahead of the
        // keyframes while the base stands d = −0.02 m off them. A foot commanded at
        // foothold + L relative to the solved base lands at foothold + L − h + d: the
        // landing offset must be L = h − d (it was −d, the foot landing h off).
        let keys = step_path();
        let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
        let feet = keys[0].feet;
        let without_fl = contacts_without(&feet, Leg::FrontLeft);
        let com = [-0.1, -0.1, 0.4];
        let mut t = 0.0;
        while ex.active_step().is_none() && t < 2.0 {
            t += 0.01;
            let mut o = obs(t, &ex, &without_fl, com);
            o.base = Pose2::new(-0.02, 0.0, 0.0);
            ex.tick(&o, 0.01);
        }
        assert!(ex.active_step().is_some(), "no lift");
        let h = ex.base_hold;
        assert!(h[0] > 0.005 && h[1].abs() < 1e-12, "{h:?}");
        assert!((ex.landing[0] - (h[0] + 0.02)).abs() < 1e-9, "{:?} {h:?}", ex.landing);
        assert!(ex.landing[1].abs() < 1e-12);
    }

    /// An executor at the front-left step of [`step_path`] (corrections up to 0.2 m), and
    /// the wheel contacts of the other three feet.
    fn waiting_to_lift_front_left() -> (StepExecutor, Vec<(Leg, [f64; 2])>) {
        let keys = step_path();
        let cfg = ExecutorConfig { max_correction_m: 0.2, ..config() };
        let ex = StepExecutor::new(&robot(), cfg, keys.clone(), ground());
        (ex, contacts_without(&keys[0].feet, Leg::FrontLeft))
    }

    /// The point `d` inside the FR–RL diagonal of [`step_path`]'s stance (the line
    /// x = −y · 0.35 / 0.32 through the origin), on its normal through the origin.
    fn inside_fr_rl(d: f64) -> [f64; 2] {
        let n = [0.32f64, 0.35];
        let len = n[0].hypot(n[1]);
        [-d * n[0] / len, -d * n[1] / len]
    }

    #[test]
    fn an_increment_pays_when_the_margin_rises_by_the_smallest_gain() {
        // 0.5 · 2 mm · 0.8 = 0.8 mm.
        assert!((MIN_CORRECTION_GAIN_M - 0.0008).abs() < 1e-15);
        // The first check has nothing to compare with.
        let c = Corrections::NONE.checked(0.03);
        assert_eq!((c.fruitless, c.measured_m), (0, 0.03));
        let c = Corrections { made: 1, ..c };
        // 3.95 → 4.65 cm pays, 4.65 → 4.70 does not.
        let c = Corrections { measured_m: 0.0395, ..c }.checked(0.0465);
        assert_eq!(c.fruitless, 0);
        let c = c.checked(0.0470);
        assert_eq!((c.fruitless, c.measured_m), (1, 0.0470));
        // A margin that falls is fruitless too.
        assert_eq!(c.checked(0.0460).fruitless, 2);
    }

    #[test]
    fn increments_go_on_while_the_measured_margin_rises() {
        // The CoM starts 3 cm inside the FR–RL diagonal (3 cm measured, 5 cm asked) and
        // follows 30 % of the base's correction: each increment gains a few millimetres,
        // and three increments are not enough (the guard used to abort after three).
        let (mut ex, without_fl) = waiting_to_lift_front_left();
        let com0 = inside_fr_rl(0.03);
        let com = |ex: &StepExecutor| {
            [com0[0] + 0.3 * ex.correction[0], com0[1] + 0.3 * ex.correction[1], 0.4]
        };
        let mut t = 0.0;
        while ex.active_step().is_none() && ex.steps_aborted == 0 && t < 60.0 {
            t += 0.01;
            let o = obs(t, &ex, &without_fl, com(&ex));
            ex.tick(&o, 0.01);
        }
        let corrections: Vec<f64> = ex
            .events
            .iter()
            .filter_map(|e| match e.event {
                ExecEventKind::Correction { margin_m, .. } => Some(margin_m),
                _ => None,
            })
            .collect();
        assert!(ex.active_step().is_some(), "aborted after {corrections:?}");
        assert!(corrections.len() > 3, "{corrections:?}");
        // Each increment paid: the margin measured at the next check rose by at least
        // the smallest gain.
        for w in corrections.windows(2) {
            assert!(w[1] - w[0] >= MIN_CORRECTION_GAIN_M, "{corrections:?}");
        }
        let lift = ex.events.iter().find_map(|e| match e.event {
            ExecEventKind::Lift { margin_m, .. } => Some(margin_m),
            _ => None,
        });
        assert!(lift.is_some_and(|m| m >= 0.05), "{lift:?}");
    }

    #[test]
    fn a_low_margin_is_corrected_toward_the_centroid_then_the_step_is_aborted() {
        let (mut ex, without_fl) = waiting_to_lift_front_left();
        // The CoM 1 cm inside the FR–RL diagonal: a measured margin of 1 cm, below the
        // 2 cm (plus reserve) to lift. It does not move (the corrections have no effect
        // here), so after three corrections the step is aborted with the foot never lifted.
        let [x, y] = inside_fr_rl(0.01);
        let com = [x, y, 0.4];
        let o = obs(0.0, &ex, &without_fl, com);
        assert!((o.support_margin(Leg::FrontLeft) - 0.01).abs() < 1e-9);
        let mut t = 0.0;
        let mut status = ExecStatus::Running;
        for _ in 0..600 {
            t += 0.01;
            let (cmd, st) = ex.tick(&obs(t, &ex, &without_fl, com), 0.01);
            assert!(ex.active_step().is_none(), "lifted at {t}");
            // Stance wheels held until the abort (then the feet roll back to neutral).
            if ex.steps_aborted == 0 {
                assert!(cmd.wheels.iter().all(|w| w.wheel_speeds == [0.0, 0.0]));
            }
            status = st;
        }
        let corrections: Vec<f64> = ex
            .events
            .iter()
            .filter_map(|e| match e.event {
                ExecEventKind::Correction { correction_m, .. } => Some(correction_m),
                _ => None,
            })
            .collect();
        // The lift needs 2 + 3 (reserve) cm; each increment aims 1 cm above:
        // (0.05 + 0.01 − 0.01) / 0.8 = 6.25 cm toward the centroid, three of them. Its
        // lateral part would roll the base by about 0.1 rad and stand every wheel pair on
        // its lower wheel, 6 cm to the side, narrowing the support more than the CoM
        // gains: the base moves only along its heading (yaw 0: x), by the increment's x.
        let cen = o.support_centroid(Leg::FrontLeft).expect("three legs");
        let along = 0.0625 * (cen[0] - com[0]) / (cen[0] - com[0]).hypot(cen[1] - com[1]);
        assert_eq!(corrections.len(), 3, "{:?}", ex.events);
        for (k, c) in corrections.iter().enumerate() {
            assert!((c - along.abs() * (k + 1) as f64).abs() < 1e-9, "{corrections:?}");
        }
        assert_eq!(ex.steps_aborted, 1);
        assert!(
            matches!(
                status,
                ExecStatus::NeedsReplan(ExecFailure::StepAborted { leg: Leg::FrontLeft, .. })
            ),
            "{status:?}"
        );
    }
}
