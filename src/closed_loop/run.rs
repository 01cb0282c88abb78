//! The closed loop itself ([`ClosedLoop`]), driven one control tick at a time: observe the
//! simulated robot, let the step executor command it (replanning from where it stands
//! when the executor leaves the plan), act, step MuJoCo, monitor static stability, and
//! record. [`run`] plans a scenario's mission and runs the loop to its end; [`execute`]
//! runs it on a mission and a simulation the caller prepared.

use super::io::{actuate, observe, stand_at_start};
use super::mission::{Mission, REPLAN_START_RADIUS_M, plan_mission};
use super::options::{CONTROL_HZ, PoseNoise, PushWhen, RunOptions, SETTLE_S};
use super::summary::{FailureKind, PushReport, RunError, RunSummary, StepMargin, expectations};
use crate::control::step_executor::{ExecEvent, ExecStatus, ExecutorConfig, StepExecutor};
use crate::geometry::{Pose2, wrap_angle};
use crate::monitor::{MonitorLimits, StabilityMonitor, StabilitySample};
use crate::motion::manoeuvres::ALL;
use crate::planner::{self, PlanError, PlanOptions, Prepared};
use crate::progress::SimProgress;
use crate::rng::Rng;
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use crate::search::Termination;
use crate::sim::Simulation;
use crate::terrain::{HeightMap, scenario_map};
use crate::viz::{Recorder, VizError};
use std::time::Instant;

/// How long the simulation goes on, the executor holding its stance, after a failure
/// stops a run (stranded, no replan left, a replan that failed), s: long enough for a
/// robot tipping over when the run stopped to fall (a fall from standing height takes
/// about 0.3 s, a slow tip about 1 s).
pub const WATCH_AFTER_STOP_S: f64 = 2.0;

/// What one control tick left ([`ClosedLoop::step`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tick {
    /// The run goes on.
    Running,
    /// The run has ended (the executor finished, a failure stopped it, or the scenario's
    /// time budget ran out): [`ClosedLoop::finish`] gives its summary.
    Ended,
}

/// A run of a mission in closed loop, one control tick per [`Self::step`] (see the module
/// docs). It borrows the simulation and the prepared world, so a caller can set both up,
/// drive the loop, and look at them afterwards.
pub struct ClosedLoop<'a> {
    scenario: &'a Scenario,
    opts: &'a RunOptions,
    prep: &'a mut Prepared,
    sim: &'a mut Simulation,
    robot: RobotDescription,
    /// The executor's height map: the map extent with an r_N margin, built once.
    heights: HeightMap,
    config: ExecutorConfig,
    exec: StepExecutor,
    recorder: Option<Recorder>,
    monitor: StabilityMonitor,
    noise: Option<(PoseNoise, Rng)>,
    progress: SimProgress,
    substeps: usize,
    control_dt: f64,
    support_gap_m: f64,
    timeout: f64,
    /// When the job started, and the execution.
    wall: Instant,
    exec_wall: Instant,
    /// Wall time spent replanning, s.
    replan_wall: f64,
    /// The first plan's cost, steps and keyframes.
    first_plan: (f64, usize, usize),
    planning_time_s: f64,
    steps_planned: usize,
    /// Path follower tracking: largest and summed error, samples; largest |pitch|.
    tracking: (f64, f64, usize),
    max_pitch: f64,
    finished: bool,
    failure: Option<String>,
    stranded: bool,
    replans: usize,
    /// Counters of executors replaced by a replan.
    done_executed: usize,
    done_aborted: usize,
    done_events: Vec<ExecEvent>,
    step_margins: Vec<StepMargin>,
    step_key: Option<(usize, usize)>,
    /// Push: the phase's start, the report (from the push's start).
    push_phase_start: Option<f64>,
    push_report: Option<PushReport>,
    last_margin: f64,
    tick: usize,
    ended: bool,
}

