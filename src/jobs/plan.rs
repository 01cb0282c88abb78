//! `momaro plan` and `momaro bench`: the hybrid driving-stepping planner (Klamt & Behnke
//! 2017, Sec. V, VII) run on a scenario, as library functions returning serialisable
//! summaries.
//!
//! [`prepare`] rasterises the scenario's terrain to a height map (2.5 cm), builds the cost
//! maps (Sec. IV) and checks the start and goal poses: a [`Prepared`] world, built once
//! per job. [`run_on`] searches its hybrid graph (`locomotion::hybrid`) with A*
//! (16-neighbourhood) or ARA* (20-neighbourhood, ε from 3 decaying to 1), as the paper
//! does; the plans of one job (`run`'s retries and replans) share the world and the
//! heuristic's tables toward its goal ([`HeuristicCache`]). [`run`] does both. The time
//! limit covers everything after option checking: map and cost-map building count
//! against it, and the search gets what is left, so a call never takes much longer than
//! the limit. With
//! [`PlanOptions::expansion_image`] the expansions per base cell are counted and drawn
//! (`render::expansion_image`), whether a path was found or not.
//!
//! Path costs are reported twice: `search_cost` as searched (with the orientation factor
//! k_Δθ of the chosen k12) and `cost`, "the costs the path would have in the plain A*
//! planner" (Sec. VIII): every edge re-evaluated with k12 = 1, so variants with different
//! k12 compare.
//!
//! [`bench()`] measures the anytime behaviour the paper reports (Sec. VIII): time to the
//! first solution, its cost over the optimum, the cost reached after 1 s and 10 s, and
//! the time to the optimal solution, for A* and for ARA*; every time is the median over
//! `BenchOptions::repeats` runs (this machine is noisy).

use crate::cost::{Cost as CostValue, CostError, CostMaps};
use crate::geometry::Pose2;
use crate::locomotion::{
    Algorithm, DrivingGoal, HeuristicCache, HybridConfig, HybridGraph, Lattice, LatticeError,
    LatticeState, ManoeuvreKind, ManoeuvreStats, Neighbourhood, PoseKey, StepCost,
};
use crate::params::{FootModel, InvalidParam, Params, StepModel};
use crate::robot::{Leg, RobotDescription};
use crate::scenario::{PAPER_MODEL_FLIGHT_STEPS, Scenario, longest_flight};
use crate::search::{
    Cost, ExpandHook, Expansion, Hooks, SearchError, SearchParams, SearchResult, Termination,
    arastar_with_hooks, astar_with_hooks,
};
use crate::terrain::{RasteriseError, rasterise};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

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
    /// The overrides that rebuild the maps `plan` was made on.
    pub fn of_plan(plan: &PlanSummary) -> Self {
        Self {
            k12: Some(plan.k12),
            step_cost_factor: Some(plan.step_cost_factor),
            foot_model: Some(plan.foot_model),
            step_model: Some(plan.step_model),
        }
    }

    /// `params` with these overrides.
    fn apply(self, mut params: Params) -> Params {
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
    /// Cap on the whole search's expansions (`SearchParams::max_expansions`). Default none.
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
    /// earlier plan of the same run (`jobs::run::plan_mission`).
    pub forbidden: Vec<(PoseKey, PoseKey)>,
    /// Write a PNG of where the search went (`render::expansion_image`: expansions
    /// per base cell over the height map), whatever the outcome: a search that finds no
    /// path shows where it spent its expansions. Default none.
    pub expansion_image: Option<PathBuf>,
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
            expansion_image: None,
        }
    }
}

/// Why a plan job failed.
#[derive(Debug, thiserror::Error)]
pub enum PlanJobError {
    /// The expansion image could not be written.
    #[error(transparent)]
    Image {
        /// The cause (names the file).
        source: crate::render::ImageError,
    },
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

/// One solution of the search, as the anytime planner delivered it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolutionSummary {
    /// Heuristic weight ε of the search that found it (1 for A*).
    pub epsilon: f64,
    /// Plain A* cost of the path (every edge with k12 = 1, Sec. VIII).
    pub cost: f64,
    /// Cost as searched (with the chosen k12).
    pub search_cost: f64,
    /// Proven bound on cost / optimum (1 = optimal).
    pub suboptimality_bound: f64,
    /// Time from the start of the search, s.
    pub time_s: f64,
    /// Expansions from the start of the search.
    pub expansions: u64,
}

/// What a path element does (the manoeuvre that leads to its pose; `start` first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PathKind {
    /// The start pose.
    Start,
    /// A straight driving move.
    Drive,
    /// A turn on the spot.
    Turn,
    /// An abstract step.
    Step,
    /// A longitudinal base shift.
    BaseShift,
    /// A front wheel pair driven forward.
    FootForward,
    /// A wheel pair driven back to neutral.
    FootNeutral,
}

impl From<ManoeuvreKind> for PathKind {
    fn from(k: ManoeuvreKind) -> Self {
        match k {
            ManoeuvreKind::Drive => PathKind::Drive,
            ManoeuvreKind::Turn => PathKind::Turn,
            ManoeuvreKind::Step => PathKind::Step,
            ManoeuvreKind::BaseShift => PathKind::BaseShift,
            ManoeuvreKind::FootForward => PathKind::FootForward,
            ManoeuvreKind::FootNeutral => PathKind::FootNeutral,
        }
    }
}

/// One pose of the planned path and the manoeuvre that reached it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathElement {
    /// The manoeuvre.
    pub kind: PathKind,
    /// The leg that moved (steps and foot moves).
    pub leg: Option<Leg>,
    /// Base pose after the manoeuvre (lattice cell centre and orientation).
    pub pose: Pose2,
    /// World (x, y) of the feet, FL, FR, RL, RR.
    pub feet: [[f64; 2]; 4],
    /// Ground height under each foot, m (`null` where unknown).
    pub foot_heights: [Option<f64>; 4],
    /// Foot offsets from the neutral footprint along the base's x', m.
    pub foot_offsets_m: [f64; 4],
    /// Plain A* cost of the manoeuvre (k12 = 1).
    pub cost: f64,
    /// The parts of C_S (eq. 5), for steps.
    pub step: Option<StepCost>,
}

