//! The driving part of the hybrid graph (Sec. V, Fig. 4; Sec. VII): a [`SearchGraph`]
//! over [`LatticeState`]s with straight moves in the 16- (A*) or 20-neighbourhood (ARA*)
//! at fixed orientation, and turns on the spot to the next orientation.
//!
//! **Edge costs** (units of "metres on flat ground"):
//! - move: `L · (C(s) + C(t)) / 2 · k_Δθ`, with `L` the move length in metres, `C` the
//!   pose cost (eq. 4) of the neutral footprint at the two poses, and k_Δθ the
//!   orientation factor of the heading against the move direction ([`OrientationFactor`]);
//! - turn: `r_turn · 2π/n · (C(s) + C(t)) / 2`, where `r_turn` is the mean distance of the
//!   neutral feet from the base centre — the arc each wheel pair drives while the robot
//!   turns on the spot (the paper gives no turn cost; this makes a turn cost what its
//!   wheel travel would cost as a drive).
//!
//! Pose costs below 1 are raised to 1 (the paper's costs are ≥ 1; the heuristic relies
//! on it); untraversable or unknown poses have no edges into them. A foot model that
//! depends on the foot heading (`Params::foot_model = wheel_pair`) prices poses with
//! straight wheels, while a drive steers every pair along its velocity: such a move or
//! turn also needs both end poses' feet to fit with the pairs steered so
//! ([`PoseCostSource::steered_fit_mask`]); the paper's model always fits. Only the two end
//! poses of a move are checked: a two-cell move could hop a one-cell-wide untraversable
//! line, which the cost client never produces (infinite foot costs are dilated by
//! r_F = 0.12 m, about five cells).
//!
//! Fixed point: edge costs are rounded up to the micro-unit and the heuristic down, each
//! with a tiny relative slack (10⁻¹² on edges, 10⁻⁹ on the heuristic) so that float noise
//! in `x · 10⁶` can neither add a micro-unit to an edge whose exact cost is an integer
//! nor break consistency.
//!
//! **Heuristic:** Euclidean distance to the goal cell (metres) plus, when the goal fixes
//! the orientation, `r_turn` × the angle still to turn. With C ≥ 1 and k_Δθ ≥ 1 every move
//! costs at least its length and every turn at least its arc, and moves and turns change
//! only one of the two terms, so the heuristic is consistent (hence admissible).
//!
//! Only the neutral footprint drives; states of other footprints (stepping manoeuvres,
//! Sec. V) have no driving successors here.

use super::lattice::{Lattice, LatticeState, Move, NEUTRAL_FOOTPRINT, Neighbourhood};
use super::orientation::OrientationFactor;
use crate::geometry::Pose2;
use crate::params::Params;
use crate::search::{
    Algorithm, Cost, Hooks, SearchError, SearchGraph, SearchParams, SearchResult,
    arastar_with_hooks, astar_with_hooks,
};

/// Where driving pose costs come from: the cost client (`cost::CostMaps`), or a stand-in
/// in tests.
pub trait PoseCostSource {
    /// Pose cost C (eq. 4) of the neutral footprint at `pose` with driving leg heights;
    /// `None` where the pose is untraversable or unknown.
    fn driving_cost(&self, pose: &Pose2) -> Option<f64>;

    /// Whether [`Self::steered_fit_mask`] can clear a bit (a foot model that depends on
    /// the heading): the graph then memoises the masks per pose. Default: no.
    fn steering_matters(&self) -> bool {
        false
    }

    /// Bit k set when the wheel pairs at `pose` fit the terrain steered for a drive in
    /// world direction `directions[k]` (`None`: a turn on the spot). The pose cost
    /// assumes straight wheels; a foot model that depends on the heading checks the
    /// steering here (`CostMaps::steered_feet_fit_mask`). Default: they all fit.
    fn steered_fit_mask(&self, _pose: &Pose2, _directions: &[Option<f64>]) -> u32 {
        u32::MAX
    }
}

impl PoseCostSource for &crate::cost::CostMaps {
    fn driving_cost(&self, pose: &Pose2) -> Option<f64> {
        self.driving_pose_cost(pose).finite()
    }

