//! The command line: clap definitions and the dispatch to `jobs`. Errors surface here as
//! `anyhow` with context; `main` maps them to exit codes.

use crate::control::wheels::Twist;
use crate::jobs;
use crate::scenario::{Scenario, ScenarioError};
use anyhow::Context as _;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// Closed-loop simulator of hybrid driving-stepping locomotion for Momaro (Klamt & Behnke, IROS 2017).
#[derive(Debug, Parser)]
#[command(name = "momaro", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Options every command that loads the robot shares.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Robot model (MJCF).
    #[arg(long, value_name = "FILE", default_value_os_t = crate::sim::default_model_path())]
    pub model: PathBuf,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario's world headless with the robot standing, or driving a constant twist.
    Sim {
        /// Scenario file (scenarios/*.toml).
        scenario: PathBuf,
        /// Simulated duration, s.
        #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
        duration: f64,
        /// Constant body velocity command in the robot frame: vx,vy,wz (m/s, m/s, rad/s).
        #[arg(long, value_name = "VX,VY,WZ", value_parser = parse_twist, allow_hyphen_values = true)]
        drive: Option<Twist>,
        /// Write a Rerun recording.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Build the height map and the paper's cost layers (foot, body, pose cost) of a scenario.
    Costmap {
        /// Scenario file.
        scenario: PathBuf,
        /// Write PNG images of the layers into this directory.
        #[arg(long, value_name = "DIR")]
        png: Option<PathBuf>,
        /// Use the height map the robot's laser senses in MuJoCo, not the rasterised one.
        #[arg(long)]
        sensed: bool,
        /// Write a Rerun recording.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Measure speed (medians over repeats; never asserted in tests).
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Write the URDF of the robot, generated from the MJCF model.
    Urdf {
        /// Output file (default: standard output).
        #[arg(long, short)]
        output: Option<PathBuf>,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// The benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Real-time factor of `momaro sim` against a bare mj_step loop on the same world.
    Sim {
        /// Scenario file.
        scenario: PathBuf,
        /// Simulated duration of each run, s.
        #[arg(long, default_value_t = 60.0)]
        duration: f64,
        /// Repeats (the median is reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Print the result as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
}

fn parse_twist(s: &str) -> Result<Twist, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three comma-separated numbers vx,vy,wz, got `{s}`"));
    }
    let mut v = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = p.parse::<f64>().map_err(|e| format!("`{p}` is not a number: {e}"))?;
        if !v[k].is_finite() {
            return Err(format!("`{p}` is not a finite number"));
        }
    }
    Ok(Twist { vx: v[0], vy: v[1], wz: v[2] })
}

/// Failure classes, for exit codes.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

fn load(path: &std::path::Path) -> anyhow::Result<Scenario> {
    Scenario::load(path).map_err(|e: ScenarioError| anyhow::Error::new(BadInput(e.to_string())))
}

fn print_json<T: serde::Serialize>(value: &T) -> anyhow::Result<()> {
    println!("{}", serde_json::to_string_pretty(value).context("serialising the summary")?);
    Ok(())
}

