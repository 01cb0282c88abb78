//! What the step executor exchanges with its caller (`closed_loop`): its tuning
//! ([`ExecutorConfig`]), what it sees each tick ([`Observation`]), the actuator targets it
//! returns ([`Command`]), its status ([`ExecStatus`]), why it left the plan
//! ([`ExecFailure`]) and the events it records for the run's summary ([`ExecEvent`]).

use crate::control::foot_contact::ContactConfirmConfig;
use crate::control::path_follower::FollowerConfig;
use crate::control::wheels::{WheelKinematics, WheelPairCommand};
use crate::geometry::Pose2;
use crate::params::Params;
use crate::posture::kinematics::support_centroid;
use crate::robot::Leg;
use crate::support::MonitorLimits;
use crate::support::stability_margin;
use serde::Serialize;

/// Gravity, m/s²: MuJoCo's default, which `models/momaro.xml` keeps.
pub(super) const STANDARD_GRAVITY: f64 = 9.81;

/// Tuning of the executor.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutorConfig {
    /// Support margin (CoM over the three support legs' contacts) required to lift a foot,
    /// m. From `Params::min_lift_margin_m` (2 cm).
    pub min_lift_margin_m: f64,
    /// Margin asked before a lift on top of `min_lift_margin_m`, m: when the foot unloads,
    /// the compliant support legs let the CoM sag toward it, so the margin during the step
    /// stays above the threshold only if it starts this much higher. From
    /// `Params::lift_margin_reserve_m` (3 cm), which the motion generator asks too.
    pub lift_margin_reserve_m: f64,
    /// With a foot in the air, a support margin below this for `emergency_hold_s` puts
    /// the foot down, m.
    pub emergency_margin_m: f64,
    /// How long the support margin must stay below `emergency_margin_m` before the foot
    /// is put down, s: the monitor's support memory plus its margin hold
    /// (`MonitorLimits::support_memory_s` + `MonitorLimits::margin_hold_s`, 0.08 s), so
    /// that a dip the monitor does not count as a loss of margin (a far support wheel
    /// bouncing as the foot unloads: measured on a steep climb, the front-left pair off
    /// the ground under 0.1 s as the rear-right foot lifted) does not put a foot down and
    /// make its step ask 3 cm more. A robot tipping from rest turns by about
    /// g·d/h² · t²/2, 5 mrad in that time for a CoM 5 cm out at 0.6 m.
    pub emergency_hold_s: f64,
    /// Time the posture is held before the margin is measured for a lift, s.
    pub lift_settle_s: f64,
    /// Integral gain of the base height hold during standing manoeuvres, 1/s. The leg
    /// joints are position servos (the model's kp): under the robot's weight the support
    /// legs give, most when one foot is lifted and three carry it, and the base sinks
    /// 1–2 cm below its keyframes. A lifted leg folds its knee under its hip as the
    /// foot passes below it, so a sunken base carries that knee into the step's edge the
    /// plan's leg clearance kept it from. The executor raises its commanded base by the
    /// integral of the measured shortfall, `lift += gain · (z_commanded − z_measured) · dt`,
    /// clamped to `[0, max_base_lift_m]`, until the base stands where the keyframes put it.
    pub base_hold_gain: f64,
    /// Largest base raise of the height hold, m.
    pub max_base_lift_m: f64,
    /// Largest planar offset of the base position hold, m. The same compliance that sinks
    /// the base lets it lag a standing manoeuvre, and stance wheels creep under the legs'
    /// push: after a base shift the base stood 4 cm beyond its keyframes and a rear
    /// thigh touched a stair nosing the plan cleared. During standing manoeuvres the
    /// executor offsets the base it solves the legs for, along its heading (the legs move
    /// in their sagittal planes), by the integral of the measured error along it,
    /// `hold += base_hold_gain · (reference − measured) · heading · dt`, the reference
    /// being the keyframes' base with the stabilising correction, clamped to this length.
    pub max_base_hold_m: f64,
    /// Stance offset from the plan's footholds beyond which the robot rolls back onto
    /// them before a step, m (`step_executor::slide`): half a cell of the height map
    /// (`Params::grid_resolution_m` / 2), what one planned base shift's end cell moves the
    /// footprint sideways at most. A stance off by more has gathered more than one shift's
    /// rounding, and is rolled back while a roll still fits: on a tread a pair steered to
    /// roll sideways swings its wheels along the fall line, and the further the stance
    /// must go sideways, the longer the rolls. At one cell, a 14-step descent (0.17 m on
    /// 0.28 m) planned 5.6° off the fall line had its sideways slides refused from 2 cm
    /// on, drifted 14 cm to the side of its plan and left it two steps from the bottom;
    /// at half a cell it descends (smallest margin 4.5 cm).
    pub slide_threshold_m: f64,
    /// Fastest stance slide, m/s.
    pub slide_speed_mps: f64,
    /// Longest stance slide, s: time to steer the pairs and roll a few centimetres; what
    /// a slide has not taken back by then is left to the next step's.
    pub max_slide_s: f64,
    /// Largest stabilising base correction toward the support centroid, m.
    pub max_correction_m: f64,
    /// Time over which a correction increment is applied, s.
    pub correction_time_s: f64,
    /// Correction increments that do not pay (each raising the measured margin by less
    /// than `guard::MIN_CORRECTION_GAIN_M`, 0.8 mm) before a step is aborted; increments
    /// that pay go on up to `max_correction_m`.
    pub max_correction_attempts: usize,
    /// Retries of a step whose foot had to be put down.
    pub max_step_retries: usize,
    /// Extra margin required to lift per retry of a step, m: the margin lost when the
    /// foot unloaded last time must be made up by more correction.
    /// (The lift needs `min_lift_margin_m + lift_margin_reserve_m + retries · this`.)
    pub retry_margin_increment_m: f64,
    /// Measured base farther than this from the commanded one (planar) needs a replan, m.
    pub drift_tolerance_m: f64,
    /// Measured heading farther than this from the commanded one needs a replan, rad.
    pub drift_tolerance_rad: f64,
    /// Joint tracking error from which the segment clock slows down, rad.
    pub slowdown_start_rad: f64,
    /// Joint tracking error at which the segment clock runs at its slowest, rad.
    pub slowdown_full_rad: f64,
    /// Slowest segment clock rate (fraction of real time).
    pub slowest_rate: f64,
    /// Joint tracking error below which a finished segment counts as reached, rad.
    pub settle_tolerance_rad: f64,
    /// Longest wait for the servos at a segment's end, s.
    pub max_settle_s: f64,
    /// Speed of a foot put down in an emergency, m/s.
    pub put_down_speed_mps: f64,
    /// Base and foot speed of the return to the driving posture, m/s.
    pub recover_speed_mps: f64,
    /// Angular speed of the return to the driving posture, rad/s.
    pub recover_angular_speed: f64,
    /// Driving leg height for the return to the driving posture, m.
    pub driving_leg_height_m: f64,
    /// Base pitch as a fraction of the slope (Sec. VI-B).
    pub pitch_fraction: f64,
    /// Speed at which a leg whose wheels have lost the ground is extended while standing,
    /// for the legs a standing manoeuvre plans in contact (`StepExecutor::comply_stance`),
    /// m/s.
    pub leg_extend_speed_mps: f64,
    /// Speed at which a drive run gives back the extension all four legs share, m/s.
    pub leg_release_speed_mps: f64,
    /// Load sharing on four feet ([`crate::control::load_sharing`]; drive runs and
    /// standing, `StepExecutor::share_load`): the speed at which the legs of the diagonal
    /// that carries less than its share of the weight lengthen (and the other diagonal's
    /// shorten back), per unit of warp error (the fraction of the weight on the wrong
    /// diagonal), m/s.
    pub load_sharing_gain_mps: f64,
    /// Largest extension of a leg below its keyframe (driving or standing), m.
    pub max_leg_extension_m: f64,
    /// Fastest rise or fall of a drive run's base with the ground under its wheels, m/s
    /// (`drive`): `√(2 g h)` for h = 1 mm, the speed at which a base whose rise stopped
    /// at once would carry its wheels 1 mm off the ground.
    pub base_rise_speed_mps: f64,
    /// Contact confirmation of a placed foot.
    pub contact: ContactConfirmConfig,
    /// The path follower of drive runs.
    pub follower: FollowerConfig,
    /// Wheel kinematics of drive runs.
    pub wheels: WheelKinematics,
}