    fn steering_matters(&self) -> bool {
        self.foot_heading_dependent()
    }

    fn steered_fit_mask(&self, pose: &Pose2, directions: &[Option<f64>]) -> u32 {
        self.steered_feet_fit_mask(pose, directions)
    }
}

impl<F: Fn(&Pose2) -> Option<f64>> PoseCostSource for F {
    fn driving_cost(&self, pose: &Pose2) -> Option<f64> {
        self(pose)
    }
}

/// Configuration of the driving graph.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrivingConfig {
    /// Driving moves (16 for A*, 20 for ARA*).
    pub neighbourhood: Neighbourhood,
    /// The k_Δθ curve.
    pub orientation: OrientationFactor,
    /// Wheel travel per radian of turning on the spot, m/rad.
    pub turn_radius_m: f64,
}

impl DrivingConfig {
    /// From the paper's constants and the robot's neutral footprint (base frame x', y').
    pub fn new(
        params: &Params,
        neutral_footprint: &[[f64; 2]; 4],
        neighbourhood: Neighbourhood,
    ) -> Self {
        let turn_radius_m = neutral_footprint.iter().map(|f| f[0].hypot(f[1])).sum::<f64>() / 4.0;
        Self {
            neighbourhood,
            orientation: OrientationFactor::new(params.k12, params.orientation_free_band_rad),
            turn_radius_m,
        }
    }
}

/// The goal of a driving search: a cell and, optionally, an orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrivingGoal {
    /// Goal cell along x.
    pub i: i16,
    /// Goal cell along y.
    pub j: i16,
    /// Required orientation index; `None` accepts any.
    pub theta: Option<u8>,
}

impl DrivingGoal {
    /// The goal at a lattice state's cell and orientation.
    pub fn at(s: LatticeState) -> Self {
        Self { i: s.i, j: s.j, theta: Some(s.theta) }
    }
}

/// The driving graph over one cost map.
pub struct DrivingGraph<C: PoseCostSource> {
    costs: C,
    lattice: Lattice,
    config: DrivingConfig,
    goal: DrivingGoal,
    moves: Vec<Move>,
    /// `L · k_Δθ` per (orientation, move), row-major by orientation.
    move_weight: Vec<f64>,
    /// Wheel travel of one orientation step, m.
    turn_length: f64,
    /// Pose costs, dense by `(j·nx + i)·orientations + θ` (the orientations of a cell
    /// side by side), computed lazily: 0 = not yet computed (costs are raised to ≥ 1, so
    /// 0 never is one; and a zeroed allocation is lazy, where filling with NaN cost
    /// milliseconds on every plan), +∞ = untraversable. 4 bytes per lattice pose
    /// (256 MB for 1000 × 1000 cells × 64); a hash map here cost a third of the search
    /// time in cache misses.
    cache: Vec<f32>,
    /// Number of pose costs computed.
    computed: usize,
    /// The moves' world directions, then `None` for the turns (bit order of `steer`).
    directions: Vec<Option<f64>>,
    /// Steering masks per lattice pose, indexed as `cache` (bit k: `directions[k]` fits;
    /// bit 31: computed), only when [`PoseCostSource::steering_matters`]; else empty.
    steer: Vec<u32>,
}

/// Bit of a computed steering mask.
const STEER_COMPUTED: u32 = 1 << 31;

/// An edge cost in fixed point: rounded up, ignoring relative float noise below 10⁻¹².
#[inline]
pub(crate) fn edge_cost(units: f64) -> Cost {
    Cost::from_f64_ceil(units * (1.0 - 1e-12))
}

/// A heuristic in fixed point: rounded down with a relative slack of 10⁻⁹ (see the
/// module docs), so it stays consistent with [`edge_cost`].
#[inline]
pub(crate) fn heuristic_cost(units: f64) -> Cost {
    Cost::from_f64_floor(units * (1.0 - 1e-9))
}

