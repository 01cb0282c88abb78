//! The base-pose cost-to-go: the hybrid heuristic's informed lower bound on the driving,
//! turning and base-shift costs still to come ([`super::HybridGraph`], issue 15). A
//! backward Dijkstra from the goal over (cell, orientation) nodes of the lattice — the
//! nodes `reachability` floods, with costs — in which every edge weighs at most what the
//! manoeuvre of the hybrid graph it stands for costs, whatever the footprint: an exact
//! relaxation, so the distance `D` it computes is consistent on every edge of the hybrid
//! graph. `HybridGraph::heuristic` takes `max(Euclidean + turn, D)` and adds the step
//! bound and the foot-offset potential of `heuristic`.
//!
//! **Which edges move the base.** Of the hybrid graph's manoeuvres (`hybrid` module
//! docs) drives, turns on the spot and base shifts change the base pose. Abstract steps,
//! "front foot forward" and "foot to neutral" leave it where it is, so `D` is the same at
//! both ends of those edges and `D(s) ≤ c(s, t) + D(t)` holds for any cost `c ≥ 0`
//! (their costs are what the step bound and the foot-offset potential bound).
//!
//! **Drive and turn edges** (`driving` module docs, eq. 4, Fig. 8). A drive by move `m`
//! from (a, θ) to (b, θ) costs `L_m · k_Δθ · (C(a, θ) + C(b, θ)) / 2` and a turn from
//! (a, θ) to (a, θ ± 1) costs `r_turn · 2π/n · (C(a, θ) + C(a, θ ± 1)) / 2`, both rounded
//! up to the micro-unit, with `C` the driving pose cost of the neutral footprint raised
//! to 1. The driving graph also drops poses its feasibility model rejects, which only
//! removes edges. So the relaxed edges take the same formulas with `P(a, θ)` =
//! `max(1, C(a, θ))` computed with the very poses (`Lattice::pose`), cost function
//! (`CostMaps::driving_pose_cost`) and move weights `L_m · k_Δθ` the driving graph uses,
//! less a relative 10⁻⁶ for the driving graph's `f32` cache of pose costs (relative error
//! ≤ 6·10⁻⁸); `P = ∞` (no edge) where `C` is not finite.
//!
//! **Base-shift edges.** A base shift by `l` cells along the heading θ moves the base
//! from the centre of cell a to `a + l · res · (cos θ, sin θ)` and snaps it to the cell b
//! holding that point (`hybrid` module docs). The cell of the exact position after k
//! cell-lengths is `⌊1/2 + k · cos θ⌋` cells from a along x (likewise y), so from one k
//! to the next each axis steps by 0 or by the sign of its direction cosine: a chain of at
//! most l *forward links* of layer θ (the up to three steps into the heading's quadrant)
//! joins (a, θ) to (b, θ). The shift costs `max(f · k10 · l · res · C_B,avg, moved) ≥
//! f · k10 · l · res` (C_B ≥ 1, eq. 3; f the step-related factor), and it lowers all four
//! foot offsets by l, which raises the foot-offset potential Φ of the heuristic by at
//! least `4 c · l · res` (`heuristic::offset_potential`). A link weighs
//! `β · res = f · k10 · res + 4 c · res`, so `D` drops along the chain by no more than
//! the shift's cost plus Φ's rise. The links are not restricted to cells where the robot
//! can stand, which only weakens the bound. (Float noise could snap the end to another
//! cell only where `1/2 + k cos θ` is within about 10⁻¹² of an integer; with 64
//! orientations it stays at least 4·10⁻⁴ away for every k ≤ 127.)
//!
//! **Consistency** (and admissibility: `D = 0` at the goal, where the search starts).
//! For every drive or turn s → t the relaxed graph has an edge from s's node to t's no
//! heavier than the edge, for every base shift a path no heavier than its cost plus Φ's
//! rise, and edges that keep the base pose need none; so Dijkstra's
//! `D(s) ≤ w(path) + D(t)` gives `D(s) + Φ(s) ≤ c(s, t) + D(t) + Φ(t)` on every edge
//! that moves the base (Φ is zero on drives and turns: neutral footprint). In fixed
//! point: relaxed weights are rounded down (with a relative slack of 10⁻⁹), edges up,
//! and `D` sums integers, so the inequalities hold exactly.
//!
//! **One layer for large maps.** Above [`MAX_ORIENTED_NODES`] (cell, orientation) nodes
//! (`HybridConfig::max_oriented_nodes`) the search has one node per cell instead: `P` is the minimum over orientations,
//! `k_Δθ` is taken as its least value 1, base shifts link all eight neighbours, and
//! there are no turn edges (the hybrid graph adds the driving heuristic's turn term,
//! consistent on its own, instead). Every argument above holds for the minimum.
//!
//! **Laziness.** Like the obstacle heuristic of Nav2's Smac planner, the Dijkstra runs
//! only as far as the queries need: a query for an unsettled node resumes the queue
//! until that node is settled, and `P` is computed per node when the search first
//! touches it. The graph (and with it this search) lives for one plan, so every ARA*
//! iteration reuses what earlier ones settled. The queue is a bucket queue (Dial's
//! algorithm; buckets no wider than the lightest edge), exact like a binary heap.