impl ExecutorConfig {
    /// The defaults with the paper's and the scenario's constants from `params`.
    pub fn from_params(params: &Params, follower: FollowerConfig) -> Self {
        Self {
            min_lift_margin_m: params.min_lift_margin_m,
            lift_margin_reserve_m: params.lift_margin_reserve_m,
            emergency_margin_m: params.min_lift_margin_m / 2.0,
            emergency_hold_s: {
                let monitor = MonitorLimits::default();
                monitor.support_memory_s + monitor.margin_hold_s
            },
            lift_settle_s: 0.3,
            base_hold_gain: 2.0,
            max_base_lift_m: 0.04,
            max_base_hold_m: 0.04,
            slide_threshold_m: params.grid_resolution_m / 2.0,
            slide_speed_mps: 0.03,
            max_slide_s: 5.0,
            max_correction_m: 0.06,
            correction_time_s: 0.8,
            max_correction_attempts: 3,
            max_step_retries: 2,
            retry_margin_increment_m: 0.03,
            drift_tolerance_m: 0.15,
            drift_tolerance_rad: 0.25,
            slowdown_start_rad: 0.05,
            slowdown_full_rad: 0.2,
            slowest_rate: 0.2,
            settle_tolerance_rad: 0.03,
            max_settle_s: 1.5,
            put_down_speed_mps: 0.25,
            recover_speed_mps: 0.1,
            recover_angular_speed: 0.2,
            driving_leg_height_m: params.driving_leg_height_m,
            pitch_fraction: params.base_pitch_slope_fraction,
            leg_extend_speed_mps: 0.05,
            leg_release_speed_mps: 0.01,
            load_sharing_gain_mps: 0.25,
            max_leg_extension_m: 0.03,
            base_rise_speed_mps: (2.0 * STANDARD_GRAVITY * 0.001).sqrt(),
            contact: ContactConfirmConfig::default(),
            follower,
            wheels: WheelKinematics::default(),
        }
    }
}

