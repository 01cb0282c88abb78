//! The world commands: `momaro sim` (the world headless), `momaro costmap` (the height map
//! and cost layers), `momaro generate` (seeded courses) and `momaro urdf`.

use super::args::*;
use super::report::*;
use crate::jobs;
use anyhow::Context as _;

/// `momaro sim`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn sim(args: SimArgs) -> anyhow::Result<bool> {
    let SimArgs { scenario, duration, drive, rerun, json, model } = args;
    let sc = load(&scenario)?;
    let opts = jobs::sim::SimOptions {
        duration_s: duration,
        drive,
        model_path: model.model,
        rerun,
        progress: !json,
    };
    let summary = jobs::sim::run(&sc, &opts).map_err(|e| match e {
        jobs::sim::SimJobError::BadOption { .. } => anyhow::Error::new(BadInput(e.to_string())),
        other => anyhow::Error::new(other).context(format!("sim {}", scenario.display())),
    })?;
    if json {
        print_json(&summary)?;
    } else {
        let s = &summary;
        say!("scenario            {}", s.scenario);
        say!(
            "sim time            {:.2} s in {:.2} s wall (x{:.1} real time)",
            s.sim_time_s,
            s.wall_time_s,
            s.real_time_factor
        );
        say!(
            "base start          x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
            s.base_start[0],
            s.base_start[1],
            s.base_start[2],
            s.base_start[3].to_degrees()
        );
        say!(
            "base end            x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
            s.base_end[0],
            s.base_end[1],
            s.base_end[2],
            s.base_end[3].to_degrees()
        );
        say!("wheels in contact   min {}", s.min_wheels_in_contact);
        say!("stability margin    min {:.3} m", s.min_stability_margin_m);
        say!("upright             {}", s.upright);
        if !s.body_collisions.is_empty() {
            say!("body collisions     {}", s.body_collisions.join(", "));
        }
    }
    Ok(summary.upright && summary.body_collisions.is_empty())
}

/// `momaro costmap`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn costmap(args: CostmapArgs) -> anyhow::Result<bool> {
    let CostmapArgs { scenario, png, sensed, rerun, json, model } = args;
    let sc = load(&scenario)?;
    let opts =
        jobs::costmap::CostmapOptions { sensed, png_dir: png, rerun, model_path: model.model };
    let s = jobs::costmap::run(&sc, &opts)
        .with_context(|| format!("costmap {}", scenario.display()))?;
    if json {
        print_json(&s)?;
    } else {
        say!("scenario            {} ({} height map)", s.scenario, s.source);
        say!(
            "map                 {} x {} cells of {} m from ({}, {})",
            s.cells[0],
            s.cells[1],
            s.resolution_m,
            s.origin[0],
            s.origin[1]
        );
        say!(
            "build time          height map {:.1} ms, cost layers {:.1} ms",
            s.height_map_time_s * 1e3,
            s.cost_maps_time_s * 1e3
        );
        say!(
            "models              foot {}, step {} (flights in the heights: at most {} riser{}, {:.2} m)",
            s.foot_model.name(),
            s.step_model.name(),
            s.flight_risers,
            if s.flight_risers == 1 { "" } else { "s" },
            s.flight_rise_m
        );
        say!(
            "foot cost cells     {} infinite, {} unknown",
            s.infinite_foot_cells,
            s.unknown_foot_cells
        );
        if let Some(sensed) = &s.sensed {
            say!(
                "laser               {} rays, {} cells seen, max error on flat cells {:.4} m, {} violations",
                sensed.rays,
                sensed.seen_cells,
                sensed.agreement.max_uniform_error_m,
                sensed.agreement.violations
            );
        }
        for img in &s.images {
            say!("wrote               {}", img.display());
        }
    }
    Ok(true)
}

/// `momaro generate`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn generate(args: GenerateArgs) -> anyhow::Result<bool> {
    let GenerateArgs { seed, count, out, class, stairs_as, json, model } = args;
    let opts = jobs::generate::GenerateOptions {
        seed,
        count,
        out_dir: out,
        class,
        stairs_as_boxes: stairs_as == StairsAsArg::Boxes,
    };
    if count == 0 {
        // Before the model loads: bad input is reported as such even without it.
        return Err(anyhow::Error::new(BadInput(
            "invalid option `count`: must be at least 1".into(),
        )));
    }
    let summary = jobs::generate::run(&opts, &robot(&model.model)?).map_err(|e| match e {
        jobs::generate::GenerateJobError::BadOption { .. } => {
            anyhow::Error::new(BadInput(e.to_string()))
        }
        other => anyhow::Error::new(other).context("generate"),
    })?;
    if json {
        print_json(&summary)?;
    } else {
        for f in &summary.files {
            say!("wrote {}  {}", f.path.display(), f.description);
        }
        let counts: Vec<String> =
            summary.per_class.iter().map(|c| format!("{} {}", c.class, c.count)).collect();
        say!(
            "{} files in {} ({})",
            summary.files.len(),
            summary.out_dir.display(),
            counts.join(", ")
        );
    }
    Ok(true)
}

/// `momaro urdf`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn urdf(args: UrdfArgs) -> anyhow::Result<bool> {
    let UrdfArgs { output, model } = args;
    let sim = crate::sim::Simulation::robot_only(&model.model)?;
    let text = crate::urdf_export::momaro_urdf_string(&sim.urdf_inputs()?)?;
    match output {
        Some(path) => {
            std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?
        }
        None => print!("{text}"),
    }
    Ok(true)
}