use super::driving::DrivingConfig;
use super::lattice::{Lattice, LatticeState};
use crate::cost::CostMaps;
use crate::planner::Cost;
use std::cell::RefCell;
use std::time::Instant;

/// Relative slack on `P` for the driving graph's `f32` pose-cost cache.
const POSE_SLACK: f64 = 1e-6;
/// Relative slack on relaxed edge weights (edges are rounded up with 10⁻¹²).
const WEIGHT_SLACK: f64 = 1e-9;
/// Default for the most (cell, orientation) nodes searched with one layer per
/// orientation (13 bytes each: about 110 MB at the limit, a 9 m × 9 m map with 64
/// orientations); larger maps get one layer, the minimum over orientations.
pub const MAX_ORIENTED_NODES: usize = 1 << 23;

/// The lazily computed backward Dijkstra over base cells (see the module docs).
#[derive(Debug)]
pub struct CostToGo {
    lattice: Lattice,
    /// Orientation layers: the lattice's orientations, or 1 (see [`MAX_ORIENTED_NODES`]).
    layers: usize,
    /// Drive moves `(di, dj)`.
    moves: Vec<(i32, i32)>,
    /// `L · k_Δθ` per (layer, move), row-major by layer: the driving graph's move
    /// weights, or `L` (k_Δθ ≥ 1) with one layer.
    move_weight: Vec<f64>,
    /// Wheel travel of one orientation step, m (turn edges between layers).
    turn_length: f64,
    /// Per layer: the cell steps a base shift's chain may take (see the module docs).
    shift_links: Vec<Vec<(i32, i32)>>,
    /// Weight of one link of a base shift, `β · res` rounded down.
    shift_step: Cost,
    /// `(sin, cos)` of each orientation's yaw, as `Pose2::theta.sin_cos()` gives them.
    trig: Vec<(f64, f64)>,
    search: RefCell<Search>,
}

/// The resumable part of the search.
#[derive(Debug)]
struct Search {
    /// `P` per node (`cell · layers + layer`, cells row-major `j · nx + i`): 0 = not
    /// computed yet (`P ≥ 1` otherwise, so 0 never is a value; a zeroed allocation is
    /// lazy), +∞ = no finite pose cost.
    pose: Vec<f32>,
    /// Tentative distances; final once `done`.
    dist: Vec<Cost>,
    done: Vec<bool>,
    queue: Buckets,
    /// Nodes settled so far.
    settled: usize,
    /// When the search must stop growing (the plan's time limit).
    deadline: Option<Instant>,
    /// Set when the deadline passed: a lower bound on `D` of every unsettled node.
    frozen: Option<Cost>,
}

