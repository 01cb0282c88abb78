//! The hybrid driving-stepping graph (Klamt & Behnke 2017, Sec. V): driving in the
//! neutral footprint plus the stepping manoeuvres of Fig. 5 and Fig. 6, as one
//! [`SearchGraph`] over [`LatticeState`]s `(i, j, θ, footprint)`.
//!
//! **States.** The base pose is a lattice pose (`lattice`); the footprint id names four
//! longitudinal foot offsets in a [`FootprintTable`] (`footprint`). A foot stands at its
//! neutral position (x', y') in the base frame moved by its offset along x'. Neutral
//! states drive and turn exactly as in [`DrivingGraph`]; every state may in addition have
//! these successors, each changing the footprint:
//!
//! - **abstract step** (Sec. V, Fig. 5, 6a): a foot moves from its pre-step to its after-step
//!   position, forward in its sagittal plane, the base staying put. Added only when all
//!   four criteria hold (see `HybridGraph::best_step`); its cost is C_S (eq. 5) of the
//!   cheapest end position, the only one returned.
//! - **longitudinal base shift** (Fig. 6b): when both front feet stand ahead of neutral,
//!   the base moves forward over the standing feet until one front foot is neutral or a
//!   rear leg reaches its reach limit. Cost C_BS = k10 · L_BS · C_B,avg. A rear leg at
//!   its limit can stand but not step (the step's stance pitches the base less), so
//!   where a rear foot close to an obstacle could not step after the full shift, the
//!   shift ends at the longest length from which it can
//!   (`HybridGraph::rear_step_ready_shift`); otherwise a square approach to a 0.186 m
//!   block left both rear feet stranded and the plan climbed diagonally at ten times
//!   the cost.
//! - **front foot forward** (Fig. 6c): when a rear foot is close to an obstacle, a front
//!   wheel pair drives forward (keeping ground contact), preparing a rear step — as far
//!   as its leg reaches and the terrain is drivable, in one move. Cost C_FM (eq. 6).
//! - **foot to neutral** (Fig. 6d): in a non-neutral footprint, one wheel pair drives
//!   back to its neutral position. Cost C_FM (eq. 6). With `step_model = "stairs"`,
//!   where the way to neutral is not drivable and the foot is not close to an obstacle,
//!   it drives up to the last drivable cell before the obstacle instead (then it is
//!   close to it, and may step). (With the paper's model it would also apply, but it
//!   slowed generated `up_and_over` searches by a fifth for no new path.)
//!
//! All four manoeuvre costs are multiplied by the step-related factor
//! ([`HybridConfig::step_cost_factor`], Sec. V, Fig. 7: the calibration is documented on
//! `Params::step_cost_factor`).
//!
//! **Choices where the paper is silent** (each tested in `locomotion::tests`):
//! - *Leg reach.* A non-neutral footprint is allowed only if the robot can stand in it by
//!   the leg-height rule of Sec. VI-B that the step motion generator uses
//!   ([`crate::posture::standing::StandingRule`]): base pitched by 70 % of the slope, its
//!   height set by the highest foot, the leg height lowered from 0.45 m in 1 cm steps until
//!   every leg reaches its foot (sagittal IK within the joint limits). A step must in
//!   addition stay within reach while the foot is carried: the stepping leg counting the
//!   higher of its grounds, the foot at its swing height above both ends. One rule for
//!   planner and generator, so no planned footprint stretches a leg the generator cannot.
//!   Each leg's offset range over all those heights, computed once from the model, bounds
//!   the scans.
//! - *Support for a step.* The paper leaves static stability to the step motion
//!   generator. A plan whose step no alignment can stabilise is useless to it, so a step
//!   must pass the generator's own check (`motion::expand::ManoeuvreCheck::step`: roll,
//!   wheel to centre, base shift, lift, swing, place and back, every centimetre, with the
//!   CoM estimate `posture::standing::EstimatedCom` and 3 mm of margin to spare): a
//!   planned step is one the generator expands, and no cheaper test turns away a step
//!   that check admits (a CoM-in-triangle pre-check once came first and turned away steps
//!   the generator expands, see `HybridGraph::step_feasible`).
//! - *Which footholds count as a step.* A step must carry the foot *over* untraversable
//!   terrain: its straight sagittal line crosses at least one cell of infinite foot cost.
//!   A foothold reachable over finite cells only is a wheel drive (front foot forward /
//!   foot to neutral), not a step — otherwise the cheapest "step" would always be one
//!   cell long.
//! - *ΔH_step* (eq. 5) is the largest |H(c) − H(f_j)| over the cells the foot passes,
//!   end included; the paper's third criterion bounds |H(f_j) − H(c_h)| by 0.3 m, and
//!   Fig. 5c's "the height difference to overcome" bounds ΔH_step as well (a leg cannot
//!   lift a foot over a 0.5 m bar even if the far side is level).
//! - *Non-neutral states* must have all four feet on cells of finite foot cost, a finite
//!   body cost C_B (eq. 3) with the legs of the standing rule above (the robot stands
//!   up for manoeuvres, Sec. VI-B), and the two feet of each side at least half the
//!   support length (`min_support_side_length_m` / 2) apart, so wheel pairs never
//!   collide. Only neutral states drive.
//! - *The rear-step approach* (`step_model = "stairs"` only): where the front feet stand
//!   on other ground than the rear ones, a rear foot is not close to an obstacle and a
//!   front foot's way ahead is blocked, a base shift past the front feet's neutral (their
//!   legs reach back) to the first length at which a rear foot, rolled forward to
//!   neutral, comes close to one. Without it the feet of one side stay a hip spacing
//!   (0.7 m) apart, and on treads shorter than that no footprint puts a rear foot at a
//!   riser while the front feet stand on a tread. It is a base shift like the others
//!   (same cost, same heuristic terms), so the heuristic stays consistent.
//! - *The climb shift* (`step_model = "stairs"` only): a climb is under way (a front
//!   foot stands higher than a rear foot), a rear foot is close to an obstacle and the
//!   front feet do not both stand ahead of neutral. On a flight longer than the robot
//!   the front feet stand on a tread they cannot roll along, at or behind neutral; no
//!   longitudinal shift applies, a rear foot lifted there leaves the CoM behind the
//!   other three, and the front legs cannot reach the next tread from so far back. The
//!   base shifts forward past the front feet's neutral as far as every leg reaches,
//!   shortened to where a rear foot close to an obstacle can still step (as the
//!   longitudinal shift is); a base shift like the others. Not offered on descents,
//!   where it stretched the lower front legs to their reach limit (a planned descent
//!   with it tipped over in closed loop).
//! - *The descent shift* (both step models): a front foot close to an obstacle steps
//!   down (its cheapest foothold lies lower than the foot by more than a wheel drives
//!   down) and the front feet do not both stand ahead of neutral. The base shifts
//!   forward past the front feet's neutral until that front hip stands over the middle
//!   of the step, or the length nearest to it at which every leg stands on the way and
//!   the foot can still step. It mirrors what a climb gets from the longitudinal shift
//!   before its rear steps (the rear hip over the riser, the rear foot behind it): with
//!   the hip over its foot, a front leg lifted over an edge folds past the knee's limit
//!   at every height from which it still reaches a floor 0.24 m or more below, beyond the
//!   edge's untraversable band, and every such drop had no path. A base shift like the
//!   others (same cost, same heuristic terms), so the heuristic stays consistent.
//!   Offered mid-flight as at a platform's edge: the one flight on which a mid-flight
//!   shift tipped the robot over lost a stance pair to the base's pitch, an executor
//!   defect its stance compliance fixed (`control::step_executor`).
//! - *Flights longer than the robot* (four or more building-code steps) need the last
//!   two and the partial foot to neutral: without them a rear foot short of a riser
//!   could neither step nor roll up to it, and every reachable pose was searched
//!   without a path.
//! - *Base shifts* end on the lattice cell containing the exact shifted position (the
//!   feet then stand up to half a cell from where they were; the paper's grid has the
//!   same issue). The edge cost is `max(C_BS · factor, distance moved)`, which keeps the
//!   heuristic consistent even for factors below 2.
//!
//! **Lazy step checks** (issue 15). A step's checks after the scan (the standing rule's
//! IK for the after-step state, the generator's own step check) cost about a quarter of a
//! millisecond when they pass, and most steps the search generates are never expanded.
//! So the search's edge for a step (`SearchGraph::successors`) goes to an *intermediate
//! node*: the same pose with [`LatticeState::step_pending`] naming the leg, at the cost of
//! the cheapest foothold the scan found, a lower bound of the step's. Expanding the node
//! runs the checks (`best_step`) and gives the step itself at the rest of its
//! cost, or nothing. The graph is the same (paths and costs are those of checking every
//! step at once), and the search's paths leave the nodes out
//! (`SearchGraph::is_intermediate`). The node's heuristic is `min_c (c_c + h(t_c)) − c_lb`
//! over the scan's footholds `c` (edge cost `c_c`, after-step state `t_c`, `c_lb` the
//! least `c_c`): consistent into the node because the heuristic is consistent on every
//! step from the pose, and out of it because the step taken is one of the `c`.
//! `labelled_successors` and [`HybridGraph::edge`] give the checked steps directly.
//!
//! **Translated step failures** (issue 15). A step check that failed is remembered by
//! the terrain it read, its stance and its step, not by where it stood: the
//! orientation, footprint, leg and new offset, and the print of every map layer over a
//! window that holds everything the check reads (`cost::prints`; the window below). A
//! check from another cell with the same key fails without being run. Along a straight
//! edge, a stair's riser or a wall the terrain repeats cell by cell, and a search whose
//! heuristic cannot tell the cells apart tries the same failing step at each: on the
//! 0.3 m step-down scenario 31 k of its 31 k step checks failed, most of them copies.
//! Only failures are taken over. A check reads the maps at points computed from its
//! absolute pose, so where one lands within rounding of a cell boundary a translated
//! copy may read the neighbouring cell: a remembered failure can turn away a step the
//! exact check would pass there (a lost option, never a plan the generator cannot
//! expand), and a remembered success could admit one it would fail. The window is the
//! box of the feet before and after the step, widened by the foot link, half the wheel
//! track, the wheel radius and a margin, and of the base's corners and hips, widened by
//! the largest base shift of a step candidate, the thigh and the margin: every leg
//! point lies within a thigh of its hip or between its knee and its foot, every foot
//! the check moves stays between the stance's feet, and the base moves only by the
//! candidates' shift (`HybridConfig::reuse_translated_step_failures`).
//!
//! **Heuristic** (issues 4 and 15): `max(h_E, D) + S + Φ`, clamped at zero, where
//!
//! 1. `h_E` is that of [`DrivingGraph`]: Euclidean distance plus the orientation
//!    difference times the turning radius. Steps and foot moves leave the base in place;
//!    drives and base shifts cost at least the distance they move the base (pose costs
//!    ≥ 1, k_Δθ ≥ 1, and a base shift's cost is at least its move); turns cost at least
//!    their arc;
//! 2. `D` is the cost-to-go of the `cost_to_go` module: a lazy backward Dijkstra over
//!    (cell, orientation) whose edges relax drives (the pose cost of eq. 4 at that
//!    orientation, k_Δθ), turns and base shifts (f · k10 per cell, plus Φ's rise);
//!    consistent on every manoeuvre, with Φ on base shifts. The larger of two consistent
//!    heuristics is consistent, and both parts leave the same share of each edge's cost
//!    to the parts below (none of drives and turns, Φ's rise on base shifts, all of
//!    steps and foot moves);
//! 3. `S` is the step bound Σ_k S_k of the `heuristic` module: per foot, the cheapest
//!    chain of steps (C_S, eq. 5, times the step-related factor) from the foot's
//!    component of finite-C_F cells to the component of its goal position. Only a step
//!    moves a foot between components, and it costs at least the bound's drop;
//! 4. `Φ = c · Σ_k (o_k⁻ − o_k⁺)` is the foot-offset potential (offsets in metres; zero
//!    for the neutral footprint): a foot behind neutral still has to come forward, one
//!    ahead has paid in advance for base motion `D` counts. Foot moves pay c per metre by
//!    eq. 6 (C_F ≥ the map's smallest), steps by the share λ of eq. 5's k7 term that `S`
//!    leaves out; a base shift raises Φ (`heuristic::offset_potential`).
//!
//! `S` is zero where no step is needed and Φ for the neutral footprint. The proofs are
//! in the `cost_to_go` and `heuristic` module docs; `locomotion::tests` checks
//! `h(s) ≤ c(s, t) + h(t)` on sampled edges of every manoeuvre near a platform edge and
//! on random walks over random small maps, and that A*'s optimum does not change.

