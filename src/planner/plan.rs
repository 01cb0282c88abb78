//! The hybrid driving-stepping planner (Klamt & Behnke 2017, Sec. V, VII) run on a
//! prepared world ([`super::world`]), returning a serialisable [`PlanSummary`].
//!
//! [`run_on`] searches the world's hybrid graph with A* (16-neighbourhood) or ARA*
//! (20-neighbourhood, ε from 3 decaying to 1), as the paper does; the plans of one job
//! (`run`'s retries and replans) share the world and the heuristic's tables toward its
//! goal ([`super::HeuristicCache`]). [`run`] prepares the world and plans. The time limit
//! covers everything after option checking: map and cost-map building count against it,
//! and the search gets what is left, so a call never takes much longer than the limit.
//! [`run_counted`] also counts the expansions per base cell ([`ExpansionCounts`]), whether
//! a path was found or not.
//!
//! Path costs are reported twice: `search_cost` as searched (with the orientation factor
//! k_Δθ of the chosen k12) and `cost`, "the costs the path would have in the plain A*
//! planner" (Sec. VIII): every edge re-evaluated with k12 = 1, so variants with different
//! k12 compare.

use super::graph::ManoeuvreSet;
use super::options::{ParamOverrides, PlanError, PlanOptions, bad, check_options};
use super::world::{MapInfo, PAPER_MODEL_FLIGHT_STEPS, Prepared, params_for, prepare_for};
use super::{HybridGraph, LatticeState, ManoeuvreStats, Neighbourhood, PoseKey};
use crate::params::{FootModel, StepModel};
use crate::path::{ManoeuvreKind, PathElement};
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use crate::search::Algorithm;
use crate::search::{
    Cost, ExpandHook, Expansion, Hooks, SearchError, SearchParams, SearchResult, Termination,
    arastar_with_hooks, astar_with_hooks,
};
use crate::terrain::HeightMap;
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

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

/// Runs one search on `graph`; with `counts` (row-major over the lattice's cells, which
/// are the height map's), counts the expansions of each base cell.
pub(crate) fn search(
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

/// Plans a path for `scenario` with `manoeuvres` (see the module docs).
///
/// # Errors
/// [`PlanError`]: bad options, an unbuildable map, a start or goal off the map or on
/// untraversable terrain, or no path found (none exists, or none within the time limit).
pub fn run(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    manoeuvres: &'static dyn ManoeuvreSet,
) -> Result<PlanSummary, PlanError> {
    run_counted(scenario, robot, opts, manoeuvres, None)
}

/// Where a search went: expansions per base cell (row-major over the height map's cells,
/// which are the lattice's), and the height map they lie on.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpansionCounts {
    /// The world's height map.
    pub heights: HeightMap,
    /// Expansions per cell.
    pub counts: Vec<u32>,
}

/// [`run`], counting the expansions per base cell into `counts` when given: filled
/// whatever the outcome once the world is built, so a search that finds no path still
/// shows where it spent its expansions.
///
/// # Errors
/// As [`run`].
pub fn run_counted(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    manoeuvres: &'static dyn ManoeuvreSet,
    counts: Option<&mut Option<ExpansionCounts>>,
) -> Result<PlanSummary, PlanError> {
    let limit = check_options(opts)?;
    let t0 = Instant::now();
    let prep = prepare_for(scenario, robot, opts, manoeuvres)?;
    search_prepared(&prep, scenario, robot, opts, (t0, limit), counts)
}

/// Plans on a world [`prepare_for`] built for `scenario` with `opts`' overrides, from its
/// start ([`Prepared::set_start`]): [`run`] without building the maps again, and with the
/// heuristic tables of the world's earlier plans toward the same goal.
///
/// # Errors
/// As [`run`]; [`PlanError::BadOption`] if `prep` was built with other parameters.
pub fn run_on(
    prep: &Prepared,
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
) -> Result<PlanSummary, PlanError> {
    run_on_counted(prep, scenario, robot, opts, None)
}

/// [`run_on`], counting the expansions as [`run_counted`] does.
///
/// # Errors
/// As [`run_on`].
pub fn run_on_counted(
    prep: &Prepared,
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    counts: Option<&mut Option<ExpansionCounts>>,
) -> Result<PlanSummary, PlanError> {
    let limit = check_options(opts)?;
    let params = params_for(scenario, &prep.flights, opts.overrides)?;
    if params != prep.params {
        return Err(bad(
            "prepared",
            "the world was prepared with other parameters than these options give",
        ));
    }
    search_prepared(prep, scenario, robot, opts, (Instant::now(), limit), counts)
}

