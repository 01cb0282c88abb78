//! What a plan may be asked to do: the options of a plan (algorithm, time limit, ARA*'s
//! schedule, overrides of the scenario's parameters, edges to leave out) and why a plan
//! fails ([`PlanError`]).

use super::{LatticeError, Neighbourhood, PoseKey};
use crate::cost::CostError;
use crate::geometry::Pose2;
use crate::params::{FootModel, InvalidParam, Params, StepModel};
use crate::search::Algorithm;
use crate::search::{SearchError, Termination};
use crate::terrain::RasteriseError;
use std::path::PathBuf;
use std::time::Duration;

/// What a command line may set over a scenario's `[params]`; `None` keeps the
/// scenario's value.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ParamOverrides {
    /// Orientation cost factor k12 (Sec. VII-A); the scenario's default is 2.0.
    pub k12: Option<f64>,
    /// Step-related cost factor (`Params::step_cost_factor`).
    pub step_cost_factor: Option<f64>,
    /// Foot model of the foot cost (`Params::foot_model`).
    pub foot_model: Option<FootModel>,
    /// Which manoeuvres prepare steps (`Params::step_model`).
    pub step_model: Option<StepModel>,
}

impl ParamOverrides {
    /// `params` with these overrides.
    pub(crate) fn apply(self, mut params: Params) -> Params {
        params.k12 = self.k12.unwrap_or(params.k12);
        params.step_cost_factor = self.step_cost_factor.unwrap_or(params.step_cost_factor);
        params.foot_model = self.foot_model.unwrap_or(params.foot_model);
        params.step_model = self.step_model.unwrap_or(params.step_model);
        params
    }
}

/// Options of a plan job.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// A* or ARA*.
    pub algorithm: Algorithm,
    /// Wall-clock budget for the whole job (maps and search), s.
    pub time_limit_s: f64,
    /// ARA*'s initial heuristic weight; default `Params::arastar_initial_epsilon` (3.0).
    pub initial_epsilon: Option<f64>,
    /// ε of ARA*'s greedy probe before the schedule; default
    /// `Params::arastar_probe_epsilon` (50). At most the initial ε: no probe.
    pub probe_epsilon: Option<f64>,
    /// Whether ARA*'s probe is guided (`SearchParams::probe_guidance`: every other
    /// expansion ordered by the heuristic without its base-pose cost-to-go,
    /// `HeuristicParts::guidance`, and after `SearchParams::probe_greedy_after`
    /// expansions without a path every third by a guidance alone, the same with the feet's
    /// offsets weighed as the straight line weighs the base's way and that way the longer
    /// of the straight line and the feet's way over climbable terrain,
    /// `HeuristicParts::greedy_guidance`). Default true.
    pub probe_guidance: bool,
    /// Expansions ARA*'s schedule may spend after its probe found a path
    /// (`SearchParams::schedule_max_expansions`): the probe's path is then the answer
    /// on any machine. Default none.
    pub schedule_expansions: Option<u64>,
    /// Expansion budget of the whole search (`SearchParams::max_expansions`): where it
    /// stops the search without a path, the plan fails as at its time limit. Default none.
    pub max_expansions: Option<u64>,
    /// ARA* stops once a solution with this ε is found (default 1: the optimum). Equal
    /// to the initial ε, the first solution is taken: the same plan on any machine, where
    /// a time limit cuts the anytime search wherever the CPU happens to be.
    pub final_epsilon: Option<f64>,
    /// Overrides of the scenario's `[params]` (k12, step-related factor, models).
    pub overrides: ParamOverrides,
    /// Driving neighbourhood; default N16 for A*, N20 for ARA* (Sec. VII-B).
    pub neighbourhood: Option<Neighbourhood>,
    /// Edges to leave out: manoeuvres the motion generator could not expand in an
    /// earlier plan of the same run (`closed_loop::plan_mission`).
    pub forbidden: Vec<(PoseKey, PoseKey)>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            algorithm: Algorithm::AraStar,
            time_limit_s: 10.0,
            initial_epsilon: None,
            probe_epsilon: None,
            probe_guidance: true,
            schedule_expansions: None,
            max_expansions: None,
            final_epsilon: None,
            overrides: ParamOverrides::default(),
            neighbourhood: None,
            forbidden: Vec::new(),
        }
    }
}