impl CostToGo {
    /// The cost-to-go on `lattice` toward `goal` (cell, and orientation if it is fixed),
    /// with the driving moves, k_Δθ and turn length of `driving` and `shift_step`, the
    /// weight β · res of one link of a base shift (see the module docs); one layer per
    /// orientation if that makes at most `max_oriented_nodes` nodes, else one. Nothing
    /// is computed until the first query.
    pub fn new(
        lattice: Lattice,
        driving: &DrivingConfig,
        shift_step: Cost,
        goal: (i16, i16, Option<u8>),
        max_oriented_nodes: usize,
    ) -> Self {
        let cells = usize::from(lattice.nx) * usize::from(lattice.ny);
        let orientations = usize::from(lattice.orientations).max(1);
        let layers =
            if cells.saturating_mul(orientations) <= max_oriented_nodes { orientations } else { 1 };
        let res = lattice.resolution;
        let all = driving.neighbourhood.moves();
        let moves = all.iter().map(|m| (i32::from(m.di), i32::from(m.dj))).collect();
        let mut move_weight = Vec::with_capacity(layers * all.len());
        let mut shift_links = Vec::with_capacity(layers);
        for k in 0..layers {
            let heading = lattice.yaw(k as u8);
            for m in &all {
                // As `DrivingGraph::new` computes it, so the weights agree bit for bit.
                let k_theta = if layers > 1 {
                    driving.orientation.factor(m.direction - heading)
                } else {
                    1.0
                };
                move_weight.push(m.cells * res * k_theta);
            }
            shift_links.push(if layers > 1 { forward_links(heading) } else { all_links() });
        }
        let turn_length =
            if layers > 1 { driving.turn_radius_m * lattice.orientation_step() } else { 0.0 };
        let shift_step = shift_step.max(Cost(1));
        let n = cells * layers;
        let mut search = Search {
            pose: vec![0.0; n],
            dist: vec![Cost::INFINITY; n],
            done: vec![false; n],
            queue: Buckets::new(min_weight(&lattice, &move_weight, turn_length, shift_step)),
            settled: 0,
            deadline: None,
            frozen: None,
        };
        let (gi, gj, gt) = goal;
        if lattice.contains(i32::from(gi), i32::from(gj)) {
            let g = gj as usize * usize::from(lattice.nx) + gi as usize;
            let sources: Vec<usize> = match gt {
                Some(t) if layers > 1 => vec![usize::from(t) % layers],
                _ => (0..layers).collect(),
            };
            for t in sources {
                let node = g * layers + t;
                search.dist[node] = Cost::ZERO;
                search.queue.push(Cost::ZERO, node as u32);
            }
        }
        Self {
            lattice,
            layers,
            moves,
            move_weight,
            turn_length,
            shift_links,
            shift_step,
            trig: (0..lattice.orientations).map(|k| lattice.yaw(k as u8).sin_cos()).collect(),
            search: RefCell::new(search),
        }
    }

    /// `D` of a state at cell (i, j) with orientation `theta`: a lower bound on the
    /// driving, turning and base-shift costs from it to the goal. Zero off the lattice
    /// (no bound).
    pub fn get(&self, maps: &CostMaps, i: i16, j: i16, theta: u8) -> Cost {
        if !self.lattice.contains(i32::from(i), i32::from(j)) {
            return Cost::ZERO;
        }
        let cell = j as usize * usize::from(self.lattice.nx) + i as usize;
        let layer = if self.layers > 1 { usize::from(theta) % self.layers } else { 0 };
        let node = cell * self.layers + layer;
        let mut search = self.search.borrow_mut();
        if !search.done[node] && search.frozen.is_none() {
            self.run_until(&mut search, maps, node);
        }
        if search.done[node] {
            search.dist[node]
        } else {
            // Frozen: the frontier's bound; else the queue ran empty: no path at all.
            search.frozen.unwrap_or(Cost::INFINITY)
        }
    }