impl<'a> ClosedLoop<'a> {
    /// Starts executing `mission` in `sim` from its current state (the robot standing at
    /// the plan's start), replanning on the world `prep` (`planner::prepare_for` with
    /// `opts.plan`, which the mission was planned on) when the executor leaves the plan;
    /// `wall` is when the job started. Opens the recording, if asked for.
    ///
    /// # Errors
    /// [`RunError`] if the executor's map cannot be built or the recording fails.
    pub fn start(
        scenario: &'a Scenario,
        prep: &'a mut Prepared,
        sim: &'a mut Simulation,
        mission: Mission,
        opts: &'a RunOptions,
        wall: Instant,
    ) -> Result<Self, RunError> {
        let robot = sim.robot().clone();
        let heights = scenario_map(scenario)
            .map_err(|source| RunError::Map { scenario: scenario.name.clone(), source })?;
        let config = ExecutorConfig::from_params(&scenario.params, opts.follower.clone());
        let first_plan = (mission.plan.cost, mission.plan.steps, mission.detailed.keyframes.len());
        let exec = StepExecutor::new(
            &robot,
            config.clone(),
            mission.detailed.keyframes.clone(),
            heights.clone(),
        );
        let recorder = match &opts.rerun {
            Some(path) => Some(open_recording(path, sim, prep, &heights, &mission)?),
            None => None,
        };
        let dt = sim.timestep();
        let substeps = ((1.0 / CONTROL_HZ) / dt).round().max(1.0) as usize;
        let limits = MonitorLimits { settle_s: SETTLE_S, ..MonitorLimits::default() };
        let timeout = scenario.expect.timeout_s;
        Ok(Self {
            scenario,
            opts,
            prep,
            robot,
            heights,
            config,
            exec,
            recorder,
            monitor: StabilityMonitor::new(limits),
            noise: opts.noise.map(|n| (n, Rng::from_state(n.seed))),
            progress: SimProgress::new(&scenario.name, timeout, opts.progress),
            substeps,
            control_dt: substeps as f64 * dt,
            support_gap_m: limits.support_gap_m,
            timeout,
            wall,
            exec_wall: Instant::now(),
            replan_wall: 0.0,
            first_plan,
            planning_time_s: mission.plan.planning_time_s,
            steps_planned: mission.detailed.steps,
            tracking: (0.0, 0.0, 0),
            max_pitch: 0.0,
            finished: false,
            failure: None,
            stranded: false,
            replans: 0,
            done_executed: 0,
            done_aborted: 0,
            done_events: Vec::new(),
            step_margins: Vec::new(),
            step_key: None,
            push_phase_start: None,
            push_report: None,
            last_margin: f64::INFINITY,
            tick: 0,
            ended: false,
            sim,
        })
    }

    /// The simulation.
    pub fn sim(&self) -> &Simulation {
        self.sim
    }

    /// Replans so far.
    pub fn replans(&self) -> usize {
        self.replans
    }

    /// The step executor running the current plan.
    pub fn executor(&self) -> &StepExecutor {
        &self.exec
    }

    /// One control tick: observe, command (or replan), act, step the physics, monitor,
    /// record. [`Tick::Ended`] once the run is over.
    ///
    /// # Errors
    /// [`RunError`] if the simulation diverges or the recording fails.
    pub fn step(&mut self) -> Result<Tick, RunError> {
        if self.ended || self.sim.time() >= self.timeout {
            self.ended = true;
            return Ok(Tick::Ended);
        }
        let base = self.sim.base();
        let truth = Pose2::new(base.position[0], base.position[1], base.rpy[2]);
        let measured = match &mut self.noise {
            Some((n, g)) => Pose2::new(
                truth.x + n.position_std_m * g.normal(),
                truth.y + n.position_std_m * g.normal(),
                truth.theta + n.yaw_std_rad * g.normal(),
            ),
            None => truth,
        };
        let obs = observe(self.sim, &base, measured, self.support_gap_m);
        let (cmd, status) = self.exec.tick(&obs, self.control_dt);
        match status {
            ExecStatus::Finished => {
                self.finished = true;
                self.ended = true;
                return Ok(Tick::Ended);
            }
            ExecStatus::Stranded { failure: f, reason } => {
                self.failure = Some(format!("{f}; stranded: {reason}"));
                self.stranded = true;
                self.ended = true;
                return Ok(Tick::Ended);
            }
            ExecStatus::NeedsReplan(f) => {
                if self.replans >= self.opts.max_replans {
                    self.failure = Some(format!("{f}; no replans left ({} used)", self.replans));
                    self.ended = true;
                    return Ok(Tick::Ended);
                }
                self.replans += 1;
                if let Err(e) = self.replan(truth) {
                    self.failure = Some(format!("replan after \"{f}\" failed: {}", chain(&e)));
                    self.ended = true;
                    return Ok(Tick::Ended);
                }
                return Ok(Tick::Running);
            }
            ExecStatus::Running => {}
        }
        actuate(self.sim, &cmd);
        self.push();
        self.sim.step(self.substeps)?;
        self.tick += 1;
        let sample = self.monitor.observe(self.sim);
        self.last_margin = sample.margin;
        if let (Some(r), Some(p)) = (&mut self.push_report, &self.opts.push) {
            r.record(p, self.sim.time(), &sample, self.control_dt);
        }
        self.note_step_margin(&sample);
        let commanded = self.exec.commanded_base();
        let track = (commanded.x - truth.x).hypot(commanded.y - truth.y);
        let (max, sum, n) = self.tracking;
        self.tracking = (max.max(track), sum + track, n + 1);
        self.max_pitch = self.max_pitch.max(self.sim.base().rpy[1].abs());
        self.record(&sample, track)?;
        self.progress.set(self.sim.time());
        Ok(Tick::Running)
    }