use super::cost_to_go::CostToGo;
use super::driving::{
    DrivingConfig, DrivingGoal, DrivingGraph, PoseCostSource, edge_cost, heuristic_cost,
};
use super::footprint::{FootOffsets, FootprintTable, NEUTRAL_OFFSETS};
use super::heuristic::{STEP_HEIGHT_TOLERANCE_M, StepBound, StepBoundParams, offsets_weighed};
use super::lattice::{Lattice, LatticeError, LatticeState, NEUTRAL_FOOTPRINT, Neighbourhood};
use super::reachability::{BaseRegions, StanceLimits};
use super::way::WayField;
use crate::cost::{Cost as CostValue, CostMaps, HeadingBin};
use crate::feasibility::DrivingCheck;
use crate::feasibility::MotionOptions;
use crate::geometry::Pose2;
use crate::motion::expand::{ManoeuvreCheck, MotionError};
use crate::params::{Params, StepModel};
use crate::path::{EdgeLabel, ManoeuvreKind, StepCost};
use crate::posture::kinematics::{Posture, hips_in_world};
use crate::posture::standing::EstimatedCom;
use crate::robot::ik::leg_ik;
use crate::robot::{Leg, RobotDescription};
use crate::search::{Cost, FxBuild, SearchGraph};
use serde::Serialize;
use std::cell::{Cell, OnceCell, RefCell};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;
use std::time::{Duration, Instant};

/// A foothold of a step by the scan (`HybridGraph::step_candidates`): C_S, the offset
/// change in cells, the cost terms and the foothold (x, y, ground z).
type StepCandidate = (f64, i32, StepCost, [f64; 3]);

/// C_S = k7 · L_step + k8 · (C_F(c_h) − 1) + k9 · ΔH_step (eq. 5), before the
/// step-related factor.
pub fn step_cost(params: &HybridConfig, length_m: f64, foothold_cost: f64, height_m: f64) -> f64 {
    params.k7 * length_m + params.k8 * (foothold_cost - 1.0) + params.k9 * height_m
}

/// C_BS = k10 · L_BS · C_B,avg (Sec. V), before the step-related factor.
pub fn base_shift_cost(params: &HybridConfig, length_m: f64, body_cost_avg: f64) -> f64 {
    params.k10 * length_m * body_cost_avg
}

/// C_FM = k11 · L_FM · C_F,avg (eq. 6), before the step-related factor.
pub fn foot_move_cost(params: &HybridConfig, length_m: f64, foot_cost_avg: f64) -> f64 {
    params.k11 * length_m * foot_cost_avg
}

/// Configuration of the hybrid graph: the driving part and the manoeuvre constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HybridConfig {
    /// Driving moves, k_Δθ, turn radius.
    pub driving: DrivingConfig,
    /// Step cost weight on L_step (eq. 5).
    pub k7: f64,
    /// Step cost weight on C_F(c_h) − 1 (eq. 5).
    pub k8: f64,
    /// Step cost weight on ΔH_step (eq. 5).
    pub k9: f64,
    /// Base shift weight (C_BS).
    pub k10: f64,
    /// Single foot move weight (eq. 6).
    pub k11: f64,
    /// Factor on every step-related manoeuvre cost (Sec. V, Fig. 7).
    pub step_cost_factor: f64,
    /// Criterion 1: an infinite-cost cell closer than this to the foot, m.
    pub step_obstacle_distance_m: f64,
    /// Criterion 3: largest |ΔH| of a step, m.
    pub max_step_height_m: f64,
    /// Largest height difference a wheel drives over (eq. 2), m.
    pub max_foot_height_diff_m: f64,
    /// Criterion 4: the feet on the non-stepping side must be farther apart, m.
    pub min_support_side_length_m: f64,
    /// Shortest "front foot forward" move, m (each such move drives as far as it can).
    pub foot_move_increment_m: f64,
    /// Cap on distinct footprints (graph size guard).
    pub max_footprints: usize,
    /// Orientation groups of the heuristic's cost-to-go, one layer of nodes each (a
    /// divisor of the lattice's orientations; see `cost_to_go`).
    pub cost_to_go_groups: usize,
    /// Most (cell, group) nodes for which the heuristic's cost-to-go keeps
    /// `cost_to_go_groups` layers (`cost_to_go::MAX_ORIENTED_NODES`); above, one layer.
    pub max_oriented_nodes: usize,
    /// Smallest stability margin of a posture, m (the generator's requirement).
    pub min_stability_margin_m: f64,
    /// Whether a step check that failed answers the same check on the same terrain at
    /// another cell (module docs, "Translated step failures").
    pub reuse_translated_step_failures: bool,
    /// The motion generator's constants: the leg-height rule for standing manoeuvres
    /// (reach and leg clearance, Sec. VI-B), the driving leg height, the base circles'
    /// radius, the wheel-to-centre move and gap of a step; with them steps are checked
    /// ([`ManoeuvreCheck::step`]), whose margin is the generator's plus
    /// [`PLANNER_MARGIN_SLACK_M`].
    pub motion: MotionOptions,
}

/// A step check by what it reads and does (`HybridGraph::translated_step`): the print
/// of its window, the window's cells relative to the state's, the orientation, the
/// footprint's offsets, the leg and its new offset.
type TranslatedStep = (u128, [i16; 4], u8, FootOffsets, u8, i8);

/// Margin of a translated step's window beyond the reach it bounds, m (with two cells
/// more): the base's pitch and roll move the hips a few centimetres, and bilinear
/// reads take the next cell.
const TRANSLATION_WINDOW_MARGIN_M: f64 = 0.05;

/// How the robot stands on a footprint at a lattice pose (`HybridGraph::stand`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stand {
    /// No height of the standing rule reaches every foot clear of the terrain, or the
    /// body would touch it.
    No,
    /// The rule's posture stands, its legs clear of the leg terrain.
    Stands,
    /// It also clears the swept leg terrain: a wheel move between two such postures
    /// needs no check in between (`HybridGraph::wheel_move_feasible`).
    SweptClear,
}

/// The [`LatticeState::step_pending`] tag of leg index `k` (0..4).
fn leg_tag(k: usize) -> u8 {
    k as u8 + 1
}

/// A wheel move the lattice offers: the leg whose pair rolls, the footprint after it, its
/// cost (C_FM times the step-related factor) and length.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FootMove {
    kind: ManoeuvreKind,
    leg: Leg,
    to: FootOffsets,
    cost: f64,
    length_m: f64,
}

impl FootMove {
    fn manoeuvre(&self) -> EdgeLabel {
        EdgeLabel {
            kind: self.kind,
            leg: Some(self.leg),
            length_m: self.length_m,
            cost: self.cost,
            step: None,
        }
    }
}

/// Margin the planner's step check requires beyond the generator's, m: the
/// planner's CoM estimate ([`EstimatedCom`]) is MuJoCo's to a micrometre with the wheels
/// level, but the roll of eqs. 6–8 is iterated to 3 mm of its target with either model,
/// so the generator's roll may differ slightly from the planner's.
pub const PLANNER_MARGIN_SLACK_M: f64 = 0.003;

impl HybridConfig {
    /// From the paper's constants and the robot's neutral footprint; the shortest foot
    /// move is 0.1 m and up to 65 536 footprints (all `u16` ids) are allowed.
    pub fn new(params: &Params, robot: &RobotDescription, neighbourhood: Neighbourhood) -> Self {
        Self {
            driving: DrivingConfig::new(params, &robot.neutral_footprint(), neighbourhood),
            k7: params.k7,
            k8: params.k8,
            k9: params.k9,
            k10: params.k10,
            k11: params.k11,
            step_cost_factor: params.step_cost_factor,
            step_obstacle_distance_m: params.step_obstacle_distance_m,
            max_step_height_m: params.max_step_height_m,
            max_foot_height_diff_m: params.max_foot_height_diff_m,
            min_support_side_length_m: params.min_support_side_length_m,
            foot_move_increment_m: 0.1,
            max_footprints: 65_536,
            cost_to_go_groups: super::cost_to_go::ORIENTATION_GROUPS,
            max_oriented_nodes: super::cost_to_go::MAX_ORIENTED_NODES,
            min_stability_margin_m: params.min_stability_margin_m,
            reuse_translated_step_failures: true,
            motion: {
                let mut m = MotionOptions::from_params(params);
                m.min_margin_m += PLANNER_MARGIN_SLACK_M;
                m.min_three_contact_margin_m += PLANNER_MARGIN_SLACK_M;
                m
            },
        }
    }
}

/// Where the four feet of a state stand and what is under them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Feet {
    /// World (x, y), FL, FR, RL, RR.
    pos: [[f64; 2]; 4],
    /// Foot cost C_F of each foot's cell (finite).
    cf: [f64; 4],
    /// Ground height of each foot's cell, m.
    h: [f64; 4],
}

/// Counters of the manoeuvres generated, for reports and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ManoeuvreStats {
    /// Steps generated (edges, counted per expansion).
    pub steps: u64,
    /// Base shifts generated.
    pub base_shifts: u64,
    /// Front-foot-forward moves generated.
    pub foot_forward: u64,
    /// Foot-to-neutral moves generated.
    pub foot_neutral: u64,
    /// Manoeuvres dropped because the footprint table was full.
    pub footprint_table_full: u64,
    /// Step checks the motion generator passed (the checks run: each step of a state is
    /// checked once, `step_checks` memoises it).
    pub step_checks_passed: u64,
    /// Step checks that found no leg height within reach (the standing rule's
    /// `step_heights`): the generator was not asked.
    pub steps_without_leg_height: u64,
    /// Step checks of a front leg the generator turned down: no candidate motion kept
    /// the robot stable and within reach.
    pub front_steps_unstable: u64,
    /// The same for a rear leg.
    pub rear_steps_unstable: u64,
    /// Step checks that failed otherwise (no standing posture before the step, unknown
    /// terrain).
    pub steps_failed_otherwise: u64,
    /// Steps turned away, without a check, by a failed check of the same step on the
    /// same terrain at another cell (module docs, "Translated step failures").
    pub step_failures_translated: u64,
}

impl ManoeuvreStats {
    /// Step checks that failed, for any reason.
    pub fn steps_failed(&self) -> u64 {
        self.steps_without_leg_height
            + self.front_steps_unstable
            + self.rear_steps_unstable
            + self.steps_failed_otherwise
    }
}

/// What the hybrid graph's heuristic looks up, built once per graph (at its first use).
struct HeuristicTables {
    /// Base cells that can still reach the goal (`reachability`): an infinite heuristic
    /// elsewhere proves "no path" without searching.
    regions: BaseRegions,
    /// The step-cost part (`heuristic`).
    step_bound: StepBound,
    /// The driving and base-shift part (`cost_to_go`): a backward Dijkstra over base
    /// cells, run lazily as far as the queries need.
    cost_to_go: CostToGo,
    /// The feet's way to the goal over terrain they could climb (`way`): the greedy
    /// list's distance where it exceeds the straight line.
    way: WayField,
    /// Time spent building the step bound, the regions and the way.
    setup: Duration,
}

/// The heuristic tables of the graphs on one cost map, by what they were built for:
/// a later graph of the same robot, configuration and goal on the same map takes them
/// over ([`HybridGraph::with_heuristic_cache`]) instead of building them again, and its
/// searches resume the cost-to-go where the earlier ones left it. A job keeps one per
/// map (`jobs::plan::Prepared`), so a plan's retries with edges the motion generator
/// rejected, and the replans of a run, share one heuristic. Forbidden edges
/// ([`HybridGraph::forbid`]) do not enter the tables, which are relaxations: a lower
/// bound, and consistent, stays so when edges are taken away.
#[derive(Default)]
pub struct HeuristicCache {
    entries: RefCell<Vec<CachedTables>>,
}

impl std::fmt::Debug for HeuristicCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeuristicCache").field("tables", &self.entries.borrow().len()).finish()
    }
}

/// One entry of a [`HeuristicCache`]: tables and what they were built for.
struct CachedTables {
    /// The cost map's address (a cache serves one map).
    maps: usize,
    robot: RobotDescription,
    config: HybridConfig,
    goal: DrivingGoal,
    tables: Rc<HeuristicTables>,
}