/// Grid of the plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapInfo {
    /// World position of the corner of cell (0, 0), m.
    pub origin: [f64; 2],
    /// Cell size, m.
    pub resolution: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Orientations per cell.
    pub orientations: u32,
}

/// The result of a plan job: everything `momaro plan --json` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanSummary {
    /// Scenario name.
    pub scenario: String,
    /// `astar` or `arastar`.
    pub algorithm: &'static str,
    /// Every solution in the order found (costs never increase).
    pub solutions: Vec<SolutionSummary>,
    /// The best path, start first.
    pub path: Vec<PathElement>,
    /// Plain A* cost of the best path (k12 = 1, Sec. VIII).
    pub cost: f64,
    /// Cost of the best path as searched.
    pub search_cost: f64,
    /// Number of abstract steps on the path.
    pub steps: usize,
    /// Search time, s.
    pub planning_time_s: f64,
    /// Height-map and cost-map building time, s.
    pub setup_time_s: f64,
    /// Why the search stopped: `optimal_proven`, `time_limit`, ...
    pub termination: &'static str,
    /// Expansions, all iterations.
    pub expansions: u64,
    /// States generated.
    pub states: usize,
    /// The heuristic's own work: its set-up and how far its cost-to-go searched.
    pub heuristic: HeuristicSummary,
    /// Distinct footprints met.
    pub footprints: usize,
    /// The manoeuvres the search generated and how its step checks (the motion
    /// generator's, run by the planner) ended.
    pub manoeuvres: ManoeuvreStats,
    /// The step-related factor used.
    pub step_cost_factor: f64,
    /// The foot model used (`paper` or `wheel_pair`).
    pub foot_model: FootModel,
    /// The step model used (`paper` or `stairs`).
    pub step_model: StepModel,
    /// k12 used.
    pub k12: f64,
    /// The grid.
    pub map: MapInfo,
    /// The path's states by cell, orientation and foot offsets (to forbid an edge of it
    /// in a replan).
    #[serde(skip)]
    pub keys: Vec<PoseKey>,
}

/// What the hybrid graph's heuristic cost (`plan --json`'s `heuristic`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HeuristicSummary {
    /// Building the step bound and the reachable regions, s (at the heuristic's first
    /// use, which `plan` makes before the search: not in `planning_time_s`).
    pub setup_time_s: f64,
    /// (Cell, orientation) nodes the lazy cost-to-go settled during the search.
    pub cost_to_go_nodes: usize,
    /// Whether the time limit stopped the cost-to-go (its bound was frozen).
    pub cost_to_go_frozen: bool,
    /// Whether an earlier plan of the job built the tables toward this goal (a retry or a
    /// replan): then `setup_time_s` is zero and `cost_to_go_nodes` counts its nodes too.
    pub reused: bool,
}

/// Snake-case name of a termination.
pub fn termination_name(t: Termination) -> &'static str {
    match t {
        Termination::OptimalProven => "optimal_proven",
        Termination::FinalEpsilonReached => "final_epsilon_reached",
        Termination::TimeLimit => "time_limit",
        Termination::Cancelled => "cancelled",
        Termination::NoPath => "no_path",
        Termination::ExpansionLimit => "expansion_limit",
        Termination::StateLimit => "state_limit",
    }
}

fn algorithm_name(a: Algorithm) -> &'static str {
    match a {
        Algorithm::AStar => "astar",
        Algorithm::AraStar => "arastar",
    }
}

/// Cost maps, lattice states of start and goal and the parameters of one scenario, and
/// the heuristic tables the job's searches built: what every search of a job shares.
pub struct Prepared {
    /// The parameters with the options' overrides.
    pub params: Params,
    /// The cost client.
    pub maps: CostMaps,
    /// The lattice over the maps.
    pub lattice: Lattice,
    /// Start state (neutral footprint).
    pub start: LatticeState,
    /// Goal state (neutral footprint).
    pub goal: LatticeState,
    /// Time spent building, s.
    pub setup_time_s: f64,
    /// The heuristic tables of the searches on these maps ([`run_on`]'s graphs).
    pub heuristics: HeuristicCache,
}

pub(super) fn bad(option: &'static str, reason: impl Into<String>) -> PlanJobError {
    PlanJobError::BadOption { option, reason: reason.into() }
}

/// Builds the height map and cost maps of `scenario` and checks its start and goal.
///
/// # Errors
/// Invalid parameters, an unbuildable map, or a start / goal off the map or on
/// untraversable terrain.
pub fn prepare(
    scenario: &Scenario,
    robot: &RobotDescription,
    overrides: ParamOverrides,
) -> Result<Prepared, PlanJobError> {
    let t0 = Instant::now();
    let params = params_for(scenario, overrides)?;
    let (maps, lattice) = build_maps(scenario, robot, &params)?;
    let endpoint = |which, pose| endpoint(scenario, robot, &params, (&maps, &lattice), which, pose);
    let start = endpoint("start", scenario.start)?;
    let goal = endpoint("goal", scenario.goal)?;
    Ok(Prepared {
        start,
        goal,
        params,
        maps,
        lattice,
        setup_time_s: t0.elapsed().as_secs_f64(),
        heuristics: HeuristicCache::default(),
    })
}

/// [`prepare`] with the overrides of `opts` (as [`run`] prepares).
///
/// # Errors
/// As [`prepare`].
pub fn prepare_for(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
) -> Result<Prepared, PlanJobError> {
    prepare(scenario, robot, opts.overrides)
}