/// What a "no path" adds for a plan with the paper's step model (named in the file or
/// asked for) on a height map with a flight of [`PAPER_MODEL_FLIGHT_STEPS`] risers or
/// more: the models that climb it. Empty otherwise.
fn stairs_model_hint(prep: &Prepared) -> String {
    let n = prep.flights.risers;
    if prep.params.step_model == StepModel::Paper && n >= PAPER_MODEL_FLIGHT_STEPS {
        format!(
            "; its height map has a flight of {n} steps, and with step_model = \"paper\" \
             flights of {PAPER_MODEL_FLIGHT_STEPS} or more have no path: set step_model = \
             \"stairs\" and foot_model = \"wheel_pair\" (docs/models.md)"
        )
    } else {
        String::new()
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
    counts_out: Option<&mut Option<ExpansionCounts>>,
) -> Result<PlanSummary, PlanError> {
    let file = || scenario.path.clone();
    let neighbourhood = opts.neighbourhood.unwrap_or_else(|| default_neighbourhood(opts.algorithm));
    let lattice_err = |source| PlanError::Lattice { scenario: file(), source };
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
    let mut counts = counts_out.is_some().then(|| {
        let (nx, ny) = prep.maps.heights().dims();
        vec![0u32; nx * ny]
    });
    let result =
        search(&mut graph, prep.start, opts.algorithm, &search_params, None, counts.as_deref_mut());
    if let (Some(out), Some(counts)) = (counts_out, counts) {
        *out = Some(ExpansionCounts { heights: prep.maps.heights().clone(), counts });
    }
    let result = result.map_err(|source| PlanError::Search { scenario: file(), source })?;
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
            Termination::ExpansionLimit => format!(
                "none found within the expansion budget of {} ({:.1} s{})",
                opts.max_expansions.unwrap_or(result.expansions),
                result.elapsed.as_secs_f64(),
                checks
            ),
            t => format!("the search stopped ({})", termination_name(t)),
        };
        let reason = reason + &stairs_model_hint(prep);
        return Err(PlanError::NoPath {
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
    let steps = path.iter().filter(|e| e.kind == ManoeuvreKind::Step).count();
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
            kind: label.map_or(ManoeuvreKind::Start, |m| m.kind),
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

/// ARA*'s probe at ε `probe` before a schedule from `initial_epsilon`
/// (`SearchParams::probe_epsilon`): none unless it is greedier than the schedule.
pub(crate) fn probe_before(probe: f64, initial_epsilon: f64) -> Option<f64> {
    (probe > initial_epsilon).then_some(probe)
}

/// How a search's step checks ended, for a failure's message: `; of N step checks M
/// failed: …` and how many steps failed checks elsewhere turned away (empty when no
/// step was checked). Where the steps fail says what stopped
/// the search: no leg height within reach, or front or rear steps with no stable motion.
pub(crate) fn step_checks_said(stats: &ManoeuvreStats) -> String {
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
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_failure_says_how_its_step_checks_ended() {
        use crate::planner::ManoeuvreStats;
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
        // The repository's six-step flight, its models chosen from its heights: the stairs
        // model gets no hint; the paper's (asked for) is told which to set, and so is a
        // four-step flight; a three-step one (which the paper's model climbs) gets none.
        use crate::params::StepModel;
        use crate::planner::graph::{Manoeuvre, ManoeuvreSet};
        use crate::planner::{ParamOverrides, prepare};
        /// The hint needs the prepared world, not its manoeuvres.
        struct NoManoeuvres;
        impl ManoeuvreSet for NoManoeuvres {
            fn instantiate(&self) -> Vec<Box<dyn Manoeuvre>> {
                Vec::new()
            }
        }
        let robot = crate::robot::RobotDescription::reference();
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/stairs_long.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        let hint = |text: &str, step_model| {
            let sc = crate::scenario::Scenario::parse(text, &path).unwrap();
            let overrides = ParamOverrides { step_model, ..ParamOverrides::default() };
            let prep = prepare(&sc, &robot, overrides, &NoManoeuvres).unwrap();
            super::stairs_model_hint(&prep)
        };
        assert_eq!(hint(&text, None), "");
        let said = hint(&text, Some(StepModel::Paper));
        assert!(
            said.starts_with("; its height map has a flight of 6 steps")
                && said.contains("step_model = \"stairs\"")
                && said.contains("foot_model = \"wheel_pair\""),
            "{said}"
        );
        for (steps, hinted) in [(4, true), (3, false)] {
            let t = text.replace("steps = 6", &format!("steps = {steps}"));
            assert_eq!(!hint(&t, Some(StepModel::Paper)).is_empty(), hinted, "{steps} steps");
        }
    }
}