    /// Plans again from where the robot stands (`truth`), on the run's world, and hands
    /// the new mission to a fresh executor.
    fn replan(&mut self, truth: Pose2) -> Result<(), RunError> {
        let t = Instant::now();
        let mut from_here = self.scenario.clone();
        from_here.start =
            planner::nearest_start(self.prep, &self.robot, truth, REPLAN_START_RADIUS_M);
        // A replan's own time limit, unless the plans have an expansion budget: then the
        // run's limit holds for it too, so that its outcome does not depend on the load.
        let time_limit_s = match self.opts.plan.max_expansions {
            Some(_) => self.opts.plan.time_limit_s,
            None => self.opts.replan_time_limit_s,
        };
        let replan_opts = PlanOptions { time_limit_s, ..self.opts.plan.clone() };
        let result = self
            .prep
            .set_start(&from_here, &self.robot, from_here.start)
            .map_err(RunError::from)
            .and_then(|()| plan_mission(self.prep, &from_here, self.sim, &replan_opts));
        self.replan_wall += t.elapsed().as_secs_f64();
        let m = result?;
        self.done_executed += self.exec.steps_executed;
        self.done_aborted += self.exec.steps_aborted;
        self.done_events.append(&mut self.exec.events);
        self.planning_time_s += m.plan.planning_time_s;
        self.steps_planned = self.done_executed + m.detailed.steps;
        if let Some(r) = &self.recorder {
            log_mission(r, &m)?;
        }
        self.exec = StepExecutor::new(
            &self.robot,
            self.config.clone(),
            m.detailed.keyframes,
            self.heights.clone(),
        );
        Ok(())
    }

    /// The disturbance, if any: starts, or ends, the push on the base.
    fn push(&mut self) {
        let Some(p) = &self.opts.push else {
            return;
        };
        let now = self.sim.time();
        let start = match p.when {
            PushWhen::At(t) => Some(t),
            PushWhen::Step { step, phase, delay_s } => {
                let in_phase = self.replans == 0
                    && self.exec.active_step().is_some_and(|a| a.number == step)
                    && self.exec.phase() == Some(phase);
                if in_phase && self.push_phase_start.is_none() {
                    self.push_phase_start = Some(now);
                }
                self.push_phase_start.map(|t0| t0 + delay_s)
            }
        };
        match (&mut self.push_report, start) {
            (None, Some(t0)) if now >= t0 => {
                self.push_report = Some(PushReport {
                    start_s: now,
                    margin_before_m: self.last_margin,
                    min_margin_after_m: self.last_margin,
                    negative_margin_s: 0.0,
                    max_tilt_deg: 0.0,
                });
                self.sim.push_base(p.force);
            }
            (Some(r), _) if r.ended(p, now) => self.sim.push_base([0.0; 3]),
            _ => {}
        }
    }

    /// Keeps the smallest margin of the step under way.
    fn note_step_margin(&mut self, sample: &StabilitySample) {
        let Some(a) = self.exec.active_step() else {
            return;
        };
        let key = (self.replans, a.number);
        if self.step_key != Some(key) {
            self.step_key = Some(key);
            self.step_margins.push(StepMargin {
                step: self.done_executed + self.done_aborted + a.number,
                leg: a.leg,
                min_margin_m: sample.margin,
            });
        }
        if let Some(m) = self.step_margins.last_mut() {
            m.min_margin_m = m.min_margin_m.min(sample.margin);
        }
    }

    /// Every fourth tick, the bodies, stability, trajectory and plots into the recording.
    fn record(&mut self, sample: &StabilitySample, track: f64) -> Result<(), RunError> {
        let Some(r) = &mut self.recorder else {
            return Ok(());
        };
        if !self.tick.is_multiple_of(4) {
            return Ok(());
        }
        let t = self.sim.time();
        r.log_bodies(t, &self.sim.body_poses())?;
        let ground = self.heights.height_at_cell(sample.com[0], sample.com[1]).unwrap_or(0.0);
        r.log_stability(sample, ground)?;
        r.log_trajectory_point(t, self.sim.base().position)?;
        r.log_scalar(t, "tracking_error_m", track)?;
        r.log_wheel_loads(t, &self.sim.wheel_loads())?;
        Ok(())
    }