/// The lattice state of `scenario`'s `which` pose `pose`, checked: on the map, and one
/// the robot can stand at ([`unfit`]).
fn endpoint(
    scenario: &Scenario,
    robot: &RobotDescription,
    params: &Params,
    (maps, lattice): (&CostMaps, &Lattice),
    which: &'static str,
    pose: Pose2,
) -> Result<LatticeState, PlanJobError> {
    let file = || scenario.path.clone();
    let Some(s) = lattice.state(&pose) else {
        return Err(PlanJobError::OffMap {
            scenario: file(),
            which,
            pose,
            bounds: maps.heights().bounds(),
        });
    };
    if let Some(reason) = unfit(robot, params, maps, &lattice.pose(s)) {
        return Err(PlanJobError::Untraversable { scenario: file(), which, pose, reason });
    }
    Ok(s)
}

/// The scenario's parameters with the options' overrides, validated.
fn params_for(scenario: &Scenario, overrides: ParamOverrides) -> Result<Params, PlanJobError> {
    let params = overrides.apply(scenario.params.clone());
    params
        .validate()
        .map_err(|source| PlanJobError::Params { scenario: scenario.path.clone(), source })?;
    Ok(params)
}

/// The height and cost maps of `scenario` with `params`, and the lattice over them.
fn build_maps(
    scenario: &Scenario,
    robot: &RobotDescription,
    params: &Params,
) -> Result<(CostMaps, crate::locomotion::Lattice), PlanJobError> {
    let file = || scenario.path.clone();
    let m = &scenario.map;
    let heights = rasterise(
        &scenario.terrain,
        [m.x_min, m.y_min],
        [m.x_max - m.x_min, m.y_max - m.y_min],
        params.grid_resolution_m,
    )
    .map_err(|source| PlanJobError::Map { scenario: file(), source })?;
    let maps = CostMaps::build(&heights, robot, params)
        .map_err(|source| PlanJobError::Cost { scenario: file(), source })?;
    let lattice = crate::locomotion::Lattice::for_map(maps.heights(), params.orientations)
        .map_err(|source| PlanJobError::Lattice { scenario: file(), source })?;
    Ok((maps, lattice))
}

/// Why the robot cannot start or end at lattice pose `pose`, if it cannot: the driving
/// pose cost must be finite and the feasibility model must fit the robot there.
fn unfit(
    robot: &RobotDescription,
    params: &Params,
    maps: &CostMaps,
    pose: &Pose2,
) -> Option<&'static str> {
    match maps.driving_pose_cost(pose) {
        CostValue::Finite(_)
            if crate::feasibility::DrivingCheck::new(robot, params)
                .lattice_pose(maps, pose)
                .is_ok() =>
        {
            None
        }
        CostValue::Finite(_) => Some(
            "the legs or the body do not fit there, driving or standing (the feasibility model the planner and the motion generator share)",
        ),
        CostValue::Infinite => Some(
            "a wheel stands on or next to an untraversable height difference (infinite foot cost)",
        ),
        CostValue::Unknown => Some("the robot stands on unknown terrain or reaches off the map"),
    }
}

