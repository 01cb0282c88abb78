//! `momaro run`: plan a scenario, expand the plan into keyframes (step motion generation,
//! Sec. VI), then execute it in closed loop in MuJoCo until the goal is reached or the
//! scenario's time budget runs out (paper Sec. IX, issue 7).
//!
//! Each 10 ms control tick the step executor (`control::step_executor`) gets the measured
//! base pose (optionally with seeded noise), joints, steering, MuJoCo's CoM and the wheels
//! MuJoCo reports in contact, and returns leg, steering and wheel targets: drive runs with
//! the B-spline path follower, steps and other manoeuvres by tracking the keyframes, with
//! the margin checked before each lift and contact confirmed before weight goes back onto
//! a placed foot. When the executor leaves the plan (step aborted or failed, drift), the
//! robot returns to the driving posture and the job replans from the simulated pose
//! (ARA*, time-limited; a bounded number of times). The stability monitor measures the
//! margin of MuJoCo's CoM over the wheels in contact, and keeps measuring for
//! [`WATCH_AFTER_STOP_S`] after a failure stops the run; the scenario's expectations
//! decide the verdict.

use super::detailed::DetailedJobError;
use super::sim::{CONTROL_HZ, SETTLE_S};
use crate::control::path_follower::FollowerConfig;
use crate::control::step_executor::{
    Command, ExecEvent, ExecStatus, ExecutorConfig, Observation, StepExecutor,
};
use crate::geometry::{Pose2, wrap_angle};
use crate::monitor::{MonitorEvent, MonitorLimits, StabilityMonitor, StabilitySample};
use crate::motion::{DetailedPath, MotionError, Phase};
use crate::planner::{self, PlanError, PlanOptions, PlanSummary, Prepared};
use crate::progress::SimProgress;
use crate::rng::Rng;
use crate::robot::Leg;
use crate::robot::ik::IkError;
use crate::scenario::{Outcome, Scenario, Stepping};
use crate::sim::{BaseState, SimError, Simulation, TOUCHING_M};
use crate::terrain::HeightMap;
use crate::viz::{Recorder, VizError};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// Why a run could not be carried out (a run that fails its expectations is not an error:
/// it is a summary with `passed = false`).
#[derive(Debug, thiserror::Error)]
pub enum RunJobError {
    /// Planning failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The plan could not be expanded into keyframes (step motion generation).
    #[error("{scenario}: step motion generation")]
    Motion {
        /// Scenario name.
        scenario: String,
        /// The cause.
        source: MotionError,
    },
    /// The height map could not be built.
    #[error(transparent)]
    Costmap(#[from] super::costmap::CostmapError),
    /// The robot stands where the height map knows no ground.
    #[error("no ground height known under a foot at ({x:.3}, {y:.3})")]
    UnknownGround {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
    },
    /// The simulation failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A leg cannot reach its foothold.
    #[error("leg targets: {0}")]
    Ik(#[from] IkError),
    /// The recording failed.
    #[error(transparent)]
    Viz(#[from] VizError),
    /// An image could not be written.
    #[error(transparent)]
    Image(#[from] crate::render::ImageError),
}

/// Seeded noise on the measured base pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseNoise {
    /// Standard deviation of x and y, m.
    pub position_std_m: f64,
    /// Standard deviation of yaw, rad.
    pub yaw_std_rad: f64,
    /// Seed of the generator (the raw xorshift64* state, `rng::Rng::from_state`).
    pub seed: u64,
}

/// Options of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Planner options.
    pub plan: PlanOptions,
    /// Path follower configuration.
    pub follower: FollowerConfig,
    /// Robot model file.
    pub model_path: PathBuf,
    /// Rerun recording to write.
    pub rerun: Option<PathBuf>,
    /// Progress bar on a terminal.
    pub progress: bool,
    /// Noise on the pose feedback.
    pub noise: Option<PoseNoise>,
    /// Replans allowed when the executor leaves the plan.
    pub max_replans: usize,
    /// Planning budget of a replan, s (wall time; the simulation waits).
    pub replan_time_limit_s: f64,
    /// A push on the base during a step (disturbance tests).
    pub push: Option<Push>,
}

/// The expansions ARA*'s schedule may spend after its probe found a path, in a run whose
/// options set none (`PlanOptions::schedule_expansions`). The probe finds a path in far
/// fewer (0.1–31k on seed 1's generated up-and-over and mixed courses); the schedule
/// stops here on any machine, where a time limit stops it wherever the CPU happens to
/// be, so a run's plan (the schedule's, or else the probe's) is the same everywhere as
/// long as the time limit does not bind first (the dev build expands 15–100k states/s:
/// give it 60 s or more). The paper's staircase, the dearest repository scenario, needs
/// 1.5M at ε = 3 (0.9M while a support pre-check refused most of its steps): its runs
/// take the probe's path. A search without the probe's path is not capped: it may still
/// prove that there is none.
pub const RUN_SCHEDULE_EXPANSIONS: u64 = 1_000_000;

impl RunOptions {
    /// Defaults for a scenario run: the given planner options (with at most
    /// [`RUN_SCHEDULE_EXPANSIONS`] for the schedule if they set none), the default follower, two
    /// replans of at most 20 s each, no noise, recording or push.
    pub fn new(mut plan: PlanOptions, model_path: PathBuf) -> Self {
        plan.schedule_expansions = plan.schedule_expansions.or(Some(RUN_SCHEDULE_EXPANSIONS));
        Self {
            plan,
            follower: FollowerConfig::default(),
            model_path,
            rerun: None,
            progress: false,
            noise: None,
            max_replans: 2,
            replan_time_limit_s: 20.0,
            push: None,
        }
    }
}

/// When a push starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PushWhen {
    /// At a simulated time, s.
    At(f64),
    /// During a step of the first plan.
    Step {
        /// The step (1-based, in execution order).
        step: usize,
        /// The phase of that step in which the push starts.
        phase: Phase,
        /// Delay after the phase starts, s.
        delay_s: f64,
    },
}

/// A force on the base for a while (disturbance tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Push {
    /// When it starts.
    pub when: PushWhen,
    /// Force in the world frame, N.
    pub force: [f64; 3],
    /// Duration, s.
    pub duration_s: f64,
}

