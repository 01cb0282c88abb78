//! `momaro run`: plan a scenario, then execute the plan in closed loop in MuJoCo until the
//! goal is reached or the scenario's time budget runs out (paper Sec. IX).
//!
//! Each 10 ms control tick: the measured base pose (optionally with seeded noise) goes to
//! the B-spline path follower, whose twist goes through the omnidirectional wheel
//! kinematics to steering and wheel targets; leg joint targets come from the driving
//! posture of `motion::kinematics` (each foot on the height map's ground, the base pitched by
//! 70 % of the slope under the feet, Sec. VI-B), so the robot follows ramps. The stability monitor measures the margin
//! of MuJoCo's CoM over the wheels MuJoCo reports in contact. The scenario's expectations
//! decide the verdict.
//!
//! Executing abstract steps (issue 7) is not built yet: a plan with steps is reported as a
//! clear error, not driven.

use super::plan::{self, PathKind, PlanJobError, PlanOptions, PlanSummary};
use super::sim::{CONTROL_HZ, SETTLE_S};
use crate::control::path_follower::{FollowerConfig, FollowerError, FollowerStatus, PathFollower};
use crate::control::wheels::WheelKinematics;
use crate::geometry::{Pose2, wrap_angle};
use crate::monitor::{MonitorEvent, MonitorLimits, StabilityMonitor};
use crate::motion::kinematics::{driving_posture, leg_joint_targets};
use crate::progress::SimProgress;
use crate::robot::Leg;
use crate::robot::ik::IkError;
use crate::scenario::{Scenario, Stepping};
use crate::sim::{SimError, Simulation};
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
    Plan(#[from] PlanJobError),
    /// The plan contains steps, which the executor cannot do yet.
    #[error(
        "{scenario}: the plan contains {steps} steps; executing steps is not implemented yet (issue 7)"
    )]
    SteppingUnsupported {
        /// Scenario name.
        scenario: String,
        /// Steps in the plan.
        steps: usize,
    },
    /// The height map could not be built.
    #[error(transparent)]
    Costmap(#[from] super::costmap::CostmapError),
    /// The cost layers for the recording could not be built.
    #[error(transparent)]
    Cost(#[from] crate::cost::CostError),
    /// The robot stands where the height map knows no ground.
    #[error("no ground height known under a foot at ({x:.3}, {y:.3})")]
    UnknownGround {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
    },
    /// The follower rejected the path or its configuration.
    #[error("path follower: {0}")]
    Follower(#[from] FollowerError),
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

/// Seeded noise on the measured base pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseNoise {
    /// Standard deviation of x and y, m.
    pub position_std_m: f64,
    /// Standard deviation of yaw, rad.
    pub yaw_std_rad: f64,
    /// Seed of the generator.
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
    /// Steps executed.
    pub steps_executed: usize,
    /// Smallest measured stability margin after settling, m.
    pub min_stability_margin_m: f64,
    /// A tip-over was seen.
    pub tipped: bool,
    /// Robot bodies other than wheels that touched terrain.
    pub body_collisions: Vec<String>,
    /// Largest cross-track error of the path follower, m.
    pub max_tracking_error_m: f64,
    /// Mean cross-track error, m.
    pub mean_tracking_error_m: f64,
    /// Largest |base pitch| seen, degrees.
    pub max_pitch_deg: f64,
    /// The expectations and their results.
    pub expectations: Vec<ExpectationResult>,
    /// Monitor events.
    pub events: Vec<MonitorEvent>,
}

/// A small deterministic generator (xorshift64*) with Box–Muller normals, so noisy runs are
/// reproducible without another dependency.
struct Noise {
    state: u64,
}

impl Noise {
    fn new(seed: u64) -> Self {
        Self { state: seed.max(1) }
    }

    fn uniform(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let v = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

fn expectations(scenario: &Scenario, s: &RunSummary) -> Vec<ExpectationResult> {
    let e = &scenario.expect;
    let mut out = Vec::new();
    if e.reach_goal {
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
        Stepping::Required => out.push(ExpectationResult {
            name: "stepping",
            passed: s.plan_steps > 0,
            detail: format!("{} steps planned, steps required", s.plan_steps),
        }),
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

/// Plans and executes `scenario` in closed loop.
///
/// # Errors
/// [`RunJobError`] if planning fails, the plan needs steps, or the simulation fails.
pub fn run(scenario: &Scenario, opts: &RunOptions) -> Result<RunSummary, RunJobError> {
    let wall = Instant::now();
    let mut sim = Simulation::new(scenario, &opts.model_path)?;
    let robot = sim.robot().clone();
    let plan: PlanSummary = plan::run(scenario, &robot, &opts.plan)?;
    if plan.steps > 0 {
        return Err(RunJobError::SteppingUnsupported {
            scenario: scenario.name.clone(),
            steps: plan.steps,
        });
    }
    let heights = super::costmap::rasterised_map(scenario)?;
    let poses: Vec<Pose2> = plan
        .path
        .iter()
        .filter(|e| matches!(e.kind, PathKind::Start | PathKind::Drive | PathKind::Turn))
        .map(|e| e.pose)
        .collect();
    let mut follower = PathFollower::new(poses.clone(), opts.follower.clone())?;
    super::stand_at_start(&mut sim, scenario)?;

    let params = &scenario.params;
    let mut recorder = match &opts.rerun {
        Some(path) => {
            let mut r = Recorder::create(path, "momaro run")?;
            r.log_world(&sim.geom_shapes(), &sim.body_poses())?;
            r.log_height_map(&heights)?;
            let maps = crate::cost::CostMaps::build(&heights, &robot, params)?;
            let (nx, ny) = heights.dims();
            let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
            if let Some(img) = crate::cost_image::cost_layer_image(&foot, nx, ny, None) {
                r.log_layer_image("foot_cost", &img, heights.origin(), heights.resolution())?;
            }
            r.log_plan(&poses)?;
            Some(r)
        }
        None => None,
    };

    let dt = sim.timestep();
    let substeps = ((1.0 / CONTROL_HZ) / dt).round().max(1.0) as usize;
    let control_dt = substeps as f64 * dt;
    let kin = WheelKinematics::default();
    let feet = robot.neutral_footprint();
    let mut monitor = StabilityMonitor::new(MonitorLimits::default());
    let mut noise = opts.noise.map(|n| (n, Noise::new(n.seed)));
    let timeout = scenario.expect.timeout_s;
    let progress = SimProgress::new(&scenario.name, timeout, opts.progress);
    let (mut max_track, mut sum_track, mut n_track, mut max_pitch) = (0.0f64, 0.0, 0usize, 0.0f64);
    let exec_wall = Instant::now();
    let mut finished = false;
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
        let out = follower.update(measured, control_dt);
        if out.status == FollowerStatus::Finished {
            finished = true;
            break;
        }
        // Leg heights from the height map, base pitched by 70 % of the slope (Sec. VI-B).
        let posture = driving_posture(
            &robot,
            &truth,
            params.driving_leg_height_m,
            params.base_pitch_slope_fraction,
            |x, y| heights.bilinear(x, y).or_else(|| heights.height_at_cell(x, y)),
        )
        .map_err(|[x, y]| RunJobError::UnknownGround { x, y })?;
        let legs = leg_joint_targets(&robot, &posture)?;
        let steer = Leg::ALL.map(|l| sim.steering_angle(l));
        let commands = kin.commands(&robot, out.twist, &feet, &steer);
        for leg in Leg::ALL {
            let i = leg.index();
            let c = kin.with_steering_rate(&robot, commands[i], sim.steering_rate(leg));
            sim.set_leg_joint_targets(leg, legs[i]);
            sim.set_steering_target(leg, c.steer);
            sim.set_wheel_speeds(leg, c.wheel_speeds);
        }
        sim.step(substeps)?;
        tick += 1;
        let sample = StabilityMonitor::measure(&sim);
        if sim.time() >= SETTLE_S {
            monitor.record(&sample);
        }
        max_track = max_track.max(out.cross_track_m.abs());
        sum_track += out.cross_track_m.abs();
        n_track += 1;
        max_pitch = max_pitch.max(sim.base().rpy[1].abs());
        if let Some(r) = &recorder
            && tick.is_multiple_of(4)
        {
            r.log_bodies(sim.time(), &sim.body_poses())?;
            r.log_stability(
                &sample,
                heights.height_at_cell(sample.com[0], sample.com[1]).unwrap_or(0.0),
            )?;
            r.log_trajectory_point(sim.time(), sim.base().position)?;
            r.log_scalar(sim.time(), "tracking_error_m", out.cross_track_m)?;
        }
        progress.set(sim.time());
    }
    progress.finish();
    let exec_wall_s = exec_wall.elapsed().as_secs_f64();
    if let Some(r) = recorder.take() {
        r.finish()?;
    }
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
        real_time_factor: sim_time_s / exec_wall_s.max(1e-9),
        planning_time_s: plan.planning_time_s,
        plan_cost: plan.cost,
        plan_steps: plan.steps,
        steps_executed: 0,
        min_stability_margin_m: monitor.min_margin,
        tipped: monitor.tipped(),
        body_collisions: monitor.collided_bodies(),
        max_tracking_error_m: max_track,
        mean_tracking_error_m: if n_track > 0 { sum_track / n_track as f64 } else { 0.0 },
        max_pitch_deg: max_pitch.to_degrees(),
        expectations: Vec::new(),
        events: monitor.events.clone(),
    };
    summary.expectations = expectations(scenario, &summary);
    summary.passed = summary.expectations.iter().all(|e| e.passed);
    Ok(summary)
}