/// The pose a replan starts from: `start` if the planner can start there, else the
/// nearest lattice pose within `radius_m` and two orientation steps of it that it can (the
/// nearest first, then the smaller turn), else `start` (whose planning then fails with
/// [`PlanJobError::Untraversable`], [`Prepared::set_start`]). A robot that stopped
/// mid-manoeuvre may stand with a wheel next to an edge, where no plan may start; the path
/// follower takes it from where it stands to the new path's first pose.
pub fn nearest_start(
    prep: &Prepared,
    robot: &RobotDescription,
    start: Pose2,
    radius_m: f64,
) -> Pose2 {
    let (params, maps, lattice) = (&prep.params, &prep.maps, &prep.lattice);
    let Some(s) = lattice.state(&start) else {
        return start;
    };
    if unfit(robot, params, maps, &lattice.pose(s)).is_none() {
        return start;
    }
    let r = (radius_m / lattice.resolution).ceil() as i32;
    let n = i32::from(lattice.orientations);
    let mut candidates = Vec::new();
    for di in -r..=r {
        for dj in -r..=r {
            let d = f64::from(di).hypot(f64::from(dj)) * lattice.resolution;
            if d > radius_m {
                continue;
            }
            for dt in [0_i32, 1, -1, 2, -2] {
                candidates.push((d, dt.abs(), di, dj, dt));
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (_, _, di, dj, dt) in candidates {
        let (i, j) = (i32::from(s.i) + di, i32::from(s.j) + dj);
        let (Ok(i), Ok(j)) = (i16::try_from(i), i16::try_from(j)) else { continue };
        if i < 0
            || j < 0
            || i32::from(i) >= i32::from(lattice.nx)
            || i32::from(j) >= i32::from(lattice.ny)
        {
            continue;
        }
        let theta = (i32::from(s.theta) + dt).rem_euclid(n) as u8;
        let pose = lattice.pose(LatticeState::new(i, j, theta));
        if unfit(robot, params, maps, &pose).is_none() {
            return pose;
        }
    }
    start
}

impl Prepared {
    /// Moves the start to `start` (a replan from where the robot stands), checked as
    /// [`prepare`] checks `scenario`'s.
    ///
    /// # Errors
    /// [`PlanJobError::OffMap`] or [`PlanJobError::Untraversable`] naming `scenario`.
    pub fn set_start(
        &mut self,
        scenario: &Scenario,
        robot: &RobotDescription,
        start: Pose2,
    ) -> Result<(), PlanJobError> {
        let world = (&self.maps, &self.lattice);
        self.start = endpoint(scenario, robot, &self.params, world, "start", start)?;
        Ok(())
    }

    /// The hybrid graph for this scenario with `neighbourhood` and k12 = `k12`.
    ///
    /// # Errors
    /// A map too large for the lattice.
    pub fn graph(
        &self,
        robot: &RobotDescription,
        neighbourhood: Neighbourhood,
        k12: f64,
    ) -> Result<HybridGraph<'_>, LatticeError> {
        let params = Params { k12, ..self.params.clone() };
        let config = HybridConfig::new(&params, robot, neighbourhood);
        HybridGraph::new(
            &self.maps,
            robot,
            self.params.orientations,
            config,
            DrivingGoal::at(self.goal),
        )
    }

    /// The map grid.
    pub fn map_info(&self) -> MapInfo {
        let hm = self.maps.heights();
        let (nx, ny) = hm.dims();
        MapInfo {
            origin: hm.origin(),
            resolution: hm.resolution(),
            nx,
            ny,
            orientations: self.params.orientations,
        }
    }
}

/// Runs one search on `graph`; with `counts` (row-major over the lattice's cells, which
/// are the height map's), counts the expansions of each base cell.
fn search(
    graph: &mut HybridGraph<'_>,
    start: LatticeState,
    algorithm: Algorithm,
    params: &SearchParams,
    cancel: Option<&AtomicBool>,
    counts: Option<&mut [u32]>,
) -> Result<SearchResult<LatticeState>, SearchError> {
    let nx = usize::from(graph.lattice().nx);
    let mut count = counts.map(|c| {
        move |e: &Expansion<LatticeState>| {
            if let (Ok(i), Ok(j)) = (usize::try_from(e.state.i), usize::try_from(e.state.j))
                && let Some(n) = c.get_mut(j * nx + i)
            {
                *n = n.saturating_add(1);
            }
        }
    });
    let hooks = Hooks {
        cancel,
        on_expand: count.as_mut().map(|c| c as ExpandHook<'_, LatticeState>),
        ..Hooks::default()
    };
    // The heuristic's lazy cost-to-go stops growing at the time limit, so a first query
    // that would reach far cannot overrun it.
    graph.set_heuristic_deadline(params.time_limit.map(|t| Instant::now() + t));
    Ok(match algorithm {
        Algorithm::AStar => astar_with_hooks(graph, start, params, hooks),
        Algorithm::AraStar => arastar_with_hooks(graph, start, params, hooks)?,
    })
}

fn default_neighbourhood(a: Algorithm) -> Neighbourhood {
    match a {
        Algorithm::AStar => Neighbourhood::N16,
        Algorithm::AraStar => Neighbourhood::N20,
    }
}

fn check_time(option: &'static str, t: f64) -> Result<Duration, PlanJobError> {
    if t.is_finite() && t > 0.0 && t < 1e7 {
        Ok(Duration::from_secs_f64(t))
    } else {
        Err(bad(option, format!("{t} must be a number of seconds > 0")))
    }
}

/// The plain A* cost (k12 = 1, Sec. VIII) of a path of `graph`, per edge; `plain` is
/// the graph with k12 = 1 and the 20-neighbourhood (which holds every move of either
/// search). States move to `plain` by their foot offsets (footprint ids are per graph).
fn plain_edge_costs(
    graph: &HybridGraph<'_>,
    plain: &mut HybridGraph<'_>,
    path: &[LatticeState],
) -> Vec<Cost> {
    let mut states = Vec::with_capacity(path.len());
    for &s in path {
        let t = graph.offsets(s).and_then(|o| plain.with_offsets(s, o));
        states.push(t);
    }
    states
        .windows(2)
        .map(|w| match (w[0], w[1]) {
            (Some(a), Some(b)) => plain.edge(a, b).map_or(Cost::INFINITY, |(c, _)| c),
            _ => Cost::INFINITY,
        })
        .collect()
}

/// Plans a path for `scenario` (see the module docs).
///
/// # Errors
/// [`PlanJobError`]: bad options, an unbuildable map, a start or goal off the map or on
/// untraversable terrain, or no path found (none exists, or none within the time limit).
pub fn run(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
) -> Result<PlanSummary, PlanJobError> {
    let limit = check_options(opts)?;
    let t0 = Instant::now();
    let prep = prepare_for(scenario, robot, opts)?;
    search_prepared(&prep, scenario, robot, opts, (t0, limit))
}

/// Plans on a world [`prepare_for`] built for `scenario` with `opts`' overrides, from its
/// start ([`Prepared::set_start`]): [`run`] without building the maps again, and with the
/// heuristic tables of the world's earlier plans toward the same goal.
///
/// # Errors
/// As [`run`]; [`PlanJobError::BadOption`] if `prep` was built with other parameters.
pub fn run_on(
    prep: &Prepared,
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
) -> Result<PlanSummary, PlanJobError> {
    let limit = check_options(opts)?;
    let params = params_for(scenario, opts.overrides)?;
    if params != prep.params {
        return Err(bad(
            "prepared",
            "the world was prepared with other parameters than these options give",
        ));
    }
    search_prepared(prep, scenario, robot, opts, (Instant::now(), limit))
}

/// The time limit of `opts`, after checking every option.
fn check_options(opts: &PlanOptions) -> Result<Duration, PlanJobError> {
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

/// What a "no path" adds for a scenario planned with the paper's step model whose
/// terrain has a flight of [`PAPER_MODEL_FLIGHT_STEPS`] or more: the models that climb
/// it. Empty otherwise.
fn stairs_model_hint(scenario: &Scenario, step_model: StepModel) -> String {
    match longest_flight(&scenario.terrain) {
        Some(n) if step_model == StepModel::Paper && n >= PAPER_MODEL_FLIGHT_STEPS => format!(
            "; its stairs have {n} steps, and with step_model = \"paper\" flights of \
             {PAPER_MODEL_FLIGHT_STEPS} or more have no path: set step_model = \"stairs\" \
             and foot_model = \"wheel_pair\" in its [params] (README, \"Step model\")"
        ),
        _ => String::new(),
    }
}

/// The search of [`run`] and [`run_on`] on `prep`, its time limit `limit` counted from
/// `t0`.
fn search_prepared(
    prep: &Prepared,
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    (t0, limit): (Instant, Duration),
) -> Result<PlanSummary, PlanJobError> {
    let file = || scenario.path.clone();
    let neighbourhood = opts.neighbourhood.unwrap_or_else(|| default_neighbourhood(opts.algorithm));
    let lattice_err = |source| PlanJobError::Lattice { scenario: file(), source };
    let mut graph = prep
        .graph(robot, neighbourhood, prep.params.k12)
        .map_err(lattice_err)?
        .with_heuristic_cache(&prep.heuristics);
    graph.forbid(&opts.forbidden);
    // The heuristic's tables are built before the search's clock starts (within the
    // plan's time limit, which counts from `t0`).
    let heuristic_setup = graph.heuristic_setup_time();
    let eps0 = opts.initial_epsilon.unwrap_or(prep.params.arastar_initial_epsilon);
    let probe = opts.probe_epsilon.unwrap_or(prep.params.arastar_probe_epsilon);
    let search_params = SearchParams {
        initial_epsilon: eps0,
        probe_epsilon: probe_before(probe, eps0),
        probe_guidance: opts.probe_guidance,
        schedule_max_expansions: opts.schedule_expansions,
        max_expansions: opts.max_expansions,
        final_epsilon: opts.final_epsilon.unwrap_or(1.0).min(eps0),
        epsilon_decay: prep.params.arastar_epsilon_decay,
        time_limit: Some(limit.saturating_sub(t0.elapsed())),
        ..SearchParams::default()
    };
    let mut counts = opts.expansion_image.as_ref().map(|_| {
        let (nx, ny) = prep.maps.heights().dims();
        vec![0u32; nx * ny]
    });
    let result =
        search(&mut graph, prep.start, opts.algorithm, &search_params, None, counts.as_deref_mut())
            .map_err(|source| PlanJobError::Search { scenario: file(), source })?;
    if let (Some(path), Some(c)) = (&opts.expansion_image, &counts) {
        crate::render::write_expansion_png(prep.maps.heights(), c, path)
            .map_err(|source| PlanJobError::Image { source })?;
    }
    let Some(best) = result.best() else {
        let checks = step_checks_said(&graph.stats());
        let reason = match result.termination {
            Termination::NoPath => format!(
                "the goal cannot be reached: every reachable pose has been searched \
                 ({} expansions, {} states, {:.1} s{})",
                result.expansions,
                result.states,
                result.elapsed.as_secs_f64(),
                checks
            ),
            Termination::TimeLimit => format!(
                "none found within the time limit of {} s ({} expansions{})",
                opts.time_limit_s, result.expansions, checks
            ),
            t => format!("the search stopped ({})", termination_name(t)),
        };
        let reason = reason + &stairs_model_hint(scenario, prep.params.step_model);
        return Err(PlanJobError::NoPath {
            scenario: file(),
            termination: result.termination,
            reason,
        });
    };

    let mut plain = prep.graph(robot, Neighbourhood::N20, 1.0).map_err(lattice_err)?;
    let plain_total = |costs: &[Cost]| costs.iter().copied().sum::<Cost>().to_f64();
    let solutions = result
        .solutions
        .iter()
        .map(|s| SolutionSummary {
            epsilon: s.epsilon,
            cost: plain_total(&plain_edge_costs(&graph, &mut plain, &s.path)),
            search_cost: s.cost.to_f64(),
            suboptimality_bound: s.suboptimality_bound,
            time_s: s.time.as_secs_f64(),
            expansions: s.expansions,
        })
        .collect();
    let plain_costs = plain_edge_costs(&graph, &mut plain, &best.path);
    let path = describe_path(&mut graph, &best.path, &plain_costs);
    let keys = best.path.iter().filter_map(|&s| graph.key(s)).collect();
    let steps = path.iter().filter(|e| e.kind == PathKind::Step).count();
    Ok(PlanSummary {
        scenario: scenario.name.clone(),
        algorithm: algorithm_name(opts.algorithm),
        solutions,
        path,
        cost: plain_total(&plain_costs),
        search_cost: best.cost.to_f64(),
        steps,
        planning_time_s: result.elapsed.as_secs_f64(),
        setup_time_s: prep.setup_time_s,
        termination: termination_name(result.termination),
        expansions: result.expansions,
        states: result.states,
        heuristic: HeuristicSummary {
            setup_time_s: heuristic_setup.as_secs_f64(),
            cost_to_go_nodes: graph.cost_to_go_nodes(),
            cost_to_go_frozen: graph.heuristic_frozen(),
            reused: graph.heuristic_reused(),
        },
        footprints: graph.footprint_count(),
        manoeuvres: graph.stats(),
        step_cost_factor: prep.params.step_cost_factor,
        foot_model: prep.params.foot_model,
        step_model: prep.params.step_model,
        k12: prep.params.k12,
        map: prep.map_info(),
        keys,
    })
}

/// The path's elements: each state with the manoeuvre that reached it.
fn describe_path(
    graph: &mut HybridGraph<'_>,
    path: &[LatticeState],
    plain_costs: &[Cost],
) -> Vec<PathElement> {
    let res = graph.lattice().resolution;
    let mut out = Vec::with_capacity(path.len());
    for (k, &s) in path.iter().enumerate() {
        let label = if k == 0 { None } else { graph.edge(path[k - 1], s).map(|(_, m)| m) };
        let feet = graph.feet(s).unwrap_or([[f64::NAN; 2]; 4]);
        let offsets = graph.offsets(s).unwrap_or([0; 4]);
        out.push(PathElement {
            kind: label.map_or(PathKind::Start, |m| m.kind.into()),
            leg: label.and_then(|m| m.leg),
            pose: graph.pose(s),
            feet,
            foot_heights: feet.map(|[x, y]| graph_height(graph, x, y)),
            foot_offsets_m: offsets.map(|o| f64::from(o) * res),
            cost: if k == 0 {
                0.0
            } else {
                plain_costs.get(k - 1).map_or(f64::INFINITY, |c| c.to_f64())
            },
            step: label.and_then(|m| m.step),
        });
    }
    out
}

fn graph_height(graph: &HybridGraph<'_>, x: f64, y: f64) -> Option<f64> {
    graph.height_at(x, y)
}

/// Options of a benchmark.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchOptions {
    /// Budget of the ARA* run, s (its anytime curve; ≥ 10 to report the 10 s cost).
    pub arastar_time_limit_s: f64,
    /// Budget of the A* runs that establish the optimum, s.
    pub optimum_time_limit_s: f64,
    /// k12; default the scenario's.
    pub k12: Option<f64>,
    /// Runs of each search; times (and the costs reached by a time) are their medians.
    pub repeats: usize,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self { arastar_time_limit_s: 15.0, optimum_time_limit_s: 300.0, k12: None, repeats: 1 }
    }
}

/// One benchmark row: an algorithm's anytime behaviour on a scenario. Costs are search
/// costs (with the scenario's k12), which is what the search optimises.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchRow {
    /// `astar`, `arastar` (the paper's schedule alone), `arastar+probe` (ARA* as `plan`
    /// and `run` search: the guided greedy probe first, `SearchParams::probe_epsilon`) or
    /// `arastar+unguided` (the same with the probe ordered by the heuristic alone, as
    /// before `SearchParams::probe_guidance`).
    pub algorithm: &'static str,
    /// `n16` or `n20`.
    pub neighbourhood: &'static str,
    /// The optimal cost in this neighbourhood (an A* run), if it finished.
    pub optimum: Option<f64>,
    /// Time of the A* run that established the optimum, s.
    pub optimum_search_time_s: f64,
    /// Time to the first solution, s.
    pub first_solution_s: Option<f64>,
    /// Time to the first solution of the same search run again on the heuristic tables
    /// the first run left (as a replan or a retry of `run` finds them,
    /// `locomotion::HeuristicCache`): the search without the heuristic's set-up and
    /// first query, s. Measured for `arastar+probe` (the first path, as `plan` finds it).
    pub first_solution_warm_s: Option<f64>,
    /// Its cost.
    pub first_cost: Option<f64>,
    /// Its cost over the optimum, % (`(first / optimum − 1) · 100`).
    pub first_over_optimum_pct: Option<f64>,
    /// The bound ARA* certifies for it (`Solution::suboptimality_bound`): its cost is at
    /// most this times the optimum.
    pub first_bound: Option<f64>,
    /// Best cost found within 1 s.
    pub cost_at_1s: Option<f64>,
    /// Best cost found within 10 s.
    pub cost_at_10s: Option<f64>,
    /// Time until a solution of optimal cost was found, s.
    pub time_to_optimum_s: Option<f64>,
    /// Expansions up to the first solution.
    pub first_expansions: Option<u64>,
    /// Expansions of the whole run.
    pub expansions: u64,
    /// Expansions per second of the run.
    pub expansions_per_s: f64,
    /// Time to build the graph's heuristic (the step bound), s: spent before the search
    /// starts, so not in any of the search times above.
    pub heuristic_setup_s: f64,
    /// `(time_s, cost)` of every solution (of the run with the median first-solution
    /// time).
    pub solutions: Vec<(f64, f64)>,
    /// Runs the times are medians of.
    pub repeats: usize,
}

impl BenchRow {
    /// The row of medians over `runs` of the same search: every time, rate, total
    /// expansion count and time-dependent cost is the median of the runs (see
    /// `bench::median_option`). The first solution (its cost and expansions) does not
    /// depend on the clock; it, the optimum and the solution list come from the run with
    /// the median first-solution time. `None` if `runs` is empty.
    fn median_of(mut runs: Vec<BenchRow>) -> Option<BenchRow> {
        use super::bench::{median, median_option};
        let n = runs.len();
        if n == 0 {
            return None;
        }
        let opt = |f: fn(&BenchRow) -> Option<f64>| median_option(runs.iter().map(f).collect());
        let val = |f: fn(&BenchRow) -> f64| median(runs.iter().map(f).collect());
        let mut expansions: Vec<u64> = runs.iter().map(|r| r.expansions).collect();
        expansions.sort_unstable();
        let expansions = expansions[n / 2];
        let first_solution_s = opt(|r| r.first_solution_s);
        let first_solution_warm_s = opt(|r| r.first_solution_warm_s);
        let time_to_optimum_s = opt(|r| r.time_to_optimum_s);
        let cost_at_1s = opt(|r| r.cost_at_1s);
        let cost_at_10s = opt(|r| r.cost_at_10s);
        let optimum_search_time_s = val(|r| r.optimum_search_time_s);
        let expansions_per_s = val(|r| r.expansions_per_s);
        let heuristic_setup_s = val(|r| r.heuristic_setup_s);
        let k = runs.iter().position(|r| r.first_solution_s == first_solution_s).unwrap_or(0);
        let mut row = runs.swap_remove(k);
        row.first_solution_s = first_solution_s;
        row.first_solution_warm_s = first_solution_warm_s;
        row.time_to_optimum_s = time_to_optimum_s;
        row.cost_at_1s = cost_at_1s;
        row.cost_at_10s = cost_at_10s;
        row.optimum_search_time_s = optimum_search_time_s;
        row.expansions_per_s = expansions_per_s;
        row.expansions = expansions;
        row.heuristic_setup_s = heuristic_setup_s;
        row.repeats = n;
        Some(row)
    }
}

/// A benchmark of one scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// Scenario name.
    pub scenario: String,
    /// Cost-map building time, s.
    pub setup_time_s: f64,
    /// A* then ARA*.
    pub rows: Vec<BenchRow>,
}