/// The hybrid graph over one cost map.
pub struct HybridGraph<'c> {
    maps: &'c CostMaps,
    driving: DrivingGraph<FeasibleDriving<'c>>,
    /// The shared feasibility model (`feasibility`): body clearance of standing states.
    feasibility: DrivingCheck,
    /// Edges the motion generator rejected in an earlier plan (`jobs::run`): left out.
    forbidden: Vec<(PoseKey, PoseKey)>,
    config: HybridConfig,
    lattice: Lattice,
    /// Neutral foot positions in the base frame (x', y'), FL, FR, RL, RR.
    neutral: [[f64; 2]; 4],
    /// The robot (leg IK of the standing rule).
    robot: RobotDescription,
    /// Widest offset range per leg, cells: `[min, max]`, over every leg height a
    /// manoeuvre can give it (the scan bound; the exact check is the standing rule).
    reach: [[i8; 2]; 4],
    footprints: FootprintTable,
    /// Per map cell: an infinite-foot-cost cell lies within the criterion-1 radius plus
    /// half a cell diagonal of its centre (a conservative pre-filter for criterion 1).
    near: Vec<bool>,
    /// `(sin θ, cos θ)` per orientation index.
    trig: Vec<(f64, f64)>,
    /// Shortest "front foot forward" move, cells.
    foot_move_cells: i8,
    /// [`GREEDY_OFFSET_PER_M`] per lattice cell.
    greedy_offset_per_cell: Cost,
    /// Scratch buffer for the labelled special successors.
    special: Vec<(LatticeState, Cost, EdgeLabel)>,
    /// The counters; a `Cell`, as the step checks are counted in `step_feasible`, which
    /// takes `&self`.
    stats: Cell<ManoeuvreStats>,
    /// The heuristic's tables, built (or taken from `heuristic_cache`) at its first
    /// use, and whether they were taken: a graph asked only for edges (`jobs::plan`'s
    /// plain-cost graph) never builds them.
    heuristic: OnceCell<(Rc<HeuristicTables>, bool)>,
    /// Where earlier graphs on this map left their tables, if given.
    heuristic_cache: Option<&'c HeuristicCache>,
    /// The cost-to-go's deadline, for tables built after it was set.
    heuristic_deadline: Cell<Option<Instant>>,
    /// [`Self::target_ok`] of non-neutral footprints by (cell, orientation, offsets): a
    /// footprint is entered from several predecessors, and each check runs the standing
    /// rule's IK. Grouped by pose: one expansion asks about a few dozen footprints at
    /// one pose (the cells of its wheel moves), so after the pose's first look-up the
    /// rest hit a small table in cache; one table of every footprint (5.2 M on the
    /// platform's A*) missed the cache at nearly every look-up.
    standable: HashMap<(i16, i16, u8), HashMap<FootOffsets, Stand, FxBuild>, FxBuild>,
    /// [`Self::step_feasible`] by the state a step starts from, the leg and its new
    /// offset: ARA* expands a state again in each iteration.
    step_checks: HashMap<(PoseKey, u8, i8), bool, FxBuild>,
    /// The failed step checks by what they read and did, wherever they stood (module
    /// docs, "Translated step failures").
    translated_failures: HashSet<TranslatedStep, FxBuild>,
    /// [`Self::wheel_segment_ok`] by the pose and footprint a one-cell wheel move starts
    /// from, the leg and its new offset.
    wheel_move_checks: HashMap<(PoseKey, u8, i8), bool, FxBuild>,
    /// [`Self::base_shift_feasible`] by the state a shift starts from (cell, orientation,
    /// footprint id) and the cell it ends on.
    base_shift_checks: HashMap<(i16, i16, u8, u16, i16, i16), bool, FxBuild>,
}

/// The parts of the hybrid heuristic of a state (`HybridGraph::heuristic_parts`):
/// `h = max(driving, to_go) + steps + behind − ahead`, clamped at zero, or infinite
/// when `reachable` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeuristicParts {
    /// Infinite when the base cell cannot reach the goal at all (`reachability`).
    pub reachable: Cost,
    /// Euclidean distance plus turn (`driving`).
    pub driving: Cost,
    /// The base-cell cost-to-go (`cost_to_go`).
    pub to_go: Cost,
    /// The step bound Σ_k S_k (`heuristic`).
    pub steps: Cost,
    /// Φ's part for feet behind neutral, c · Σ o⁻.
    pub behind: Cost,
    /// Φ's part for feet ahead of neutral, c · Σ o⁺ (subtracted).
    pub ahead: Cost,
    /// The greedy list's share for feet behind neutral, [`GREEDY_OFFSET_PER_M`] · Σ o⁻.
    pub greedy_behind: Cost,
    /// The greedy list's share for feet ahead of neutral, [`GREEDY_OFFSET_PER_M`] · Σ o⁺
    /// (subtracted).
    pub greedy_ahead: Cost,
    /// The feet's mean way to the goal over terrain they could climb, one per metre like
    /// the straight line, plus the same turn as `driving` (`way`; zero where unknown): the
    /// greedy list takes the larger of the two.
    pub way: Cost,
}

/// The weight of each foot's offset from neutral, per metre, in the estimate that orders
/// the probe's greedy list ([`HeuristicParts::greedy_guidance`]): a quarter of what the
/// guidance counts per metre the base still has to go (the driving heuristic's straight
/// line, 1 per metre), so that a base shift toward the goal, which brings the base `l`
/// nearer and leaves all four feet `l` further behind, leaves the estimate where it was.
/// At the heuristic's own weight c (eq. 6's `f · k11 · C_F,min`, 1.34 per metre with the
/// paper's constants) every such shift raises it by `(4c − 1) · l`, a hill a greedy
/// search crosses only after every state below it: before a 0.3 m drop, whose steps
/// need the base shifted over the edge, the whole platform at every heading. The
/// weighted guided list keeps c: there the strong pull of feet toward neutral and ahead
/// of it orders the many footprints of one stance, and a probe ordered by the level
/// estimate alone lost a 0.174 m descent it found in 4,091 expansions (`README.md`,
/// "Planner speed"). Where the feet's way is longer than the straight line (`way`), the
/// shift is not level: it leaves the feet, and their way, where they were and raises the
/// offsets' share by `l`. The way is longer beside a climb, and, by up to 8 % (the octile
/// way's excess), at bearings off the grid's axes and diagonals; the drops measured
/// (`scenarios/step_down.toml`, `step_down_030002`) took 5 % and 4 % fewer expansions
/// with it, not more.
pub const GREEDY_OFFSET_PER_M: f64 = 0.25;

impl HeuristicParts {
    /// `h = max(driving, to_go) + steps + behind − ahead`, clamped at zero; infinite
    /// when `reachable` is.
    pub fn total(&self) -> Cost {
        if self.reachable.is_infinite() {
            return Cost::INFINITY;
        }
        let h = self.driving.max(self.to_go).saturating_add(self.steps).saturating_add(self.behind);
        if h.is_infinite() {
            return h;
        }
        // Clamped at zero (feet ahead of neutral have paid in advance).
        h.saturating_sub(self.ahead)
    }

    /// The guided probe's estimate (`SearchGraph::heuristic_and_guidance`):
    /// [`Self::total`] without the cost-to-go, `driving + steps + behind − ahead`. The
    /// cost-to-go relaxes base shifts over any edge, so it pulls the search to where the
    /// base could be shifted onto a platform most cheaply if steps were free, such as the
    /// open side of a flight of stairs, where the feet cannot follow; the step bound
    /// alone, with the straight-line distance, leads to the front of the flight.
    pub fn guidance(&self) -> Cost {
        let without = Self { to_go: Cost::ZERO, ..*self };
        without.total()
    }

    /// The estimate of the probe's greedy list (`SearchGraph::heuristic_and_guidances`):
    /// [`Self::guidance`] with the feet's offsets weighed at [`GREEDY_OFFSET_PER_M`] and
    /// the straight line replaced by the feet's way where that is longer,
    /// `max(driving, way) + steps + greedy_behind − greedy_ahead`. The straight line
    /// misleads where the goal lies beyond a climb: beside a flight's top the floor is
    /// nearer the goal than the flight's foot, and a probe stuck at the foot searched that
    /// floor at every heading first. The feet's way (`way` module) goes back to the foot
    /// and up the flight. Not a bound, nor meant to be one (the way is counted per cell,
    /// and not every manoeuvre that shortens it pays one per metre): ε′ comes from
    /// [`Self::total`].
    pub fn greedy_guidance(&self) -> Cost {
        let without = Self {
            to_go: Cost::ZERO,
            driving: self.driving.max(self.way),
            behind: self.greedy_behind,
            ahead: self.greedy_ahead,
            ..*self
        };
        without.total()
    }
}

/// A lattice state by what it means, not by this graph's footprint ids: cell,
/// orientation and foot offsets. Names a state across graphs (replans).
pub type PoseKey = (i16, i16, u8, FootOffsets);

/// Driving pose costs of the cost client where the shared feasibility model admits the
/// driving posture (`feasibility::DrivingCheck::lattice_pose`), none elsewhere: the
/// driving graph memoises both per lattice pose.
struct FeasibleDriving<'c> {
    maps: &'c CostMaps,
    check: DrivingCheck,
}

impl PoseCostSource for FeasibleDriving<'_> {
    fn driving_cost(&self, pose: &Pose2) -> Option<f64> {
        let cost = self.maps.driving_pose_cost(pose).finite()?;
        self.check.lattice_pose(self.maps, pose).ok().map(|()| cost)
    }

    fn steering_matters(&self) -> bool {
        self.maps.foot_heading_dependent()
    }

    fn steered_fit_mask(&self, pose: &Pose2, directions: &[Option<f64>]) -> u32 {
        self.maps.steered_feet_fit_mask(pose, directions)
    }
}

/// The offsets (cells, −64..=63) at which `leg` reaches its foot with the hip `height`
/// above the ground (sagittal leg IK, level base), as a bit set: bit `o + 64`.
fn leg_reach(robot: &RobotDescription, leg: Leg, height: f64, res: f64) -> u128 {
    let mut bits = 0u128;
    for o in -64..64_i32 {
        let x = robot.neutral_foot_offset_x[leg.index()] + f64::from(o) * res;
        if leg_ik(robot, leg, [x, -height], 0.0).is_ok() {
            bits |= 1 << (o + 64);
        }
    }
    bits
}

/// The smallest and largest offset in a reach bit set (`[0, 0]` if empty).
fn bit_range(bits: u128) -> [i8; 2] {
    if bits == 0 {
        return [0, 0];
    }
    let lo = bits.trailing_zeros() as i32 - 64;
    let hi = 127 - bits.leading_zeros() as i32 - 64;
    [lo as i8, hi as i8]
}

impl<'c> HybridGraph<'c> {
    /// The hybrid graph on `maps` (lattice over its height map with `orientations`
    /// orientations) searching for `goal`.
    ///
    /// # Errors
    /// A map too large for the lattice or an invalid orientation count.
    pub fn new(
        maps: &'c CostMaps,
        robot: &RobotDescription,
        orientations: u32,
        config: HybridConfig,
        goal: DrivingGoal,
    ) -> Result<Self, LatticeError> {
        let lattice = Lattice::for_map(maps.heights(), orientations)?;
        let res = lattice.resolution;
        // Level-base leg reach over hip heights from the straight leg down to the driving
        // height less the largest step, in 1 cm steps: a superset of what the standing
        // rule admits (pitch below 45° moves a foot less than the leg's full swing).
        let mut union = [0u128; 4];
        let top = (robot.max_leg_length() * 100.0).ceil() as i32;
        let low = ((config.motion.standing.min_leg_height_m - config.max_step_height_m) * 100.0)
            .floor()
            .max(0.0) as i32;
        for cm in low..=top {
            let h = f64::from(cm) * 0.01;
            for (k, leg) in Leg::ALL.iter().enumerate() {
                union[k] |= leg_reach(robot, *leg, h, res);
            }
        }
        let reach = union.map(bit_range);
        let trig = (0..lattice.orientations).map(|k| lattice.yaw(k as u8).sin_cos()).collect();
        let foot_move_cells = (config.foot_move_increment_m / res).round().clamp(1.0, 127.0) as i8;
        let near = near_obstacle_layer(maps, config.step_obstacle_distance_m);
        let feasibility = DrivingCheck::from_parts(
            robot,
            config.motion.standing,
            config.motion.driving_leg_height_m,
            config.min_stability_margin_m,
            config.motion.base_circle_radius_m,
        );
        Ok(Self {
            maps,
            driving: DrivingGraph::new(
                FeasibleDriving { maps, check: feasibility.clone() },
                lattice,
                config.driving,
                goal,
            ),
            feasibility,
            forbidden: Vec::new(),
            near,
            config,
            lattice,
            neutral: maps.neutral_footprint(),
            robot: robot.clone(),
            reach,
            footprints: FootprintTable::new(config.max_footprints),
            trig,
            foot_move_cells,
            greedy_offset_per_cell: Cost::from_f64(GREEDY_OFFSET_PER_M * res),
            special: Vec::with_capacity(16),
            stats: Cell::new(ManoeuvreStats::default()),
            heuristic: OnceCell::new(),
            heuristic_cache: None,
            heuristic_deadline: Cell::new(None),
            standable: HashMap::default(),
            wheel_move_checks: HashMap::default(),
            base_shift_checks: HashMap::default(),
            step_checks: HashMap::default(),
            translated_failures: HashSet::default(),
        })
    }

    /// This graph with the heuristic tables of `cache` (see [`HeuristicCache`]): taken
    /// over if an earlier graph on the same map built them for the same robot,
    /// configuration and goal, else built at the first query and left there.
    #[must_use]
    pub fn with_heuristic_cache(mut self, cache: &'c HeuristicCache) -> Self {
        self.heuristic_cache = Some(cache);
        self
    }

    /// The heuristic's tables, built (or taken from the cache) on the first call.
    fn tables(&self) -> &HeuristicTables {
        &self.tables_and_origin().0
    }

    /// The heuristic's tables and whether they came from the cache.
    fn tables_and_origin(&self) -> &(Rc<HeuristicTables>, bool) {
        self.heuristic.get_or_init(|| {
            let goal = self.driving.goal();
            let maps = std::ptr::from_ref(self.maps) as usize;
            let fits = |e: &CachedTables| {
                e.maps == maps && e.goal == goal && e.config == self.config && e.robot == self.robot
            };
            let cached = self.heuristic_cache.and_then(|cache| {
                cache.entries.borrow().iter().find(|e| fits(e)).map(|e| Rc::clone(&e.tables))
            });
            let reused = cached.is_some();
            let tables = cached.unwrap_or_else(|| {
                let tables = Rc::new(self.build_tables());
                if let Some(cache) = self.heuristic_cache {
                    cache.entries.borrow_mut().push(CachedTables {
                        maps,
                        robot: self.robot.clone(),
                        config: self.config,
                        goal,
                        tables: Rc::clone(&tables),
                    });
                }
                tables
            });
            // A new search's budget: taken tables grow again from where the earlier
            // searches left them.
            tables.cost_to_go.thaw();
            tables.cost_to_go.set_deadline(self.heuristic_deadline.get());
            (tables, reused)
        })
    }

