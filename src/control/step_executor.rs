//! The closed-loop step executor (issue 7): executes a detailed path's keyframes
//! (`motion::DetailedPath`, Sec. VI) on the robot, one control tick at a time.
//!
//! A pure state machine: each tick it takes an [`Observation`] (measured base pose,
//! joints, steering, MuJoCo's CoM and the wheels MuJoCo reports touching terrain) and
//! returns actuator targets ([`Command`]). The simulation loop lives in `jobs::run`.
//!
//! - **Drive** runs (consecutive [`Phase::Drive`] keyframes) go to the B-spline
//!   [`PathFollower`] (Sec. IX) and the omnidirectional wheel kinematics; the legs hold the
//!   keyframes' posture interpolated at the robot's progress. The follower stops at the run's
//!   end (within its 2 cm / 2° goal tolerance) and stepping starts at once.
//! - **Other segments** track the linear interpolation between keyframes with a smoothstep
//!   time law over the generator's keyframe time (longer if the servos lag): leg joint
//!   targets from the sagittal IK of the interpolated posture (base height, roll, pitch,
//!   feet). A foot moved along the ground in contact (wheel to centre, wheel back, wheel
//!   moves) rolls its pair at the foot's world speed over the wheel radius, steering
//!   straight. Stance wheels need no spin (the ankle keeps a planted wheel level); since
//!   the wheel actuators are velocity servos, a stance pair holds its wheel angles with a
//!   proportional loop so the foot does not creep under the legs' horizontal forces.
//! - **Before a lift** the support margin measured from MuJoCo (CoM over the wheel
//!   contacts of the three support legs) must reach [`ExecutorConfig::min_lift_margin_m`]
//!   (2 cm) plus a reserve for the sag of the compliant support legs when the foot unloads
//!   ([`ExecutorConfig::lift_margin_reserve_m`]). If it does not, the base is moved toward
//!   the support triangle's centroid in bounded increments: longitudinally by a base shift,
//!   laterally by a roll about the ground ([`correction_roll`]; the legs move only in their
//!   sagittal planes). If that does not suffice, the step is aborted (the foot is not
//!   lifted).
//! - **While a foot is in the air** the support margin is watched; below
//!   [`ExecutorConfig::emergency_margin_m`] the foot is put down where it is (lowered until
//!   MuJoCo reports contact), and the step is retried from the lift (bounded).
//! - **Swing foot landing**: the planar drift of the measured base from the commanded one,
//!   frozen at the lift, is taken out of the foothold, so the foot lands on the world
//!   foothold rather than on the plan's.
//! - **Placing**: after the place keyframe, weight goes back onto the foot only when
//!   MuJoCo reports contact ([`ContactConfirm`]: the foot is lowered a bounded extra
//!   distance; no contact fails the step).
//! - **Failures** (step aborted or failed, drift beyond tolerance, IK): a lifted foot is put
//!   down, the robot returns to the driving posture at its pose (feet rolled to the
//!   neutral footprint) and the executor reports [`ExecStatus::NeedsReplan`].
//!
//! Postures are kept in the plan's coordinates; only the relative geometry of base and
//! feet reaches the joints, so a small planar offset of the whole robot from the plan does
//! not disturb stepping.

use super::foot_contact::{ContactConfirm, ContactConfirmConfig, ContactStatus};
use super::path_follower::{FollowerConfig, FollowerStatus, PathFollower};
use super::wheels::{WheelKinematics, WheelPairCommand};
use crate::geometry::{Pose2, wrap_angle};
use crate::motion::kinematics::support_centroid;
use crate::motion::kinematics::{Posture, contacts_in_base, driving_posture, interpolate};
use crate::motion::{Keyframe, Phase};
use crate::params::Params;
use crate::robot::ik::{IkError, leg_ik};
use crate::robot::{Leg, RobotDescription};
use crate::stability::stability_margin;
use crate::terrain::HeightMap;
use serde::Serialize;