/// Benchmarks A* (16-neighbourhood) and ARA* (20-neighbourhood, ε from 3) on
/// `scenario`, ARA* twice: the paper's schedule alone, and as `plan` runs it, after the
/// greedy probe (the scenario's `arastar_probe_epsilon`). The optimum of each
/// neighbourhood comes from an A* run with `optimum_time_limit_s`; for the A* row that
/// run is the measurement itself.
///
/// # Errors
/// As [`run`]'s set-up errors, and invalid options.
pub fn bench(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &BenchOptions,
) -> Result<BenchReport, PlanJobError> {
    let ara_limit = check_time("arastar_time_limit_s", opts.arastar_time_limit_s)?;
    let opt_limit = check_time("optimum_time_limit_s", opts.optimum_time_limit_s)?;
    if opts.repeats == 0 {
        return Err(bad("repeats", "0 must be at least 1"));
    }
    let file = || scenario.path.clone();
    let prep = prepare(scenario, robot, ParamOverrides { k12: opts.k12, ..Default::default() })?;
    let k12 = prep.params.k12;
    // `tables`: the heuristic cache the graph shares (none: tables of its own), and
    // whether the search stops at its first path.
    let run_one = |algorithm,
                   n,
                   limit,
                   probe_epsilon,
                   probe_guidance,
                   tables: Option<(&HeuristicCache, bool)>|
     -> Result<(SearchResult<LatticeState>, f64), PlanJobError> {
        let mut g = prep
            .graph(robot, n, k12)
            .map_err(|source| PlanJobError::Lattice { scenario: file(), source })?;
        if let Some((cache, _)) = tables {
            g = g.with_heuristic_cache(cache);
        }
        let setup = g.heuristic_setup_time().as_secs_f64();
        let first_only = tables.is_some_and(|(_, first)| first);
        let p = SearchParams {
            initial_epsilon: prep.params.arastar_initial_epsilon,
            epsilon_decay: prep.params.arastar_epsilon_decay,
            time_limit: Some(limit),
            probe_epsilon,
            probe_guidance,
            schedule_max_expansions: first_only.then_some(0),
            ..SearchParams::default()
        };
        search(&mut g, prep.start, algorithm, &p, None, None)
            .map(|r| (r, setup))
            .map_err(|source| PlanJobError::Search { scenario: file(), source })
    };
    // The repeats alternate the searches, so slow phases of a noisy machine spread over
    // all of them.
    let (mut astar_runs, mut ara_runs) = (Vec::new(), Vec::new());
    let (mut probe_runs, mut unguided_runs) = (Vec::new(), Vec::new());
    let probe_epsilon =
        probe_before(prep.params.arastar_probe_epsilon, prep.params.arastar_initial_epsilon);
    for _ in 0..opts.repeats {
        let (astar16, setup16) =
            run_one(Algorithm::AStar, Neighbourhood::N16, opt_limit, None, false, None)?;
        astar_runs.push(row("astar", "n16", &astar16, optimum_of(&astar16), &astar16, setup16));
        let (astar20, _) =
            run_one(Algorithm::AStar, Neighbourhood::N20, opt_limit, None, false, None)?;
        let optimum20 = optimum_of(&astar20);
        let (ara, setup20) =
            run_one(Algorithm::AraStar, Neighbourhood::N20, ara_limit, None, false, None)?;
        ara_runs.push(row("arastar", "n20", &ara, optimum20, &astar20, setup20));
        if probe_epsilon.is_some() {
            // Cold, filling a cache of its own; then the same search on that cache.
            let cache = HeuristicCache::default();
            let ara_probe = |tables| {
                run_one(
                    Algorithm::AraStar,
                    Neighbourhood::N20,
                    ara_limit,
                    probe_epsilon,
                    true,
                    tables,
                )
            };
            let (ara, setup) = ara_probe(Some((&cache, false)))?;
            let mut probed = row("arastar+probe", "n20", &ara, optimum20, &astar20, setup);
            let (warm, _) = ara_probe(Some((&cache, true)))?;
            probed.first_solution_warm_s = warm.solutions.first().map(|s| s.time.as_secs_f64());
            probe_runs.push(probed);
            let (ara, setup) = run_one(
                Algorithm::AraStar,
                Neighbourhood::N20,
                ara_limit,
                probe_epsilon,
                false,
                None,
            )?;
            unguided_runs.push(row("arastar+unguided", "n20", &ara, optimum20, &astar20, setup));
        }
    }
    let rows = [astar_runs, ara_runs, probe_runs, unguided_runs]
        .into_iter()
        .filter_map(BenchRow::median_of)
        .collect();
    Ok(BenchReport { scenario: scenario.name.clone(), setup_time_s: prep.setup_time_s, rows })
}