/// What a push did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PushReport {
    /// When the push started, s.
    pub start_s: f64,
    /// Measured margin just before it, m.
    pub margin_before_m: f64,
    /// Smallest measured margin from the push start until 2 s after its end, m.
    pub min_margin_after_m: f64,
    /// Time the measured margin was negative in that window, s.
    pub negative_margin_s: f64,
    /// Largest |roll| or |pitch| in that window, degrees.
    pub max_tilt_deg: f64,
}

impl PushReport {
    /// Whether `push` (the one this reports) has ended at `now`.
    fn ended(&self, push: &Push, now: f64) -> bool {
        now >= self.start_s + push.duration_s
    }

    /// Takes in a monitor `sample` at `now`, a control tick of `dt` s after the last,
    /// while in the window (until 2 s after `push` ends).
    fn record(&mut self, push: &Push, now: f64, sample: &StabilitySample, dt: f64) {
        if now > self.start_s + push.duration_s + 2.0 {
            return;
        }
        self.min_margin_after_m = self.min_margin_after_m.min(sample.margin);
        if sample.margin < 0.0 {
            self.negative_margin_s += dt;
        }
        self.max_tilt_deg = self.max_tilt_deg.max(sample.tilt().to_degrees());
    }
}

/// The smallest measured margin while one step's foot was off its support (from the lift
/// to the confirmed contact).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepMargin {
    /// Step number (execution order, 1-based).
    pub step: usize,
    /// The leg.
    pub leg: Leg,
    /// Smallest measured margin, m.
    pub min_margin_m: f64,
}

/// One expectation of the scenario and whether the run met it.
#[derive(Debug, Clone, Serialize)]
pub struct ExpectationResult {
    /// What was expected.
    pub name: &'static str,
    /// Whether it held.
    pub passed: bool,
    /// Measured value and limit.
    pub detail: String,
}

/// Why a run stopped short of the goal, for machines (`run --json`, `check`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// The planner proved there is no path (every reachable pose searched).
    NoPath,
    /// The planner found no path within its limits, time or expansions (not a proof).
    PlanningTimeLimit,
    /// The planner returned a path its motion generator could not expand: a bug of the
    /// shared feasibility model, never a property of the course.
    MotionGeneration,
    /// The executor left the plan and no replan was left or a replan failed.
    Replanning,
    /// The executor left the plan where the robot cannot return to the driving posture
    /// a replan starts from (`control::step_executor::Stranding`): it holds its stance.
    Stranded,
    /// The scenario's simulated-time budget ran out.
    Timeout,
}