/// Tuning of the executor.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutorConfig {
    /// Support margin (CoM over the three support legs' contacts) required to lift a foot,
    /// m. From `Params::min_lift_margin_m` (2 cm).
    pub min_lift_margin_m: f64,
    /// Margin asked before a lift on top of `min_lift_margin_m`, m: when the foot unloads,
    /// the compliant support legs let the CoM sag toward it (measured in MuJoCo: 2.5–3 cm
    /// on the platform's and the staircase's front steps up), so the margin during the step
    /// stays above the threshold only if it starts this much higher.
    pub lift_margin_reserve_m: f64,
    /// With a foot in the air, a support margin below this puts the foot down, m.
    pub emergency_margin_m: f64,
    /// Time the posture is held before the margin is measured for a lift, s.
    pub lift_settle_s: f64,
    /// Gain of the stance wheels' angle hold (speed command per rad of creep), 1/s.
    pub wheel_hold_gain: f64,
    /// Largest stabilising base correction toward the support centroid, m.
    pub max_correction_m: f64,
    /// Time over which a correction increment is applied, s.
    pub correction_time_s: f64,
    /// Correction increments tried before a step is aborted.
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
            lift_margin_reserve_m: 0.03,
            emergency_margin_m: params.min_lift_margin_m / 2.0,
            lift_settle_s: 0.3,
            wheel_hold_gain: 5.0,
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
    /// Measured hip, knee, ankle angles per leg, rad.
    pub joints: [[f64; 3]; 4],
    /// Measured steering angles, rad.
    pub steering: [f64; 4],
    /// Measured steering rates, rad/s.
    pub steering_rate: [f64; 4],
    /// Measured wheel angles (left, right) per leg, rad.
    pub wheel_angles: [[f64; 2]; 4],
    /// Whole-robot CoM, m.
    pub com: [f64; 3],
    /// Horizontal contact points of the wheels touching terrain, with their legs.
    pub wheel_contacts: Vec<(Leg, [f64; 2])>,
}

impl Observation {
    /// Whether a wheel of `leg` touches terrain.
    pub fn leg_in_contact(&self, leg: Leg) -> bool {
        self.wheel_contacts.iter().any(|(l, _)| *l == leg)
    }

    /// Margin of the CoM over the contacts of every leg but `lifted`, m.
    pub fn support_margin(&self, lifted: Leg) -> f64 {
        let pts: Vec<[f64; 2]> =
            self.wheel_contacts.iter().filter(|(l, _)| *l != lifted).map(|(_, p)| *p).collect();
        stability_margin(&pts, [self.com[0], self.com[1]])
    }

    /// Centroid of the contacts of every leg but `lifted` (vertex mean of their hull).
    pub fn support_centroid(&self, lifted: Leg) -> Option<[f64; 2]> {
        let pts: Vec<[f64; 2]> =
            self.wheel_contacts.iter().filter(|(l, _)| *l != lifted).map(|(_, p)| *p).collect();
        support_centroid(&pts)
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
    #[error("step of {leg:?} aborted: support margin {margin_m:.3} m below {required_m:.3} m")]
    StepAborted {
        /// The stepping leg.
        leg: Leg,
        /// Margin measured at the last check, m.
        margin_m: f64,
        /// Required margin, m.
        required_m: f64,
    },
    /// A foot found no contact within the extra lowering.
    #[error("step of {leg:?} failed: no contact {extra_m:.3} m below the foothold")]
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
    #[error("leg IK: {0}")]
    Ik(String),
    /// The path follower rejected a drive run.
    #[error("path follower: {0}")]
    Follower(String),
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

/// `3s² − 2s³` on [0, 1]: zero velocity at both ends.
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// d smoothstep / ds.
pub fn smoothstep_rate(s: f64) -> f64 {
    if !(0.0..=1.0).contains(&s) {
        return 0.0;
    }
    6.0 * s * (1.0 - s)
}

/// Wheel speed (rad/s) that rolls a pair steered straight along a base heading `yaw` at
/// the foot's world velocity `v` (only the component along the heading can roll).
pub fn rolling_wheel_speed(robot: &RobotDescription, v: [f64; 2], yaw: f64) -> f64 {
    let (s, c) = yaw.sin_cos();
    (c * v[0] + s * v[1]) / robot.wheel_radius
}

/// Segment clock rate for a joint tracking error `err` (rad): 1 up to `start`, falling
/// linearly to `slowest` at `full`.
pub fn clock_rate(err: f64, start: f64, full: f64, slowest: f64) -> f64 {
    if err <= start {
        1.0
    } else if err >= full {
        slowest
    } else {
        1.0 - (1.0 - slowest) * (err - start) / (full - start)
    }
}

/// Time to move from `a` to `b` at `speed` (m/s, base and feet) and `angular` (rad/s).
pub fn motion_duration(a: &Posture, b: &Posture, speed: f64, angular: f64) -> f64 {
    let d = |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]);
    let lin =
        (0..4).map(|i| d(a.feet[i], b.feet[i])).fold(d(a.base_position, b.base_position), f64::max);
    let ang = (0..3).map(|k| wrap_angle(b.base_rpy[k] - a.base_rpy[k]).abs()).fold(0.0, f64::max);
    (lin / speed).max(ang / angular).max(0.1)
}

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

/// Spare reach the executor keeps when it has to pull a foot in, m.
const REACH_SPARE_M: f64 = 0.001;

