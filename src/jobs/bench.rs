//! `momaro bench`: speed measurements that are not assertions.
//!
//! The medians here (`median`, `median_option`) also serve `bench plan`
//! (`jobs::plan::bench`), whose times are medians over its repeats.
//!
//! `bench probe` times the planner's first path as `plan` finds it (the guided greedy
//! probe, cold: maps and heuristic tables built for the file) over a suite of scenario
//! files, one at a time: per file the median of the repeats, then the suite's median,
//! mean and largest. Issue 15's targets for generated courses are such medians.
//!
//! `bench sim` runs a scenario's world twice for the same simulated time: once as a bare
//! `mj_step` loop with the actuator targets of the standing posture fixed (the physics
//! limit), once as `momaro sim` runs it (controller and stability monitor every control
//! tick). The ratio of the two real-time factors is the cost of our own code per step.

use super::plan::{self, PlanJobError, PlanOptions};
use super::sim::{SimJobError, SimOptions};
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use crate::search::Termination;
use crate::sim::Simulation;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// Result of `bench sim`.
#[derive(Debug, Clone, Serialize)]
pub struct SimBench {
    /// Scenario name.
    pub scenario: String,
    /// Simulated time of each run, s.
    pub sim_time_s: f64,
    /// Physics steps per run.
    pub steps: usize,
    /// Real-time factor of the bare `mj_step` loop (median of the repeats).
    pub bare_real_time_factor: f64,
    /// Real-time factor with controller and monitor (median of the repeats).
    pub controlled_real_time_factor: f64,
    /// Mean wall time per physics step, bare, µs.
    pub bare_step_us: f64,
    /// Mean wall time per physics step with controller and monitor, µs.
    pub controlled_step_us: f64,
    /// (controlled − bare) / bare wall time: our code's share of a step.
    pub overhead_fraction: f64,
    /// Repeats of each run.
    pub repeats: usize,
}

/// The median of `v` (the upper one of an even count); NaN if `v` is empty.
pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The median of `v` with `None` counted as larger than every value (a run that found
/// no solution in time); `None` if that is where the median falls or `v` is empty.
pub(crate) fn median_option(mut v: Vec<Option<f64>>) -> Option<f64> {
    v.sort_by(|a, b| match (a, b) {
        (Some(x), Some(y)) => x.total_cmp(y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => std::cmp::Ordering::Equal,
    });
    v.get(v.len() / 2).copied().flatten()
}

/// Runs the benchmark: `repeats` alternating bare and controlled runs of `duration_s`.
///
/// # Errors
/// As `momaro sim`.
pub fn sim_bench(
    scenario: &Scenario,
    opts: &SimOptions,
    repeats: usize,
) -> Result<SimBench, SimJobError> {
    let repeats = repeats.max(1);
    let mut bare = Vec::with_capacity(repeats);
    let mut controlled = Vec::with_capacity(repeats);
    let mut steps = 0;
    for _ in 0..repeats {
        let mut sim = Simulation::new(scenario, &opts.model_path)?;
        super::stand_at_start(&mut sim, scenario)?;
        steps = (opts.duration_s / sim.timestep()).round() as usize;
        let t = Instant::now();
        sim.step(steps)?;
        bare.push(opts.duration_s / t.elapsed().as_secs_f64());
        let s = super::sim::run(
            scenario,
            &SimOptions { rerun: None, progress: false, ..opts.clone() },
        )?;
        controlled.push(s.real_time_factor);
    }
    let (bare_rtf, ctrl_rtf) = (median(bare), median(controlled));
    let per_step = |rtf: f64| opts.duration_s / rtf / steps.max(1) as f64 * 1e6;
    Ok(SimBench {
        scenario: scenario.name.clone(),
        sim_time_s: opts.duration_s,
        steps,
        bare_real_time_factor: bare_rtf,
        controlled_real_time_factor: ctrl_rtf,
        bare_step_us: per_step(bare_rtf),
        controlled_step_us: per_step(ctrl_rtf),
        overhead_fraction: bare_rtf / ctrl_rtf - 1.0,
        repeats,
    })
}

/// Options of `bench probe`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeBenchOptions {
    /// Planning time limit of each run, s (`plan --time-limit`).
    pub time_limit_s: f64,
    /// Runs of each file; its time is their median.
    pub repeats: usize,
}

/// One file of `bench probe`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeRow {
    /// Scenario name.
    pub scenario: String,
    /// The file.
    pub path: PathBuf,
    /// `path` (a path found), `no_path` (every reachable pose searched) or `time_limit`,
    /// of the last repeat (repeats differ only where the time limit falls between them).
    pub outcome: &'static str,
    /// Median over the repeats of the wall time of the whole plan: maps, the heuristic's
    /// set-up and the search (what a user of `plan` waits for), s.
    pub time_s: f64,
    /// Median over the repeats of the search's own time (`plan`'s `planning_time_s`: the
    /// lazy cost-to-go included, the maps and the heuristic's set-up not), when it
    /// found a path, s.
    pub search_s: Option<f64>,
    /// States the search expanded (of the last repeat; the search is deterministic), when
    /// it found a path.
    pub expansions: Option<u64>,
    /// The path's cost, when one was found.
    pub cost: Option<f64>,
}