    /// Builds the heuristic's tables for this graph's map, configuration and goal.
    fn build_tables(&self) -> HeuristicTables {
        let t0 = Instant::now();
        let res = self.lattice.resolution;
        let max_step_cells = self.reach.iter().map(|r| i32::from(r[1]) - i32::from(r[0])).max();
        let max_step_length_m = f64::from(max_step_cells.unwrap_or(0).max(0)) * res;
        let (config, goal) = (&self.config, self.driving.goal());
        // The goal's feet: the step bound's sources and the way's.
        let goal_feet = goal_feet(self.maps, &self.lattice, goal);
        let step_bound = build_step_bound(
            self.maps,
            &self.near,
            config,
            &self.lattice,
            &goal_feet,
            max_step_length_m,
        );
        // A base shift costs at least f · k10 per metre (C_B ≥ 1) and raises the
        // foot-offset potential by 4 c per cell (`heuristic::offset_potential`).
        let shift_step =
            Cost::from_f64_floor(config.step_cost_factor * config.k10 * res * (1.0 - 1e-9))
                .saturating_add(Cost(step_bound.offset_per_cell().0.saturating_mul(4)));
        let cost_to_go = CostToGo::new(
            self.lattice,
            &config.driving,
            shift_step,
            (goal.i, goal.j, goal.theta),
            (config.cost_to_go_groups, config.max_oriented_nodes),
        );
        let regions = BaseRegions::build(
            self.maps,
            &self.robot,
            &self.lattice,
            (config.motion.base_circle_radius_m, &self.stance_limits(), &step_bound),
            (goal.i, goal.j),
        );
        let goal_points: Vec<[f64; 2]> = goal_feet.iter().flatten().copied().collect();
        let max_rise = config.max_step_height_m + STEP_HEIGHT_TOLERANCE_M;
        let way = WayField::build(self.maps.heights(), &goal_points, max_rise);
        HeuristicTables { regions, step_bound, cost_to_go, way, setup: t0.elapsed() }
    }

    /// How high any state's hips and base stand above its feet (`reachability`): the
    /// standing rule's tallest leg height and pitch fraction, and the mean front feet's
    /// least lead over the mean rear feet: each side's front foot stands at least half
    /// the support length ahead of its rear foot ([`Self::sides_ok`]; neutral states a hip
    /// spacing), or the legs' reach limits, whichever says more.
    fn stance_limits(&self) -> StanceLimits {
        let res = self.lattice.resolution;
        let x = |k: usize, o: i8| {
            self.robot.hips[k][0] + self.robot.neutral_foot_offset_x[k] + f64::from(o) * res
        };
        let [fl, fr, rl, rr] = self.reach;
        let reach = (x(0, fl[0]) + x(1, fr[0]) - x(2, rl[1]) - x(3, rr[1])) / 2.0;
        let sides = 0.5 * self.config.min_support_side_length_m;
        let spread = reach.max(sides.min(self.side_length(&[0; 4], true)));
        let standing = &self.config.motion.standing;
        StanceLimits {
            leg_height_m: standing.leg_height_m.max(self.config.motion.driving_leg_height_m),
            pitch_fraction: standing.pitch_fraction,
            min_feet_spread_m: spread,
        }
    }

    /// The front-foot-forward move of leg index `k` from `s` that `special_successors`
    /// offers ([`Self::push_longest_feasible_move`]), or with `longest_first` the one
    /// trying the moves longest first finds ([`Self::push_first_feasible_move`]): its
    /// footprint, and the leg's offset at the end of the longest move it chose from
    /// (`None`: there was none). For tests.
    #[cfg(test)]
    pub(crate) fn forward_move(
        &mut self,
        s: LatticeState,
        k: usize,
        longest_first: bool,
    ) -> (Option<FootOffsets>, Option<i8>) {
        let Some((o, feet)) = self.offsets(s).and_then(|o| Some((o, self.feet_of(s, &o)?))) else {
            return (None, None);
        };
        let moves = self.foot_forward_moves(s, &o, &feet, k);
        self.special.clear();
        if longest_first {
            self.push_first_feasible_move(s, &o, &moves);
        } else {
            self.push_longest_feasible_move(s, &o, &moves);
        }
        let to = self.special.first().and_then(|&(t, _, _)| self.offsets(t));
        (to, moves.first().map(|m| m.to[k]))
    }

    /// Whether the heuristic's tables have been built (by a first heuristic query).
    #[cfg(test)]
    pub(crate) fn heuristic_built(&self) -> bool {
        self.heuristic.get().is_some()
    }

    /// Time spent building the heuristic's step bound and reachable regions (not part of
    /// any search's time: `jobs::plan` has them built before it starts the clock); zero
    /// when they came from a [`HeuristicCache`].
    pub fn heuristic_setup_time(&self) -> Duration {
        let (tables, reused) = self.tables_and_origin();
        if *reused { Duration::ZERO } else { tables.setup }
    }

    /// Whether the heuristic's tables came from a [`HeuristicCache`] (an earlier graph
    /// built them); builds or fetches them if no query has yet.
    pub fn heuristic_reused(&self) -> bool {
        self.tables_and_origin().1
    }

    /// The parts of the heuristic of `s` (see [`HeuristicParts`]).
    pub fn heuristic_parts(&self, s: LatticeState) -> HeuristicParts {
        let o = self.footprints.get(s.footprint);
        let feet = o.map(|o| self.feet_pos(s, &o));
        self.parts_with(s, o.as_ref().zip(feet.as_ref()))
    }

    /// [`Self::heuristic_parts`] of the pose of `s` with foot offsets and feet positions
    /// `footprint` (none: an unknown footprint, which adds no step bound).
    fn parts_with(
        &self,
        s: LatticeState,
        footprint: Option<(&FootOffsets, &[[f64; 2]; 4])>,
    ) -> HeuristicParts {
        let mut p = HeuristicParts {
            reachable: Cost::ZERO,
            driving: Cost::ZERO,
            to_go: Cost::ZERO,
            steps: Cost::ZERO,
            behind: Cost::ZERO,
            ahead: Cost::ZERO,
            greedy_behind: Cost::ZERO,
            greedy_ahead: Cost::ZERO,
            way: Cost::ZERO,
        };
        let tables = self.tables();
        if !tables.regions.reachable(s.i, s.j) {
            p.reachable = Cost::INFINITY;
            return p;
        }
        p.driving = self.driving.heuristic(s);
        if let Some((o, feet)) = footprint {
            p.steps = tables.step_bound.lower_bound(self.maps, feet);
            (p.behind, p.ahead) = tables.step_bound.offset_potential(o);
            (p.greedy_behind, p.greedy_ahead) = offsets_weighed(o, self.greedy_offset_per_cell);
            p.way = tables.way.mean_of(self.maps.heights(), feet).map_or(Cost::ZERO, |w| {
                heuristic_cost(w).saturating_add(self.driving.turn_heuristic(s))
            });
        }
        if p.steps.is_infinite() {
            // No chain of steps reaches the goal: the cost-to-go need not be searched.
            return p;
        }
        p.to_go = tables.cost_to_go.get(self.maps, s.i, s.j, s.theta);
        if !tables.cost_to_go.oriented() {
            // One layer for all orientations: turns are not in it.
            p.to_go = p.to_go.saturating_add(self.driving.turn_heuristic(s));
        }
        p
    }

    /// The heuristic and the guidance (`HeuristicParts::guidance`) of an intermediate
    /// node `p` (see [`SearchGraph::heuristic`] of this graph); `None` if its pose has
    /// no footprint or feet on finite cells, or the scan no foothold (the node then has
    /// no successor).
    fn pending_heuristic(&self, p: LatticeState) -> Option<(Cost, Cost, Cost)> {
        let k = usize::from(p.step_pending.checked_sub(1)?);
        let s = LatticeState { step_pending: 0, ..p };
        let o = self.footprints.get(s.footprint)?;
        let feet = self.feet_of(s, &o)?;
        let f = self.config.step_cost_factor;
        let candidates = self.step_candidates(s, &o, &feet, k);
        let charged = edge_cost(f * candidates.first()?.0);
        let (mut best, mut guided, mut greedy) = (Cost::INFINITY, Cost::INFINITY, Cost::INFINITY);
        for &(c_s, d, _, _) in &candidates {
            let mut o2 = o;
            o2[k] = (i32::from(o[k]) + d) as i8;
            // The after-step state's own heuristic: its feet as `feet_pos` places them.
            let parts = self.parts_with(s, Some((&o2, &self.feet_pos(s, &o2))));
            let c = edge_cost(f * c_s);
            best = best.min(c.saturating_add(parts.total()));
            guided = guided.min(c.saturating_add(parts.guidance()));
            greedy = greedy.min(c.saturating_add(parts.greedy_guidance()));
        }
        Some((
            best.saturating_sub(charged),
            guided.saturating_sub(charged),
            greedy.saturating_sub(charged),
        ))
    }

    /// Stops the heuristic's cost-to-go from growing after `deadline` (the plan's time
    /// limit): see `CostToGo::set_deadline`.
    pub fn set_heuristic_deadline(&self, deadline: Option<Instant>) {
        self.heuristic_deadline.set(deadline);
        if let Some((tables, _)) = self.heuristic.get() {
            tables.cost_to_go.set_deadline(deadline);
        }
    }

    /// Whether the plan's time limit stopped the heuristic's cost-to-go (see
    /// `CostToGo::set_deadline`).
    pub fn heuristic_frozen(&self) -> bool {
        self.heuristic.get().is_some_and(|(t, _)| t.cost_to_go.frozen())
    }

    /// (Cell, orientation) nodes the heuristic's cost-to-go has settled so far (with
    /// those of the earlier searches, when the tables came from a [`HeuristicCache`]).
    pub fn cost_to_go_nodes(&self) -> usize {
        self.heuristic.get().map_or(0, |(t, _)| t.cost_to_go.settled())
    }

    /// Number of foot components the step bound found (0: no step bound).
    pub fn step_bound_components(&self) -> usize {
        self.tables().step_bound.components()
    }

    /// The lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The configuration.
    pub fn config(&self) -> &HybridConfig {
        &self.config
    }

    /// The widest offset range `[min, max]` (cells) of each leg.
    pub fn reach(&self) -> [[i8; 2]; 4] {
        self.reach
    }

    /// Manoeuvres generated so far, and how their step checks ended.
    pub fn stats(&self) -> ManoeuvreStats {
        self.stats.get()
    }

    /// Adds one to the counter `counter` picks.
    fn count(&self, counter: impl FnOnce(&mut ManoeuvreStats) -> &mut u64) {
        let mut stats = self.stats.get();
        *counter(&mut stats) += 1;
        self.stats.set(stats);
    }

    /// Number of footprints met so far (the neutral one included).
    pub fn footprint_count(&self) -> usize {
        self.footprints.len()
    }

    /// The foot offsets (cells) of a state's footprint.
    pub fn offsets(&self, s: LatticeState) -> Option<FootOffsets> {
        self.footprints.get(s.footprint)
    }

    /// The state at `s`'s pose with footprint `offsets` (interned in this graph's table;
    /// footprint ids are per graph, so a state moves between graphs by its offsets).
    /// `None` when the footprint table is full.
    pub fn with_offsets(&mut self, s: LatticeState, offsets: FootOffsets) -> Option<LatticeState> {
        self.with_footprint(s, offsets)
    }

    /// The base pose of a state.
    /// What state `s` means, independent of this graph's footprint ids.
    pub fn key(&self, s: LatticeState) -> Option<PoseKey> {
        self.footprints.get(s.footprint).map(|o| (s.i, s.j, s.theta, o))
    }

    /// Leaves out the edges between these states from now on (the motion generator could
    /// not expand them: see `jobs::run::plan_mission`).
    pub fn forbid(&mut self, edges: &[(PoseKey, PoseKey)]) {
        self.forbidden.extend_from_slice(edges);
    }

    pub fn pose(&self, s: LatticeState) -> Pose2 {
        self.lattice.pose(s)
    }

    /// World (x, y) of the four feet of a state (FL, FR, RL, RR).
    pub fn feet(&self, s: LatticeState) -> Option<[[f64; 2]; 4]> {
        let o = self.footprints.get(s.footprint)?;
        Some(self.feet_pos(s, &o))
    }

    /// Known ground height under (x, y), m.
    pub fn height_at(&self, x: f64, y: f64) -> Option<f64> {
        self.maps.height_at(x, y)
    }

    /// Pose cost of a neutral state (the driving cost, ≥ 1), `None` if untraversable.
    pub fn driving_pose_cost(&mut self, s: LatticeState) -> Option<f64> {
        self.driving.pose_cost(LatticeState { footprint: NEUTRAL_FOOTPRINT, step_pending: 0, ..s })
    }

    #[inline]
    fn heading(&self, theta: u8) -> (f64, f64) {
        let (s, c) = self.trig[usize::from(theta)];
        (c, s)
    }