/// Result of a run, as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Every expectation held.
    pub passed: bool,
    /// Within the goal tolerances at the end.
    pub reached_goal: bool,
    /// Distance of the base from the goal at the end, m.
    pub goal_position_error_m: f64,
    /// Heading error at the end, rad.
    pub goal_heading_error_rad: f64,
    /// Simulated time, s.
    pub sim_time_s: f64,
    /// Wall time of planning and execution, s.
    pub wall_time_s: f64,
    /// Simulated over execution wall time.
    pub real_time_factor: f64,
    /// Planning wall time, s.
    pub planning_time_s: f64,
    /// Plain A* cost of the plan.
    pub plan_cost: f64,
    /// Steps in the plan.
    pub plan_steps: usize,
    /// Steps executed (placed foot confirmed in contact).
    pub steps_executed: usize,
    /// Steps planned over the run: those of the last plan plus those executed before it.
    pub steps_planned: usize,
    /// Steps aborted before lifting or failed.
    pub steps_aborted: usize,
    /// Replans.
    pub replans: usize,
    /// Keyframes of the first detailed plan.
    pub keyframes: usize,
    /// Smallest measured margin during each executed or attempted step.
    pub step_margins: Vec<StepMargin>,
    /// What the executor did (lifts, corrections, steps, failures).
    pub executor_events: Vec<ExecEvent>,
    /// Why the run stopped early, if it did (no path, replan failed, replans exhausted).
    pub failure: Option<String>,
    /// The kind of that failure.
    pub failure_kind: Option<FailureKind>,
    /// The push and the margins around it, if one was applied.
    pub push: Option<PushReport>,
    /// Smallest stability margin held for 50 ms after settling, m (over the supporting
    /// wheels, see `monitor`).
    pub min_stability_margin_m: f64,
    /// Smallest margin of any single sample, m.
    pub min_instant_margin_m: f64,
    /// Total time the CoM lay outside the support polygon, s.
    pub static_violation_s: f64,
    /// Most negative margin of those violations, m (0 if none).
    pub worst_static_violation_m: f64,
    /// The robot fell over (tilt past the limit, trunk on the terrain, or a fall); a
    /// static-stability violation alone is not a tip-over.
    pub tipped: bool,
    /// Robot bodies other than wheels that touched terrain.
    pub body_collisions: Vec<String>,
    /// Largest cross-track error of the path follower, m.
    pub max_tracking_error_m: f64,
    /// Mean cross-track error, m.
    pub mean_tracking_error_m: f64,
    /// Largest |base pitch| seen, degrees.
    pub max_pitch_deg: f64,
    /// Largest |roll| or |pitch| seen after settling, degrees.
    pub max_tilt_deg: f64,
    /// The expectations and their results.
    pub expectations: Vec<ExpectationResult>,
    /// Monitor events.
    pub events: Vec<MonitorEvent>,
}

impl RunSummary {
    /// The summary of a run of `scenario` that executed nothing: every count zero, no
    /// margin measured (infinite), nothing passed yet.
    pub fn not_run(scenario: &str) -> Self {
        Self {
            scenario: scenario.to_owned(),
            passed: false,
            reached_goal: false,
            goal_position_error_m: 0.0,
            goal_heading_error_rad: 0.0,
            sim_time_s: 0.0,
            wall_time_s: 0.0,
            real_time_factor: 0.0,
            planning_time_s: 0.0,
            plan_cost: 0.0,
            plan_steps: 0,
            steps_executed: 0,
            steps_planned: 0,
            steps_aborted: 0,
            replans: 0,
            keyframes: 0,
            step_margins: Vec::new(),
            executor_events: Vec::new(),
            failure: None,
            failure_kind: None,
            push: None,
            min_stability_margin_m: f64::INFINITY,
            min_instant_margin_m: f64::INFINITY,
            static_violation_s: 0.0,
            worst_static_violation_m: 0.0,
            tipped: false,
            body_collisions: Vec::new(),
            max_tracking_error_m: 0.0,
            mean_tracking_error_m: 0.0,
            max_pitch_deg: 0.0,
            max_tilt_deg: 0.0,
            expectations: Vec::new(),
            events: Vec::new(),
        }
    }
}

