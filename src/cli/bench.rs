//! `momaro bench`: planner and simulation speed, as medians over repeats.

use super::args::*;
use super::report::*;
use super::suite::{repository_scenarios_dir, suite_files};
use crate::jobs;
use anyhow::Context as _;

/// `momaro bench plan`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn bench_plan(args: BenchPlanArgs) -> anyhow::Result<bool> {
    let BenchPlanArgs {
        scenario,
        arastar_limit,
        optimum_limit,
        run: BenchRunArgs { repeats, json, model },
    } = args;
    let sc = load(&scenario)?;
    let opts = jobs::bench::BenchOptions {
        arastar_time_limit_s: arastar_limit,
        optimum_time_limit_s: optimum_limit,
        repeats,
        ..Default::default()
    };
    let report = jobs::bench::bench(&sc, &robot(&model.model)?, &opts).map_err(plan_error)?;
    if json {
        print_json(&report)?;
    } else {
        let pct = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.1} %"));
        let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{:.1} ms", v * 1e3));
        let c = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.3}"));
        say!(
            "scenario {} (setup {:.1} ms; times are medians of {})",
            report.scenario,
            report.setup_time_s * 1e3,
            opts.repeats
        );
        say!(
            "{:<13} {:<5} {:>10} {:>12} {:>10} {:>10} {:>7} {:>10} {:>10} {:>12} {:>10} {:>10}",
            "algo",
            "nbhd",
            "optimum",
            "first",
            "warm first",
            "over opt",
            "bound",
            "cost@1s",
            "cost@10s",
            "to optimum",
            "first exp",
            "h setup"
        );
        for r in &report.rows {
            say!(
                "{:<13} {:<5} {:>10} {:>12} {:>10} {:>10} {:>7} {:>10} {:>10} {:>12} {:>10} {:>10}",
                r.algorithm,
                r.neighbourhood,
                c(r.optimum),
                ms(r.first_solution_s),
                ms(r.first_solution_warm_s),
                pct(r.first_over_optimum_pct),
                r.first_bound.map_or("-".to_owned(), |b| format!("{b:.2}")),
                c(r.cost_at_1s),
                c(r.cost_at_10s),
                ms(r.time_to_optimum_s),
                r.first_expansions.map_or("-".to_owned(), |e| e.to_string()),
                ms(Some(r.heuristic_setup_s))
            );
        }
    }
    Ok(true)
}

/// `momaro bench probe`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn bench_probe(args: BenchProbeArgs) -> anyhow::Result<bool> {
    let BenchProbeArgs { paths, time_limit, run: BenchRunArgs { repeats, json, model } } = args;
    let scenarios =
        suite_files(&paths)?.iter().map(|f| load(f)).collect::<anyhow::Result<Vec<_>>>()?;
    let opts = jobs::bench::ProbeBenchOptions { time_limit_s: time_limit, repeats };
    let total = scenarios.len();
    let b = jobs::bench::probe_bench(&scenarios, &robot(&model.model)?, &opts, &mut |done, r| {
        progress_line(
            done,
            total,
            format_args!("{:<24} {:<10} {:>8.1} ms", r.scenario, r.outcome, r.time_s * 1e3),
        );
    })
    .map_err(plan_error)?;
    if json {
        print_json(&b)?;
    } else {
        let ms = |v: Option<f64>| v.map_or("-".to_owned(), |t| format!("{:.1}", t * 1e3));
        say!(
            "{:<28} {:<10} {:>10} {:>10} {:>11} {:>12}",
            "scenario",
            "outcome",
            "wall ms",
            "search ms",
            "expansions",
            "cost"
        );
        for r in &b.rows {
            say!(
                "{:<28} {:<10} {:>10.1} {:>10} {:>11} {:>12}",
                r.scenario,
                r.outcome,
                r.time_s * 1e3,
                ms(r.search_s),
                r.expansions.map_or("-".to_owned(), |e| e.to_string()),
                r.cost.map_or("-".to_owned(), |c| format!("{c:.3}"))
            );
        }
        say!(
            "{} files, {} with a path (median of {} runs each): wall median {:.1} ms, mean {:.1} ms, largest {:.1} ms; search median {} ms",
            b.rows.len(),
            b.paths,
            b.repeats,
            b.median_s * 1e3,
            b.mean_s * 1e3,
            b.max_s * 1e3,
            ms(b.median_search_s)
        );
    }
    Ok(true)
}