    #[inline]
    fn feet_pos(&self, s: LatticeState, o: &FootOffsets) -> [[f64; 2]; 4] {
        let p = self.lattice.pose(s);
        let (sn, cs) = self.trig[usize::from(s.theta)];
        let res = self.lattice.resolution;
        std::array::from_fn(|k| {
            let fx = self.neutral[k][0] + f64::from(o[k]) * res;
            let fy = self.neutral[k][1];
            [p.x + cs * fx - sn * fy, p.y + sn * fx + cs * fy]
        })
    }

    /// The foot-cost heading bin of the feet of a state with orientation `theta`: the
    /// feet stand with straight wheels, at the base heading.
    #[inline]
    fn bin(&self, theta: u8) -> HeadingBin {
        self.maps.foot_heading_bin(self.lattice.yaw(theta))
    }

    /// Foot cost (at heading bin `bin`) and ground height of the cell under (x, y):
    /// `Err(true)` for an infinite foot cost, `Err(false)` for unknown terrain or off the
    /// map.
    #[inline]
    fn cell(&self, x: f64, y: f64, bin: HeadingBin) -> Result<(f64, f64), bool> {
        let hm = self.maps.heights();
        let Some((i, j)) = hm.cell_of(x, y) else {
            return Err(false);
        };
        let h = hm.get(i, j).ok_or(false)?;
        match self.maps.foot_cost_cell_at(i, j, bin) {
            CostValue::Finite(c) => Ok((c, h)),
            CostValue::Infinite => Err(true),
            CostValue::Unknown => Err(false),
        }
    }

    /// Feet of a state with offsets `o`, all on known cells of finite foot cost.
    fn feet_of(&self, s: LatticeState, o: &FootOffsets) -> Option<Feet> {
        let pos = self.feet_pos(s, o);
        let bin = self.bin(s.theta);
        let mut cf = [0.0; 4];
        let mut h = [0.0; 4];
        for k in 0..4 {
            let (c, hh) = self.cell(pos[k][0], pos[k][1], bin).ok()?;
            cf[k] = c;
            h[k] = hh;
        }
        Some(Feet { pos, cf, h })
    }

    /// Criterion 1 (Sec. V): an infinite-foot-cost cell lies closer than
    /// `step_obstacle_distance_m` to the foot at (x, y).
    #[inline]
    fn near_obstacle(&self, p: [f64; 2], bin: HeadingBin) -> bool {
        let hm = self.maps.heights();
        let Some((i, j)) = hm.cell_of(p[0], p[1]) else {
            return false;
        };
        self.near[j * hm.nx() + i]
            && self.maps.infinite_foot_cost_within_at(
                p[0],
                p[1],
                self.config.step_obstacle_distance_m,
                Some(bin),
            )
    }

    /// Longitudinal distance between the two feet on one side (left: FL–RL), m.
    fn side_length(&self, o: &FootOffsets, left: bool) -> f64 {
        let (f, r) = if left { (0, 2) } else { (1, 3) };
        let res = self.lattice.resolution;
        (self.neutral[f][0] + f64::from(o[f]) * res) - (self.neutral[r][0] + f64::from(o[r]) * res)
    }

    /// World feet (x, y, ground z) of `feet`.
    fn feet_xyz(feet: &Feet) -> [[f64; 3]; 4] {
        std::array::from_fn(|k| [feet.pos[k][0], feet.pos[k][1], feet.h[k]])
    }

    /// Leg heights (hip above the foot's ground, m) of the standing rule for the robot at
    /// state `s`'s pose on feet `feet`, and whether its thighs and shins also clear the
    /// swept leg terrain ([`CostMaps::swept_leg_terrain`]); `None` if no leg height of the
    /// rule reaches every foot (see the module docs).
    fn standing_legs(&self, s: LatticeState, feet: &Feet) -> Option<([f64; 4], bool)> {
        let pose = self.lattice.pose(s);
        let world = Self::feet_xyz(feet);
        let rule = &self.config.motion.standing;
        let (terrain, swept) = (self.maps.leg_terrain(), self.maps.swept_leg_terrain());
        let (p, _, swept) = rule
            .stand_clear_of(&self.robot, terrain, swept, world, [pose.x, pose.y], pose.theta)
            .ok()?;
        self.feasibility.body_clear(&p, self.maps).ok()?;
        let hips = hips_in_world(&self.robot, &p);
        Some((std::array::from_fn(|k| hips[k][2] - world[k][2]), swept))
    }

    /// Whether a non-neutral footprint keeps the wheel pairs apart.
    fn sides_ok(&self, o: &FootOffsets) -> bool {
        let min_side = 0.5 * self.config.min_support_side_length_m;
        self.side_length(o, true) >= min_side && self.side_length(o, false) >= min_side
    }

    /// Whether the step of leg `leg` from feet `feet` (state `s`) to the foot at `post`
    /// (x, y, ground z) is one the motion generator expands:
    /// - it stays within reach while the foot is carried at some height of the standing
    ///   rule ([`StandingRule::step_heights`], drawn lazily, tallest first), and
    /// - the generator's own check ([`ManoeuvreCheck::step`]) from the standing posture of
    ///   the shared rule finds a stable motion at those heights, at every sample, with the
    ///   CoM estimate ([`EstimatedCom`]) and [`PLANNER_MARGIN_SLACK_M`] to spare.
    ///
    /// No support pre-check comes first: the CoM-in-triangle filters this planner had
    /// (the paper model's at the unaligned stance, the stairs model's through the lift's
    /// alignments) turned away 1–6 % of the steps checked on generated flights and 40–98 %
    /// on the paper's staircase and generated mixed courses, and the generator expands
    /// much of what they turned away (on the staircase 5,545 of 7,575): the planner
    /// missed steps, and paths, it could take.
    fn step_feasible(&self, s: LatticeState, feet: &Feet, leg: usize, post: [f64; 3]) -> bool {
        let pose = self.lattice.pose(s);
        let (robot, maps, rule) = (&self.robot, self.maps, &self.config.motion.standing);
        let pre_feet = Self::feet_xyz(feet);
        let xy = [pose.x, pose.y];
        let mut heights = rule
            .step_heights(
                robot,
                maps.heights(),
                maps.leg_terrain(),
                pre_feet,
                leg,
                post,
                xy,
                pose.theta,
            )
            .peekable();
        if heights.peek().is_none() {
            self.count(|c| &mut c.steps_without_leg_height);
            return false;
        }
        let outcome = self
            .generator_outcome(s, feet, |check, pre| check.step(pre, Leg::ALL[leg], post, heights));
        self.count(|c| match outcome {
            Ok(()) => &mut c.step_checks_passed,
            Err(Some(MotionError::Step { .. })) if Leg::ALL[leg].is_front() => {
                &mut c.front_steps_unstable
            }
            Err(Some(MotionError::Step { .. })) => &mut c.rear_steps_unstable,
            Err(_) => &mut c.steps_failed_otherwise,
        });
        outcome.is_ok()
    }