impl<C: PoseCostSource> DrivingGraph<C> {
    /// A driving graph on `lattice` with costs from `costs`, searching for `goal`.
    pub fn new(costs: C, lattice: Lattice, config: DrivingConfig, goal: DrivingGoal) -> Self {
        let moves = config.neighbourhood.moves();
        let mut move_weight = Vec::with_capacity(moves.len() * usize::from(lattice.orientations));
        for k in 0..lattice.orientations {
            let heading = lattice.yaw(k as u8);
            for m in &moves {
                let k_theta = config.orientation.factor(m.direction - heading);
                move_weight.push(m.cells * lattice.resolution * k_theta);
            }
        }
        let poses =
            usize::from(lattice.nx) * usize::from(lattice.ny) * usize::from(lattice.orientations);
        // Masks have 31 usable bits: at most 20 moves and the turns.
        let steer =
            if costs.steering_matters() && moves.len() < 31 { vec![0; poses] } else { Vec::new() };
        let directions = moves.iter().map(|m| Some(m.direction)).chain([None]).collect();
        Self {
            costs,
            lattice,
            config,
            goal,
            moves,
            move_weight,
            turn_length: config.turn_radius_m * lattice.orientation_step(),
            cache: vec![0.0; poses],
            computed: 0,
            directions,
            steer,
        }
    }

    /// The steering mask of `s` (see `steer`); all ones when steering does not matter.
    /// `s` must be on the lattice (as `pose_cost` has checked).
    #[inline]
    fn steer_mask(&mut self, s: LatticeState) -> u32 {
        if self.steer.is_empty() {
            return u32::MAX;
        }
        let cell = s.j as usize * usize::from(self.lattice.nx) + s.i as usize;
        let idx = cell * usize::from(self.lattice.orientations) + usize::from(s.theta);
        let mut m = self.steer[idx];
        if m & STEER_COMPUTED == 0 {
            m = self.costs.steered_fit_mask(&self.lattice.pose(s), &self.directions)
                | STEER_COMPUTED;
            self.steer[idx] = m;
        }
        m
    }

    /// The lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The configuration.
    pub fn config(&self) -> &DrivingConfig {
        &self.config
    }

    /// The goal.
    pub fn goal(&self) -> DrivingGoal {
        self.goal
    }

    /// Number of pose costs computed so far.
    pub fn cached_poses(&self) -> usize {
        self.computed
    }

    /// Pose cost of `s` (at least 1), `None` if untraversable, unknown or off the map.
    /// Computed once per pose and cached (as `f32`).
    #[inline]
    pub fn pose_cost(&mut self, s: LatticeState) -> Option<f64> {
        if !self.lattice.contains(i32::from(s.i), i32::from(s.j))
            || u16::from(s.theta) >= self.lattice.orientations
        {
            return None;
        }
        let cell = s.j as usize * usize::from(self.lattice.nx) + s.i as usize;
        let idx = cell * usize::from(self.lattice.orientations) + usize::from(s.theta);
        let mut c = self.cache[idx];
        if c == 0.0 {
            c = self
                .costs
                .driving_cost(&self.lattice.pose(s))
                .filter(|c| c.is_finite())
                .map_or(f32::INFINITY, |c| c.max(1.0) as f32);
            self.cache[idx] = c;
            self.computed += 1;
        }
        c.is_finite().then_some(f64::from(c))
    }

    /// The turn term of the heuristic alone: `r_turn` × the angle still to turn when the
    /// goal fixes the orientation, else zero (rounded down like the heuristic). Turns
    /// cost at least their arc and no other move changes θ, so it is consistent on its
    /// own; the hybrid graph adds it to its base-cell cost-to-go.
    pub fn turn_heuristic(&self, s: LatticeState) -> Cost {
        match self.goal.theta {
            Some(g) => {
                let steps = self.lattice.orientation_steps_between(s.theta, g);
                heuristic_cost(f64::from(steps) * self.turn_length)
            }
            None => Cost::ZERO,
        }
    }

    /// The continuous poses of a path.
    pub fn poses(&self, path: &[LatticeState]) -> Vec<Pose2> {
        path.iter().map(|&s| self.lattice.pose(s)).collect()
    }
}

impl<C: PoseCostSource> SearchGraph for DrivingGraph<C> {
    type State = LatticeState;