    /// Stops growing the search once `deadline` has passed (checked every 1024 settled
    /// nodes), so a plan's time limit holds however far the first queries reach. From
    /// then on an unsettled node gets the frontier's distance `L` instead of `D`: every
    /// unsettled node has `D ≥ L`, so this is `min(D, L)`, consistent like `D` (the
    /// minimum of a consistent heuristic and a constant is), and fixed from then on
    /// (queries before settled their nodes, whose `D` never changes).
    pub fn set_deadline(&self, deadline: Option<Instant>) {
        self.search.borrow_mut().deadline = deadline;
    }

    /// Whether the deadline stopped the search (see [`CostToGo::set_deadline`]).
    pub fn frozen(&self) -> bool {
        self.search.borrow().frozen.is_some()
    }

    /// Whether the search has one layer per orientation (else: one for all).
    pub fn oriented(&self) -> bool {
        self.layers > 1
    }

    /// Nodes settled so far (for reports).
    pub fn settled(&self) -> usize {
        self.search.borrow().settled
    }

    /// `P` of a node (computed on first use): the driving pose cost at that orientation
    /// (with one layer: the smallest over all orientations), raised to 1, less the cache
    /// slack; +∞ if not finite.
    fn pose_bound(&self, search: &mut Search, maps: &CostMaps, node: usize) -> f64 {
        let v = search.pose[node];
        if v != 0.0 {
            return f64::from(v);
        }
        let nx = usize::from(self.lattice.nx);
        let cell = node / self.layers;
        let (i, j) = ((cell % nx) as i16, (cell / nx) as i16);
        let thetas = if self.layers > 1 {
            let t = (node % self.layers) as u16;
            t..t + 1
        } else {
            0..self.lattice.orientations
        };
        let mut best = f64::INFINITY;
        for theta in thetas {
            let pose = self.lattice.pose(LatticeState::new(i, j, theta as u8));
            let sc = self.trig[usize::from(theta)];
            if let Some(cost) = maps.driving_pose_cost_sc(&pose, sc).finite() {
                best = best.min(cost.max(1.0));
            }
        }
        // Rounded toward zero by the slack, then to f32 (within 6·10⁻⁸ of it): below
        // whatever the driving graph's f32 cache holds for the pose.
        let stored =
            if best.is_finite() { (best * (1.0 - POSE_SLACK)) as f32 } else { f32::INFINITY };
        search.pose[node] = stored;
        f64::from(stored)
    }

    /// Resumes the Dijkstra until node `target` is settled or the queue is empty.
    fn run_until(&self, search: &mut Search, maps: &CostMaps, target: usize) {
        let (nx, ny) = (i32::from(self.lattice.nx), i32::from(self.lattice.ny));
        let layers = self.layers;
        let node_of = |a: i32, b: i32, t: usize| (b * nx + a) as usize * layers + t;
        while let Some(c) = search.queue.pop() {
            let c = c as usize;
            // Stale entries (the node was settled, or queued again lower): skip.
            if search.done[c] || !search.queue.holds(search.dist[c]) {
                continue;
            }
            let d = search.dist[c];
            search.done[c] = true;
            search.settled += 1;
            if search.settled.is_multiple_of(1024)
                && search.deadline.is_some_and(|t| Instant::now() >= t)
            {
                search.frozen = Some(search.queue.floor());
            }
            let (cell, t) = (c / layers, c % layers);
            let (ci, cj) = ((cell % nx as usize) as i32, (cell / nx as usize) as i32);
            // Base shifts into c: from c minus a link of its layer.
            for &(di, dj) in &self.shift_links[t] {
                let (a, b) = (ci - di, cj - dj);
                if a >= 0 && b >= 0 && a < nx && b < ny {
                    Self::relax(search, node_of(a, b, t), d.saturating_add(self.shift_step));
                }
            }
            let pc = self.pose_bound(search, maps, c);
            if !pc.is_finite() {
                continue;
            }
            // Drives into c: from a = c − m for every move m, same orientation.
            let row = t * self.moves.len();
            for (k, &(di, dj)) in self.moves.iter().enumerate() {
                let (a, b) = (ci - di, cj - dj);
                if a < 0 || b < 0 || a >= nx || b >= ny {
                    continue;
                }
                let n = node_of(a, b, t);
                if search.done[n] {
                    continue;
                }
                let pa = self.pose_bound(search, maps, n);
                if pa.is_finite() {
                    let w = self.move_weight[row + k] * 0.5 * (pa + pc);
                    let w = Cost::from_f64_floor(w * (1.0 - WEIGHT_SLACK));
                    Self::relax(search, n, d.saturating_add(w));
                }
            }
            // Turns on the spot into c: from the neighbouring orientations.
            if layers > 1 {
                for t2 in [(t + 1) % layers, (t + layers - 1) % layers] {
                    let n = cell * layers + t2;
                    if search.done[n] {
                        continue;
                    }
                    let pa = self.pose_bound(search, maps, n);
                    if pa.is_finite() {
                        let w = self.turn_length * 0.5 * (pa + pc);
                        let w = Cost::from_f64_floor(w * (1.0 - WEIGHT_SLACK));
                        Self::relax(search, n, d.saturating_add(w));
                    }
                }
            }
            if c == target || search.frozen.is_some() {
                return;
            }
        }
    }