/// Result of `bench probe`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeBench {
    /// One row per file, in the order given.
    pub rows: Vec<ProbeRow>,
    /// Runs of each file.
    pub repeats: usize,
    /// Files whose plan found a path.
    pub paths: usize,
    /// Median of the rows' times (the upper one of an even count), s.
    pub median_s: f64,
    /// Mean of the rows' times, s.
    pub mean_s: f64,
    /// Largest of the rows' times, s.
    pub max_s: f64,
    /// Median of the rows' search times, over the rows with a path, s (`None` if none).
    pub median_search_s: Option<f64>,
}

/// Times `plan`'s first path (the probe's, `--schedule-expansions 0`) on each of
/// `scenarios`, `opts.repeats` times each, one run at a time. A file with no path (or
/// none within the limit) is a row with its time, not an error. `on_row` hears of each
/// row as it is done, with how many are (progress on long suites).
///
/// # Errors
/// `opts` out of range, or a plan that fails for another reason than finding no path
/// (a start off the map, a bad parameter, ...).
pub fn probe_bench(
    scenarios: &[Scenario],
    robot: &RobotDescription,
    opts: &ProbeBenchOptions,
    on_row: &mut dyn FnMut(usize, &ProbeRow),
) -> Result<ProbeBench, PlanJobError> {
    if opts.repeats == 0 {
        return Err(plan::bad("repeats", "0 must be at least 1"));
    }
    let plan_opts = PlanOptions {
        time_limit_s: opts.time_limit_s,
        schedule_expansions: Some(0),
        ..PlanOptions::default()
    };
    let mut rows = Vec::with_capacity(scenarios.len());
    for sc in scenarios {
        let (mut times, mut searches) = (Vec::new(), Vec::new());
        let (mut outcome, mut expansions, mut cost) = ("path", None, None);
        for _ in 0..opts.repeats {
            let t = Instant::now();
            let result = plan::run(sc, robot, &plan_opts);
            times.push(t.elapsed().as_secs_f64());
            if let Ok(s) = &result {
                searches.push(s.planning_time_s);
            }
            (outcome, expansions, cost) = match result {
                Ok(s) => ("path", Some(s.expansions), Some(s.cost)),
                Err(PlanJobError::NoPath { termination: Termination::NoPath, .. }) => {
                    ("no_path", None, None)
                }
                Err(PlanJobError::NoPath { .. }) => ("time_limit", None, None),
                Err(e) => return Err(e),
            };
        }
        rows.push(ProbeRow {
            scenario: sc.name.clone(),
            path: sc.path.clone(),
            outcome,
            time_s: median(times),
            search_s: (!searches.is_empty()).then(|| median(searches)),
            expansions,
            cost,
        });
        if let Some(r) = rows.last() {
            on_row(rows.len(), r);
        }
    }
    let times: Vec<f64> = rows.iter().map(|r| r.time_s).collect();
    let mean_s = times.iter().sum::<f64>() / times.len().max(1) as f64;
    let max_s = times.iter().copied().fold(0.0, f64::max);
    let searches: Vec<f64> = rows.iter().filter_map(|r| r.search_s).collect();
    Ok(ProbeBench {
        median_search_s: (!searches.is_empty()).then(|| median(searches)),
        paths: rows.iter().filter(|r| r.outcome == "path").count(),
        median_s: median(times),
        mean_s,
        max_s,
        repeats: opts.repeats,
        rows,
    })
}
