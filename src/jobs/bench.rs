//! `momaro bench`: speed measurements that are not assertions.
//!
//! The medians here (`median`, `median_option`) also serve `bench plan`
//! (`jobs::plan::bench`), whose times are medians over its repeats.
//!
//! `bench sim` runs a scenario's world twice for the same simulated time: once as a bare
//! `mj_step` loop with the actuator targets of the standing posture fixed (the physics
//! limit), once as `momaro sim` runs it (controller and stability monitor every control
//! tick). The ratio of the two real-time factors is the cost of our own code per step.

use super::sim::{SimJobError, SimOptions};
use crate::scenario::Scenario;
use crate::sim::Simulation;
use serde::Serialize;
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
