//! The tables the hybrid heuristic looks up ([`HeuristicTables`]), built once per graph
//! from what its manoeuvres say of themselves ([`Relaxation`]), and the cache through
//! which the graphs of one job share them ([`HeuristicCache`]).

use super::cost_to_go::CostToGo;
use super::reachability::{BaseRegions, StanceLimits};
use super::step_bound::{STEP_HEIGHT_TOLERANCE_M, StepBound, StepBoundParams};
use super::way::WayField;
use crate::cost::CostMaps;
use crate::planner::config::HybridConfig;
use crate::planner::driving::DrivingGoal;
use crate::planner::lattice::{Lattice, LatticeState};
use crate::robot::RobotDescription;
use crate::search::Cost;
use std::cell::RefCell;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// Which term of the heuristic pays for a manoeuvre's edges: what the manoeuvre tells
/// the heuristic of itself (`planner::graph::Manoeuvre::relaxation`). The consistency
/// proofs of the terms are in their modules (`cost_to_go`, `step_bound`); a manoeuvre
/// that none of them bounds needs a new term and its proof.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Relaxation {
    /// Moves the base as a drive or a turn on the spot does, at the pose costs of eq. 4:
    /// the Euclidean distance plus turn and the cost-to-go's driving edges bound it.
    Driving,
    /// Carries one foot across untraversable terrain at C_S (eq. 5): the step bound's
    /// chains between components of finite foot cost bound it.
    Step,
    /// Moves the base along its heading over standing feet at no less than `f · k10` per
    /// metre: the cost-to-go's base-shift links, with the foot-offset potential's rise.
    BaseShift,
    /// Rolls one wheel pair along the ground at C_FM (eq. 6): the foot-offset potential
    /// Φ bounds it.
    WheelMove,
}

/// What the hybrid graph's heuristic looks up, built once per graph (at its first use).
pub struct HeuristicTables {
    /// Base cells that can still reach the goal (`reachability`): an infinite heuristic
    /// elsewhere proves "no path" without searching.
    pub regions: BaseRegions,
    /// The step-cost part (`step_bound`); zero everywhere without steps.
    pub step_bound: StepBound,
    /// The driving and base-shift part (`cost_to_go`): a backward search over base
    /// cells (an A* aimed at the start), run lazily as far as the queries need.
    pub cost_to_go: CostToGo,
    /// The feet's way to the goal over terrain they could climb (`way`): the greedy
    /// list's distance where it exceeds the straight line.
    pub way: WayField,
    /// Time spent building the step bound, the regions and the way.
    pub setup: Duration,
}

/// What [`HeuristicTables::build`] reads.
pub struct TableInputs<'a> {
    /// The cost maps.
    pub maps: &'a CostMaps,
    /// The robot.
    pub robot: &'a RobotDescription,
    /// The lattice.
    pub lattice: &'a Lattice,
    /// The graph's configuration.
    pub config: &'a HybridConfig,
    /// The goal.
    pub goal: DrivingGoal,
    /// The criterion-1 pre-filter per cell (`planner::core`).
    pub near: &'a [bool],
    /// Each leg's widest offset range, cells.
    pub reach: [[i8; 2]; 4],
    /// How high any state's hips and base stand above its feet.
    pub stance: StanceLimits,
    /// What the graph's manoeuvres say of themselves.
    pub relaxations: &'a [Relaxation],
}

impl HeuristicTables {
    /// Builds the tables for a graph's map, configuration, goal and manoeuvres: the step
    /// bound where a manoeuvre steps (zero otherwise), the cost-to-go's base-shift links
    /// where one shifts the base (none otherwise), the reachable regions and the way.
    pub fn build(input: &TableInputs<'_>) -> Self {
        let t0 = Instant::now();
        let TableInputs { maps, robot, lattice, config, goal, near, reach, .. } = *input;
        let res = lattice.resolution;
        let has = |r: Relaxation| input.relaxations.contains(&r);
        let max_step_cells = reach.iter().map(|r| i32::from(r[1]) - i32::from(r[0])).max();
        let max_step_length_m = f64::from(max_step_cells.unwrap_or(0).max(0)) * res;
        // The goal's feet: the step bound's sources and the way's.
        let goal_feet = goal_feet(maps, lattice, goal);
        let step_bound = if has(Relaxation::Step) {
            build_step_bound(maps, near, config, lattice, &goal_feet, max_step_length_m)
        } else {
            StepBound::zero()
        };
        // A base shift costs at least f · k10 per metre (C_B ≥ 1) and raises the
        // foot-offset potential by 4 c per cell (`step_bound::offset_potential`).
        let shift_step = if has(Relaxation::BaseShift) {
            Cost::from_f64_floor(config.step_cost_factor * config.k10 * res * (1.0 - 1e-9))
                .saturating_add(Cost(step_bound.offset_per_cell().0.saturating_mul(4)))
        } else {
            Cost::INFINITY
        };
        let cost_to_go = CostToGo::new(
            *lattice,
            &config.driving,
            shift_step,
            (goal.i, goal.j, goal.theta),
            (config.cost_to_go_groups, config.max_oriented_nodes),
        );
        let regions = BaseRegions::build(
            maps,
            robot,
            lattice,
            (config.motion.base_circle_radius_m, &input.stance, &step_bound),
            (goal.i, goal.j),
        );
        let goal_points: Vec<[f64; 2]> = goal_feet.iter().flatten().copied().collect();
        let max_rise = config.max_step_height_m + STEP_HEIGHT_TOLERANCE_M;
        let way = WayField::build(maps.heights(), &goal_points, max_rise);
        Self { regions, step_bound, cost_to_go, way, setup: t0.elapsed() }
    }
}