    #[inline]
    fn relax(search: &mut Search, n: usize, d: Cost) {
        if !search.done[n] && d < search.dist[n] {
            search.dist[n] = d;
            search.queue.push(d, n as u32);
        }
    }
}

/// All eight neighbour steps (one layer for every heading).
fn all_links() -> Vec<(i32, i32)> {
    let mut v = Vec::with_capacity(8);
    for dj in -1..=1 {
        for di in -1..=1 {
            if (di, dj) != (0, 0) {
                v.push((di, dj));
            }
        }
    }
    v
}

/// The cell steps of a base shift along `heading`: the cell of the exact position after
/// k cell-lengths is `⌊1/2 + k · cos θ⌋` cells along x from the start (likewise y), so
/// from one k to the next each axis steps by 0 or by the sign of its direction cosine
/// (either sign where the cosine is within 10⁻⁹ of zero, against float noise).
fn forward_links(heading: f64) -> Vec<(i32, i32)> {
    let axis = |c: f64| -> Vec<i32> {
        if c.abs() < 1e-9 {
            vec![-1, 0, 1]
        } else if c > 0.0 {
            vec![0, 1]
        } else {
            vec![0, -1]
        }
    };
    let (xs, ys) = (axis(heading.cos()), axis(heading.sin()));
    let mut v = Vec::new();
    for &dj in &ys {
        for &di in &xs {
            if (di, dj) != (0, 0) {
                v.push((di, dj));
            }
        }
    }
    v
}

/// The smallest edge weight of the relaxed graph, at least one micro-unit: pose costs
/// are at least 1 (less the slacks), so a drive weighs at least its `L · k_Δθ` and a turn
/// its wheel travel.
fn min_weight(lattice: &Lattice, move_weight: &[f64], turn_length: f64, shift_step: Cost) -> Cost {
    let drive = move_weight.iter().copied().fold(f64::INFINITY, f64::min);
    let turn = if turn_length > 0.0 { turn_length } else { f64::INFINITY };
    let w = Cost::from_f64_floor(drive.min(turn).min(lattice.resolution) * (1.0 - 1e-3));
    w.min(shift_step).max(Cost(1))
}

/// Dial's bucket queue: bucket k holds the nodes queued with a distance in
/// `[k · width, (k + 1) · width)`. With `width` at most the smallest edge weight, a node
/// relaxed from bucket k lands in a later bucket, so every node of the current bucket is
/// final when it is taken, in any order: the distances are exactly Dijkstra's (and the
/// same on every run). Cheaper than a binary heap of millions of entries.
#[derive(Debug)]
struct Buckets {
    width: u64,
    /// Indexed by absolute bucket number; emptied buckets keep their allocation.
    buckets: Vec<Vec<u32>>,
    /// The bucket being taken from.
    current: usize,
    len: usize,
}

impl Buckets {
    fn new(width: Cost) -> Self {
        Self { width: width.0.max(1), buckets: Vec::new(), current: 0, len: 0 }
    }

