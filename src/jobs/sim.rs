//! `momaro sim`: the scenario's world run headless, the robot holding its neutral driving
//! posture under a standing controller, optionally driving a constant body twist through
//! the omnidirectional wheel kinematics, while the stability monitor measures it.

use crate::closed_loop::options::{CONTROL_HZ, SETTLE_S};
use crate::control::wheels::{Twist, WheelKinematics};
use crate::geometry::wrap_angle;
use crate::monitor::{MonitorEvent, MonitorLimits, StabilityMonitor};
use crate::progress::SimProgress;
use crate::robot::Leg;
use crate::robot::ik::IkError;
use crate::scenario::Scenario;
use crate::sim::{SimError, Simulation};
use crate::viz::{Recorder, VizError};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// Why a sim job failed.
#[derive(Debug, thiserror::Error)]
pub enum SimJobError {
    /// Building or stepping the simulation failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The standing posture is out of the legs' reach.
    #[error("cannot hold the driving posture: {0}")]
    Posture(#[from] IkError),
    /// Writing the recording failed.
    #[error(transparent)]
    Viz(#[from] VizError),
    /// An option is out of range.
    #[error("invalid option `{option}`: {reason}")]
    BadOption {
        /// The option.
        option: &'static str,
        /// Why.
        reason: String,
    },
}

/// Options of a sim job.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// Simulated duration, s.
    pub duration_s: f64,
    /// Constant body twist to drive, if any.
    pub drive: Option<Twist>,
    /// Robot model file.
    pub model_path: PathBuf,
    /// Rerun recording to write, if any.
    pub rerun: Option<PathBuf>,
    /// Draw a progress bar on a terminal.
    pub progress: bool,
}

/// Linear and angular acceleration limits of the commanded twist, m/s², rad/s².
const ACCEL_LIMITS: [f64; 2] = [1.0, 2.0];
/// Recording rate of body poses, Hz.
const RECORD_HZ: f64 = 25.0;

/// Result of a sim job, as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
pub struct SimSummary {
    /// Scenario name.
    pub scenario: String,
    /// Simulated time, s.
    pub sim_time_s: f64,
    /// Wall-clock time of the loop, s.
    pub wall_time_s: f64,
    /// Simulated over wall time.
    pub real_time_factor: f64,
    /// Base pose at the start: x, y, z (m), yaw (rad).
    pub base_start: [f64; 4],
    /// Base pose at the end: x, y, z (m), yaw (rad).
    pub base_end: [f64; 4],
    /// Base height above the ground in the neutral driving posture, from the model, m.
    pub nominal_base_height_m: f64,
    /// Commanded twist.
    pub drive: Option<Twist>,
    /// Fewest wheels in ground contact after settling.
    pub min_wheels_in_contact: usize,
    /// Smallest static stability margin after settling, m.
    pub min_stability_margin_m: f64,
    /// Largest |roll| or |pitch|, degrees.
    pub max_tilt_deg: f64,
    /// Never tipped (margin ≥ 0 and tilt within limits throughout).
    pub upright: bool,
    /// Robot bodies that touched terrain.
    pub body_collisions: Vec<String>,
    /// Monitor events.
    pub events: Vec<MonitorEvent>,
    /// The robot's mass, from the model, kg.
    pub total_mass_kg: f64,
    /// Load on each leg's wheel pair at the end (MuJoCo's contact forces), N.
    pub wheel_loads_end_n: [f64; 4],
}

fn pose4(sim: &Simulation) -> [f64; 4] {
    let b = sim.base();
    [b.position[0], b.position[1], b.position[2], b.rpy[2]]
}

fn ramp(current: f64, target: f64, max_step: f64) -> f64 {
    current + (target - current).clamp(-max_step, max_step)
}

/// Runs the sim job.
///
/// # Errors
/// [`SimJobError`] if the world cannot be built, the posture is unreachable, the physics
/// diverges or the recording cannot be written.
pub fn run(scenario: &Scenario, opts: &SimOptions) -> Result<SimSummary, SimJobError> {
    if !(opts.duration_s.is_finite() && opts.duration_s > 0.0) {
        return Err(SimJobError::BadOption {
            option: "--duration",
            reason: format!("{} must be > 0", opts.duration_s),
        });
    }
    if let Some(t) = opts.drive
        && !(t.vx.is_finite() && t.vy.is_finite() && t.wz.is_finite())
    {
        return Err(SimJobError::BadOption {
            option: "--drive",
            reason: "components must be finite".into(),
        });
    }
    let mut sim = Simulation::new(scenario, &opts.model_path)?;
    let robot = sim.robot().clone();
    let (posture, nominal_base_height) = crate::closed_loop::stand_at_start(&mut sim, scenario)?;

    let mut recorder = match &opts.rerun {
        Some(path) => {
            let mut r = Recorder::create(path, "momaro sim")?;
            r.log_world(&sim.geom_shapes(), &sim.body_poses())?;
            Some(r)
        }
        None => None,
    };

    let dt = sim.timestep();
    let substeps = ((1.0 / CONTROL_HZ) / dt).round().max(1.0) as usize;
    let control_dt = substeps as f64 * dt;
    let record_every = ((CONTROL_HZ / RECORD_HZ).round() as usize).max(1);
    let kin = WheelKinematics::default();
    let feet = robot.neutral_footprint();
    let target = opts.drive.unwrap_or_default();
    let mut twist = Twist::default();
    let mut monitor =
        StabilityMonitor::new(MonitorLimits { settle_s: SETTLE_S, ..MonitorLimits::default() });
    let progress = SimProgress::new(&scenario.name, opts.duration_s, opts.progress);
    let base_start = pose4(&sim);
    let wall = Instant::now();
    let mut tick = 0usize;
    while sim.time() < opts.duration_s - 1e-9 {
        twist = Twist {
            vx: ramp(twist.vx, target.vx, ACCEL_LIMITS[0] * control_dt),
            vy: ramp(twist.vy, target.vy, ACCEL_LIMITS[0] * control_dt),
            wz: ramp(twist.wz, target.wz, ACCEL_LIMITS[1] * control_dt),
        };
        let steer = Leg::ALL.map(|l| sim.steering_angle(l));
        let commands = kin.commands(&robot, twist, &feet, &steer);
        for leg in Leg::ALL {
            let c = kin.with_steering_rate(&robot, commands[leg.index()], sim.steering_rate(leg));
            sim.set_leg_joint_targets(leg, posture[leg.index()]);
            sim.set_steering_target(leg, c.steer);
            sim.set_wheel_speeds(leg, c.wheel_speeds);
        }
        sim.step(substeps)?;
        tick += 1;
        let sample = monitor.observe(&sim);
        if let Some(r) = &mut recorder
            && tick.is_multiple_of(record_every)
        {
            r.log_bodies(sim.time(), &sim.body_poses())?;
            r.log_stability(&sample, scenario.terrain_height(sample.com[0], sample.com[1]))?;
            r.log_wheel_loads(sim.time(), &sim.wheel_loads())?;
        }
        progress.set(sim.time());
    }
    progress.finish();
    monitor.finish();
    let wall_time_s = wall.elapsed().as_secs_f64();
    if let Some(r) = recorder.take() {
        r.finish()?;
    }
    let base_end = pose4(&sim);
    let sim_time_s = sim.time();
    Ok(SimSummary {
        scenario: scenario.name.clone(),
        sim_time_s,
        wall_time_s,
        real_time_factor: sim_time_s / wall_time_s.max(1e-9),
        base_start,
        base_end: [base_end[0], base_end[1], base_end[2], wrap_angle(base_end[3])],
        nominal_base_height_m: nominal_base_height,
        drive: opts.drive,
        min_wheels_in_contact: if monitor.min_wheels == usize::MAX {
            0
        } else {
            monitor.min_wheels
        },
        min_stability_margin_m: monitor.min_margin,
        max_tilt_deg: monitor.max_tilt.to_degrees(),
        upright: !monitor.tipped(),
        body_collisions: monitor.collided_bodies(),
        events: monitor.events,
        total_mass_kg: robot.total_mass,
        wheel_loads_end_n: sim.wheel_loads(),
    })
}
