//! The closed-loop step executor (issue 7): executes a detailed path's keyframes
//! (`motion::DetailedPath`, Sec. VI) on the robot, one control tick at a time.
//!
//! A pure state machine: each tick it takes an [`Observation`] (measured base pose,
//! joints, steering, MuJoCo's CoM, the wheels MuJoCo reports touching terrain or within
//! the monitor's support gap, and the load on each wheel pair) and returns actuator
//! targets ([`Command`]). The simulation loop lives in `closed_loop`.
//!
//! - **Drive** runs (consecutive [`Phase::Drive`] keyframes) go to the B-spline
//!   [`PathFollower`] (Sec. IX) and the omnidirectional wheel kinematics; the legs hold the
//!   keyframes' posture interpolated at the robot's progress, the legs of the diagonal
//!   that carries less than its share of the weight lengthened (`drive`, load sharing).
//!   The follower stops at the run's end (within its 2 cm / 2° goal tolerance) and
//!   stepping starts at once.
//! - **Other segments** track the linear interpolation between keyframes with a smoothstep
//!   time law over the generator's keyframe time (longer if the servos lag): leg joint
//!   targets from the sagittal IK of the interpolated posture (base height, roll, pitch,
//!   feet). A foot moved along the ground in contact (wheel to centre, wheel back, wheel
//!   moves) rolls its pair at the foot's world speed over the wheel radius, steering
//!   straight. Stance wheels get a zero speed target (the ankle keeps a planted wheel
//!   level): the wheel actuators are velocity servos, so a stance pair gives a little
//!   under the legs' horizontal push, which relieves the forces the four position-servoed
//!   legs set up against each other. (Holding the wheel angles stiffly instead, with a
//!   proportional loop, made 2 of the stairs envelope's 70 flights lose their support
//!   and 4 more fail.)
//! - **Base height** in the standing modes (segments, the lift guard, placing, putting
//!   down): the leg servos give under the robot's weight and the base sinks 1–2 cm below
//!   its keyframes, carrying a lifted leg's folded knee toward the edge it passes. The
//!   commanded base is raised by the integral of the measured shortfall
//!   ([`ExecutorConfig::base_hold_gain`], capped at [`ExecutorConfig::max_base_lift_m`]);
//!   driving drops the raise.
//! - **Base position** in the same modes: the compliance also lets the base lag a standing
//!   manoeuvre and the stance wheels creep under the legs' push (after a base shift on a
//!   stair descent the base stood 4 cm beyond its keyframes and a rear thigh touched a
//!   nosing). The legs are solved for a base offset along its heading by the integral of
//!   the measured error along it (the sagittal legs cannot carry it sideways; the guard's
//!   roll does that), capped at [`ExecutorConfig::max_base_hold_m`] and scaled back every
//!   tick to what the legs in contact reach, so it never winds up into a foot pulled off
//!   the ground; before a lift, as for the guard's corrections, the foot about to leave
//!   the ground does not count (it bounded the hold, which then gave back every
//!   correction the guard added).
//! - **Before a step** (the first keyframe of a path element that lifts a foot) the
//!   stance is brought back onto the plan's footholds if the wheel contacts MuJoCo
//!   reports put a foot more than [`ExecutorConfig::slide_threshold_m`] off its
//!   foothold: the pairs steer and roll the robot, turned and shifted, legs held, where
//!   the height map says a steered pair keeps its ground (`slide`). The legs cannot move
//!   or turn the stance, yet a planned base shift ends on a lattice cell up to half a
//!   cell to the side of its heading, stance wheels creep, and a base rolled while
//!   pitched less than its feet's line turns the robot.
//! - **Before a lift** the support margin measured from MuJoCo (CoM over the wheels of the
//!   three support legs that the monitor counts as support, within its 4 mm gap: a pair
//!   standing on one wheel with the other a millimetre up still holds the robot, and
//!   counting only touching wheels aborted a stair step at 3.3 cm where the monitor
//!   measured 13) must reach [`ExecutorConfig::min_lift_margin_m`]
//!   (2 cm) plus a reserve for the sag of the compliant support legs when the foot unloads
//!   ([`ExecutorConfig::lift_margin_reserve_m`]). If it does not, the base is moved toward
//!   the support triangle's centroid in bounded increments: longitudinally by a base shift,
//!   laterally by a roll about the ground ([`correction_roll`]; the legs move only in their
//!   sagittal planes), the roll left out where it is predicted to lose margin (a rolled
//!   base tilts each wheel pair onto its lower wheel, `posture::kinematics::wheel_support`).
//!   If that does not suffice, the step is aborted (the foot is not lifted).
//! - **While a foot is in the air** the support margin is watched; below
//!   [`ExecutorConfig::emergency_margin_m`] for [`ExecutorConfig::emergency_hold_s`] (what
//!   the monitor counts as a loss of margin, not a wheel's bounce) the foot is put down
//!   where it is (lowered until MuJoCo reports contact), and the step is retried from the
//!   lift (bounded).
//! - **Stance feet keep the ground** in the same modes: a leg the posture has bearing
//!   weight whose wheels touch nothing is lowered until they do (bounded,
//!   [`ExecutorConfig::max_leg_extension_m`]; the support legs give under a shifted CoM,
//!   the base pitches past its keyframes and lifts a pair off its tread).
//! - **Swing foot landing**: the planar drift of the measured base from the base the legs
//!   are solved for (the position hold included), frozen at the lift, is taken out of the
//!   foothold, so the foot lands on the world foothold rather than on the plan's.
//! - **Placing**: after the place keyframe, weight goes back onto the foot only when
//!   MuJoCo reports contact ([`ContactConfirm`]: the foot is lowered a bounded extra
//!   distance; no contact fails the step).
//! - **Failures** (step aborted or failed, drift beyond tolerance, IK): a lifted foot is put
//!   down, the robot returns to the driving posture at its pose (feet rolled to the
//!   neutral footprint) and the executor reports [`ExecStatus::NeedsReplan`]; where a
//!   foot's way back would roll over an edge (mid-staircase) it holds its stance instead
//!   and reports [`ExecStatus::Stranded`].
//!
//! Postures are kept in the plan's coordinates; only the relative geometry of base and
//! feet reaches the joints, so a small planar offset of the whole robot from the plan does
//! not disturb stepping.
//!
//! The executor is cut by job: `interface` (configuration, observation, command, status,
//! events, failures), `timing` (time laws and segment clock), `actuation` (postures to
//! joint and wheel targets), `drive` (drive runs handed to the path follower), `segment`
//! (keyframe tracking, watching the margin of a foot in the air), `slide` (the stance
//! rolled back onto its footholds before a step), `guard` (the margin
//! check and stabilising corrections before a lift, the landing offset), `contact`
//! (contact confirmation of a placed foot, the emergency put-down) and `recovery` (the
//! return to the driving posture). This file holds the state machine itself: its modes,
//! its state, and the tick that dispatches on the mode.