/// What the executor sees each tick.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// Simulated time, s.
    pub time: f64,
    /// Measured planar base pose.
    pub base: Pose2,
    /// Measured base height, m: what the support legs' kinematics (and an IMU) give.
    /// `None` without it; the base height is then not held (`ExecutorConfig::base_hold_gain`).
    pub base_z: Option<f64>,
    /// Measured hip, knee, ankle angles per leg, rad.
    pub joints: [[f64; 3]; 4],
    /// Measured steering angles, rad.
    pub steering: [f64; 4],
    /// Measured steering rates, rad/s.
    pub steering_rate: [f64; 4],
    /// Whole-robot CoM, m.
    pub com: [f64; 3],
    /// Horizontal contact points of the wheels touching terrain, with their legs: what
    /// confirms a placed foot, and what the stance compliance and the slide go by.
    pub wheel_contacts: Vec<(Leg, [f64; 2])>,
    /// Horizontal contact points of the wheels that support the robot as the monitor
    /// counts them (within [`crate::support::MonitorLimits::support_gap_m`] of the terrain,
    /// a superset of `wheel_contacts`): the support margins are taken over these, so the
    /// executor's margin is the monitor's.
    pub support_contacts: Vec<(Leg, [f64; 2])>,
    /// Normal load on each leg's wheel pair, N (MuJoCo's contact forces); all zero where
    /// nothing measures them.
    pub wheel_loads: [f64; 4],
}

impl Observation {
    /// Whether a wheel of `leg` touches terrain.
    pub fn leg_in_contact(&self, leg: Leg) -> bool {
        self.wheel_contacts.iter().any(|(l, _)| *l == leg)
    }

    /// Margin of the CoM over the support contacts of every leg but `lifted`, m.
    pub fn support_margin(&self, lifted: Leg) -> f64 {
        stability_margin(&self.supports_without(lifted), [self.com[0], self.com[1]])
    }

    /// Centroid of the support contacts of every leg but `lifted` (vertex mean of their
    /// hull).
    pub fn support_centroid(&self, lifted: Leg) -> Option<[f64; 2]> {
        support_centroid(&self.supports_without(lifted))
    }

    fn supports_without(&self, lifted: Leg) -> Vec<[f64; 2]> {
        self.support_contacts.iter().filter(|(l, _)| *l != lifted).map(|(_, p)| *p).collect()
    }
}

/// Actuator targets of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Hip, knee, ankle position targets per leg, rad.
    pub legs: [[f64; 3]; 4],
    /// Steering and wheel speed targets per leg.
    pub wheels: [WheelPairCommand; 4],
}