/// Joint targets for `p` like `motion::kinematics::leg_joint_targets`, except that a foot
/// beyond a leg's reach is pulled toward its hip (along the hip–ankle line) until the leg
/// has `spare` m of reach left: the executor's corrections (landing offset, stabilising
/// shift) may ask a few millimetres more than a posture planned at the reach limit has.
///
/// # Errors
/// [`IkError`] for a joint limit or non-finite input.
pub fn reachable_leg_targets(
    robot: &RobotDescription,
    p: &Posture,
    spare: f64,
) -> Result<[[f64; 3]; 4], IkError> {
    let local = contacts_in_base(robot, p);
    let pitch = p.base_rpy[1];
    let below = robot.foot_length + robot.wheel_radius;
    let reach = robot.thigh_length + robot.shin_length - spare;
    // World down in the base frame (the foot segment's direction), as `leg_ik` uses it.
    let down = [pitch.sin(), -pitch.cos()];
    let mut q = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let c = local[leg.index()];
        let mut contact = [c[0], c[2]];
        let ankle = [contact[0] - below * down[0], contact[1] - below * down[1]];
        let d = ankle[0].hypot(ankle[1]);
        if d > reach {
            let k = reach / d;
            contact = [ankle[0] * k + below * down[0], ankle[1] * k + below * down[1]];
        }
        q[leg.index()] = leg_ik(robot, leg, contact, pitch)?;
    }
    Ok(q)
}

fn planar(p: &Posture) -> Pose2 {
    Pose2::new(p.base_position[0], p.base_position[1], p.base_rpy[2])
}

fn straight(speed: f64) -> WheelPairCommand {
    WheelPairCommand { steer: 0.0, wheel_speeds: [speed, speed] }
}

/// What follows a foot put down.
#[derive(Debug, Clone, PartialEq)]
enum AfterPutDown {
    /// Retry the step from its lift keyframe.
    Retry(usize),
    /// Return to the driving posture and stop.
    Recover(ExecFailure),
}

#[derive(Debug, Clone)]
enum Mode {
    Drive { follower: Box<PathFollower>, first: usize, last: usize },
    Segment { from: Posture, index: usize, elapsed: f64, duration: f64, settle: f64 },
    Guard { index: usize, wait: f64, attempts: usize, corr_from: [f64; 2] },
    Confirm { index: usize, confirm: ContactConfirm },
    PutDown { leg: Leg, lowered: f64, floor: f64, confirm: ContactConfirm, then: AfterPutDown },
    Recover { from: Posture, to: Posture, elapsed: f64, duration: f64, failure: ExecFailure },
    Finished,
    Stopped(ExecFailure),
}

/// A step in progress: from the lift to the confirmed contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActiveStep {
    /// 1-based number of the step in the path.
    pub number: usize,
    /// The stepping leg.
    pub leg: Leg,
}

/// Executes one detailed path (see the module docs).
#[derive(Debug, Clone)]
pub struct StepExecutor {
    robot: RobotDescription,
    config: ExecutorConfig,
    keys: Vec<Keyframe>,
    ground: HeightMap,
    mode: Mode,
    /// The last commanded posture (plan coordinates, without offsets or correction).
    cmd: Posture,
    /// Per-leg foot offsets (plan coordinates): landing corrections and extra lowering.
    foot_offset: [[f64; 3]; 4],
    /// Stabilising base correction (plan coordinates), m.
    correction: [f64; 2],
    /// The correction at the start of the segment that fades it out.
    fading: Option<[f64; 2]>,
    /// Foot offset of the stepping leg when its lift began (faded out during the lift).
    lift_offset: [f64; 3],
    /// Landing offset of the current step.
    landing: [f64; 2],
    last_legs: [[f64; 3]; 4],
    /// Wheel angles the stance wheels hold (None: not holding), rad.
    wheel_hold: [Option<[f64; 2]>; 4],
    now: f64,
    retries: usize,
    steps_started: usize,
    active: Option<ActiveStep>,
    /// Steps whose placed foot was confirmed in contact.
    pub steps_executed: usize,
    /// Steps aborted before lifting (margin) or failed.
    pub steps_aborted: usize,
    /// What happened, in time order.
    pub events: Vec<ExecEvent>,
}

impl StepExecutor {
    /// An executor for `keys` (the keyframes of a detailed path, starting with its start
    /// keyframe), with the height map `ground` for the return to the driving posture.
    pub fn new(
        robot: &RobotDescription,
        config: ExecutorConfig,
        keys: Vec<Keyframe>,
        ground: HeightMap,
    ) -> Self {
        let cmd = keys.first().map_or(
            Posture {
                base_position: [0.0; 3],
                base_rpy: [0.0; 3],
                feet: [[0.0; 3]; 4],
                contact: [true; 4],
            },
            Keyframe::posture,
        );
        let last_legs = keys.first().map_or([[0.0; 3]; 4], |k| k.joints);
        let mut ex = Self {
            robot: robot.clone(),
            config,
            keys,
            ground,
            mode: Mode::Finished,
            cmd,
            foot_offset: [[0.0; 3]; 4],
            correction: [0.0; 2],
            fading: None,
            lift_offset: [0.0; 3],
            landing: [0.0; 2],
            last_legs,
            wheel_hold: [None; 4],
            now: 0.0,
            retries: 0,
            steps_started: 0,
            active: None,
            steps_executed: 0,
            steps_aborted: 0,
            events: Vec::new(),
        };
        ex.advance(1, 0.0);
        ex
    }