    fn successors(&mut self, s: LatticeState, out: &mut Vec<(LatticeState, Cost)>) {
        if s.footprint != NEUTRAL_FOOTPRINT {
            return;
        }
        let Some(cs) = self.pose_cost(s) else { return };
        let steer_s = self.steer_mask(s);
        let row = usize::from(s.theta) * self.moves.len();
        for idx in 0..self.moves.len() {
            let m = self.moves[idx];
            let t = LatticeState {
                i: s.i.wrapping_add(i16::from(m.di)),
                j: s.j.wrapping_add(i16::from(m.dj)),
                ..s
            };
            // `contains` also rejects indices that wrapped at the i16 range.
            if !self
                .lattice
                .contains(i32::from(s.i) + i32::from(m.di), i32::from(s.j) + i32::from(m.dj))
            {
                continue;
            }
            if let Some(ct) = self.pose_cost(t)
                && (steer_s & self.steer_mask(t)) >> idx & 1 == 1
            {
                let w = self.move_weight[row + idx];
                out.push((t, edge_cost(w * 0.5 * (cs + ct))));
            }
        }
        let n = self.lattice.orientations;
        let left = ((u16::from(s.theta) + 1) % n) as u8;
        let right = ((u16::from(s.theta) + n - 1) % n) as u8;
        let turns: &[u8] = match n {
            1 => &[],
            2 => &[left], // left and right are the same orientation
            _ => &[left, right],
        };
        for &theta in turns {
            let t = LatticeState { theta, ..s };
            let turn_bit = self.moves.len();
            if let Some(ct) = self.pose_cost(t)
                && (steer_s & self.steer_mask(t)) >> turn_bit & 1 == 1
            {
                out.push((t, edge_cost(self.turn_length * 0.5 * (cs + ct))));
            }
        }
    }

    fn heuristic(&self, s: LatticeState) -> Cost {
        let di = f64::from(i32::from(self.goal.i) - i32::from(s.i));
        let dj = f64::from(i32::from(self.goal.j) - i32::from(s.j));
        // Cell offsets are small integers: `sqrt` is exact enough (the heuristic slack
        // covers its rounding) and much cheaper than libm's `hypot`.
        let mut h = (di * di + dj * dj).sqrt() * self.lattice.resolution;
        if let Some(g) = self.goal.theta {
            let steps = self.lattice.orientation_steps_between(s.theta, g);
            h += f64::from(steps) * self.turn_length;
        }
        heuristic_cost(h)
    }

    fn is_goal(&self, s: LatticeState) -> bool {
        s.footprint == NEUTRAL_FOOTPRINT
            && s.i == self.goal.i
            && s.j == self.goal.j
            && self.goal.theta.is_none_or(|t| t == s.theta)
    }
}

/// Why a driving plan could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DrivingPlanError {
    /// The start pose is off the map (or not finite).
    #[error("start pose {0:?} is off the map")]
    StartOffMap(Pose2),
    /// The goal pose is off the map (or not finite).
    #[error("goal pose {0:?} is off the map")]
    GoalOffMap(Pose2),
    /// The search parameters are invalid.
    #[error(transparent)]
    Search(#[from] SearchError),
}

/// Plans a driving path from `start` to `goal` (poses snapped to the lattice; the goal
/// orientation is required). Use [`Neighbourhood::N16`] with A* and
/// [`Neighbourhood::N20`] with ARA*, as the paper does.
///
/// # Errors
/// A start or goal off the map, or invalid search parameters.
#[allow(clippy::too_many_arguments)]
pub fn plan_driving<C: PoseCostSource>(
    costs: C,
    lattice: Lattice,
    config: DrivingConfig,
    start: &Pose2,
    goal: &Pose2,
    algorithm: Algorithm,
    params: &SearchParams,
    hooks: Hooks<'_, LatticeState>,
) -> Result<SearchResult<LatticeState>, DrivingPlanError> {
    let s = lattice.state(start).ok_or(DrivingPlanError::StartOffMap(*start))?;
    let g = lattice.state(goal).ok_or(DrivingPlanError::GoalOffMap(*goal))?;
    let mut graph = DrivingGraph::new(costs, lattice, config, DrivingGoal::at(g));
    Ok(match algorithm {
        Algorithm::AStar => astar_with_hooks(&mut graph, s, params, hooks),
        Algorithm::AraStar => arastar_with_hooks(&mut graph, s, params, hooks)?,
    })
}