    /// Runs one of the generator's own checks (`check`, [`ManoeuvreCheck`]) from
    /// the shared rule's standing posture at `s`'s pose on feet `feet`, with the CoM
    /// estimate and the planner's margins; whether it holds.
    fn generator_check(
        &self,
        s: LatticeState,
        feet: &Feet,
        check: impl FnOnce(&mut ManoeuvreCheck<'_>, Posture) -> Result<(), MotionError>,
    ) -> bool {
        self.generator_outcome(s, feet, check).is_ok()
    }

    /// [`Self::generator_check`]'s outcome: the check's error, or `None` where the rule
    /// found no standing posture to start from.
    fn generator_outcome(
        &self,
        s: LatticeState,
        feet: &Feet,
        check: impl FnOnce(&mut ManoeuvreCheck<'_>, Posture) -> Result<(), MotionError>,
    ) -> Result<(), Option<MotionError>> {
        let pose = self.lattice.pose(s);
        let robot = &self.robot;
        let rule = &self.config.motion.standing;
        let world = Self::feet_xyz(feet);
        let xy = [pose.x, pose.y];
        let Ok((pre, _)) = rule.stand(robot, self.maps.leg_terrain(), world, xy, pose.theta) else {
            return Err(None);
        };
        let mut model = EstimatedCom { robot };
        let options = &self.config.motion;
        let mut c = ManoeuvreCheck { robot, maps: self.maps, model: &mut model, options };
        check(&mut c, pre).map_err(Some)
    }

    /// Whether state `t` (footprint offsets `o`) may be entered; its body cost for
    /// non-neutral footprints.
    fn target_ok(&mut self, t: LatticeState, o: &FootOffsets) -> bool {
        if *o == NEUTRAL_OFFSETS {
            return self.driving.pose_cost(t).is_some();
        }
        if !self.sides_ok(o)
            || !(0..4).all(|k| (self.reach[k][0]..=self.reach[k][1]).contains(&o[k]))
        {
            return false;
        }
        self.stand(t, o) != Stand::No
    }

    /// How the robot stands at `t`'s pose on footprint `o` ([`Stand`], memoised): the
    /// shared rule's standing posture ([`Self::standing_legs`]) at finite body cost.
    fn stand(&mut self, t: LatticeState, o: &FootOffsets) -> Stand {
        let pose = (t.i, t.j, t.theta);
        if let Some(&stand) = self.standable.get(&pose).and_then(|at| at.get(o)) {
            return stand;
        }
        let stand =
            self.feet_of(t, o).map_or(Stand::No, |feet| match self.standing_legs(t, &feet) {
                Some((legs, swept))
                    if self.maps.body_cost(&self.lattice.pose(t), &feet.pos, &legs).is_finite() =>
                {
                    if swept {
                        Stand::SweptClear
                    } else {
                        Stand::Stands
                    }
                }
                _ => Stand::No,
            });
        self.standable.entry(pose).or_default().insert(*o, stand);
        stand
    }

    /// Whether the robot at `s` (offsets `o`) can roll the wheel pair of move `m` its
    /// whole way, as the generator moves it (`expand`'s wheel move: a keyframe per cell of
    /// the way, the base stood by the shared rule at each, every point 1 cm apart between
    /// two checked):
    /// - the footprint with that foot at every cell of the way, the last one included,
    ///   can stand ([`Self::target_ok`], memoised);
    /// - between two cells whose postures both clear the swept leg terrain
    ///   ([`Stand::SweptClear`]) no leg point comes within the legs' clearance of the
    ///   terrain (the argument of `feasibility` for neighbouring lattice poses: a leg point
    ///   moves less than the sweep's two cells between them);
    /// - between any other two, near an edge, the generator's own expansion of that cell's
    ///   move decides ([`ManoeuvreCheck::wheel_move`], memoised by pose, footprint, leg and
    ///   new offset, so moves through the same cells share it).
    ///
    /// Checking the two ends alone let a knee dip below the legs' clearance on the way;
    /// checking the cells alone let a knee pass within it over a block's edge between two.
    fn wheel_move_feasible(&mut self, s: LatticeState, o: &FootOffsets, m: &FootMove) -> bool {
        // The end first: where it cannot stand, the way needs no look.
        let to = m.to[m.leg.index()];
        self.target_ok(s, &m.to) && self.feasible_roll(s, o, m.leg, to, to) == to
    }

    /// The generator's one-cell wheel move of `leg`'s pair from footprint `a` to `b` at
    /// `s`'s pose ([`ManoeuvreCheck::wheel_move`] from the rule's standing posture on `a`),
    /// with the CoM estimate and [`PLANNER_MARGIN_SLACK_M`] to spare; memoised.
    fn wheel_segment_ok(
        &mut self,
        s: LatticeState,
        a: &FootOffsets,
        leg: Leg,
        b: &FootOffsets,
    ) -> bool {
        let k = leg.index();
        let key = ((s.i, s.j, s.theta, *a), k as u8, b[k]);
        if let Some(&ok) = self.wheel_move_checks.get(&key) {
            return ok;
        }
        let ok = self.wheel_segment_motion(s, a, leg, b);
        self.wheel_move_checks.insert(key, ok);
        ok
    }

    /// [`Self::wheel_segment_ok`] unmemoised.
    fn wheel_segment_motion(
        &self,
        s: LatticeState,
        a: &FootOffsets,
        leg: Leg,
        b: &FootOffsets,
    ) -> bool {
        let (Some(feet), Some(after)) = (self.feet_of(s, a), self.feet_of(s, b)) else {
            return false;
        };
        let foot = after.pos[leg.index()];
        self.generator_check(s, &feet, |check, pre| check.wheel_move(pre, leg, foot))
    }

    /// Whether the generator expands the base shift from `s` (feet `feet`) to `t`: its
    /// own expansion ([`ManoeuvreCheck::base_shift`]: the base stood by the shared rule at
    /// every cell of the way, every point between checked) from the rule's standing
    /// posture, with the CoM estimate and [`PLANNER_MARGIN_SLACK_M`] to spare; memoised
    /// by state and length. The end alone let a path through whose shift could not
    /// stand on the way.
    fn base_shift_feasible(&mut self, s: LatticeState, feet: &Feet, t: LatticeState) -> bool {
        let key = (s.i, s.j, s.theta, s.footprint, t.i, t.j);
        if let Some(&ok) = self.base_shift_checks.get(&key) {
            return ok;
        }
        let to = self.lattice.pose(t);
        let ok = self.feet(t).is_some_and(|after| {
            self.generator_check(s, feet, |check, pre| check.base_shift(pre, after, &to))
        });
        self.base_shift_checks.insert(key, ok);
        ok
    }

    /// Interns `o` and returns the state at `(i, j, θ)` with that footprint.
    fn with_footprint(&mut self, t: LatticeState, o: FootOffsets) -> Option<LatticeState> {
        match self.footprints.intern(o) {
            Some(footprint) => Some(LatticeState { footprint, ..t }),
            None => {
                self.count(|c| &mut c.footprint_table_full);
                None
            }
        }
    }

    /// The cheapest abstract step of `leg` from state `s` (offsets `o`, feet `feet`),
    /// given that criteria 1 (close to an obstacle) and 4 (support side) hold: of the
    /// footholds of the scan ([`Self::step_candidates`], criteria 2 and 3, cheapest
    /// first), the first whose after-step state may be entered and whose step passes
    /// [`Self::step_feasible`], with its new offsets.
    fn best_step(
        &mut self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        leg: usize,
        candidates: Vec<StepCandidate>,
    ) -> Option<(FootOffsets, StepCost)> {
        candidates.into_iter().find_map(|(_, d, cost, foothold)| {
            let mut o2 = *o;
            o2[leg] = (i32::from(o[leg]) + d) as i8;
            let key = ((s.i, s.j, s.theta, *o), leg as u8, o2[leg]);
            let known = self.step_checks.get(&key).copied();
            if !self.target_ok(s, &o2) {
                return None;
            }
            let ok = known.unwrap_or_else(|| {
                let translated = self.translated_step(s, o, feet, leg, o2[leg], foothold);
                let ok = if translated.is_some_and(|t| self.translated_failures.contains(&t)) {
                    self.count(|c| &mut c.step_failures_translated);
                    false
                } else {
                    let ok = self.step_feasible(s, feet, leg, foothold);
                    if let (false, Some(t)) = (ok, translated) {
                        self.translated_failures.insert(t);
                    }
                    ok
                };
                self.step_checks.insert(key, ok);
                ok
            });
            ok.then_some((o2, cost))
        })
    }

    /// The key of the step of `leg` from `s` (offsets `o`, feet `feet`) to `foothold`
    /// (new offset `to`) among the translated failures: the print of the window the
    /// check reads, relative to `s`'s cell, with the stance and the step (module docs,
    /// "Translated step failures"). `None` where the window leaves the prints' padding,
    /// or with the reuse turned off.
    fn translated_step(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        leg: usize,
        to: i8,
        foothold: [f64; 3],
    ) -> Option<TranslatedStep> {
        if !self.config.reuse_translated_step_failures {
            return None;
        }
        let r = &self.robot;
        let res = self.lattice.resolution;
        let margin = TRANSLATION_WINDOW_MARGIN_M + 2.0 * res;
        // The prints' padding: the farthest a window reaches from its base cell.
        let reach =
            r.max_leg_length() + r.hips.iter().map(|h| h[0].hypot(h[1])).fold(0.0, f64::max);
        let far = reach + self.config.motion.max_base_shift_m + r.wheel_track + margin;
        let prints = self.maps.prints((far / res).ceil() as usize + 2);
        let pose = self.lattice.pose(s);
        let [hx, hy, _] = r.base_half_extents;
        let body = [[hx, hy], [hx, -hy], [-hx, hy], [-hx, -hy]]
            .into_iter()
            .chain(r.hips.iter().map(|h| [h[0], h[1]]))
            .map(|p| pose.transform(p));
        let r_body = self.config.motion.max_base_shift_m + r.thigh_length + margin;
        let r_foot = r.foot_length + r.wheel_track / 2.0 + r.wheel_radius + margin;
        let feet_xy = feet.pos.into_iter().chain([[foothold[0], foothold[1]]]);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for (p, grow) in feet_xy.map(|p| (p, r_foot)).chain(body.map(|p| (p, r_body))) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] - grow);
                hi[k] = hi[k].max(p[k] + grow);
            }
        }
        let cell =
            |[x, y]: [f64; 2]| self.maps.heights().grid_coords(x, y).map(|g| g.floor() as i64);
        let ([i0, j0], [i1, j1]) = (cell(lo), cell(hi));
        let print = prints.print([i0, i1], [j0, j1])?;
        let (si, sj) = (i64::from(s.i), i64::from(s.j));
        let rel = [i0 - si, i1 - si, j0 - sj, j1 - sj].map(|d| d as i16);
        Some((print, rel, s.theta, *o, leg as u8, to))
    }

    /// The footholds of `leg`'s step by the scan alone (C_S, offset change, cost terms,
    /// foothold x, y, z), cheapest first (ties: the shorter step): the foot's sagittal
    /// line forward to the end of the leg's reach, footholds that
    ///
    /// - have finite foot cost C_F (criterion 2) and lie beyond at least one cell of
    ///   infinite C_F (the foot is carried over the obstacle, see the module docs),
    /// - differ in height from the foot by at most `max_step_height_m` (criterion 3),
    ///   as does every cell passed on the way.
    ///
    /// The checks that need the IK are left to [`Self::best_step`].
    fn step_candidates(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        leg: usize,
    ) -> Vec<StepCandidate> {
        let res = self.lattice.resolution;
        let (hx, hy) = self.heading(s.theta);
        let bin = self.bin(s.theta);
        let [x0, y0] = feet.pos[leg];
        let h0 = feet.h[leg];
        let max_d = i32::from(self.reach[leg][1]) - i32::from(o[leg]);
        let mut crossed = false;
        let mut dh_max = 0.0_f64;
        // Footholds by the scan: (C_S, offset, cost terms, foothold). The checks that
        // need the IK run afterwards in order of C_S, and stop at the first that holds.
        let mut candidates: Vec<StepCandidate> = Vec::new();
        for d in 1..=max_d {
            let l = f64::from(d) * res;
            let (x, y) = (x0 + hx * l, y0 + hy * l);
            let hm = self.maps.heights();
            let Some((i, j)) = hm.cell_of(x, y) else {
                break;
            };
            // Unknown terrain cannot be stepped over: the leg could hit anything.
            let Some(h) = hm.get(i, j) else { break };
            dh_max = dh_max.max((h - h0).abs());
            if dh_max > self.config.max_step_height_m + STEP_HEIGHT_TOLERANCE_M {
                break;
            }
            let cf = match self.maps.foot_cost_cell_at(i, j, bin) {
                CostValue::Finite(c) => c,
                CostValue::Infinite => {
                    crossed = true;
                    continue;
                }
                CostValue::Unknown => break,
            };
            if !crossed {
                continue;
            }
            let c_s = step_cost(&self.config, l, cf, dh_max);
            let cost = StepCost { length_m: l, foothold_cost: cf, height_m: dh_max, c_s };
            candidates.push((c_s, d, cost, [x, y, h]));
        }
        // Cheapest first; ties: the shorter step (the scan order, kept by a stable sort).
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        candidates
    }

    /// The descent shift of state `s` (offsets `o`, feet `feet`, criterion 1 per foot
    /// `near`), in cells: where a front foot close to an obstacle steps down (its
    /// cheapest foothold by the scan lies lower than the foot by more than a wheel drives
    /// down, `max_foot_height_diff_m`) and the front feet do not both stand ahead of
    /// neutral (the longitudinal shift's case), the base forward until that front hip
    /// stands over the middle of its step, or the length nearest to it at which every
    /// leg stands on the way ([`Self::shift_in_reach`]) and the front foot can still step
    /// ([`Self::step_reaches`]). `None` when no front foot steps down, its hip is at or
    /// past the middle already, or no length holds.
    fn descent_shift(
        &mut self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        near: [bool; 4],
    ) -> Option<i8> {
        if o[0] > 0 && o[1] > 0 {
            return None;
        }
        let down = |f: usize| -> Option<i32> {
            if !near[f] {
                return None;
            }
            let c = *self.step_candidates(s, o, feet, f).first()?;
            (c.3[2] < feet.h[f] - self.config.max_foot_height_diff_m).then_some(c.1)
        };
        // The hip over the middle of the step: the foot's offset plus half the step.
        let (leg, target) = [0, 1]
            .into_iter()
            .filter_map(|f| down(f).map(|d| (f, i32::from(o[f]) + d / 2)))
            .min_by_key(|&(_, t)| t)?;
        if target <= 0 {
            return None;
        }
        let longest = self.longest_shift_in_reach(s, feet, self.shift_room(o));
        let mut lengths: Vec<i8> = (1..=longest).collect();
        lengths.sort_by_key(|&l| (i32::from(l) - target).abs());
        lengths.into_iter().find(|&l| {
            self.shifted(s, o, l)
                .and_then(|(t, o2)| Some((t, o2, self.feet_of(t, &o2)?)))
                .is_some_and(|(t, o2, f)| self.step_reaches(t, &o2, &f, leg))
        })
    }

    /// The longest drive of a wheel pair from `p` in direction `dir`, at most `cells`
    /// cells, over drivable cells only: its length in cells and mean foot cost (both
    /// ends included); `None` if the cell under `p` is not drivable.
    fn drivable_prefix(
        &self,
        p: [f64; 2],
        dir: (f64, f64),
        cells: i32,
        bin: HeadingBin,
    ) -> Option<(i32, f64)> {
        let res = self.lattice.resolution;
        let mut sum = 0.0;
        let mut last = -1;
        for k in 0..=cells {
            let l = f64::from(k) * res;
            let Ok((c, _)) = self.cell(p[0] + dir.0 * l, p[1] + dir.1 * l, bin) else { break };
            sum += c;
            last = k;
        }
        (last >= 0).then(|| (last, sum / f64::from(last + 1)))
    }

    /// Mean foot cost along a wheel pair's straight drive of `cells` cells from `p` in
    /// direction `dir` (both ends included); `None` if any cell is not drivable.
    fn drive_line_cost(
        &self,
        p: [f64; 2],
        dir: (f64, f64),
        cells: i32,
        bin: HeadingBin,
    ) -> Option<f64> {
        let (n, avg) = self.drivable_prefix(p, dir, cells, bin)?;
        (n == cells).then_some(avg)
    }

    /// Appends the labelled non-driving successors of `s` (steps, base shifts, foot
    /// moves) to `self.special`. With `lazy`, a step's successor is its intermediate node
    /// at the cheapest foothold's cost (see "Lazy step checks" in the module docs), else
    /// the step itself.
    fn special_successors(&mut self, s: LatticeState, lazy: bool) {
        self.special.clear();
        let Some(o) = self.footprints.get(s.footprint) else {
            return;
        };
        let neutral = o == NEUTRAL_OFFSETS;
        let pos = self.feet_pos(s, &o);
        let bin = self.bin(s.theta);
        let near = pos.map(|p| self.near_obstacle(p, bin));
        // Neutral states only have steps and front-foot-forward moves, both of which need
        // a foot close to an obstacle: the common case ends here.
        if neutral && !near.iter().any(|&n| n) {
            return;
        }
        let Some(feet) = self.feet_of(s, &o) else {
            return;
        };
        let heading = self.heading(s.theta);

        // Abstract steps: criteria 1 and 4 here, 2 and 3 in `best_step`.
        for leg in Leg::ALL {
            let k = leg.index();
            if !near[k] {
                continue;
            }
            // Criterion 4: the two feet on the other side carry the robot while it steps.
            if self.side_length(&o, !leg.is_left()) <= self.config.min_support_side_length_m {
                continue;
            }
            let candidates = self.step_candidates(s, &o, &feet, k);
            if lazy {
                // The cheapest foothold by the scan: a lower bound of the step's cost.
                if let Some(&(_, _, step, _)) = candidates.first() {
                    let (cost, m) = self.step_edge(k, step);
                    self.special.push((LatticeState { step_pending: leg_tag(k), ..s }, cost, m));
                }
                continue;
            }
            if let Some(edge) = self.checked_step(s, &o, &feet, k, candidates) {
                self.special.push(edge);
            }
        }

        // Longitudinal base shift: both front feet ahead of neutral; forward until a
        // front foot is neutral or a rear leg is at the end of its reach.
        if o[0] > 0 && o[1] > 0 {
            // Every cell of the way must stand by the rule (the generator moves the base
            // through them), so the shift ends before the first that cannot.
            let mut l = self.longest_shift_in_reach(s, &feet, o[0].min(o[1]));
            // The paper's shift ends where a rear leg reaches its full length. A rear leg
            // at full length cannot also lift its foot over an edge (its step stance
            // pitches the base less), so where a rear foot close to an obstacle could not
            // step from there, the shift ends earlier, where it can.
            if let Some(ready) = self.rear_step_ready_shift(s, &o, near, l) {
                l = ready;
            }
            if l > 0 {
                self.push_base_shift(s, &o, &feet, l);
            }
        }

        // Rear-step approach: the front feet stand on other ground than the rear feet (a
        // climb or descent is under way), a rear foot is not close to an obstacle, and
        // the base shifts
        // past the front feet's neutral (their legs reach back) to the first length at
        // which a rear wheel pair, rolled forward to its neutral again (foot to neutral),
        // comes close to one. This is how the rear feet reach a stair's first riser
        // while the front feet stand on a tread too short to drive along: with the front
        // feet never behind neutral, the feet of one side stay at least a hip spacing
        // apart, and on treads shorter than that no footprint puts a rear foot at the
        // riser and a front foot on a tread.
        let far_rear = [2, 3].map(|r| !near[r]);
        let split = [0, 1].iter().any(|&f| {
            [2, 3]
                .iter()
                .any(|&r| (feet.h[f] - feet.h[r]).abs() > self.config.max_foot_height_diff_m)
        });
        let stairs = self.config.motion.step_model == StepModel::Stairs;
        // (A shift the longitudinal base shift above already offers is left out.)
        if stairs
            && split
            && far_rear.iter().any(|&f| f)
            && let Some(l) = self.rear_approach_shift(s, &o, &feet, far_rear, heading, bin)
            && !(o[0] > 0 && o[1] > 0 && l <= o[0].min(o[1]))
        {
            self.push_base_shift(s, &o, &feet, l);
        }

        // Climb shift (see the module docs): on a climb, with a rear foot close to an
        // obstacle and the front feet not both ahead of neutral, as far past their
        // neutral as every leg reaches, shortened to where a rear foot can still step.
        let climbing = [0, 1].iter().any(|&f| {
            [2, 3].iter().any(|&r| feet.h[f] - feet.h[r] > self.config.max_foot_height_diff_m)
        });
        if stairs && climbing && (near[2] || near[3]) && !(o[0] > 0 && o[1] > 0) {
            let l = self.longest_shift_in_reach(s, &feet, self.shift_room(&o));
            if let Some(l) = self.rear_step_ready_shift(s, &o, near, l) {
                self.push_base_shift(s, &o, &feet, l);
            }
        }

        // Descent shift (see the module docs): before a front foot steps down.
        if let Some(l) = self.descent_shift(s, &o, &feet, near) {
            self.push_base_shift(s, &o, &feet, l);
        }

        // Front wheel pairs forward, preparing a rear step: when a rear foot is close to
        // an obstacle (Sec. V). One move per foot, as far as the leg reaches and the
        // wheels can drive (at least `foot_move_increment_m`): shorter moves would only
        // multiply footprints, and a later base shift uses the whole lead.
        if near[2] || near[3] {
            for k in [Leg::FrontLeft.index(), Leg::FrontRight.index()] {
                let moves = self.foot_forward_moves(s, &o, &feet, k);
                self.push_longest_feasible_move(s, &o, &moves);
            }
        }

        // A wheel pair back to neutral. Moves of different feet commute, so only the
        // first foot (in FL, FR, RL, RR order) that can move is offered: the same
        // footprints stay reachable, through a chain instead of every subset of feet
        // (2^4 intermediate footprints per pose become 4).
        if !neutral {
            let moves = self.foot_neutral_moves(s, &o, &feet, near);
            self.push_first_feasible_move(s, &o, &moves);
        }
    }

    /// The wheel move of `kind` of `leg`'s pair to footprint `to`, `length_m` long over
    /// cells of mean foot cost `avg`, at its cost C_FM (eq. 6) times the step-related
    /// factor.
    fn foot_move(
        &self,
        kind: ManoeuvreKind,
        leg: Leg,
        to: FootOffsets,
        length_m: f64,
        avg: f64,
    ) -> FootMove {
        let cost = self.config.step_cost_factor * foot_move_cost(&self.config, length_m, avg);
        FootMove { kind, leg, to, cost, length_m }
    }

    /// The wheel pairs back toward neutral from `s` (offsets `o`, feet `feet`, criterion
    /// 1 per foot `near`), in FL, FR, RL, RR order (of which `special_successors` takes
    /// the first that passes its checks): to neutral where the way is drivable; with
    /// `step_model = "stairs"`, a foot not close to an obstacle whose way is not, up to
    /// the last drivable cell before the obstacle, where it is close to it. Without
    /// that, a rear foot behind neutral short of a stair's riser could neither step (it
    /// is not close to the riser) nor roll to neutral (the way climbs the riser), and no
    /// base shift brings it closer while the front feet stand behind neutral on a tread:
    /// flights of four or more steps had no path.
    fn foot_neutral_moves(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        near: [bool; 4],
    ) -> Vec<FootMove> {
        let res = self.lattice.resolution;
        let heading = self.heading(s.theta);
        let bin = self.bin(s.theta);
        let partial = self.config.motion.step_model == StepModel::Stairs;
        let mut moves = Vec::new();
        for leg in Leg::ALL {
            let k = leg.index();
            if o[k] == 0 {
                continue;
            }
            let back = if o[k] > 0 { (-heading.0, -heading.1) } else { heading };
            let all = i32::from(o[k]).abs();
            let (cells, avg) = match self.drivable_prefix(feet.pos[k], back, all, bin) {
                Some((cells, avg)) if cells == all || (partial && cells > 0 && !near[k]) => {
                    (cells, avg)
                }
                _ => continue,
            };
            let mut to = *o;
            to[k] = if o[k] > 0 { o[k] - cells as i8 } else { o[k] + cells as i8 };
            let length_m = f64::from(cells) * res;
            moves.push(self.foot_move(ManoeuvreKind::FootNeutral, leg, to, length_m, avg));
        }
        moves
    }

    /// Offers the first of `moves` (from `s`, offsets `o`) whose way the robot can
    /// stand on ([`Self::wheel_move_feasible`]).
    fn push_first_feasible_move(&mut self, s: LatticeState, o: &FootOffsets, moves: &[FootMove]) {
        if let Some(m) = moves.iter().find(|m| self.wheel_move_feasible(s, o, m)).copied() {
            self.push_move(s, &m);
        }
    }

    /// Offers wheel move `m` from `s`, checked.
    fn push_move(&mut self, s: LatticeState, m: &FootMove) {
        let Some(t) = self.with_footprint(s, m.to) else {
            return;
        };
        match m.kind {
            ManoeuvreKind::FootForward => self.count(|c| &mut c.foot_forward),
            _ => self.count(|c| &mut c.foot_neutral),
        }
        self.special.push((t, edge_cost(m.cost), m.manoeuvre()));
    }

    /// Offers the longest of `moves` (one leg's wheel moves from `s`, offsets `o`, all
    /// the same way, longest first) whose way the robot can stand on: the move
    /// [`Self::push_first_feasible_move`] offers, found by [`Self::feasible_roll`] with
    /// one look at each cell up to the first that fails, where trying the moves longest
    /// first stood the robot at every cell beyond the first failure too (on the
    /// platform's A*, 5.23 M standing checks became 5.01 M).
    fn push_longest_feasible_move(&mut self, s: LatticeState, o: &FootOffsets, moves: &[FootMove]) {
        let Some(longest) = moves.first() else {
            return;
        };
        let k = longest.leg.index();
        let shortest = moves.last().map_or(longest.to[k], |m| m.to[k]);
        let rolled = self.feasible_roll(s, o, longest.leg, longest.to[k], shortest);
        let reach = (i32::from(rolled) - i32::from(o[k])).abs();
        let chosen = moves.iter().find(|m| {
            debug_assert!(m.leg == longest.leg, "one leg's moves");
            (i32::from(m.to[k]) - i32::from(o[k])).abs() <= reach
        });
        if let Some(m) = chosen {
            debug_assert!(self.wheel_move_feasible(s, o, m), "the longest feasible move");
            self.push_move(s, m);
        }
    }

    /// How far `leg`'s wheel pair rolls from footprint `o` at `s` toward offset `to`:
    /// the last offset of the longest way from `o` whose every cell can stand
    /// ([`Self::target_ok`]) and every one-cell segment passes (the checks
    /// [`Self::wheel_move_feasible`] describes, and makes by this roll). A move is
    /// feasible exactly when its end lies on that way: both conditions hold for a way when
    /// they hold for a longer one, so the cells are looked at nearest first, each once, up
    /// to the first that fails, and the segments only up to there, and only where that
    /// reaches `at_least` (the offset of the shortest move wanted; short of it, the cells'
    /// reach is returned).
    fn feasible_roll(
        &mut self,
        s: LatticeState,
        o: &FootOffsets,
        leg: Leg,
        to: i8,
        at_least: i8,
    ) -> i8 {
        let k = leg.index();
        let dir: i8 = if to >= o[k] { 1 } else { -1 };
        let mut way = *o;
        // The cells: every one up to the first that cannot stand.
        while way[k] != to {
            let mut next = way;
            next[k] += dir;
            if !self.target_ok(s, &next) {
                break;
            }
            way = next;
        }
        if (i32::from(way[k]) - i32::from(at_least)) * i32::from(dir) < 0 {
            return way[k];
        }
        // The segments between them, up to the first that fails.
        let mut a = *o;
        let mut a_clear = a[k] != way[k] && self.stand(s, &a) == Stand::SweptClear;
        while a[k] != way[k] {
            let mut b = a;
            b[k] += dir;
            let b_clear = self.stand(s, &b) == Stand::SweptClear;
            let swept = a_clear && b_clear;
            if !swept && !self.wheel_segment_ok(s, &a, leg, &b) {
                break;
            }
            (a, a_clear) = (b, b_clear);
        }
        a[k]
    }

    /// A step of leg `k` with cost terms `step`: its edge cost (C_S times the
    /// step-related factor) and label.
    fn step_edge(&self, k: usize, step: StepCost) -> (Cost, EdgeLabel) {
        let cost = self.config.step_cost_factor * step.c_s;
        let m = EdgeLabel {
            kind: ManoeuvreKind::Step,
            leg: Some(Leg::ALL[k]),
            length_m: step.length_m,
            cost,
            step: Some(step),
        };
        (edge_cost(cost), m)
    }

    /// The step of leg `k` from state `s` (offsets `o`, feet `feet`) to the cheapest of
    /// the scan's `candidates` that passes every check (`best_step`), labelled, at its
    /// full cost.
    fn checked_step(
        &mut self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        k: usize,
        candidates: Vec<StepCandidate>,
    ) -> Option<(LatticeState, Cost, EdgeLabel)> {
        let (o2, step) = self.best_step(s, o, feet, k, candidates)?;
        let t = self.with_footprint(s, o2)?;
        self.count(|c| &mut c.steps);
        let (cost, m) = self.step_edge(k, step);
        Some((t, cost, m))
    }

    /// The successor of an intermediate node `p` (see "Lazy step checks" in the module
    /// docs): its step, checked now, at the rest of its cost (the full cost less what
    /// the edge into `p` charged). `None` when no foothold passes the checks.
    fn pending_step(&mut self, p: LatticeState) -> Option<(LatticeState, Cost, EdgeLabel)> {
        let k = usize::from(p.step_pending.checked_sub(1)?);
        let s = LatticeState { step_pending: 0, ..p };
        let o = self.footprints.get(s.footprint)?;
        let feet = self.feet_of(s, &o)?;
        let candidates = self.step_candidates(s, &o, &feet, k);
        let &(_, _, cheapest, _) = candidates.first()?;
        let (charged, _) = self.step_edge(k, cheapest);
        let (t, cost, m) = self.checked_step(s, &o, &feet, k, candidates)?;
        Some((t, cost.saturating_sub(charged), m))
    }

    /// The "front foot forward" moves of leg index `k` (see `special_successors`), longest
    /// first: as far as the leg reaches and the wheels can drive, at least
    /// `foot_move_increment_m`.
    fn foot_forward_moves(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        k: usize,
    ) -> Vec<FootMove> {
        let res = self.lattice.resolution;
        let (hx, hy) = self.heading(s.theta);
        let bin = self.bin(s.theta);
        let [x0, y0] = feet.pos[k];
        let max_d = i32::from(self.reach[k][1]) - i32::from(o[k]);
        // Prefix sums of C_F along the drivable part of the line.
        let mut sums = [0.0_f64; 128];
        sums[0] = feet.cf[k];
        let mut last = 0;
        for d in 1..=max_d.min(127) {
            let l = f64::from(d) * res;
            match self.cell(x0 + hx * l, y0 + hy * l, bin) {
                Ok((c, _)) => {
                    sums[d as usize] = sums[d as usize - 1] + c;
                    last = d;
                }
                Err(_) => break,
            }
        }
        let min_d = i32::from(self.foot_move_cells);
        let leg = Leg::ALL[k];
        (min_d..=last)
            .rev()
            .map(|d| {
                let mut to = *o;
                to[k] = (i32::from(o[k]) + d) as i8;
                let avg = sums[d as usize] / f64::from(d + 1);
                let length_m = f64::from(d) * res;
                self.foot_move(ManoeuvreKind::FootForward, leg, to, length_m, avg)
            })
            .collect()
    }

    /// The longest shift of at most `max` cells from `s` (feet `feet`) whose every cell
    /// of the way stands by the rule ([`Self::shift_in_reach`]): the generator moves the
    /// base through them.
    fn longest_shift_in_reach(&self, s: LatticeState, feet: &Feet, max: i8) -> i8 {
        let mut l = 0;
        while l < max && self.shift_in_reach(s, feet, l + 1) {
            l += 1;
        }
        l
    }

    /// The most cells the base can shift forward over feet with offsets `o`: every
    /// offset drops by the shift, and the leg with the least room behind it bounds it.
    fn shift_room(&self, o: &FootOffsets) -> i8 {
        let room = (0..4).map(|k| i32::from(o[k]) - i32::from(self.reach[k][0])).min();
        room.map_or(0, |m| m.clamp(0, i32::from(i8::MAX)) as i8)
    }

    /// Whether the robot can stand by the rule with its base `l` cells ahead of state
    /// `s`'s pose, over the same feet.
    fn shift_in_reach(&self, s: LatticeState, feet: &Feet, l: i8) -> bool {
        let p = self.lattice.pose(s);
        let (hx, hy) = self.heading(s.theta);
        let d = f64::from(l) * self.lattice.resolution;
        let xy = [p.x + hx * d, p.y + hy * d];
        self.config
            .motion
            .standing
            .stand(&self.robot, self.maps.leg_terrain(), Self::feet_xyz(feet), xy, p.theta)
            .is_ok()
    }

    /// The state a base shift of `l` cells from state `s` (offsets `o`) ends in: the base
    /// on the lattice cell holding the exact shifted position, the same orientation and
    /// footprint id as `s`, and every foot offset lowered by `l` (the feet stay put).
    /// `None` off the lattice.
    fn shifted(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        l: i8,
    ) -> Option<(LatticeState, FootOffsets)> {
        let (hx, hy) = self.heading(s.theta);
        let p = self.lattice.pose(s);
        let d = f64::from(l) * self.lattice.resolution;
        let cell = self.lattice.state(&Pose2::new(p.x + hx * d, p.y + hy * d, p.theta))?;
        Some((LatticeState { i: cell.i, j: cell.j, ..s }, o.map(|v| v - l)))
    }

    /// The longest base shift of at most `max` cells from state `s` (offsets `o`) after
    /// which a rear leg close to an obstacle (`near`, criterion 1; the feet stay where
    /// they stand, so it holds before and after) keeps every leg in reach while it steps
    /// to its cheapest foothold ([`StandingRule::step_heights`] yields a height): `None`
    /// when no rear foot is close to an obstacle or no such shift exists. The shift's
    /// other checks (stability, the generator's) stay with the step itself.
    fn rear_step_ready_shift(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        near: [bool; 4],
        max: i8,
    ) -> Option<i8> {
        if !near[2] && !near[3] {
            return None;
        }
        (1..=max).rev().find(|&l| {
            let Some((t, o2)) = self.shifted(s, o, l) else {
                return false;
            };
            let Some(feet) = self.feet_of(t, &o2) else {
                return false;
            };
            [2, 3].into_iter().filter(|&r| near[r]).any(|r| self.step_reaches(t, &o2, &feet, r))
        })
    }

    /// Whether leg `r` at state `t` (offsets `o`, feet `feet`) keeps every leg in reach
    /// through a step to its cheapest foothold by the scan.
    fn step_reaches(&self, t: LatticeState, o: &FootOffsets, feet: &Feet, r: usize) -> bool {
        let Some(&(_, _, _, post)) = self.step_candidates(t, o, feet, r).first() else {
            return false;
        };
        let pose = self.lattice.pose(t);
        self.config
            .motion
            .standing
            .step_heights(
                &self.robot,
                self.maps.heights(),
                self.maps.leg_terrain(),
                Self::feet_xyz(feet),
                r,
                post,
                [pose.x, pose.y],
                pose.theta,
            )
            .next()
            .is_some()
    }

    /// The rear-step approach's shift (see `special_successors`): the fewest cells `l`
    /// the base can shift forward over the standing feet (every cell of the way standing
    /// by the rule, every leg within its offset reach afterwards) after which a rear foot
    /// of `far` (RL, RR) rolled forward by `l` cells over drivable cells is close to an
    /// obstacle (criterion 1).
    fn rear_approach_shift(
        &self,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        far: [bool; 2],
        heading: (f64, f64),
        bin: HeadingBin,
    ) -> Option<i8> {
        let res = self.lattice.resolution;
        for l in 1..=self.shift_room(o) {
            if !self.shift_in_reach(s, feet, l) {
                return None;
            }
            let d = f64::from(l) * res;
            let close = [2, 3].into_iter().filter(|&r| far[r - 2]).any(|r| {
                let p = feet.pos[r];
                let q = [p[0] + heading.0 * d, p[1] + heading.1 * d];
                self.near_obstacle(q, bin)
                    && self.drive_line_cost(p, heading, i32::from(l), bin).is_some()
            });
            if close {
                // Where the front wheel pairs could roll as far, driving does the same:
                // the shift is offered only where a front foot's way ahead is blocked.
                let blocked = [0, 1].into_iter().any(|f| {
                    self.drive_line_cost(feet.pos[f], heading, i32::from(l), bin).is_none()
                });
                return blocked.then_some(l);
            }
        }
        None
    }

    /// A base shift by `l` cells over the standing feet (see the module docs).
    fn push_base_shift(&mut self, s: LatticeState, o: &FootOffsets, feet: &Feet, l: i8) {
        let res = self.lattice.resolution;
        let (hx, hy) = self.heading(s.theta);
        let p = self.lattice.pose(s);
        let Some((legs, _)) = self.standing_legs(s, feet) else {
            return;
        };
        // C_B,avg: the body cost at every cell-length of the shift, feet fixed in the world.
        let mut sum = 0.0;
        for k in 0..=l {
            let d = f64::from(k) * res;
            let pk = Pose2::new(p.x + hx * d, p.y + hy * d, p.theta);
            match self.maps.body_cost(&pk, &feet.pos, &legs).finite() {
                Some(c) => sum += c,
                None => return,
            }
        }
        let cb_avg = sum / f64::from(l + 1);
        let length = f64::from(l) * res;
        let Some((t, o2)) = self.shifted(s, o, l) else {
            return;
        };
        let moved = self.lattice.pose(t).distance(&p);
        if !self.target_ok(t, &o2) {
            return;
        }
        let Some(t) = self.with_footprint(t, o2) else {
            return;
        };
        if !self.base_shift_feasible(s, feet, t) {
            return;
        }
        let cost = (self.config.step_cost_factor * base_shift_cost(&self.config, length, cb_avg))
            .max(moved);
        self.count(|c| &mut c.base_shifts);
        self.special.push((
            t,
            edge_cost(cost),
            EdgeLabel {
                kind: ManoeuvreKind::BaseShift,
                leg: None,
                length_m: moved,
                cost,
                step: None,
            },
        ));
    }

    /// Every successor of `s` with its cost and label, in the search's order.
    pub fn labelled_successors(&mut self, s: LatticeState) -> Vec<(LatticeState, Cost, EdgeLabel)> {
        let mut out = Vec::new();
        if s.footprint == NEUTRAL_FOOTPRINT && s.step_pending == 0 {
            let mut plain = Vec::new();
            self.driving.successors(s, &mut plain);
            let a = self.lattice.pose(s);
            for (t, c) in plain {
                let b = self.lattice.pose(t);
                let m = if (t.i, t.j) == (s.i, s.j) {
                    EdgeLabel {
                        kind: ManoeuvreKind::Turn,
                        leg: None,
                        length_m: self.driving.config().turn_radius_m
                            * self.lattice.orientation_step(),
                        cost: c.to_f64(),
                        step: None,
                    }
                } else {
                    EdgeLabel {
                        kind: ManoeuvreKind::Drive,
                        leg: None,
                        length_m: a.distance(&b),
                        cost: c.to_f64(),
                        step: None,
                    }
                };
                out.push((t, c, m));
            }
        }
        if s.step_pending != 0 {
            out.extend(self.pending_step(s));
            return out;
        }
        self.special_successors(s, false);
        out.extend_from_slice(&self.special);
        out
    }

    /// The cheapest edge from `s` to `t`, labelled; `None` if there is none.
    pub fn edge(&mut self, s: LatticeState, t: LatticeState) -> Option<(Cost, EdgeLabel)> {
        self.labelled_successors(s)
            .into_iter()
            .filter(|(u, _, _)| *u == t)
            .map(|(_, c, m)| (c, m))
            .min_by_key(|(c, _)| *c)
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

/// The criterion-1 pre-filter: per cell, whether an infinite-foot-cost cell's centre lies
/// within `radius` plus half a cell diagonal of the cell's centre (so for every point of
/// the cell, "an infinite cell closer than `radius`" implies the flag). Stamps a disc
/// around each infinite cell on the border of an infinite region only: the nearest
/// infinite cell to any other cell is such a border cell.
fn near_obstacle_layer(maps: &CostMaps, radius: f64) -> Vec<bool> {
    let hm = maps.heights();
    let (nx, ny) = hm.dims();
    let res = hm.resolution();
    let inf = |i: isize, j: isize| {
        i >= 0
            && j >= 0
            && (i as usize) < nx
            && (j as usize) < ny
            && maps.foot_cost_infinite_at_some_heading(i as usize, j as usize)
    };
    let r = radius.max(0.0) + res * std::f64::consts::FRAC_1_SQRT_2;
    let reach = (r / res).ceil() as isize;
    let mut disc = Vec::new();
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            if res * ((dx * dx + dy * dy) as f64).sqrt() < r {
                disc.push((dx, dy));
            }
        }
    }
    let mut near = vec![false; nx * ny];
    for j in 0..ny as isize {
        for i in 0..nx as isize {
            if !inf(i, j) {
                continue;
            }
            let border = (-1..=1).any(|dy| (-1..=1).any(|dx| !inf(i + dx, j + dy)));
            if !border {
                near[j as usize * nx + i as usize] = true;
                continue;
            }
            for &(dx, dy) in &disc {
                let (a, b) = (i + dx, j + dy);
                if a >= 0 && b >= 0 && (a as usize) < nx && (b as usize) < ny {
                    near[b as usize * nx + a as usize] = true;
                }
            }
        }
    }
    near
}

