//! The state every manoeuvre of the hybrid graph reads and shares ([`GraphCore`]): the
//! cost maps and the lattice over them, the footprints met so far, where a state's feet
//! stand and whether the robot can stand there (the shared standing rule, memoised), the
//! driving graph of the neutral footprint, the heuristic's tables, and the counters.
//!
//! **Stances.** A non-neutral footprint is allowed only if the robot can stand in it by
//! the leg-height rule of Sec. VI-B that the step motion generator uses
//! (`posture::standing::StandingRule`): base pitched by 70 % of the slope, its height set
//! by the highest foot, the leg height lowered from 0.45 m in 1 cm steps until every leg
//! reaches its foot (sagittal IK within the joint limits). Each leg's offset range over
//! all those heights, computed once from the model, bounds the scans ([`GraphCore::reach`]).
//! Non-neutral states must have all four feet on cells of finite foot cost, a finite body
//! cost C_B (eq. 3) with the legs of the standing rule above, and the two feet of each
//! side at least half the support length apart, so wheel pairs never collide
//! ([`GraphCore::target_ok`]). Only neutral states drive.
//!
//! **Leaving the driving footprint.** A neutral state leaves its footprint only where a
//! foot stands close to an obstacle (criterion 1 of Sec. V, `step_obstacle_distance_m`):
//! steps and front-foot-forward moves need one, and the common case, driving in the open,
//! ends there ([`GraphCore::stance`]).

use super::config::{HybridConfig, ManoeuvreStats};
use super::driving::heuristic_cost;
use super::driving::{DrivingGoal, DrivingGraph, PoseCostSource};
use super::footprint::{FootOffsets, FootprintTable, NEUTRAL_OFFSETS};
use super::heuristic::reachability::StanceLimits;
use super::heuristic::step_bound::offsets_weighed;
use super::heuristic::tables::{TableInputs, TablesKey};
use super::heuristic::{
    GREEDY_OFFSET_PER_M, HeuristicCache, HeuristicParts, HeuristicTables, Relaxation,
};
use super::lattice::{Lattice, LatticeError, LatticeState, NEUTRAL_FOOTPRINT};
use crate::cost::{Cost as CostValue, CostMaps, HeadingBin};
use crate::feasibility::DrivingCheck;
use crate::geometry::Pose2;
use crate::posture::kinematics::hips_in_world;
use crate::robot::ik::leg_ik;
use crate::robot::{Leg, RobotDescription};
use crate::search::{Cost, FxBuild, SearchGraph};
use std::cell::{Cell, OnceCell};
use std::collections::HashMap;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// How the robot stands on a footprint at a lattice pose ([`GraphCore::stand`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stand {
    /// No height of the standing rule reaches every foot clear of the terrain, or the
    /// body would touch it.
    No,
    /// The rule's posture stands, its legs clear of the leg terrain.
    Stands,
    /// It also clears the swept leg terrain: a wheel move between two such postures
    /// needs no check in between (the wheel moves' roll).
    SweptClear,
}

/// Where the four feet of a state stand and what is under them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feet {
    /// World (x, y), FL, FR, RL, RR.
    pub pos: [[f64; 2]; 4],
    /// Foot cost C_F of each foot's cell (finite).
    pub cf: [f64; 4],
    /// Ground height of each foot's cell, m.
    pub h: [f64; 4],
}

/// A lattice state by what it means, not by this graph's footprint ids: cell,
/// orientation and foot offsets. Names a state across graphs (replans).
pub type PoseKey = (i16, i16, u8, FootOffsets);

/// Where a state's feet stand and what may start from them: what the successors of
/// every manoeuvre that leaves or changes the footprint read ([`GraphCore::stance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// The state.
    pub s: LatticeState,
    /// Its foot offsets.
    pub o: FootOffsets,
    /// Whether the footprint is the neutral one.
    pub neutral: bool,
    /// Its feet, all on cells of finite foot cost.
    pub feet: Feet,
    /// Criterion 1 per foot: an infinite-foot-cost cell lies close.
    pub near: [bool; 4],
    /// The base heading (cos θ, sin θ).
    pub heading: (f64, f64),
    /// The feet's foot-cost heading bin.
    pub bin: HeadingBin,
}

/// Driving pose costs of the cost client where the shared feasibility model admits the
/// driving posture (`feasibility::DrivingCheck::lattice_pose`), none elsewhere: the
/// driving graph memoises both per lattice pose.
pub struct FeasibleDriving<'c> {
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