/// Why a plan job failed.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// An option is out of range.
    #[error("invalid option `{option}`: {reason}")]
    BadOption {
        /// The option.
        option: &'static str,
        /// Why.
        reason: String,
    },
    /// A parameter (after the options' overrides) is invalid.
    #[error("scenario {scenario}: {source}")]
    Params {
        /// The scenario file.
        scenario: PathBuf,
        /// The parameter.
        source: InvalidParam,
    },
    /// The height map could not be built.
    #[error("scenario {scenario}: cannot build the height map: {source}")]
    Map {
        /// The scenario file.
        scenario: PathBuf,
        /// The cause.
        source: RasteriseError,
    },
    /// The cost maps could not be built.
    #[error("scenario {scenario}: cannot build the cost maps: {source}")]
    Cost {
        /// The scenario file.
        scenario: PathBuf,
        /// The cause.
        source: CostError,
    },
    /// The map is too large for the lattice.
    #[error("scenario {scenario}: {source}")]
    Lattice {
        /// The scenario file.
        scenario: PathBuf,
        /// The cause.
        source: LatticeError,
    },
    /// The start or goal pose lies off the map.
    #[error(
        "scenario {scenario}: the {which} pose ({x:.3}, {y:.3}) lies off the map [{x_min}, {x_max}] x [{y_min}, {y_max}]",
        x = pose.x, y = pose.y, x_min = bounds[0], y_min = bounds[1], x_max = bounds[2], y_max = bounds[3]
    )]
    OffMap {
        /// The scenario file.
        scenario: PathBuf,
        /// `start` or `goal`.
        which: &'static str,
        /// The pose.
        pose: Pose2,
        /// Map bounds `[x_min, y_min, x_max, y_max]`, m.
        bounds: [f64; 4],
    },
    /// The robot cannot stand at the start or goal pose in its driving footprint.
    #[error(
        "scenario {scenario}: the {which} pose ({x:.3}, {y:.3}, {yaw:.1}°) is untraversable: {reason}",
        x = pose.x, y = pose.y, yaw = pose.theta.to_degrees()
    )]
    Untraversable {
        /// The scenario file.
        scenario: PathBuf,
        /// `start` or `goal`.
        which: &'static str,
        /// The pose.
        pose: Pose2,
        /// Why (a foot in an infinite-cost cell, unknown terrain).
        reason: &'static str,
    },
    /// The search ended without a path.
    #[error("scenario {scenario}: no path from start to goal: {reason}")]
    NoPath {
        /// The scenario file.
        scenario: PathBuf,
        /// Why the search ended.
        termination: Termination,
        /// What that means.
        reason: String,
    },
    /// The search could not start.
    #[error("scenario {scenario}: {source}")]
    Search {
        /// The scenario file.
        scenario: PathBuf,
        /// The cause.
        source: SearchError,
    },
}

pub(crate) fn bad(option: &'static str, reason: impl Into<String>) -> PlanError {
    PlanError::BadOption { option, reason: reason.into() }
}

pub(crate) fn check_time(option: &'static str, t: f64) -> Result<Duration, PlanError> {
    if t.is_finite() && t > 0.0 && t < 1e7 {
        Ok(Duration::from_secs_f64(t))
    } else {
        Err(bad(option, format!("{t} must be a number of seconds > 0")))
    }
}

/// The time limit of `opts`, after checking every option.
pub(crate) fn check_options(opts: &PlanOptions) -> Result<Duration, PlanError> {
    let limit = check_time("time_limit_s", opts.time_limit_s)?;
    if let Some(e) = opts.initial_epsilon
        && !(e.is_finite() && e >= 1.0)
    {
        return Err(bad("initial_epsilon", format!("{e} must be at least 1")));
    }
    if let Some(e) = opts.probe_epsilon
        && !(e.is_finite() && e >= 1.0)
    {
        return Err(bad("probe_epsilon", format!("{e} must be at least 1")));
    }
    if let Some(k) = opts.overrides.k12
        && !(k.is_finite() && k >= 1.0)
    {
        return Err(bad("k12", format!("{k} must be at least 1")));
    }
    if opts.max_expansions == Some(0) {
        return Err(bad("max_expansions", "0 must be at least 1"));
    }
    if let Some(e) = opts.final_epsilon
        && !(e.is_finite() && e >= 1.0 && e <= opts.initial_epsilon.unwrap_or(e))
    {
        return Err(bad(
            "final_epsilon",
            format!("{e} must be at least 1 and at most the initial ε"),
        ));
    }
    Ok(limit)
}