/// Why the executor stopped following the plan.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ExecFailure {
    /// The support margin stayed below the lift threshold after the corrections.
    #[error(
        "step of {leg:?} aborted: support margin {margin_m:.3} m below {required_m:.3} m (planned {planned_m:.3} m)"
    )]
    StepAborted {
        /// The stepping leg.
        leg: Leg,
        /// Margin measured at the last check, m.
        margin_m: f64,
        /// Required margin, m.
        required_m: f64,
        /// The margin the plan gives the step's lift keyframe, m.
        planned_m: f64,
    },
    /// A foot found no contact within the extra lowering (after placing: below the
    /// foothold; when put down: below where it was put down from).
    #[error("step of {leg:?} failed: no contact after lowering the foot {extra_m:.3} m")]
    NoContact {
        /// The leg.
        leg: Leg,
        /// Extra lowering tried, m.
        extra_m: f64,
    },
    /// The robot drifted from the plan.
    #[error("drifted {distance_m:.3} m / {heading_rad:.3} rad from the plan")]
    Drift {
        /// Planar distance, m.
        distance_m: f64,
        /// Heading difference, rad.
        heading_rad: f64,
    },
    /// A posture could not be solved.
    #[error("leg IK: {message}")]
    Ik {
        /// The solver's message.
        message: String,
    },
    /// The path follower rejected a drive run.
    #[error("path follower: {message}")]
    Follower {
        /// The follower's message.
        message: String,
    },
}

/// What the executor is doing after a tick.
#[derive(Debug, Clone, PartialEq)]
pub enum ExecStatus {
    /// Executing the path.
    Running,
    /// The last keyframe is reached.
    Finished,
    /// The plan was left (see the failure); the robot stands in the driving posture and
    /// needs a new plan.
    NeedsReplan(ExecFailure),
    /// The plan was left (see the failure) where the robot cannot return to the driving
    /// posture: a foot's way back to the neutral footprint would roll its wheels over a
    /// height change no drive may cross (an edge mid-staircase), or a foot of that posture
    /// is off the known map. The robot holds its stance; no plan (which starts from the driving
    /// posture) can start here.
    Stranded {
        /// Why the plan was left.
        failure: ExecFailure,
        /// Why the robot cannot return to the driving posture.
        reason: Stranding,
    },
}

/// Why the robot cannot return to the driving posture after leaving a plan.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Stranding {
    /// A wheel would meet an edge on its foot's way back to the neutral footprint.
    #[error(
        "{leg:?}'s way back to the driving posture rolls its wheels over a {height_change_m:.3} m height change (at most {allowed_m:.3} m)"
    )]
    Edge {
        /// The leg.
        leg: Leg,
        /// Height range over which a wheel of the pair rests along the foot's way, m.
        height_change_m: f64,
        /// The most a driving wheel meets, m.
        allowed_m: f64,
    },
    /// A foot of the driving posture at the robot's pose stands where the map knows no
    /// height.
    #[error("a foot of the driving posture, at ({:.2}, {:.2}), is off the known map", at[0], at[1])]
    OffMap {
        /// Where the foot would stand, m.
        at: [f64; 2],
    },
}

/// Something the executor did, for the run's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ExecEventKind {
    /// The margin check passed and the foot is lifted.
    Lift {
        /// The leg.
        leg: Leg,
        /// Support margin measured before lifting, m.
        margin_m: f64,
        /// The margin the plan gives the lift keyframe (the motion generator's CoM over
        /// the three planned support feet), m: beside `margin_m`, how far the plan's
        /// estimate is from MuJoCo's measure.
        planned_m: f64,
    },
    /// Before a step the feet stood this far from the plan's footholds, and the robot
    /// rolled back onto them (`step_executor::slide`).
    Slide {
        /// The stance's offset measured from the wheel contacts (its feet's centroid), m.
        offset_m: f64,
        /// How far the stance is turned from the plan (counter-clockwise), rad.
        yaw_rad: f64,
        /// How far the slide moves the base, m.
        slid_m: f64,
        /// How far the slide turns it, rad.
        turned_rad: f64,
        /// In how many rolls: the turn alone first where the pairs cannot steer to the
        /// whole of it, and the shift in two where they cannot steer straight back but
        /// can at a smaller angle (forward, then backward, or the other way).
        rolls: usize,
    },
    /// Before a step the feet stood more than a cell from the plan's footholds, but no
    /// roll back keeps every pair on the ground it stands on (narrow treads: a pair
    /// steered across puts a wheel over the nosing), and the part along the heading is
    /// within a cell: the step goes ahead from where the stance is.
    SlideRefused {
        /// The stance's offset measured from the wheel contacts (its feet's centroid), m.
        offset_m: f64,
        /// Its part across the heading (positive: to the robot's left), m.
        lateral_m: f64,
        /// How far the stance is turned from the plan (counter-clockwise), rad.
        yaw_rad: f64,
    },
    /// A stabilising base correction toward the support centroid.
    Correction {
        /// The stepping leg.
        leg: Leg,
        /// Support margin measured, m.
        margin_m: f64,
        /// Total correction now commanded, m.
        correction_m: f64,
    },
    /// The placed foot touches the terrain: the step is done.
    StepExecuted {
        /// The leg.
        leg: Leg,
        /// Extra lowering needed for contact, m.
        extra_m: f64,
    },
    /// A foot in the air was put down because the support margin fell.
    FootPutDown {
        /// The leg.
        leg: Leg,
        /// Margin that triggered it, m.
        margin_m: f64,
    },
    /// The plan was left.
    Failure {
        /// Why.
        failure: ExecFailure,
    },
}