/// Runs the parsed command line; returns whether the job's own checks passed.
///
/// # Errors
/// Any failure, with context; a [`BadInput`] in the chain marks invalid input.
pub fn run(cli: Cli) -> anyhow::Result<bool> {
    match cli.command {
        Command::Sim { scenario, duration, drive, rerun, json, model } => {
            let sc = load(&scenario)?;
            let opts = jobs::sim::SimOptions {
                duration_s: duration,
                drive,
                model_path: model.model,
                rerun,
                progress: !json,
            };
            let summary = jobs::sim::run(&sc, &opts).map_err(|e| match e {
                jobs::sim::SimJobError::BadOption { .. } => {
                    anyhow::Error::new(BadInput(e.to_string()))
                }
                other => anyhow::Error::new(other).context(format!("sim {}", scenario.display())),
            })?;
            if json {
                print_json(&summary)?;
            } else {
                let s = &summary;
                println!("scenario            {}", s.scenario);
                println!(
                    "sim time            {:.2} s in {:.2} s wall (x{:.1} real time)",
                    s.sim_time_s, s.wall_time_s, s.real_time_factor
                );
                println!(
                    "base start          x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
                    s.base_start[0],
                    s.base_start[1],
                    s.base_start[2],
                    s.base_start[3].to_degrees()
                );
                println!(
                    "base end            x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
                    s.base_end[0],
                    s.base_end[1],
                    s.base_end[2],
                    s.base_end[3].to_degrees()
                );
                println!("wheels in contact   min {}", s.min_wheels_in_contact);
                println!("stability margin    min {:.3} m", s.min_stability_margin_m);
                println!("upright             {}", s.upright);
                if !s.body_collisions.is_empty() {
                    println!("body collisions     {}", s.body_collisions.join(", "));
                }
            }
            Ok(summary.upright && summary.body_collisions.is_empty())
        }
        Command::Costmap { scenario, png, sensed, rerun, json, model } => {
            let sc = load(&scenario)?;
            let opts = jobs::costmap::CostmapOptions {
                sensed,
                png_dir: png,
                rerun,
                model_path: model.model,
            };
            let s = jobs::costmap::run(&sc, &opts)
                .with_context(|| format!("costmap {}", scenario.display()))?;
            if json {
                print_json(&s)?;
            } else {
                println!("scenario            {} ({} height map)", s.scenario, s.source);
                println!(
                    "map                 {} x {} cells of {} m from ({}, {})",
                    s.cells[0], s.cells[1], s.resolution_m, s.origin[0], s.origin[1]
                );
                println!(
                    "build time          height map {:.1} ms, cost layers {:.1} ms",
                    s.height_map_time_s * 1e3,
                    s.cost_maps_time_s * 1e3
                );
                println!(
                    "foot cost cells     {} infinite, {} unknown",
                    s.infinite_foot_cells, s.unknown_foot_cells
                );
                if let Some(sensed) = &s.sensed {
                    println!(
                        "laser               {} rays, {} cells seen, max error on flat cells {:.4} m, {} violations",
                        sensed.rays,
                        sensed.seen_cells,
                        sensed.agreement.max_uniform_error_m,
                        sensed.agreement.violations
                    );
                }
                for img in &s.images {
                    println!("wrote               {}", img.display());
                }
            }
            Ok(true)
        }
        Command::Bench(BenchCommand::Sim { scenario, duration, repeats, json, model }) => {
            let sc = load(&scenario)?;
            let opts = jobs::sim::SimOptions {
                duration_s: duration,
                drive: None,
                model_path: model.model,
                rerun: None,
                progress: false,
            };
            let b = jobs::bench::sim_bench(&sc, &opts, repeats)
                .with_context(|| format!("bench sim {}", scenario.display()))?;
            if json {
                print_json(&b)?;
            } else {
                println!(
                    "scenario            {} ({} s simulated, {} steps, median of {})",
                    b.scenario, b.sim_time_s, b.steps, b.repeats
                );
                println!(
                    "bare mj_step loop   x{:.1} real time ({:.2} µs/step)",
                    b.bare_real_time_factor, b.bare_step_us
                );
                println!(
                    "momaro sim          x{:.1} real time ({:.2} µs/step)",
                    b.controlled_real_time_factor, b.controlled_step_us
                );
                println!("controller+monitor  {:.1} % of a step", b.overhead_fraction * 100.0);
            }
            Ok(true)
        }
        Command::Urdf { output, model } => {
            let sim = crate::sim::Simulation::robot_only(&model.model)?;
            let text = crate::urdf_export::momaro_urdf_string(&sim.urdf_inputs()?)?;
            match output {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => print!("{text}"),
            }
            Ok(true)
        }
    }
}