fn expectations(scenario: &Scenario, s: &RunSummary) -> Vec<ExpectationResult> {
    let e = &scenario.expect;
    let mut out = Vec::new();
    if e.outcome == Outcome::NoPath {
        out.push(ExpectationResult {
            name: "outcome",
            passed: s.failure_kind == Some(FailureKind::NoPath),
            detail: match (&s.failure_kind, &s.failure) {
                (Some(FailureKind::NoPath), _) => "no path, as expected".into(),
                (_, Some(f)) => format!("\"no path\" expected, got: {f}"),
                (_, None) => format!("\"no path\" expected, got a plan of {} steps", s.plan_steps),
            },
        });
        return out;
    }
    {
        out.push(ExpectationResult {
            name: "reach_goal",
            passed: s.reached_goal,
            detail: format!(
                "{:.3} m / {:.1}° from the goal (tolerance {} m / {}°)",
                s.goal_position_error_m,
                s.goal_heading_error_rad.to_degrees(),
                e.goal_tolerance_m,
                e.goal_tolerance_deg
            ),
        });
    }
    match e.stepping {
        Stepping::Any => {}
        Stepping::Required => {
            out.push(ExpectationResult {
                name: "stepping",
                passed: s.plan_steps > 0,
                detail: format!("{} steps planned, steps required", s.plan_steps),
            });
            out.push(ExpectationResult {
                name: "steps_executed",
                passed: s.steps_planned > 0 && s.steps_executed == s.steps_planned,
                detail: format!(
                    "{} of {} steps executed, {} aborted, {} replans",
                    s.steps_executed, s.steps_planned, s.steps_aborted, s.replans
                ),
            });
        }
        Stepping::Forbidden => out.push(ExpectationResult {
            name: "stepping",
            passed: s.plan_steps == 0,
            detail: format!("{} steps planned, driving only expected", s.plan_steps),
        }),
    }
    out.push(ExpectationResult {
        name: "min_stability_margin",
        passed: s.min_stability_margin_m >= e.min_stability_margin_m,
        detail: format!(
            "{:.3} m measured, {} m required",
            s.min_stability_margin_m, e.min_stability_margin_m
        ),
    });
    out.push(ExpectationResult {
        name: "static_violation",
        passed: s.static_violation_s <= e.max_static_violation_s,
        detail: format!(
            "{:.3} s with the CoM outside the support (worst {:.3} m), {} s allowed",
            s.static_violation_s, s.worst_static_violation_m, e.max_static_violation_s
        ),
    });
    out.push(ExpectationResult {
        name: "no_tip_over",
        passed: !s.tipped,
        detail: format!("tipped: {}", s.tipped),
    });
    out.push(ExpectationResult {
        name: "no_body_collision",
        passed: s.body_collisions.is_empty(),
        detail: if s.body_collisions.is_empty() {
            "none".into()
        } else {
            s.body_collisions.join(", ")
        },
    });
    out
}

/// A plan and its expansion into keyframes.
#[derive(Debug, Clone)]
pub struct Mission {
    /// The abstract plan.
    pub plan: PlanSummary,
    /// Its keyframes.
    pub detailed: DetailedPath,
}

/// Plans `scenario` on the world `prep` (`planner::prepare_for` with `opts`) from its start
/// and expands the path with `sim`'s CoM model.
///
/// # Errors
/// Planning or the expansion failed.
pub fn plan_mission(
    prep: &Prepared,
    scenario: &Scenario,
    sim: &mut Simulation,
    opts: &PlanOptions,
) -> Result<Mission, RunJobError> {
    let robot = sim.robot().clone();
    let mut plan = planner::run_on(prep, scenario, &robot, opts)?;
    let mut planning_time_s = plan.planning_time_s;
    // The planner and the generator share one feasibility model, but the generator
    // checks every centimetre of a manoeuvre the planner checks at its stances: what it
    // rejects is left out and the search runs again (ARA*'s first solution, each with
    // the full time limit, so the outcome does not depend on the machine's speed). If
    // no retry expands, the first rejection is the run's failure.
    let mut retry = PlanOptions {
        final_epsilon: opts.initial_epsilon.or(Some(scenario.params.arastar_initial_epsilon)),
        ..opts.clone()
    };
    let mut first: Option<RunJobError> = None;
    loop {
        let expanded =
            super::detailed::expand_prefix_on(prep, scenario, sim, &plan, plan.path.len());
        let (name, source) = match expanded.map_err(RunJobError::from) {
            Ok(detailed) => {
                plan.planning_time_s = planning_time_s;
                return Ok(Mission { plan, detailed });
            }
            Err(RunJobError::Motion { scenario: name, source }) => (name, source),
            Err(e) => return Err(e),
        };
        let edge = source
            .index()
            .and_then(|k| Some((*plan.keys.get(k.checked_sub(1)?)?, *plan.keys.get(k)?)));
        let original = first.take().unwrap_or(RunJobError::Motion { scenario: name, source });
        let Some(e) = edge.filter(|e| {
            retry.forbidden.len() < MAX_REJECTED_MANOEUVRES && !retry.forbidden.contains(e)
        }) else {
            return Err(original);
        };
        retry.forbidden.push(e);
        match planner::run_on(prep, scenario, &robot, &retry) {
            Ok(p) => {
                planning_time_s += p.planning_time_s;
                plan = p;
                first = Some(original);
            }
            Err(_) => return Err(original),
        }
    }
}