/// A timed [`ExecEventKind`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExecEvent {
    /// Simulated time, s.
    pub time_s: f64,
    /// What happened.
    pub event: ExecEventKind,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn support_margins_count_the_wheels_the_monitor_counts() {
        // Feet at (±0.35, ±0.32), each pair on its outer wheel (y = ±0.40), the inner
        // wheels (y = ±0.24) 1.2 mm up, as on a rolled base: touching, only the outer
        // wheels; within the monitor's 4 mm support gap, the inner ones too. CoM at the
        // origin, front-left lifted. Over the outer wheels of FR, RL and RR the hull edge
        // from RL (−0.35, 0.40) to FR (0.35, −0.40) passes through the origin: margin 0.
        // With the inner wheels the edge runs from RL's outer (−0.35, 0.40) to FR's inner
        // wheel (0.35, −0.24), direction (0.7, −0.64): the origin is
        // |(−0.35)(−0.64) − 0.40 · 0.7| / |(0.7, −0.64)| = 0.056 / 0.9485 = 5.9 cm inside,
        // which is 0.08 · 0.35 / |(0.35, 0.32)|.
        let outer = |l: Leg, x: f64, y: f64| (l, [x, y + y.signum() * 0.08]);
        let inner = |l: Leg, x: f64, y: f64| (l, [x, y - y.signum() * 0.08]);
        let feet = [
            (Leg::FrontLeft, 0.35, 0.32),
            (Leg::FrontRight, 0.35, -0.32),
            (Leg::RearLeft, -0.35, 0.32),
            (Leg::RearRight, -0.35, -0.32),
        ];
        let touching: Vec<_> = feet.iter().map(|&(l, x, y)| outer(l, x, y)).collect();
        let mut within_gap = touching.clone();
        within_gap.extend(feet.iter().map(|&(l, x, y)| inner(l, x, y)));
        let obs = Observation {
            time: 0.0,
            base: Pose2::new(0.0, 0.0, 0.0),
            base_z: None,
            joints: [[0.0; 3]; 4],
            steering: [0.0; 4],
            steering_rate: [0.0; 4],
            com: [0.0, 0.0, 0.4],
            wheel_contacts: touching,
            support_contacts: within_gap,
            wheel_loads: [0.0; 4],
        };
        let expected = 0.08 * 0.35 / 0.35f64.hypot(0.32);
        let m = obs.support_margin(Leg::FrontLeft);
        assert!((m - expected).abs() < 1e-12, "{m} vs {expected}");
        let only_touching = Observation { support_contacts: obs.wheel_contacts.clone(), ..obs };
        assert!(only_touching.support_margin(Leg::FrontLeft).abs() < 1e-12);
    }

    #[test]
    fn every_failure_serialises_in_an_event() {
        // serde cannot write a tagged newtype variant holding a string: `run --json` once
        // failed on an IK failure with "cannot serialize tagged newtype variant".
        for failure in [
            ExecFailure::Ik { message: "knee".into() },
            ExecFailure::Follower { message: "path".into() },
        ] {
            let e = ExecEvent { time_s: 1.0, event: ExecEventKind::Failure { failure } };
            let v = serde_json::to_value(&e).expect("serialises");
            assert!(v["event"]["failure"]["message"].is_string(), "{v}");
        }
    }
}