    /// Ends the run and gives its summary. A run stopped by a failure ends with the robot
    /// holding its last posture, perhaps already falling: a stranded run on generated
    /// stairs ended at the drift check with the robot pitching over backward at 15.8° and
    /// reported no tip-over. So the simulation goes on for [`WATCH_AFTER_STOP_S`] with the
    /// executor holding its stance (and a push still on ending on time), and the monitor
    /// keeps watching.
    ///
    /// # Errors
    /// [`RunError`] if the simulation diverges or the recording fails.
    pub fn finish(mut self) -> Result<RunSummary, RunError> {
        if self.failure.is_some() {
            self.watch_after_stop()?;
        }
        self.progress.finish();
        self.monitor.finish();
        let exec_wall_s = (self.exec_wall.elapsed().as_secs_f64() - self.replan_wall).max(1e-9);
        if let Some(r) = self.recorder.take() {
            r.finish()?;
        }
        let (finished, stranded) = (self.finished, self.stranded);
        let mut failure = self.failure.take();
        let mut failure_kind = failure
            .as_ref()
            .map(|_| if stranded { FailureKind::Stranded } else { FailureKind::Replanning });
        if !finished && failure.is_none() {
            failure = Some(format!("time budget of {} s used up", self.timeout));
            failure_kind = Some(FailureKind::Timeout);
        }
        let mut events = std::mem::take(&mut self.done_events);
        events.append(&mut self.exec.events);
        let (scenario, sim, monitor) = (self.scenario, &self.sim, &self.monitor);
        let base = sim.base();
        let goal = scenario.goal;
        let goal_position_error_m = (base.position[0] - goal.x).hypot(base.position[1] - goal.y);
        let goal_heading_error_rad = wrap_angle(base.rpy[2] - goal.theta);
        let reached_goal = goal_position_error_m <= scenario.expect.goal_tolerance_m
            && goal_heading_error_rad.abs() <= scenario.expect.goal_tolerance_deg.to_radians();
        let sim_time_s = sim.time();
        let (max_track, sum_track, n_track) = self.tracking;
        let mut summary = RunSummary {
            scenario: scenario.name.clone(),
            passed: false,
            reached_goal: reached_goal && finished,
            goal_position_error_m,
            goal_heading_error_rad,
            sim_time_s,
            wall_time_s: self.wall.elapsed().as_secs_f64(),
            real_time_factor: sim_time_s / exec_wall_s,
            planning_time_s: self.planning_time_s,
            plan_cost: self.first_plan.0,
            plan_steps: self.first_plan.1,
            steps_executed: self.done_executed + self.exec.steps_executed,
            steps_planned: self.steps_planned,
            steps_aborted: self.done_aborted + self.exec.steps_aborted,
            replans: self.replans,
            keyframes: self.first_plan.2,
            step_margins: std::mem::take(&mut self.step_margins),
            executor_events: events,
            failure,
            failure_kind,
            push: self.push_report,
            min_stability_margin_m: monitor.min_margin,
            min_instant_margin_m: monitor.min_instant_margin,
            static_violation_s: monitor.static_violation_s,
            worst_static_violation_m: monitor.worst_violation_m,
            tipped: monitor.tipped(),
            body_collisions: monitor.collided_bodies(),
            max_tracking_error_m: max_track,
            mean_tracking_error_m: if n_track > 0 { sum_track / n_track as f64 } else { 0.0 },
            max_pitch_deg: self.max_pitch.to_degrees(),
            max_tilt_deg: monitor.max_tilt.to_degrees(),
            expectations: Vec::new(),
            events: monitor.events.clone(),
        };
        summary.expectations = expectations(scenario, &summary);
        summary.passed = summary.expectations.iter().all(|e| e.passed);
        Ok(summary)
    }