/// How far from where the robot stopped a replan may start when no plan can start there
/// (a wheel next to an edge after an aborted manoeuvre), m: a little more than the paper's
/// foot radius r_F (0.12 m), within which an edge makes a wheel's cell untraversable.
pub const REPLAN_START_RADIUS_M: f64 = 0.15;

/// Manoeuvres the generator may reject in one planning before the run gives up with a
/// motion-generation failure.
pub const MAX_REJECTED_MANOEUVRES: usize = 8;

/// Expands the first `end` elements of `plan`'s path (the whole path for its length).
///
/// # Errors
/// The maps cannot be built or the expansion fails.
pub fn expand_mission(
    scenario: &Scenario,
    sim: &mut Simulation,
    plan: &PlanSummary,
    end: usize,
) -> Result<DetailedPath, RunJobError> {
    Ok(super::detailed::expand_prefix(scenario, sim, plan, end)?)
}

impl From<DetailedJobError> for RunJobError {
    fn from(e: DetailedJobError) -> Self {
        match e {
            DetailedJobError::Plan(e) => RunJobError::Plan(e),
            DetailedJobError::Image(e) => RunJobError::Image(e),
            DetailedJobError::Motion { scenario, source } => {
                RunJobError::Motion { scenario, source }
            }
        }
    }
}

/// Plans, expands and executes `scenario` in closed loop.
///
/// # Errors
/// [`RunJobError`] if planning or the expansion fails or the simulation fails.
pub fn run(scenario: &Scenario, opts: &RunOptions) -> Result<RunSummary, RunJobError> {
    let wall = Instant::now();
    let mut sim = Simulation::new(scenario, &opts.model_path)?;
    // One world for the run: every plan (retries, replans), the generator and the
    // recording use its maps, and the plans share its heuristic toward the goal.
    let mut prep =
        planner::prepare_for(scenario, sim.robot(), &opts.plan, &crate::motion::manoeuvres::ALL)?;
    let mission = match plan_mission(&prep, scenario, &mut sim, &opts.plan) {
        Ok(m) => m,
        Err(e) => return unexecuted(scenario, e, wall),
    };
    super::stand_at_start(&mut sim, scenario)?;
    execute(scenario, &mut prep, &mut sim, mission, opts, wall)
}

/// The summary of a run that never started executing because planning ended without a
/// path or the plan could not be expanded; other errors pass through.
fn unexecuted(
    scenario: &Scenario,
    e: RunJobError,
    wall: Instant,
) -> Result<RunSummary, RunJobError> {
    let kind = match &e {
        RunJobError::Plan(PlanError::NoPath { termination, .. }) => match termination {
            crate::search::Termination::NoPath => FailureKind::NoPath,
            _ => FailureKind::PlanningTimeLimit,
        },
        RunJobError::Motion { .. } => FailureKind::MotionGeneration,
        _ => return Err(e),
    };
    let planning_time_s = wall.elapsed().as_secs_f64();
    let mut summary = RunSummary {
        goal_position_error_m: (scenario.start.x - scenario.goal.x)
            .hypot(scenario.start.y - scenario.goal.y),
        goal_heading_error_rad: wrap_angle(scenario.start.theta - scenario.goal.theta),
        wall_time_s: planning_time_s,
        planning_time_s,
        failure: Some(chain(&e)),
        failure_kind: Some(kind),
        ..RunSummary::not_run(&scenario.name)
    };
    summary.expectations = expectations(scenario, &summary);
    summary.passed = summary.expectations.iter().all(|e| e.passed);
    Ok(summary)
}

/// An error and its sources, joined by ": ".
fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    s
}

/// How long the simulation goes on, the executor holding its stance, after a failure
/// stops a run (stranded, no replan left, a replan that failed), s: long enough for a
/// robot tipping over when the run stopped to fall (a fall from standing height takes
/// about 0.3 s, a slow tip about 1 s).
pub const WATCH_AFTER_STOP_S: f64 = 2.0;

/// Sends the executor's command to the simulated actuators.
fn actuate(sim: &mut Simulation, cmd: &Command) {
    for leg in Leg::ALL {
        let i = leg.index();
        sim.set_leg_joint_targets(leg, cmd.legs[i]);
        sim.set_steering_target(leg, cmd.wheels[i].steer);
        sim.set_wheel_speeds(leg, cmd.wheels[i].wheel_speeds);
    }
}