    /// The step in progress (lift to confirmed contact), if any.
    pub fn active_step(&self) -> Option<ActiveStep> {
        self.active
    }

    /// Index of the keyframe being worked toward (the path's length when finished).
    pub fn keyframe_index(&self) -> usize {
        match &self.mode {
            Mode::Drive { first, .. } => *first,
            Mode::Segment { index, .. }
            | Mode::Guard { index, .. }
            | Mode::Confirm { index, .. } => *index,
            _ => self.keys.len(),
        }
    }

    /// The commanded planar base pose (plan coordinates, with the stabilising correction).
    pub fn commanded_base(&self) -> Pose2 {
        let p = self.with_offsets(&self.cmd);
        planar(&p)
    }

    /// The phase of the keyframe being worked toward, if any.
    pub fn phase(&self) -> Option<Phase> {
        self.keys.get(self.keyframe_index()).map(|k| k.phase)
    }

    /// The commanded posture with the foot offsets and the correction applied.
    fn with_offsets(&self, p: &Posture) -> Posture {
        let mut q = *p;
        q.base_position[0] += self.correction[0];
        q.base_position[1] += self.correction[1];
        q.base_rpy[0] += correction_roll(p, self.correction);
        for (f, o) in q.feet.iter_mut().zip(self.foot_offset) {
            for k in 0..3 {
                f[k] += o[k];
            }
        }
        q
    }

    fn event(&mut self, time: f64, event: ExecEventKind) {
        self.events.push(ExecEvent { time_s: time, event });
    }

    /// Starts work toward keyframe `i`.
    fn advance(&mut self, i: usize, time: f64) {
        let Some(k) = self.keys.get(i) else {
            self.mode = Mode::Finished;
            return;
        };
        match k.phase {
            Phase::Drive => {
                let mut last = i;
                while self.keys.get(last + 1).is_some_and(|k| k.phase == Phase::Drive) {
                    last += 1;
                }
                let poses: Vec<Pose2> =
                    self.keys[i - 1..=last].iter().map(|k| planar(&k.posture())).collect();
                match PathFollower::new(poses, self.config.follower.clone()) {
                    Ok(f) => {
                        self.foot_offset = [[0.0; 3]; 4];
                        self.correction = [0.0; 2];
                        self.fading = None;
                        self.mode = Mode::Drive { follower: Box::new(f), first: i, last };
                    }
                    Err(e) => self.fail(ExecFailure::Follower(e.to_string()), time),
                }
            }
            Phase::Lift => {
                self.retries = 0;
                self.mode =
                    Mode::Guard { index: i, wait: 0.0, attempts: 0, corr_from: self.correction };
            }
            _ => self.start_segment(i),
        }
    }

    fn start_segment(&mut self, i: usize) {
        let from = self.cmd;
        let to = self.keys[i].posture();
        let planned = self.keys[i].time_s - self.keys[i - 1].time_s;
        let c = &self.config;
        let duration =
            planned.max(motion_duration(&from, &to, c.recover_speed_mps, c.recover_angular_speed));
        self.mode = Mode::Segment { from, index: i, elapsed: 0.0, duration, settle: 0.0 };
    }

    /// Puts a lifted foot down if there is one, then returns to the driving posture.
    fn fail(&mut self, failure: ExecFailure, time: f64) {
        self.event(time, ExecEventKind::Failure { failure: failure.clone() });
        self.active = None;
        if let Some(leg) = Leg::ALL.into_iter().find(|l| !self.cmd.contact[l.index()]) {
            self.start_put_down(leg, AfterPutDown::Recover(failure));
        } else {
            self.start_recover(failure);
        }
    }