    /// The [`WATCH_AFTER_STOP_S`] after a failure stopped the run (see [`Self::finish`]).
    fn watch_after_stop(&mut self) -> Result<(), RunError> {
        let until = self.sim.time() + WATCH_AFTER_STOP_S;
        while self.sim.time() < until {
            let base = self.sim.base();
            let truth = Pose2::new(base.position[0], base.position[1], base.rpy[2]);
            let obs = observe(self.sim, &base, truth, self.support_gap_m);
            let (cmd, _) = self.exec.tick(&obs, self.control_dt);
            actuate(self.sim, &cmd);
            if let (Some(r), Some(p)) = (&self.push_report, &self.opts.push)
                && r.ended(p, self.sim.time())
            {
                self.sim.push_base([0.0; 3]);
            }
            self.sim.step(self.substeps)?;
            let sample = self.monitor.observe(self.sim);
            if let (Some(r), Some(p)) = (&mut self.push_report, &self.opts.push) {
                r.record(p, self.sim.time(), &sample, self.control_dt);
            }
            self.max_pitch = self.max_pitch.max(self.sim.base().rpy[1].abs());
        }
        Ok(())
    }

    /// Steps until the run ends, then [`Self::finish`].
    ///
    /// # Errors
    /// As [`Self::step`] and [`Self::finish`].
    pub fn run_to_end(mut self) -> Result<RunSummary, RunError> {
        while self.step()? == Tick::Running {}
        self.finish()
    }
}

/// The recording of a run: the world, the height map, the planner's foot-cost layer and
/// the first mission.
fn open_recording(
    path: &std::path::Path,
    sim: &Simulation,
    prep: &Prepared,
    heights: &HeightMap,
    mission: &Mission,
) -> Result<Recorder, VizError> {
    let mut r = Recorder::create(path, "momaro run")?;
    r.log_world(&sim.geom_shapes(), &sim.body_poses())?;
    r.log_height_map(heights)?;
    let (maps, planned) = (&prep.maps, prep.maps.heights());
    let (nx, ny) = planned.dims();
    let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
    if let Some(img) = crate::render::cost_layer_image(&foot, nx, ny, None) {
        r.log_layer_image("foot_cost", &img, planned.origin(), planned.resolution())?;
    }
    log_mission(&r, mission)?;
    Ok(r)
}

/// A mission's path, steps and keyframes into the recording.
fn log_mission(r: &Recorder, m: &Mission) -> Result<(), VizError> {
    let poses: Vec<Pose2> = m.plan.path.iter().map(|e| e.pose).collect();
    r.log_plan(&poses)?;
    r.log_steps(&crate::viz::step_lines(&m.plan.path))?;
    r.log_keyframes(&m.detailed.keyframes)
}

/// Plans, expands and executes `scenario` in closed loop: the library's whole run.
///
/// # Errors
/// [`RunError`] if the world cannot be built or the simulation fails. A course with no
/// path or a plan the generator cannot expand is a summary, not an error.
pub fn run(scenario: &Scenario, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let wall = Instant::now();
    let mut sim = Simulation::new(scenario, &opts.model_path)?;
    // One world for the run: every plan (retries, replans), the generator and the
    // recording use its maps, and the plans share its heuristic toward the goal.
    let mut prep = planner::prepare_for(scenario, sim.robot(), &opts.plan, &ALL)?;
    let mission = match plan_mission(&prep, scenario, &mut sim, &opts.plan) {
        Ok(m) => m,
        Err(e) => return unexecuted(scenario, e, wall),
    };
    stand_at_start(&mut sim, scenario)?;
    execute(scenario, &mut prep, &mut sim, mission, opts, wall)
}

/// Executes `mission` in `sim` from its current state (the robot standing at the plan's
/// start), replanning on the world `prep` when the executor leaves the plan: a
/// [`ClosedLoop`] run to its end.
///
/// # Errors
/// [`RunError`] if the maps cannot be built, the simulation diverges or the recording
/// fails. A run that fails its expectations is a summary with `passed = false`.
pub fn execute(
    scenario: &Scenario,
    prep: &mut Prepared,
    sim: &mut Simulation,
    mission: Mission,
    opts: &RunOptions,
    wall: Instant,
) -> Result<RunSummary, RunError> {
    ClosedLoop::start(scenario, prep, sim, mission, opts, wall)?.run_to_end()
}

/// The summary of a run that never started executing because planning ended without a
/// path or the plan could not be expanded; other errors pass through.
fn unexecuted(scenario: &Scenario, e: RunError, wall: Instant) -> Result<RunSummary, RunError> {
    let kind = match &e {
        RunError::Plan(PlanError::NoPath { termination, .. }) => match termination {
            Termination::NoPath => FailureKind::NoPath,
            _ => FailureKind::PlanningTimeLimit,
        },
        RunError::Motion { .. } => FailureKind::MotionGeneration,
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
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    s
}