/// ARA*'s probe at ε `probe` before a schedule from `initial_epsilon`
/// (`SearchParams::probe_epsilon`): none unless it is greedier than the schedule.
fn probe_before(probe: f64, initial_epsilon: f64) -> Option<f64> {
    (probe > initial_epsilon).then_some(probe)
}

fn optimum_of(r: &SearchResult<LatticeState>) -> Option<f64> {
    (r.termination == Termination::OptimalProven)
        .then(|| r.best().map(|s| s.cost.to_f64()))
        .flatten()
}

fn row(
    algorithm: &'static str,
    neighbourhood: &'static str,
    r: &SearchResult<LatticeState>,
    optimum: Option<f64>,
    reference: &SearchResult<LatticeState>,
    heuristic_setup_s: f64,
) -> BenchRow {
    let sols: Vec<(f64, f64)> =
        r.solutions.iter().map(|s| (s.time.as_secs_f64(), s.cost.to_f64())).collect();
    let first = sols.first().copied();
    let at = |t: f64| sols.iter().rev().find(|(ts, _)| *ts <= t).map(|&(_, c)| c);
    // Costs are sums of the same fixed-point edges, so "optimal" is an exact match up
    // to the micro-unit.
    let time_to_optimum =
        optimum.and_then(|o| sols.iter().find(|(_, c)| (c - o).abs() < 1e-6).map(|&(t, _)| t));
    BenchRow {
        algorithm,
        neighbourhood,
        optimum,
        optimum_search_time_s: reference.elapsed.as_secs_f64(),
        first_solution_s: first.map(|f| f.0),
        first_solution_warm_s: None,
        first_cost: first.map(|f| f.1),
        first_over_optimum_pct: first.zip(optimum).map(|(f, o)| (f.1 / o - 1.0) * 100.0),
        first_bound: r.solutions.first().map(|s| s.suboptimality_bound),
        cost_at_1s: at(1.0),
        cost_at_10s: at(10.0),
        time_to_optimum_s: time_to_optimum,
        first_expansions: r.solutions.first().map(|s| s.expansions),
        expansions: r.expansions,
        expansions_per_s: r.expansions as f64 / r.elapsed.as_secs_f64().max(1e-9),
        heuristic_setup_s,
        solutions: sols,
        repeats: 1,
    }
}