    fn start_put_down(&mut self, leg: Leg, then: AfterPutDown) {
        // Fold the offsets of this leg into the commanded posture and lower from there.
        let i = leg.index();
        let p = self.with_offsets(&self.cmd);
        self.cmd.feet[i] = p.feet[i];
        self.foot_offset[i] = [0.0; 3];
        // The lowest ground the foot was planned on, minus the extra lowering allowed.
        let floor = self
            .keys
            .iter()
            .filter(|k| k.leg == Some(leg))
            .map(|k| k.feet[i][2])
            .fold(self.cmd.feet[i][2], f64::min)
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

    fn start_recover(&mut self, failure: ExecFailure) {
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

    fn legs_for(&mut self, p: &Posture, time: f64) -> Option<[[f64; 3]; 4]> {
        match reachable_leg_targets(&self.robot, p, REACH_SPARE_M) {
            Ok(q) => {
                self.last_legs = q;
                Some(q)
            }
            Err(e) => {
                self.fail(ExecFailure::Ik(e.to_string()), time);
                None
            }
        }
    }

    /// Joint targets for `p`, or the last ones if `p` cannot be solved (while already
    /// recovering, a failure must not start another recovery).
    fn legs_or_hold(&mut self, p: &Posture) -> [[f64; 3]; 4] {
        if let Ok(q) = reachable_leg_targets(&self.robot, p, REACH_SPARE_M) {
            self.last_legs = q;
        }
        self.last_legs
    }

    fn hold(&self) -> Command {
        Command { legs: self.last_legs, wheels: [straight(0.0); 4] }
    }

    fn with_steer_rate(
        &self,
        cmd: [WheelPairCommand; 4],
        obs: &Observation,
    ) -> [WheelPairCommand; 4] {
        std::array::from_fn(|i| {
            self.config.wheels.with_steering_rate(&self.robot, cmd[i], obs.steering_rate[i])
        })
    }

    /// Wheel commands for a posture moving at `velocity` (world feet velocities): pairs in
    /// contact roll at their foot's speed along the heading, steering straight.
    fn rolling(
        &self,
        p: &Posture,
        velocity: &[[f64; 2]; 4],
        obs: &Observation,
    ) -> [WheelPairCommand; 4] {
        let yaw = p.base_rpy[2];
        let cmd = std::array::from_fn(|i| {
            if p.contact[i] {
                straight(rolling_wheel_speed(&self.robot, velocity[i], yaw))
            } else {
                straight(0.0)
            }
        });
        self.with_steer_rate(cmd, obs)
    }

    /// One control tick of `dt` s.
    pub fn tick(&mut self, obs: &Observation, dt: f64) -> (Command, ExecStatus) {
        let cmd = self.step_mode(obs, dt);
        let status = match &self.mode {
            Mode::Finished => ExecStatus::Finished,
            Mode::Stopped(f) => ExecStatus::NeedsReplan(f.clone()),
            _ => ExecStatus::Running,
        };
        (cmd, status)
    }

    fn drift(&self, obs: &Observation, commanded: &Posture) -> Option<ExecFailure> {
        let c = planar(commanded);
        let distance_m = (obs.base.x - c.x).hypot(obs.base.y - c.y);
        let heading_rad = wrap_angle(obs.base.theta - c.theta);
        (distance_m > self.config.drift_tolerance_m
            || heading_rad.abs() > self.config.drift_tolerance_rad)
            .then_some(ExecFailure::Drift { distance_m, heading_rad })
    }

    fn step_mode(&mut self, obs: &Observation, dt: f64) -> Command {
        let time = obs.time;
        self.now = time;
        let mode = std::mem::replace(&mut self.mode, Mode::Finished);
        match mode {
            Mode::Finished => {
                self.mode = Mode::Finished;
                self.hold()
            }
            Mode::Stopped(f) => {
                self.mode = Mode::Stopped(f);
                self.hold()
            }
            Mode::Drive { follower, first, last } => {
                self.drive_tick(obs, dt, follower, first, last)
            }
            Mode::Segment { from, index, elapsed, duration, settle } => {
                self.segment_tick(obs, dt, from, index, elapsed, duration, settle)
            }
            Mode::Guard { index, wait, attempts, corr_from } => {
                self.guard_tick(obs, dt, index, wait, attempts, corr_from)
            }
            Mode::Confirm { index, confirm } => self.confirm_tick(obs, dt, index, confirm),
            Mode::PutDown { leg, lowered, floor, confirm, then } => {
                self.put_down_tick(obs, dt, leg, lowered, floor, confirm, then)
            }
            Mode::Recover { from, to, elapsed, duration, failure } => {
                self.recover_tick(obs, dt, from, to, elapsed, duration, failure)
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn drive_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        mut follower: Box<PathFollower>,
        first: usize,
        last: usize,
    ) -> Command {
        let time = obs.time;
        let out = follower.update(obs.base, dt);
        if out.status == FollowerStatus::Finished {
            self.cmd = self.keys[last].posture();
            self.advance(last + 1, time);
            return self.hold();
        }
        if out.cross_track_m.abs() > self.config.drift_tolerance_m {
            self.cmd = self.keys[(first - 1 + out.progress_index).min(last)].posture();
            self.fail(
                ExecFailure::Drift {
                    distance_m: out.cross_track_m.abs(),
                    heading_rad: out.heading_error_rad,
                },
                time,
            );
            return self.hold();
        }
        // The keyframe posture at the robot's progress along the run.
        let path = follower.path();
        let k = out.progress_index.min(path.len() - 1);
        let a_idx = first - 1 + k;
        let p = if k + 1 < path.len() {
            let (a, b) = (path[k], path[k + 1]);
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 1e-8 {
                ((obs.base.x - a.x) * dx + (obs.base.y - a.y) * dy) / len2
            } else {
                let dth = wrap_angle(b.theta - a.theta);
                if dth.abs() > 1e-6 { wrap_angle(obs.base.theta - a.theta) / dth } else { 1.0 }
            };
            interpolate(
                &self.keys[a_idx].posture(),
                &self.keys[a_idx + 1].posture(),
                t.clamp(0.0, 1.0),
            )
        } else {
            self.keys[a_idx].posture()
        };
        self.cmd = p;
        self.wheel_hold = [None; 4];
        self.mode = Mode::Drive { follower, first, last };
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let local = contacts_in_base(&self.robot, &p);
        let feet: [[f64; 2]; 4] = std::array::from_fn(|i| {
            [local[i][0] + self.robot.hips[i][0], local[i][1] + self.robot.hips[i][1]]
        });
        let wheels = self.config.wheels.commands(&self.robot, out.twist, &feet, &obs.steering);
        Command { legs, wheels: self.with_steer_rate(wheels, obs) }
    }

    #[allow(clippy::too_many_arguments)]
    fn segment_tick(
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
            if airborne && m < self.config.emergency_margin_m {
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

    #[allow(clippy::too_many_arguments)]
    fn guard_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        index: usize,
        mut wait: f64,
        mut attempts: usize,
        corr_from: [f64; 2],
    ) -> Command {
        let time = obs.time;
        let leg = self.keys[index].leg.unwrap_or(Leg::FrontLeft);
        let c = self.config.clone();
        wait += dt;
        let ramp = if attempts == 0 { 1.0 } else { smoothstep(wait / c.correction_time_s) };
        let target = self.correction;
        let applied = [
            corr_from[0] + (target[0] - corr_from[0]) * ramp,
            corr_from[1] + (target[1] - corr_from[1]) * ramp,
        ];
        let saved = self.correction;
        self.correction = applied;
        let p = self.with_offsets(&self.cmd);
        self.correction = saved;
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let ready = wait >= c.lift_settle_s + if attempts == 0 { 0.0 } else { c.correction_time_s };
        if !ready {
            self.mode = Mode::Guard { index, wait, attempts, corr_from };
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let m = obs.support_margin(leg);
        let required = c.min_lift_margin_m
            + c.lift_margin_reserve_m
            + self.retries as f64 * c.retry_margin_increment_m;
        if m >= required {
            self.event(time, ExecEventKind::Lift { leg, margin_m: m });
            if self.retries == 0 {
                self.steps_started += 1;
            }
            self.active = Some(ActiveStep { number: self.steps_started, leg });
            self.lift_offset = self.foot_offset[leg.index()];
            // Landing: the drift of the measured base, frozen now.
            let place = self.place_index(index);
            let foothold = self.keys[place].feet[leg.index()];
            self.landing = landing_offset(planar(&p), obs.base, [foothold[0], foothold[1]]);
            self.fading = None;
            self.start_segment(index);
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let centroid = obs.support_centroid(leg);
        let total = self.correction[0].hypot(self.correction[1]);
        if attempts < c.max_correction_attempts
            && total < c.max_correction_m - 1e-6
            && let Some(cen) = centroid
        {
            let dir = [cen[0] - obs.com[0], cen[1] - obs.com[1]];
            let n = dir[0].hypot(dir[1]).max(1e-9);
            let want = (required + 0.01 - m) / 0.8;
            let mut next =
                [self.correction[0] + want * dir[0] / n, self.correction[1] + want * dir[1] / n];
            let len = next[0].hypot(next[1]);
            if len > c.max_correction_m {
                next = next.map(|v| v * c.max_correction_m / len);
            }
            let from = self.correction;
            self.correction = next;
            self.event(
                time,
                ExecEventKind::Correction {
                    leg,
                    margin_m: m,
                    correction_m: next[0].hypot(next[1]),
                },
            );
            attempts += 1;
            self.mode = Mode::Guard { index, wait: 0.0, attempts, corr_from: from };
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        self.steps_aborted += 1;
        self.fail(ExecFailure::StepAborted { leg, margin_m: m, required_m: required }, time);
        Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) }
    }

    #[allow(clippy::too_many_arguments)]
    fn confirm_tick(
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

    #[allow(clippy::too_many_arguments)]
    fn put_down_tick(
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
                    AfterPutDown::Retry(lift) => {
                        self.mode = Mode::Guard {
                            index: lift,
                            wait: 0.0,
                            attempts: 0,
                            corr_from: self.correction,
                        };
                    }
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

    #[allow(clippy::too_many_arguments)]
    fn recover_tick(
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

    /// The lift keyframe of the step whose keyframe `index` is part of.
    fn lift_index(&self, index: usize) -> usize {
        (0..=index).rev().find(|&j| self.keys[j].phase == Phase::Lift).unwrap_or(index)
    }

    /// The place keyframe of the step lifting at `index`.
    fn place_index(&self, index: usize) -> usize {
        (index..self.keys.len()).find(|&j| self.keys[j].phase == Phase::Place).unwrap_or(index)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::kinematics::{contacts_in_base, leg_joint_targets};
    use crate::robot::ik::leg_fk;

    fn robot() -> RobotDescription {
        RobotDescription::reference()
    }

    /// Level base 0.5 m up at the origin, feet under the hips on flat ground.
    fn standing() -> Posture {
        let r = robot();
        Posture {
            base_position: [0.0, 0.0, 0.5],
            base_rpy: [0.0, 0.0, 0.0],
            feet: std::array::from_fn(|i| [r.hips[i][0], r.hips[i][1], 0.0]),
            contact: [true; 4],
        }
    }

    fn key(time_s: f64, phase: Phase, leg: Option<Leg>, p: &Posture) -> Keyframe {
        Keyframe {
            time_s,
            phase,
            path_index: 0,
            leg,
            base_position: p.base_position,
            base_rpy: p.base_rpy,
            feet: p.feet,
            contact: p.contact,
            leg_heights: [0.45; 4],
            joints: leg_joint_targets(&robot(), p).unwrap(),
            com: [0.0; 3],
            margin_m: 0.1,
            segment_min_margin_m: 0.1,
            centroid_distance_m: 0.0,
        }
    }

    #[test]
    fn smoothstep_by_hand() {
        assert_eq!(smoothstep(0.0), 0.0);
        assert_eq!(smoothstep(1.0), 1.0);
        assert!((smoothstep(0.5) - 0.5).abs() < 1e-12);
        // 3·0.25² − 2·0.25³ = 0.1875 − 0.03125.
        assert!((smoothstep(0.25) - 0.15625).abs() < 1e-12);
        assert_eq!(smoothstep(2.0), 1.0);
        // 6·0.5·0.5 = 1.5 at the middle, zero at the ends.
        assert!((smoothstep_rate(0.5) - 1.5).abs() < 1e-12);
        assert_eq!(smoothstep_rate(0.0), 0.0);
        assert_eq!(smoothstep_rate(1.0), 0.0);
    }

    #[test]
    fn wheel_speed_is_the_foot_speed_along_the_heading_over_the_radius() {
        // r = 0.08 m: 0.1 m/s straight ahead is 1.25 rad/s; heading 90° sees only v_y.
        let r = robot();
        assert!((rolling_wheel_speed(&r, [0.1, 0.0], 0.0) - 1.25).abs() < 1e-12);
        assert!((rolling_wheel_speed(&r, [0.1, 0.0], std::f64::consts::FRAC_PI_2)).abs() < 1e-12);
        assert!(
            (rolling_wheel_speed(&r, [0.0, -0.04], std::f64::consts::FRAC_PI_2) + 0.5).abs()
                < 1e-12
        );
        // 60°: 0.1·cos 60° = 0.05 m/s → 0.625 rad/s.
        assert!(
            (rolling_wheel_speed(&r, [0.1, 0.0], std::f64::consts::FRAC_PI_3) - 0.625).abs()
                < 1e-12
        );
    }

    #[test]
    fn clock_slows_linearly_between_the_error_bounds() {
        assert_eq!(clock_rate(0.01, 0.05, 0.2, 0.2), 1.0);
        // Half-way (0.125 rad): 1 − 0.8·0.5 = 0.6.
        assert!((clock_rate(0.125, 0.05, 0.2, 0.2) - 0.6).abs() < 1e-12);
        assert_eq!(clock_rate(0.5, 0.05, 0.2, 0.2), 0.2);
    }

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
    fn motion_duration_takes_the_slowest_part() {
        let a = standing();
        let mut b = a;
        b.feet[0][0] += 0.3; // 3 s at 0.1 m/s
        b.base_rpy[0] = 0.1; // 0.5 s at 0.2 rad/s
        assert!((motion_duration(&a, &b, 0.1, 0.2) - 3.0).abs() < 1e-12);
        assert!((motion_duration(&a, &a, 0.1, 0.2) - 0.1).abs() < 1e-12);
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
    fn a_foot_beyond_reach_is_pulled_in_along_the_hip_ankle_line() {
        let r = robot();
        let mut p = standing();
        // Hip 0.45 m above the ground: the ankle (0.18 m above the contact) 0.27 m below
        // the hip, reachable. Moving the front-left foot 0.45 m forward puts the ankle
        // √(0.45² + 0.27²) = 0.525 m from the hip, beyond 0.5.
        p.feet[0][0] += 0.45;
        assert!(leg_joint_targets(&r, &p).is_err());
        let q = reachable_leg_targets(&r, &p, 0.001).unwrap();
        let c = leg_fk(&r, q[0], 0.0);
        let ankle = [c[0], c[1] + r.foot_length + r.wheel_radius];
        assert!((ankle[0].hypot(ankle[1]) - 0.499).abs() < 1e-9);
        // Along the line: the ankle direction is unchanged.
        let want = 0.45f64.atan2(0.27);
        assert!((ankle[0].atan2(-ankle[1]) - want).abs() < 1e-9);
        // Reachable feet are untouched.
        let local = contacts_in_base(&r, &p);
        for i in 1..4 {
            let f = leg_fk(&r, q[i], 0.0);
            assert!((f[0] - local[i][0]).abs() < 1e-9 && (f[1] - local[i][2]).abs() < 1e-9);
        }
    }

    fn obs(
        time: f64,
        ex: &StepExecutor,
        contacts: &[(Leg, [f64; 2])],
        com: [f64; 3],
    ) -> Observation {
        Observation {
            time,
            base: Pose2::new(0.0, 0.0, 0.0),
            joints: ex.last_legs,
            steering: [0.0; 4],
            steering_rate: [0.0; 4],
            wheel_angles: [[0.0; 2]; 4],
            com,
            wheel_contacts: contacts.to_vec(),
        }
    }

    fn config() -> ExecutorConfig {
        ExecutorConfig::from_params(&Params::default(), FollowerConfig::default())
    }

    /// Start, lift, swing and place of the front-left foot 0.1 m forward on flat ground.
    fn step_path() -> Vec<Keyframe> {
        let a = standing();
        let mut lift = a;
        lift.feet[0][2] = 0.05;
        lift.contact[0] = false;
        let mut swing = lift;
        swing.feet[0][0] += 0.1;
        let mut place = swing;
        place.feet[0][2] = 0.0;
        place.contact[0] = true;
        vec![
            key(0.0, Phase::Start, None, &a),
            key(0.5, Phase::Lift, Some(Leg::FrontLeft), &lift),
            key(1.5, Phase::Swing, Some(Leg::FrontLeft), &swing),
            key(2.0, Phase::Place, Some(Leg::FrontLeft), &place),
        ]
    }

    fn all_contacts(feet: &[[f64; 3]; 4]) -> Vec<(Leg, [f64; 2])> {
        Leg::ALL.iter().map(|&l| (l, [feet[l.index()][0], feet[l.index()][1]])).collect()
    }

    fn ground() -> HeightMap {
        HeightMap::filled([-2.0, -2.0], 0.025, 160, 160, 0.0).unwrap()
    }

    #[test]
    fn a_step_lifts_after_the_margin_check_and_ends_only_on_contact() {
        let keys = step_path();
        let mut ex = StepExecutor::new(&robot(), config(), keys.clone(), ground());
        let feet = keys[0].feet;
        // The CoM 0.14 m inside the FR–RL diagonal (which passes through the origin).
        let com = [-0.1, -0.1, 0.4];
        let without_fl: Vec<_> =
            all_contacts(&feet).into_iter().filter(|(l, _)| *l != Leg::FrontLeft).collect();
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
    fn a_low_margin_is_corrected_toward_the_centroid_then_the_step_is_aborted() {
        let keys = step_path();
        let cfg = ExecutorConfig { max_correction_m: 0.2, ..config() };
        let mut ex = StepExecutor::new(&robot(), cfg, keys.clone(), ground());
        let feet = keys[0].feet;
        let without_fl: Vec<_> =
            all_contacts(&feet).into_iter().filter(|(l, _)| *l != Leg::FrontLeft).collect();
        // The CoM 1 cm inside the FR–RL diagonal (x = −y·0.35/0.32 through the origin):
        // a measured margin of 1 cm, below the 2 cm (plus reserve) to lift. It does not
        // move (the corrections have no effect here), so after three corrections the step
        // is aborted with the foot never lifted.
        let n = [0.32f64, 0.35];
        let len = n[0].hypot(n[1]);
        let com = [-0.01 * n[0] / len, -0.01 * n[1] / len, 0.4];
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
        // (0.05 + 0.01 − 0.01) / 0.8 = 6.25 cm, three of them.
        assert_eq!(corrections.len(), 3, "{:?}", ex.events);
        assert!((corrections[0] - 0.0625).abs() < 1e-9, "{corrections:?}");
        assert!((corrections[1] - 0.125).abs() < 1e-9);
        assert!((corrections[2] - 0.1875).abs() < 1e-9);
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