    fn bucket(&self, d: Cost) -> usize {
        usize::try_from(d.0 / self.width).unwrap_or(usize::MAX)
    }

    fn push(&mut self, d: Cost, node: u32) {
        let b = self.bucket(d);
        if b == usize::MAX {
            return;
        }
        if b >= self.buckets.len() {
            self.buckets.resize_with(b + 1, Vec::new);
        }
        self.buckets[b].push(node);
        self.len += 1;
    }

    /// A lower bound on the distance of every node not yet taken: the current bucket's
    /// lower edge.
    fn floor(&self) -> Cost {
        Cost((self.current as u64).saturating_mul(self.width))
    }

    /// Whether a node queued at distance `d` belongs to the bucket being taken (else
    /// its entry is stale).
    fn holds(&self, d: Cost) -> bool {
        self.bucket(d) == self.current
    }

    fn pop(&mut self) -> Option<u32> {
        while self.len > 0 {
            if let Some(n) = self.buckets.get_mut(self.current).and_then(Vec::pop) {
                self.len -= 1;
                return Some(n);
            }
            self.current += 1;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::locomotion::lattice::Neighbourhood;
    use crate::params::Params;
    use crate::robot::RobotDescription;
    use crate::scenario::Primitive;
    use crate::terrain::rasterise;

    fn setup() -> (CostMaps, Lattice, DrivingConfig) {
        let robot = RobotDescription::reference();
        let prims = [
            Primitive::Box { center: [1.8, 0.0], size: [2.0, 2.0], height: 0.2, yaw_deg: 0.0 },
            Primitive::Box { center: [0.5, 0.5], size: [0.2, 0.2], height: 0.1, yaw_deg: 20.0 },
        ];
        let m = rasterise(&prims, [-0.8, -0.8], [3.2, 1.6], 0.025).expect("map");
        let maps = CostMaps::build(&m, &robot, &Params::default()).expect("maps");
        let lattice = Lattice::for_map(maps.heights(), 64).expect("lattice");
        let driving =
            DrivingConfig::new(&Params::default(), &robot.neutral_footprint(), Neighbourhood::N16);
        (maps, lattice, driving)
    }

    const GOAL: (i16, i16, Option<u8>) = (100, 32, Some(0));

    #[test]
    fn one_layer_is_below_every_orientation() {
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let oriented = CostToGo::new(lattice, &driving, step, GOAL, usize::MAX);
        let flat = CostToGo::new(lattice, &driving, step, GOAL, 0);
        assert!(oriented.oriented() && !flat.oriented());
        for (i, j) in [(10, 32), (40, 20), (60, 50), (99, 32), (120, 10)] {
            let one = flat.get(&maps, i, j, 0);
            let best = (0..64).map(|t| oriented.get(&maps, i, j, t)).min().expect("64");
            assert!(one <= best, "({i}, {j}): {one} > {best}");
        }
        assert_eq!(oriented.get(&maps, GOAL.0, GOAL.1, 0), Cost::ZERO);
        assert_eq!(flat.get(&maps, GOAL.0, GOAL.1, 17), Cost::ZERO);
    }

    #[test]
    fn a_past_deadline_freezes_at_a_lower_bound() {
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let exact = CostToGo::new(lattice, &driving, step, GOAL, usize::MAX);
        let frozen = CostToGo::new(lattice, &driving, step, GOAL, usize::MAX);
        frozen.set_deadline(Some(Instant::now()));
        let far = frozen.get(&maps, 2, 2, 40);
        assert!(frozen.frozen());
        assert!(far <= exact.get(&maps, 2, 2, 40), "{far}");
        // Fixed from then on, and below D everywhere.
        assert_eq!(frozen.get(&maps, 2, 2, 40), far);
        for (i, j, t) in [(10, 32, 0), (90, 32, 0), (99, 33, 1), (30, 5, 63)] {
            assert!(frozen.get(&maps, i, j, t) <= exact.get(&maps, i, j, t));
        }
    }
}