/// How a search's step checks ended, for a failure's message: `; of N step checks M
/// failed: …` and how many steps failed checks elsewhere turned away (empty when no
/// step was checked). Where the steps fail says what stopped
/// the search: no leg height within reach, or front or rear steps with no stable motion.
fn step_checks_said(stats: &ManoeuvreStats) -> String {
    let failed = stats.steps_failed();
    let checked = failed + stats.step_checks_passed;
    if checked == 0 {
        return String::new();
    }
    let copies = match stats.step_failures_translated {
        0 => String::new(),
        n => format!("; {n} more steps turned away as copies of failed checks elsewhere"),
    };
    format!(
        "; of {checked} step checks {failed} failed: {} with no leg height within reach, \
         {} front and {} rear steps with no stable motion, {} otherwise{copies}",
        stats.steps_without_leg_height,
        stats.front_steps_unstable,
        stats.rear_steps_unstable,
        stats.steps_failed_otherwise
    )
}

#[cfg(test)]
mod tests {
    use super::BenchRow;

    #[test]
    fn a_failure_says_how_its_step_checks_ended() {
        use crate::locomotion::ManoeuvreStats;
        assert_eq!(super::step_checks_said(&ManoeuvreStats::default()), "");
        let stats = ManoeuvreStats {
            step_checks_passed: 10,
            steps_without_leg_height: 4,
            front_steps_unstable: 3,
            rear_steps_unstable: 2,
            steps_failed_otherwise: 1,
            ..ManoeuvreStats::default()
        };
        assert_eq!(
            super::step_checks_said(&stats),
            "; of 20 step checks 10 failed: 4 with no leg height within reach, 3 front and \
             2 rear steps with no stable motion, 1 otherwise"
        );
        let copied = ManoeuvreStats { step_failures_translated: 7, ..stats };
        let said = super::step_checks_said(&copied);
        let copies = "1 otherwise; 7 more steps turned away as copies of failed checks elsewhere";
        assert!(said.ends_with(copies), "{said}");
    }