/// The hybrid graph's state over one cost map, shared by its manoeuvres
/// (`planner::graph::Manoeuvre`).
pub struct GraphCore<'c> {
    maps: &'c CostMaps,
    driving: DrivingGraph<FeasibleDriving<'c>>,
    /// The shared feasibility model (`feasibility`): body clearance of standing states.
    feasibility: DrivingCheck,
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
    /// What the graph's manoeuvres say of themselves: which heuristic terms to build.
    relaxations: Vec<Relaxation>,
    /// The counters; a `Cell`, as manoeuvres count their checks where they hold the
    /// core by shared reference.
    stats: Cell<ManoeuvreStats>,
    /// The heuristic's tables, built (or taken from `heuristic_cache`) at its first
    /// use, and whether they were taken: a graph asked only for edges (the plan's
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
}

impl<'c> GraphCore<'c> {
    /// The graph's state on `maps` (lattice over its height map with `orientations`
    /// orientations) searching for `goal`, for manoeuvres whose heuristic terms are
    /// `relaxations`.
    ///
    /// # Errors
    /// A map too large for the lattice or an invalid orientation count.
    pub fn new(
        maps: &'c CostMaps,
        robot: &RobotDescription,
        orientations: u32,
        config: HybridConfig,
        goal: DrivingGoal,
        relaxations: Vec<Relaxation>,
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
            relaxations,
            stats: Cell::new(ManoeuvreStats::default()),
            heuristic: OnceCell::new(),
            heuristic_cache: None,
            heuristic_deadline: Cell::new(None),
            standable: HashMap::default(),
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
    pub fn tables(&self) -> &HeuristicTables {
        &self.tables_and_origin().0
    }

    /// The heuristic's tables and whether they came from the cache.
    fn tables_and_origin(&self) -> &(Rc<HeuristicTables>, bool) {
        self.heuristic.get_or_init(|| {
            let goal = self.driving.goal();
            let key = TablesKey {
                maps: std::ptr::from_ref(self.maps) as usize,
                robot: self.robot.clone(),
                config: self.config,
                relaxations: self.relaxations.clone(),
                goal,
            };
            let cached = self.heuristic_cache.and_then(|cache| cache.get(&key));
            let reused = cached.is_some();
            let tables = cached.unwrap_or_else(|| {
                let tables = Rc::new(HeuristicTables::build(&TableInputs {
                    maps: self.maps,
                    robot: &self.robot,
                    lattice: &self.lattice,
                    config: &self.config,
                    goal,
                    near: &self.near,
                    reach: self.reach,
                    stance: self.stance_limits(),
                    relaxations: &self.relaxations,
                }));
                if let Some(cache) = self.heuristic_cache {
                    cache.insert(key, &tables);
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

    /// How high any state's hips and base stand above its feet (`reachability`): the
    /// standing rule's tallest leg height and pitch fraction, and the mean front feet's
    /// least lead over the mean rear feet: each side's front foot stands at least half
    /// the support length ahead of its rear foot ([`Self::sides_ok`]; neutral states a hip
    /// spacing), or the legs' reach limits, whichever says more.
    pub fn stance_limits(&self) -> StanceLimits {
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

    /// Whether the heuristic's tables have been built (by a first heuristic query).
    #[cfg(test)]
    pub fn heuristic_built(&self) -> bool {
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
    pub fn parts_with(
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
    pub fn count(&self, counter: impl FnOnce(&mut ManoeuvreStats) -> &mut u64) {
        let mut stats = self.stats.get();
        *counter(&mut stats) += 1;
        self.stats.set(stats);
    }

    /// Number of footprints met so far (the neutral one included).
    pub fn footprint_count(&self) -> usize {
        self.footprints.len()
    }

    /// The cost maps.
    pub fn maps(&self) -> &'c CostMaps {
        self.maps
    }

    /// The robot.
    pub fn robot(&self) -> &RobotDescription {
        &self.robot
    }

    /// Shortest "front foot forward" move, cells.
    pub fn foot_move_cells(&self) -> i8 {
        self.foot_move_cells
    }

    /// The driving graph of the neutral footprint (drives, turns on the spot, their
    /// costs and the driving heuristic).
    pub fn driving(&self) -> &DrivingGraph<FeasibleDriving<'c>> {
        &self.driving
    }

    /// Appends the driving successors of neutral state `s` (drives and turns on the spot)
    /// to `out`.
    pub fn driving_successors(&mut self, s: LatticeState, out: &mut Vec<(LatticeState, Cost)>) {
        self.driving.successors(s, out);
    }

    /// Where state `s`'s feet stand, for the manoeuvres that leave or change the
    /// footprint: `None` where none may start (a neutral state with no foot close to an
    /// obstacle, see the module docs, or a foot off finite-cost cells).
    pub fn stance(&self, s: LatticeState) -> Option<Stance> {
        let o = self.footprints.get(s.footprint)?;
        let neutral = o == NEUTRAL_OFFSETS;
        let pos = self.feet_pos(s, &o);
        let bin = self.bin(s.theta);
        let near = pos.map(|p| self.near_obstacle(p, bin));
        // Neutral states only have steps and front-foot-forward moves, both of which need
        // a foot close to an obstacle: the common case ends here.
        if neutral && !near.iter().any(|&n| n) {
            return None;
        }
        let feet = self.feet_of(s, &o)?;
        Some(Stance { s, o, neutral, feet, near, heading: self.heading(s.theta), bin })
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
        self.driving.pose_cost(LatticeState { footprint: NEUTRAL_FOOTPRINT, pending: 0, ..s })
    }

    #[inline]
    pub fn heading(&self, theta: u8) -> (f64, f64) {
        let (s, c) = self.trig[usize::from(theta)];
        (c, s)
    }

    #[inline]
    pub fn feet_pos(&self, s: LatticeState, o: &FootOffsets) -> [[f64; 2]; 4] {
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
    pub fn bin(&self, theta: u8) -> HeadingBin {
        self.maps.foot_heading_bin(self.lattice.yaw(theta))
    }

    /// Foot cost (at heading bin `bin`) and ground height of the cell under (x, y):
    /// `Err(true)` for an infinite foot cost, `Err(false)` for unknown terrain or off the
    /// map.
    #[inline]
    pub fn cell(&self, x: f64, y: f64, bin: HeadingBin) -> Result<(f64, f64), bool> {
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
    pub fn feet_of(&self, s: LatticeState, o: &FootOffsets) -> Option<Feet> {
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
    pub fn near_obstacle(&self, p: [f64; 2], bin: HeadingBin) -> bool {
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
    pub fn side_length(&self, o: &FootOffsets, left: bool) -> f64 {
        let (f, r) = if left { (0, 2) } else { (1, 3) };
        let res = self.lattice.resolution;
        (self.neutral[f][0] + f64::from(o[f]) * res) - (self.neutral[r][0] + f64::from(o[r]) * res)
    }

    /// World feet (x, y, ground z) of `feet`.
    pub fn feet_xyz(feet: &Feet) -> [[f64; 3]; 4] {
        std::array::from_fn(|k| [feet.pos[k][0], feet.pos[k][1], feet.h[k]])
    }

    /// Leg heights (hip above the foot's ground, m) of the standing rule for the robot at
    /// state `s`'s pose on feet `feet`, and whether its thighs and shins also clear the
    /// swept leg terrain ([`CostMaps::swept_leg_terrain`]); `None` if no leg height of the
    /// rule reaches every foot (see the module docs).
    pub fn standing_legs(&self, s: LatticeState, feet: &Feet) -> Option<([f64; 4], bool)> {
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
    pub fn sides_ok(&self, o: &FootOffsets) -> bool {
        let min_side = 0.5 * self.config.min_support_side_length_m;
        self.side_length(o, true) >= min_side && self.side_length(o, false) >= min_side
    }

    /// Whether state `t` (footprint offsets `o`) may be entered; its body cost for
    /// non-neutral footprints.
    pub fn target_ok(&mut self, t: LatticeState, o: &FootOffsets) -> bool {
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
    pub fn stand(&mut self, t: LatticeState, o: &FootOffsets) -> Stand {
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

    /// Interns `o` and returns the state at `(i, j, θ)` with that footprint.
    pub fn with_footprint(&mut self, t: LatticeState, o: FootOffsets) -> Option<LatticeState> {
        match self.footprints.intern(o) {
            Some(footprint) => Some(LatticeState { footprint, ..t }),
            None => {
                self.count(|c| &mut c.footprint_table_full);
                None
            }
        }
    }

    /// The longest drive of a wheel pair from `p` in direction `dir`, at most `cells`
    /// cells, over drivable cells only: its length in cells and mean foot cost (both
    /// ends included); `None` if the cell under `p` is not drivable.
    pub fn drivable_prefix(
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
    pub fn drive_line_cost(
        &self,
        p: [f64; 2],
        dir: (f64, f64),
        cells: i32,
        bin: HeadingBin,
    ) -> Option<f64> {
        let (n, avg) = self.drivable_prefix(p, dir, cells, bin)?;
        (n == cells).then_some(avg)
    }
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