impl SearchGraph for HybridGraph<'_> {
    type State = LatticeState;

    fn successors(&mut self, s: LatticeState, out: &mut Vec<(LatticeState, Cost)>) {
        let first = out.len();
        if s.step_pending != 0 {
            out.extend(self.pending_step(s).map(|(t, c, _)| (t, c)));
        } else {
            if s.footprint == NEUTRAL_FOOTPRINT {
                self.driving.successors(s, out);
            }
            self.special_successors(s, true);
            out.extend(self.special.iter().map(|&(t, c, _)| (t, c)));
        }
        if !self.forbidden.is_empty()
            && let Some(from) = self.key(s)
        {
            let mut k = first;
            while k < out.len() {
                let to = self.key(out[k].0);
                if to.is_some_and(|to| self.forbidden.contains(&(from, to))) {
                    out.remove(k);
                } else {
                    k += 1;
                }
            }
        }
    }

    /// The larger of the driving heuristic (Euclidean distance plus turn,
    /// [`DrivingGraph`]) and the base-cell cost-to-go (`cost_to_go`), plus the step
    /// bound Σ_k S_k of the four feet and the foot-offset potential Φ (`heuristic`
    /// module), clamped at zero: consistent on every manoeuvre (see the module docs of
    /// all three and of this module).
    ///
    /// An intermediate node of a lazy step (see "Lazy step checks" in the module docs)
    /// gets `min_c (c_c + h(t_c)) − c_lb` over the step's footholds `c` by the scan (edge
    /// cost `c_c` and after-step state `t_c`; `c_lb` the least `c_c`, which the edge into
    /// the node charged), consistent on both of its edges.
    fn heuristic(&self, s: LatticeState) -> Cost {
        if s.step_pending == 0 {
            return self.heuristic_parts(s).total();
        }
        self.pending_heuristic(s).map_or(Cost::INFINITY, |(h, _, _)| h)
    }

    /// The heuristic and, as guidance for ARA*'s probe, the same without the cost-to-go
    /// (`HeuristicParts::guidance`).
    fn heuristic_and_guidance(&self, s: LatticeState) -> (Cost, Cost) {
        let (h, g, _) = self.heuristic_and_guidances(s);
        (h, g)
    }

    /// The heuristic, the guidance and, for the probe's greedy list, the guidance with
    /// the feet's offsets weighed as the straight line weighs the base's way and the
    /// feet's way over climbable terrain where it is longer than the straight line
    /// (`HeuristicParts::greedy_guidance`).
    fn heuristic_and_guidances(&self, s: LatticeState) -> (Cost, Cost, Cost) {
        if s.step_pending == 0 {
            let parts = self.heuristic_parts(s);
            return (parts.total(), parts.guidance(), parts.greedy_guidance());
        }
        self.pending_heuristic(s).unwrap_or((Cost::INFINITY, Cost::INFINITY, Cost::INFINITY))
    }

    fn is_goal(&self, s: LatticeState) -> bool {
        s.step_pending == 0 && self.driving.is_goal(s)
    }

    fn is_intermediate(&self, s: LatticeState) -> bool {
        s.step_pending != 0
    }

    fn dense_len(&self) -> usize {
        usize::from(self.lattice.nx)
            * usize::from(self.lattice.ny)
            * usize::from(self.lattice.orientations)
    }

    /// Neutral states only: `(j·nx + i)·orientations + θ`, the layout of the driving
    /// pose-cost cache, so a cell's orientations share cache lines.
    #[inline]
    fn dense_index(&self, s: LatticeState) -> Option<usize> {
        if s.footprint != NEUTRAL_FOOTPRINT
            || s.step_pending != 0
            || !self.lattice.contains(i32::from(s.i), i32::from(s.j))
        {
            return None;
        }
        let cell = s.j as usize * usize::from(self.lattice.nx) + s.i as usize;
        Some(cell * usize::from(self.lattice.orientations) + usize::from(s.theta))
    }
}