/// What the executor sees of the simulation, with `measured` as the planar base pose and
/// the height of `base` (the simulated base, read once per tick); wheels within
/// `support_gap_m` of the terrain support it, as they do for the monitor.
fn observe(sim: &Simulation, base: &BaseState, measured: Pose2, support_gap_m: f64) -> Observation {
    let wheels = sim.wheel_contacts();
    let within = |gap: f64| -> Vec<(Leg, [f64; 2])> {
        wheels
            .iter()
            .filter(|c| c.distance <= gap)
            .map(|c| (c.leg, [c.position[0], c.position[1]]))
            .collect()
    };
    Observation {
        time: sim.time(),
        base: measured,
        base_z: Some(base.position[2]),
        joints: Leg::ALL.map(|l| sim.leg_joints(l)),
        steering: Leg::ALL.map(|l| sim.steering_angle(l)),
        steering_rate: Leg::ALL.map(|l| sim.steering_rate(l)),
        com: sim.center_of_mass(),
        wheel_contacts: within(TOUCHING_M),
        support_contacts: within(support_gap_m),
        wheel_loads: sim.wheel_loads(),
    }
}

fn log_mission(r: &Recorder, m: &Mission) -> Result<(), VizError> {
    let poses: Vec<Pose2> = m.plan.path.iter().map(|e| e.pose).collect();
    r.log_plan(&poses)?;
    r.log_steps(&super::plan_recording::step_lines(&m.plan))?;
    r.log_keyframes(&m.detailed.keyframes)
}