    #[test]
    fn a_long_flight_planned_with_the_paper_step_model_is_told_the_stairs_models() {
        // The repository's six-step flight names the stairs models; without them (or with
        // the paper's) a "no path" says which to set, and so does a four-step flight; a
        // three-step one (which the paper's model climbs) and the stairs model get none.
        use crate::params::StepModel;
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/stairs_long.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        let sc = crate::scenario::Scenario::parse(&text, &path).unwrap();
        assert_eq!(super::stairs_model_hint(&sc, StepModel::Stairs), "");
        let hint = super::stairs_model_hint(&sc, StepModel::Paper);
        assert!(
            hint.starts_with("; its stairs have 6 steps")
                && hint.contains("step_model = \"stairs\"")
                && hint.contains("foot_model = \"wheel_pair\""),
            "{hint}"
        );
        for (steps, hinted) in [(4, true), (3, false)] {
            let t = text.replace("steps = 6", &format!("steps = {steps}"));
            let sc = crate::scenario::Scenario::parse(&t, &path).unwrap();
            assert_eq!(!super::stairs_model_hint(&sc, StepModel::Paper).is_empty(), hinted);
        }
    }

    fn run(first: f64, to_optimum: Option<f64>, at_1s: Option<f64>, rate: f64) -> BenchRow {
        BenchRow {
            algorithm: "arastar",
            neighbourhood: "n20",
            optimum: Some(78.0),
            optimum_search_time_s: 2.0 * first,
            first_solution_s: Some(first),
            first_solution_warm_s: Some(first / 10.0),
            first_cost: Some(80.0),
            first_over_optimum_pct: Some(2.5),
            first_bound: Some(1.6),
            cost_at_1s: at_1s,
            cost_at_10s: Some(79.0),
            time_to_optimum_s: to_optimum,
            first_expansions: Some(400),
            expansions: 1000,
            expansions_per_s: rate,
            heuristic_setup_s: 0.01,
            solutions: vec![(first, 80.0)],
            repeats: 1,
        }
    }

    #[test]
    fn bench_rows_take_the_median_of_each_time() {
        let m = BenchRow::median_of(vec![
            run(3.0, Some(10.0), None, 100.0),
            run(1.0, None, None, 300.0),
            run(2.0, Some(5.0), Some(80.0), 200.0),
        ])
        .expect("three runs");
        // First solutions 1, 2, 3 s: 2 s, and that run's solution list.
        assert_eq!(m.first_solution_s, Some(2.0));
        assert_eq!(m.first_solution_warm_s, Some(0.2));
        assert_eq!(m.solutions, vec![(2.0, 80.0)]);
        // To the optimum 5, 10 and never: 10 s. A cost at 1 s in one run of three: none.
        assert_eq!(m.time_to_optimum_s, Some(10.0));
        assert_eq!(m.cost_at_1s, None);
        assert_eq!(m.optimum_search_time_s, 4.0);
        assert_eq!(m.expansions_per_s, 200.0);
        assert_eq!(m.repeats, 3);
        assert_eq!(BenchRow::median_of(Vec::new()), None);
    }
}