mod actuation;
mod contact;
mod drive;
mod guard;
mod interface;
mod recovery;
mod segment;
mod slide;
#[cfg(test)]
mod test_support;
mod timing;

pub use actuation::{reachable_leg_targets, rolling_wheel_speed};
use guard::Corrections;
pub use guard::{correction_roll, landing_offset};
pub use interface::{
    Command, ExecEvent, ExecEventKind, ExecFailure, ExecStatus, ExecutorConfig, Observation,
    Stranding,
};
pub use slide::{StanceError, stance_error};
pub use timing::{clock_rate, motion_duration, smoothstep, smoothstep_rate};

use super::foot_contact::ContactConfirm;
use super::path_follower::PathFollower;
use crate::geometry::Pose2;
use crate::motion::{Keyframe, Phase};
use crate::posture::kinematics::Posture;
use crate::robot::{Leg, RobotDescription};
use crate::terrain::HeightMap;
use actuation::{REACH_SPARE_M, held_by, reach_excess, reachable_fraction};

fn planar(p: &Posture) -> Pose2 {
    Pose2::new(p.base_position[0], p.base_position[1], p.base_rpy[2])
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
    Drive {
        follower: Box<PathFollower>,
        first: usize,
        last: usize,
    },
    Segment {
        from: Posture,
        index: usize,
        elapsed: f64,
        duration: f64,
        settle: f64,
    },
    /// The first keyframe of a step is next: the stance is measured on the next tick
    /// (`slide`).
    CheckStance {
        index: usize,
    },
    /// Rolling the stance back onto its footholds before keyframe `index` (`slide`).
    Slide {
        index: usize,
        start: Pose2,
        rolls: Vec<slide::Roll>,
        roll: usize,
        elapsed: f64,
        rolling: bool,
    },
    Guard {
        index: usize,
        wait: f64,
        corrections: Corrections,
        corr_from: [f64; 2],
    },
    Confirm {
        index: usize,
        confirm: ContactConfirm,
    },
    PutDown {
        leg: Leg,
        lowered: f64,
        floor: f64,
        confirm: ContactConfirm,
        then: AfterPutDown,
    },
    Recover {
        from: Posture,
        to: Posture,
        elapsed: f64,
        duration: f64,
        failure: ExecFailure,
    },
    Finished,
    Stopped(ExecFailure),
    Stranded(ExecFailure, Stranding),
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
    /// Per-leg extension of a drive run's legs by their load sharing, m (`drive`).
    drive_extension: [f64; 4],
    /// A drive run's rise of the base with the ground under its wheels, m (`drive`).
    drive_rise: f64,
    /// A drive run's last commanded base height, m (`drive`: it comes down no faster than
    /// it may rise); `None` before the run's first tick.
    drive_base_z: Option<f64>,
    /// Stabilising base correction (plan coordinates), m.
    correction: [f64; 2],
    /// The correction at the start of the segment that fades it out.
    fading: Option<[f64; 2]>,
    /// Foot offset of the stepping leg when its lift began (faded out during the lift).
    lift_offset: [f64; 3],
    /// Landing offset of the current step.
    landing: [f64; 2],
    /// The base height hold's raise of the commanded base, m
    /// (`ExecutorConfig::base_hold_gain`).
    base_lift: f64,
    /// The base position hold's planar offset of the base the legs are solved for, m
    /// (`ExecutorConfig::max_base_hold_m`).
    base_hold: [f64; 2],
    last_legs: [[f64; 3]; 4],
    now: f64,
    /// Since when the support margin of a foot in the air has been below
    /// `ExecutorConfig::emergency_margin_m`, s.
    low_margin_since: Option<f64>,
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
    /// keyframe), with the height map `ground` for the return to the driving posture and
    /// for how low a foot put down in an emergency may go.
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
            drive_extension: [0.0; 4],
            drive_rise: 0.0,
            drive_base_z: None,
            correction: [0.0; 2],
            fading: None,
            lift_offset: [0.0; 3],
            landing: [0.0; 2],
            base_lift: 0.0,
            base_hold: [0.0; 2],
            last_legs,
            now: 0.0,
            low_margin_since: None,
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
            | Mode::CheckStance { index }
            | Mode::Slide { index, .. }
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
        self.with_correction(p, self.correction)
    }

    /// [`Self::with_offsets`] with the stabilising correction `correction` in place of
    /// the current one.
    fn with_correction(&self, p: &Posture, correction: [f64; 2]) -> Posture {
        let mut q = *p;
        q.base_position[0] += correction[0];
        q.base_position[1] += correction[1];
        q.base_position[2] += self.base_lift;
        q.base_rpy[0] += correction_roll(p, correction);
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
                        // The stance compliance's extensions carry over (no jump).
                        let max = self.config.max_leg_extension_m;
                        self.drive_extension = self.foot_offset.map(|o| (-o[2]).clamp(0.0, max));
                        self.drive_rise = 0.0;
                        self.drive_base_z = None;
                        self.foot_offset = [[0.0; 3]; 4];
                        self.correction = [0.0; 2];
                        self.fading = None;
                        self.mode = Mode::Drive { follower: Box::new(f), first: i, last };
                    }
                    Err(e) => self.fail(ExecFailure::Follower { message: e.to_string() }, time),
                }
            }
            _ if self.starts_a_step(i) => {
                self.retries = 0;
                self.mode = Mode::CheckStance { index: i };
            }
            Phase::Lift => {
                self.retries = 0;
                self.start_guard(i);
            }
            _ => self.start_segment(i),
        }
    }

    /// One control tick of `dt` s.
    pub fn tick(&mut self, obs: &Observation, dt: f64) -> (Command, ExecStatus) {
        self.hold_base(obs, dt);
        self.comply_stance(obs, dt);
        let cmd = self.step_mode(obs, dt);
        let status = match &self.mode {
            Mode::Finished => ExecStatus::Finished,
            Mode::Stopped(f) => ExecStatus::NeedsReplan(f.clone()),
            Mode::Stranded(f, r) => ExecStatus::Stranded { failure: f.clone(), reason: r.clone() },
            _ => ExecStatus::Running,
        };
        (cmd, status)
    }

    /// The base height and position holds (`ExecutorConfig::base_hold_gain`,
    /// `ExecutorConfig::max_base_hold_m`): in the standing modes that command postures
    /// through [`Self::with_offsets`], integrate how far the measured base stands below
    /// the commanded one, and how far it stands from it in the plane; during a stance
    /// slide both are kept as they are; elsewhere (driving, the return to the driving
    /// posture, finished) both are dropped.
    fn hold_base(&mut self, obs: &Observation, dt: f64) {
        // A stance slide moves base and feet together on the wheels: the holds keep their
        // values, or the position hold would move the base over the feet while the wheels
        // carry it, and the feet would end off by what it moved.
        if matches!(self.mode, Mode::Slide { .. }) {
            return;
        }
        let standing = matches!(
            self.mode,
            Mode::Segment { .. }
                | Mode::CheckStance { .. }
                | Mode::Guard { .. }
                | Mode::Confirm { .. }
                | Mode::PutDown { .. }
        );
        if !standing {
            self.base_lift = 0.0;
            self.base_hold = [0.0; 2];
            return;
        }
        let c = &self.config;
        if let Some(z) = obs.base_z {
            let shortfall = self.cmd.base_position[2] - z;
            self.base_lift =
                (self.base_lift + c.base_hold_gain * shortfall * dt).clamp(0.0, c.max_base_lift_m);
        } else {
            self.base_lift = 0.0;
        }
        // Along the heading only: the legs move in their sagittal planes and cannot carry
        // the base sideways (the guard's roll does that).
        let p = self.with_offsets(&self.cmd);
        let reference = p.base_position;
        let (sy, cy) = self.cmd.base_rpy[2].sin_cos();
        let along = (reference[0] - obs.base.x) * cy + (reference[1] - obs.base.y) * sy;
        let held =
            (self.base_hold[0] * cy + self.base_hold[1] * sy + c.base_hold_gain * along * dt)
                .clamp(-c.max_base_hold_m, c.max_base_hold_m);
        // Never past the legs' reach: a hold that stretches a leg in contact beyond its
        // reach (or further beyond than the posture itself does) would pull that foot off
        // the ground (`reachable_leg_targets`). The hold is scaled back to what the legs
        // reach, every tick, as the posture moves on; the integral does not wind up.
        // Before a lift, as for the guard's corrections (`StepExecutor::within_reach`),
        // the foot about to leave the ground does not bound the hold.
        let lifting = match self.mode {
            Mode::Guard { index, .. } => self.keys[index].leg,
            _ => None,
        };
        let excess = |a: f64| {
            let h = a * held;
            reach_excess(&self.robot, &held_by(&p, [h * cy, h * sy]), REACH_SPARE_M, lifting)
        };
        let held = held * reachable_fraction(excess, excess(0.0).max(0.0));
        self.base_hold = [held * cy, held * sy];
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
            Mode::Stranded(f, r) => {
                self.mode = Mode::Stranded(f, r);
                self.hold()
            }
            Mode::Drive { follower, first, last } => {
                self.drive_tick(obs, dt, follower, first, last)
            }
            Mode::Segment { from, index, elapsed, duration, settle } => {
                self.segment_tick(obs, dt, from, index, elapsed, duration, settle)
            }
            Mode::CheckStance { index } => {
                self.check_stance(index, obs);
                self.step_mode(obs, dt)
            }
            Mode::Slide { index, start, rolls, roll, elapsed, rolling } => {
                self.slide_tick(obs, dt, index, start, rolls, roll, elapsed, rolling)
            }
            Mode::Guard { index, wait, corrections, corr_from } => {
                self.guard_tick(obs, dt, index, wait, corrections, corr_from)
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

    /// The lift keyframe of the step whose keyframe `index` is part of.
    fn lift_index(&self, index: usize) -> usize {
        (0..=index).rev().find(|&j| self.keys[j].phase == Phase::Lift).unwrap_or(index)
    }

    /// The place keyframe of the step lifting at `index`.
    fn place_index(&self, index: usize) -> usize {
        (index..self.keys.len()).find(|&j| self.keys[j].phase == Phase::Place).unwrap_or(index)
    }
}
