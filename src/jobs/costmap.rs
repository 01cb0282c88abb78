//! `momaro costmap`: the scenario's height map (rasterised from the terrain, or sensed by
//! the simulated laser in MuJoCo) and the paper's cost layers (eq. 1–4), as PNG images, a
//! Rerun recording and a JSON summary with build times and cell counts.
//!
//! The height map covers the scenario's map extent plus a margin of r_N on every side, so
//! cells at the edge of the planning area still see their whole foot-cost neighbourhood.

use crate::cost::{CostError, CostMaps};
use crate::render::{self, ImageError, RgbImage};
use crate::scenario::Scenario;
use crate::sim::{SimError, Simulation};
use crate::terrain::sensed::{SensedAgreement, agreement};
use crate::terrain::{HeightMap, LaserScanner, RasteriseError, SensedError, scenario_map};
use crate::viz::{Recorder, VizError};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a costmap job failed.
#[derive(Debug, thiserror::Error)]
pub enum CostmapError {
    /// Rasterising the terrain failed.
    #[error("cannot rasterise the terrain of {scenario}: {source}")]
    Rasterise {
        /// Scenario name.
        scenario: String,
        /// Cause.
        source: RasteriseError,
    },
    /// Building the simulation for the sensed map failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The robot cannot stand at the start.
    #[error("cannot place the robot at the start: {0}")]
    Posture(#[from] crate::robot::ik::IkError),
    /// The laser scan failed.
    #[error(transparent)]
    Sensed(#[from] SensedError),
    /// Building the cost layers failed.
    #[error(transparent)]
    Cost(#[from] CostError),
    /// Writing an image failed.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// Creating the PNG directory failed.
    #[error("cannot create directory {path}: {source}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Writing the recording failed.
    #[error(transparent)]
    Viz(#[from] VizError),
}

/// Options of a costmap job.
#[derive(Debug, Clone)]
pub struct CostmapOptions {
    /// Use the laser-sensed height map instead of the rasterised one.
    pub sensed: bool,
    /// Write PNG images of the layers into this directory.
    pub png_dir: Option<PathBuf>,
    /// Write a Rerun recording.
    pub rerun: Option<PathBuf>,
    /// Robot model file.
    pub model_path: PathBuf,
}

/// What the sensed map saw.
#[derive(Debug, Clone, Serialize)]
pub struct SensedSummary {
    /// Laser origin (the head), m.
    pub laser_origin: [f64; 3],
    /// Rays cast.
    pub rays: usize,
    /// Returns used as heights.
    pub height_hits: usize,
    /// Cells with a height.
    pub seen_cells: usize,
    /// Comparison with the rasterised map (1 cm tolerance).
    pub agreement: SensedAgreement,
}

/// Result of a costmap job, as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
pub struct CostmapSummary {
    /// Scenario name.
    pub scenario: String,
    /// `rasterised` or `sensed`.
    pub source: &'static str,
    /// Cell size, m.
    pub resolution_m: f64,
    /// Cells along x and y.
    pub cells: [usize; 2],
    /// World position of cell (0, 0)'s corner, m.
    pub origin: [f64; 2],
    /// Time to build the height map, s.
    pub height_map_time_s: f64,
    /// Time to build the cost layers (foot cost and body-cost maxima), s.
    pub cost_maps_time_s: f64,
    /// The most risers of a flight of steps in the height map (`terrain::flights`).
    pub flight_risers: u32,
    /// The most height a flight of the map climbs, its risers summed, m.
    pub flight_rise_m: f64,
    /// The foot model of the layers: the file's, else the one the height map calls for
    /// (`planner::terrain_models`).
    pub foot_model: crate::params::FootModel,
    /// The step model a plan on this map gets, chosen the same way.
    pub step_model: crate::params::StepModel,
    /// Cells with infinite foot cost.
    pub infinite_foot_cells: usize,
    /// Cells with unknown foot cost.
    pub unknown_foot_cells: usize,
    /// Cells with unknown height.
    pub unknown_height_cells: usize,
    /// The laser scan, for `--sensed`.
    pub sensed: Option<SensedSummary>,
    /// PNG files written.
    pub images: Vec<PathBuf>,
}

/// The scenario's rasterised height map.
///
/// # Errors
/// [`CostmapError::Rasterise`].
pub fn rasterised_map(scenario: &Scenario) -> Result<HeightMap, CostmapError> {
    scenario_map(scenario)
        .map_err(|source| CostmapError::Rasterise { scenario: scenario.name.clone(), source })
}

/// The height map the robot's laser senses standing at the start, and the scan's summary.
///
/// # Errors
/// Building the world, placing the robot or scanning fails.
pub fn sensed_map(
    scenario: &Scenario,
    model_path: &Path,
    raster: &HeightMap,
) -> Result<(HeightMap, SensedSummary), CostmapError> {
    let mut sim = Simulation::new(scenario, model_path)?;
    crate::closed_loop::stand_at_start(&mut sim, scenario)?;
    let laser_origin = sim.site_position("laser")?;
    let scanner = LaserScanner::at(laser_origin);
    let (nx, ny) = raster.dims();
    let (map, stats) = scanner.scan(&mut sim, raster.origin(), raster.resolution(), nx, ny)?;
    let summary = SensedSummary {
        laser_origin,
        rays: stats.rays,
        height_hits: stats.height_hits,
        seen_cells: map.known_count(),
        agreement: agreement(&scenario.terrain, raster, &map, 0.01),
    };
    Ok((map, summary))
}

/// Runs the costmap job.
///
/// # Errors
/// [`CostmapError`].
pub fn run(scenario: &Scenario, opts: &CostmapOptions) -> Result<CostmapSummary, CostmapError> {
    let t = Instant::now();
    let raster = rasterised_map(scenario)?;
    let (heights, sensed) = if opts.sensed {
        let (map, summary) = sensed_map(scenario, &opts.model_path, &raster)?;
        (map, Some(summary))
    } else {
        (raster, None)
    };
    let height_map_time_s = t.elapsed().as_secs_f64();
    let robot = Simulation::robot_only(&opts.model_path)?.robot().clone();
    let t = Instant::now();
    // The models the planner would choose on this map (the sensed one with --sensed).
    let flights = crate::planner::terrain_flights(&heights, &robot, &scenario.params);
    let params = crate::planner::scenario_params(scenario, &flights);
    let maps = CostMaps::build(&heights, &robot, &params)?;
    let cost_maps_time_s = t.elapsed().as_secs_f64();

    let theta = scenario.start.theta;
    let leg = scenario.params.driving_leg_height_m;
    let (nx, ny) = heights.dims();
    let foot: Vec<_> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
    let layers: Vec<(&str, Option<RgbImage>)> = vec![
        ("height", render::height_image(&heights)),
        ("foot_cost", render::cost_layer_image(&foot, nx, ny, None)),
        ("body_cost", render::cost_layer_image(&maps.body_cost_layer(theta, leg), nx, ny, None)),
        ("pose_cost", render::cost_layer_image(&maps.pose_cost_layer(theta, leg), nx, ny, None)),
    ];
    let mut images = Vec::new();
    if let Some(dir) = &opts.png_dir {
        std::fs::create_dir_all(dir)
            .map_err(|source| CostmapError::Dir { path: dir.clone(), source })?;
        for (name, img) in &layers {
            if let Some(img) = img {
                let path = dir.join(format!("{}_{name}.png", scenario.name));
                render::write_png(img, &path)?;
                images.push(path);
            }
        }
    }
    if let Some(path) = &opts.rerun {
        let rec = Recorder::create(path, "momaro costmap")?;
        rec.log_height_map(&heights)?;
        for (name, img) in &layers {
            if let Some(img) = img {
                rec.log_layer_image(name, img, heights.origin(), heights.resolution())?;
            }
        }
        rec.finish()?;
    }
    Ok(CostmapSummary {
        scenario: scenario.name.clone(),
        source: if opts.sensed { "sensed" } else { "rasterised" },
        resolution_m: heights.resolution(),
        cells: [nx, ny],
        origin: heights.origin(),
        height_map_time_s,
        cost_maps_time_s,
        flight_risers: flights.risers,
        flight_rise_m: flights.rise_m,
        foot_model: params.foot_model,
        step_model: params.step_model,
        infinite_foot_cells: maps.infinite_foot_cells(),
        unknown_foot_cells: maps.unknown_foot_cells(),
        unknown_height_cells: maps.unknown_height_cells(),
        sensed,
        images,
    })
}