/// Executes `mission` in `sim` from its current state (the robot standing at the plan's
/// start), replanning on the world `prep` (`planner::prepare_for` with `opts.plan`, which the
/// mission was planned on) when the executor leaves the plan; `wall` is when the job
/// started.
///
/// # Errors
/// [`RunJobError`] if the maps cannot be built, the simulation diverges or the recording
/// fails. A run that fails its expectations is a summary with `passed = false`.
#[allow(clippy::too_many_lines)]
pub fn execute(
    scenario: &Scenario,
    prep: &mut Prepared,
    sim: &mut Simulation,
    mission: Mission,
    opts: &RunOptions,
    wall: Instant,
) -> Result<RunSummary, RunJobError> {
    let robot = sim.robot().clone();
    let heights: HeightMap = super::costmap::rasterised_map(scenario)?;
    let params = &scenario.params;
    let config = ExecutorConfig::from_params(params, opts.follower.clone());
    let first_plan = (mission.plan.cost, mission.plan.steps, mission.detailed.keyframes.len());
    let mut planning_time_s = mission.plan.planning_time_s;
    let mut steps_planned = mission.detailed.steps;
    let mut exec = StepExecutor::new(
        &robot,
        config.clone(),
        mission.detailed.keyframes.clone(),
        heights.clone(),
    );

    let mut recorder = match &opts.rerun {
        Some(path) => {
            let mut r = Recorder::create(path, "momaro run")?;
            r.log_world(&sim.geom_shapes(), &sim.body_poses())?;
            r.log_height_map(&heights)?;
            let (maps, planned) = (&prep.maps, prep.maps.heights());
            let (nx, ny) = planned.dims();
            let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
            if let Some(img) = crate::render::cost_layer_image(&foot, nx, ny, None) {
                r.log_layer_image("foot_cost", &img, planned.origin(), planned.resolution())?;
            }
            log_mission(&r, &mission)?;
            Some(r)
        }
        None => None,
    };

    let dt = sim.timestep();
    let substeps = ((1.0 / CONTROL_HZ) / dt).round().max(1.0) as usize;
    let control_dt = substeps as f64 * dt;
    let limits = MonitorLimits { settle_s: SETTLE_S, ..MonitorLimits::default() };
    let support_gap_m = limits.support_gap_m;
    let mut monitor = StabilityMonitor::new(limits);
    let mut noise = opts.noise.map(|n| (n, Rng::from_state(n.seed)));
    let timeout = scenario.expect.timeout_s;
    let progress = SimProgress::new(&scenario.name, timeout, opts.progress);
    let (mut max_track, mut sum_track, mut n_track, mut max_pitch) = (0.0f64, 0.0, 0usize, 0.0f64);
    let exec_wall = Instant::now();
    let mut replan_wall = 0.0;
    let mut finished = false;
    let mut failure = None;
    let mut replans = 0;
    let mut stranded = false;
    // Counters of executors replaced by a replan.
    let (mut done_executed, mut done_aborted, mut done_events) = (0, 0, Vec::new());
    let mut step_margins: Vec<StepMargin> = Vec::new();
    let mut step_key: Option<(usize, usize)> = None;
    // Push: phase start, push start, margin before, min margin after.
    let mut push_phase_start: Option<f64> = None;
    let mut push_report: Option<PushReport> = None;
    let mut last_margin = f64::INFINITY;
    let mut tick = 0usize;
    while sim.time() < timeout {
        let base = sim.base();
        let truth = Pose2::new(base.position[0], base.position[1], base.rpy[2]);
        let measured = match &mut noise {
            Some((n, g)) => Pose2::new(
                truth.x + n.position_std_m * g.normal(),
                truth.y + n.position_std_m * g.normal(),
                truth.theta + n.yaw_std_rad * g.normal(),
            ),
            None => truth,
        };
        let obs = observe(sim, &base, measured, support_gap_m);
        let (cmd, status) = exec.tick(&obs, control_dt);
        match status {
            ExecStatus::Finished => {
                finished = true;
                break;
            }
            ExecStatus::Stranded { failure: f, reason } => {
                failure = Some(format!("{f}; stranded: {reason}"));
                stranded = true;
                break;
            }
            ExecStatus::NeedsReplan(f) => {
                if replans >= opts.max_replans {
                    failure = Some(format!("{f}; no replans left ({replans} used)"));
                    break;
                }
                replans += 1;
                let t = Instant::now();
                let mut from_here = scenario.clone();
                from_here.start =
                    planner::nearest_start(prep, &robot, truth, REPLAN_START_RADIUS_M);
                let replan_opts =
                    PlanOptions { time_limit_s: opts.replan_time_limit_s, ..opts.plan.clone() };
                let result = prep
                    .set_start(&from_here, &robot, from_here.start)
                    .map_err(RunJobError::from)
                    .and_then(|()| plan_mission(prep, &from_here, sim, &replan_opts));
                replan_wall += t.elapsed().as_secs_f64();
                match result {
                    Ok(m) => {
                        done_executed += exec.steps_executed;
                        done_aborted += exec.steps_aborted;
                        done_events.append(&mut exec.events);
                        planning_time_s += m.plan.planning_time_s;
                        steps_planned = done_executed + m.detailed.steps;
                        if let Some(r) = &recorder {
                            log_mission(r, &m)?;
                        }
                        exec = StepExecutor::new(
                            &robot,
                            config.clone(),
                            m.detailed.keyframes,
                            heights.clone(),
                        );
                        continue;
                    }
                    Err(e) => {
                        failure = Some(format!("replan after \"{f}\" failed: {}", chain(&e)));
                        break;
                    }
                }
            }
            ExecStatus::Running => {}
        }
        actuate(sim, &cmd);
        // The disturbance, if any.
        if let Some(p) = &opts.push {
            let now = sim.time();
            let start = match p.when {
                PushWhen::At(t) => Some(t),
                PushWhen::Step { step, phase, delay_s } => {
                    let in_phase = replans == 0
                        && exec.active_step().is_some_and(|a| a.number == step)
                        && exec.phase() == Some(phase);
                    if in_phase && push_phase_start.is_none() {
                        push_phase_start = Some(now);
                    }
                    push_phase_start.map(|t0| t0 + delay_s)
                }
            };
            match (&mut push_report, start) {
                (None, Some(t0)) if now >= t0 => {
                    push_report = Some(PushReport {
                        start_s: now,
                        margin_before_m: last_margin,
                        min_margin_after_m: last_margin,
                        negative_margin_s: 0.0,
                        max_tilt_deg: 0.0,
                    });
                    sim.push_base(p.force);
                }
                (Some(r), _) if r.ended(p, now) => sim.push_base([0.0; 3]),
                _ => {}
            }
        }
        sim.step(substeps)?;
        tick += 1;
        let sample = monitor.observe(sim);
        last_margin = sample.margin;
        if let (Some(r), Some(p)) = (&mut push_report, &opts.push) {
            r.record(p, sim.time(), &sample, control_dt);
        }
        if let Some(a) = exec.active_step() {
            let key = (replans, a.number);
            if step_key != Some(key) {
                step_key = Some(key);
                step_margins.push(StepMargin {
                    step: done_executed + done_aborted + a.number,
                    leg: a.leg,
                    min_margin_m: sample.margin,
                });
            }
            if let Some(m) = step_margins.last_mut() {
                m.min_margin_m = m.min_margin_m.min(sample.margin);
            }
        }
        let commanded = exec.commanded_base();
        let track = (commanded.x - truth.x).hypot(commanded.y - truth.y);
        max_track = max_track.max(track);
        sum_track += track;
        n_track += 1;
        max_pitch = max_pitch.max(sim.base().rpy[1].abs());
        if let Some(r) = &mut recorder
            && tick.is_multiple_of(4)
        {
            r.log_bodies(sim.time(), &sim.body_poses())?;
            r.log_stability(
                &sample,
                heights.height_at_cell(sample.com[0], sample.com[1]).unwrap_or(0.0),
            )?;
            r.log_trajectory_point(sim.time(), sim.base().position)?;
            r.log_scalar(sim.time(), "tracking_error_m", track)?;
            r.log_wheel_loads(sim.time(), &sim.wheel_loads())?;
        }
        progress.set(sim.time());
    }
    // A run stopped by a failure ends with the robot holding its last posture, perhaps
    // already falling: a stranded run on generated stairs ended at the drift check with
    // the robot pitching over backward at 15.8° and reported no tip-over. The simulation
    // goes on for `WATCH_AFTER_STOP_S` with the executor holding its stance (and a push
    // still on ending on time), and the monitor keeps watching.
    if failure.is_some() {
        let until = sim.time() + WATCH_AFTER_STOP_S;
        while sim.time() < until {
            let base = sim.base();
            let truth = Pose2::new(base.position[0], base.position[1], base.rpy[2]);
            let (cmd, _) = exec.tick(&observe(sim, &base, truth, support_gap_m), control_dt);
            actuate(sim, &cmd);
            if let (Some(r), Some(p)) = (&push_report, &opts.push)
                && r.ended(p, sim.time())
            {
                sim.push_base([0.0; 3]);
            }
            sim.step(substeps)?;
            let sample = monitor.observe(sim);
            if let (Some(r), Some(p)) = (&mut push_report, &opts.push) {
                r.record(p, sim.time(), &sample, control_dt);
            }
            max_pitch = max_pitch.max(sim.base().rpy[1].abs());
        }
    }
    progress.finish();
    monitor.finish();
    let exec_wall_s = (exec_wall.elapsed().as_secs_f64() - replan_wall).max(1e-9);
    if let Some(r) = recorder.take() {
        r.finish()?;
    }
    let mut failure_kind = failure
        .as_ref()
        .map(|_| if stranded { FailureKind::Stranded } else { FailureKind::Replanning });
    if !finished && failure.is_none() {
        failure = Some(format!("time budget of {timeout} s used up"));
        failure_kind = Some(FailureKind::Timeout);
    }
    done_events.append(&mut exec.events);
    let base = sim.base();
    let goal = scenario.goal;
    let goal_position_error_m = (base.position[0] - goal.x).hypot(base.position[1] - goal.y);
    let goal_heading_error_rad = wrap_angle(base.rpy[2] - goal.theta);
    let reached_goal = goal_position_error_m <= scenario.expect.goal_tolerance_m
        && goal_heading_error_rad.abs() <= scenario.expect.goal_tolerance_deg.to_radians();
    let sim_time_s = sim.time();
    let mut summary = RunSummary {
        scenario: scenario.name.clone(),
        passed: false,
        reached_goal: reached_goal && finished,
        goal_position_error_m,
        goal_heading_error_rad,
        sim_time_s,
        wall_time_s: wall.elapsed().as_secs_f64(),
        real_time_factor: sim_time_s / exec_wall_s,
        planning_time_s,
        plan_cost: first_plan.0,
        plan_steps: first_plan.1,
        steps_executed: done_executed + exec.steps_executed,
        steps_planned,
        steps_aborted: done_aborted + exec.steps_aborted,
        replans,
        keyframes: first_plan.2,
        step_margins,
        executor_events: done_events,
        failure,
        failure_kind,
        push: push_report,
        min_stability_margin_m: monitor.min_margin,
        min_instant_margin_m: monitor.min_instant_margin,
        static_violation_s: monitor.static_violation_s,
        worst_static_violation_m: monitor.worst_violation_m,
        tipped: monitor.tipped(),
        body_collisions: monitor.collided_bodies(),
        max_tracking_error_m: max_track,
        mean_tracking_error_m: if n_track > 0 { sum_track / n_track as f64 } else { 0.0 },
        max_pitch_deg: max_pitch.to_degrees(),
        max_tilt_deg: monitor.max_tilt.to_degrees(),
        expectations: Vec::new(),
        events: monitor.events.clone(),
    };
    summary.expectations = expectations(scenario, &summary);
    summary.passed = summary.expectations.iter().all(|e| e.passed);
    Ok(summary)
}
