//! What a closed-loop run reports ([`RunSummary`], `run --json`), why a run could not be
//! carried out ([`RunError`]), and the scenario's expectations judged on the summary.

use super::options::Push;
use crate::control::step_executor::ExecEvent;
use crate::monitor::{MonitorEvent, StabilitySample};
use crate::motion::MotionError;
use crate::planner::PlanError;
use crate::robot::Leg;
use crate::robot::ik::IkError;
use crate::scenario::{Outcome, Scenario, Stepping};
use crate::sim::SimError;
use crate::terrain::RasteriseError;
use crate::viz::VizError;
use serde::Serialize;

/// Why a run could not be carried out (a run that fails its expectations is not an error:
/// it is a summary with `passed = false`).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
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
    /// The executor's height map could not be built.
    #[error("{scenario}: cannot build the height map: {source}")]
    Map {
        /// Scenario name.
        scenario: String,
        /// The cause.
        source: RasteriseError,
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
    pub fn ended(&self, push: &Push, now: f64) -> bool {
        now >= self.start_s + push.duration_s
    }

    /// Takes in a monitor `sample` at `now`, a control tick of `dt` s after the last,
    /// while in the window (until 2 s after `push` ends).
    pub fn record(&mut self, push: &Push, now: f64, sample: &StabilitySample, dt: f64) {
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

/// The scenario's expectations, judged on summary `s`: `outcome = "no_path"` alone, or the
/// goal reached, the stepping asked for, the held margin, the static violations, no
/// tip-over and no body collision.
pub fn expectations(scenario: &Scenario, s: &RunSummary) -> Vec<ExpectationResult> {
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