/// The heuristic tables of the graphs on one cost map, by what they were built for:
/// a later graph of the same robot, configuration, manoeuvres and goal on the same map
/// takes them over (`HybridGraph::with_heuristic_cache`) instead of building them again,
/// and its searches resume the cost-to-go where the earlier ones left it. A job keeps
/// one per map (`planner::Prepared`), so a plan's retries with edges the motion
/// generator rejected, and the replans of a run, share one heuristic. Forbidden edges
/// (`HybridGraph::forbid`) do not enter the tables, which are relaxations: a lower bound,
/// and consistent, stays so when edges are taken away.
#[derive(Default)]
pub struct HeuristicCache {
    entries: RefCell<Vec<CachedTables>>,
}

impl std::fmt::Debug for HeuristicCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeuristicCache").field("tables", &self.entries.borrow().len()).finish()
    }
}

/// What a set of tables was built for: the cost map's address (a cache serves one map),
/// the robot, the configuration, the manoeuvres' relaxations and the goal.
#[derive(Clone, PartialEq)]
pub struct TablesKey {
    /// The cost map's address.
    pub maps: usize,
    /// The robot.
    pub robot: RobotDescription,
    /// The configuration.
    pub config: HybridConfig,
    /// The manoeuvres' relaxations.
    pub relaxations: Vec<Relaxation>,
    /// The goal.
    pub goal: DrivingGoal,
}

/// One entry of a [`HeuristicCache`]: tables and what they were built for.
struct CachedTables {
    key: TablesKey,
    tables: Rc<HeuristicTables>,
}

impl HeuristicCache {
    /// The tables built for `key`, if an earlier graph left them here.
    pub fn get(&self, key: &TablesKey) -> Option<Rc<HeuristicTables>> {
        self.entries.borrow().iter().find(|e| e.key == *key).map(|e| Rc::clone(&e.tables))
    }

    /// Leaves `tables`, built for `key`, for later graphs.
    pub fn insert(&self, key: TablesKey, tables: &Rc<HeuristicTables>) {
        self.entries.borrow_mut().push(CachedTables { key, tables: Rc::clone(tables) });
    }
}

/// The step bound of the heuristic for the goal's feet `goal_feet` ([`goal_feet`]). The
/// link radius covers the largest jump of a foot's cell in a drive (2), a
/// turn (the chord of the widest foot) and a base shift (1), plus one against rounding.
fn build_step_bound(
    maps: &CostMaps,
    near: &[bool],
    config: &HybridConfig,
    lattice: &Lattice,
    goal_feet: &[[[f64; 2]; 4]],
    max_step_length_m: f64,
) -> StepBound {
    let res = lattice.resolution;
    let radius = maps.neutral_footprint().iter().map(|f| f[0].hypot(f[1])).fold(0.0, f64::max);
    let chord = 2.0 * radius * (0.5 * lattice.orientation_step()).sin();
    let chord_cells = if lattice.orientations > 1 { (chord / res).ceil() } else { 0.0 };
    let link_cells = chord_cells.clamp(2.0, 1000.0) as usize + 1;
    let params = StepBoundParams {
        step_cost_factor: config.step_cost_factor,
        k7: config.k7,
        k8: config.k8,
        k9: config.k9,
        max_step_height_m: config.max_step_height_m,
        link_cells,
        max_step_length_m,
        k10: config.k10,
        k11: config.k11,
    };
    StepBound::build(maps, near, &params, goal_feet)
}

/// The neutral feet of the goal pose, one array of four per goal orientation accepted
/// (every orientation when the goal leaves it free).
fn goal_feet(maps: &CostMaps, lattice: &Lattice, goal: DrivingGoal) -> Vec<[[f64; 2]; 4]> {
    let thetas: Vec<u8> = match goal.theta {
        Some(t) => vec![t],
        None => (0..lattice.orientations).map(|k| k as u8).collect(),
    };
    thetas
        .into_iter()
        .map(|theta| maps.neutral_feet(&lattice.pose(LatticeState::new(goal.i, goal.j, theta))))
        .collect()
}