/// `momaro bench sim`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn bench_sim(args: BenchSimArgs) -> anyhow::Result<bool> {
    let BenchSimArgs { scenario, duration, repeats, json, model } = args;
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
        say!(
            "scenario            {} ({} s simulated, {} steps, median of {})",
            b.scenario,
            b.sim_time_s,
            b.steps,
            b.repeats
        );
        say!(
            "bare mj_step loop   x{:.1} real time ({:.2} µs/step)",
            b.bare_real_time_factor,
            b.bare_step_us
        );
        say!(
            "momaro sim          x{:.1} real time ({:.2} µs/step)",
            b.controlled_real_time_factor,
            b.controlled_step_us
        );
        say!("controller+monitor  {:.1} % of a step", b.overhead_fraction * 100.0);
    }
    Ok(true)
}

/// `momaro bench scaling`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn bench_scaling(args: BenchScalingArgs) -> anyhow::Result<bool> {
    let BenchScalingArgs {
        scenario,
        map_sizes,
        lengths,
        length_map,
        time_limit,
        run: BenchRunArgs { repeats, json, model },
    } = args;
    let file = scenario.unwrap_or_else(|| repository_scenarios_dir().join("flat.toml"));
    let sc = load(&file)?;
    let opts = jobs::scaling::ScalingOptions {
        map_sizes_m: map_sizes,
        lengths_m: lengths,
        length_map_m: length_map,
        time_limit_s: time_limit,
        repeats,
    };
    let b =
        jobs::scaling::scaling_bench(&sc, &robot(&model.model)?, &opts, &mut |done, total, r| {
            progress_line(
                done,
                total,
                format_args!(
                    "{:<6} map {:>5.1} m  course {:>5.2} m  {:<10} {:>9.1} ms",
                    r.sweep,
                    r.map_m,
                    r.length_m,
                    r.outcome,
                    r.time_s * 1e3
                ),
            );
        })
        .map_err(plan_error)?;
    if json {
        print_json(&b)?;
    } else {
        say!(
            "{} (cold first path, medians of {} runs; ms; warm: a replan from the path's \
             middle to the same goal)",
            b.scenario,
            b.repeats
        );
        say!(
            "{:<7} {:>6} {:>10} {:>8} {:>10} {:>9} {:>9} {:>9} {:>10} {:>11} {:>10} {:>9}",
            "sweep",
            "map m",
            "cells",
            "course m",
            "total",
            "maps",
            "h setup",
            "search",
            "c-t-g nodes",
            "expansions",
            "cost",
            "warm"
        );
        for r in &b.rows {
            say!(
                "{:<7} {:>6.1} {:>10} {:>8.2} {:>10.1} {:>9.1} {:>9.1} {:>9.1} {:>10} {:>11} {:>10} {:>9}",
                r.sweep,
                r.map_m,
                r.cells,
                r.length_m,
                r.time_s * 1e3,
                r.maps_s * 1e3,
                r.heuristic_setup_s * 1e3,
                r.search_s * 1e3,
                r.cost_to_go_nodes,
                r.expansions,
                r.cost.map_or_else(|| r.outcome.to_owned(), |c| format!("{c:.3}")),
                r.warm_replan_s.map_or_else(|| "-".to_owned(), |t| format!("{:.1}", t * 1e3))
            );
        }
        let ratio = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
        say!(
            "largest map / smallest: {}x; longest course / shortest: {}x",
            ratio(b.area_ratio),
            ratio(b.length_ratio)
        );
    }
    Ok(true)
}
