//! The base-pose cost-to-go: the hybrid heuristic's informed lower bound on the driving,
//! turning and base-shift costs still to come ([`crate::planner::HybridGraph`], issue 15). A
//! backward shortest-path search from the goal (an A* aimed at the start, see "Aim"; its
//! distances are Dijkstra's) over (cell, orientation) nodes of the lattice — the
//! nodes `reachability` floods, with costs — in which every edge weighs at most what the
//! manoeuvre of the hybrid graph it stands for costs, whatever the footprint: an exact
//! relaxation, so the distance `D` it computes is consistent on every edge of the hybrid
//! graph. `HybridGraph::heuristic` takes `max(Euclidean + turn, D)` and adds the step
//! bound and the foot-offset potential of `heuristic`.
//!
//! **Which edges move the base.** Of the hybrid graph's manoeuvres (`planner::graph` and
//! the units of `motion::manoeuvres`) drives, turns on the spot and base shifts change the
//! base pose. Abstract steps, "front foot forward" and "foot to neutral" leave it where it
//! is, so `D` is the same at both ends of those edges and `D(s) ≤ c(s, t) + D(t)` holds for
//! any cost `c ≥ 0` (their costs are what the step bound and the foot-offset potential
//! bound).
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
//! holding that point (`motion::manoeuvres::base_shift`). The cell of the exact position after k
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
//! rise, and edges that keep the base pose need none; so the shortest distance's
//! `D(s) ≤ w(path) + D(t)` gives `D(s) + Φ(s) ≤ c(s, t) + D(t) + Φ(t)` on every edge
//! that moves the base (Φ is zero on drives and turns: neutral footprint). In fixed
//! point: relaxed weights are rounded down (with a relative slack of 10⁻⁹), edges up,
//! and `D` sums integers, so the inequalities hold exactly.
//!
//! **Orientation groups.** The nodes need not be one per orientation: with `G` groups
//! of `n / G` consecutive orientations (centred on every `n / G`-th; `G` =
//! `HybridConfig::cost_to_go_groups`, one group where `G` does not divide `n` or the
//! nodes would exceed [`MAX_ORIENTED_NODES`]), a node stands for a cell and a group, and
//! every fine edge maps onto a relaxed one no heavier: `P` is the minimum over the
//! group's orientations, a drive's `L · k_Δθ` the minimum over them, a base shift's
//! links the union of their forward links, and a turn costs one orientation step's
//! wheel travel between neighbouring groups (`r_turn · 2π/n · (P + P′) / 2`, the fine
//! turn that crosses the border) and nothing within a group. So `D` is still a distance
//! in a relaxation of the hybrid graph, and every argument above holds for it: coarser
//! groups give a lower `D`, never an inconsistent one. With one group there are no turn
//! edges (the hybrid graph adds the driving heuristic's turn term, consistent on its own,
//! instead), and the links are all eight neighbours. What `G` buys is search work: a
//! Dijkstra's first query settles every node nearer the goal than the start, about the
//! whole floor of a course times `G` (the platform: 1.03 M nodes at `G` = 64), and a
//! `P` is a handful of look-ups ([`CostMaps::driving_stencil`]), so the nodes are the
//! cost (see [`ORIENTATION_GROUPS`] for the measured choice).
//!
//! **Laziness.** Like the obstacle heuristic of Nav2's Smac planner, the search runs
//! only as far as the queries need: a query for a node not yet final resumes the queue
//! until that node is, and `P` is computed per node when the search first touches it.
//! The tables (and with them this search) are shared by the graphs of a job
//! (`HeuristicCache`), so every ARA* iteration and every replan to the same goal reuses
//! what earlier ones settled. The nodes' records keep distances below [`MAX_DIST`]; a
//! search that would go past it answers `min(D, MAX_DIST)` instead, consistent like a
//! deadline's frozen bound ([`CostToGo::set_deadline`]).
//!
//! **Aim** (issue 67). A Dijkstra from the goal settles every node nearer the goal than
//! the first query, the start: on open ground a disc around the goal at every heading,
//! however straight the drive (a 2 m drive on flat ground settled 1.14 M nodes for 52
//! expansions). So the search is an A* aimed at the first query's node `a`: a node's key
//! is `D(n) + H(n)`, with `H(n)` a lower bound on the relaxed graph's distance from `a`
//! to `n` ([`CostToGo::aim_bound`]): the octagonal norm `max(|Δi|, |Δj|, (|Δi| + |Δj|) /
//! √2)` of the cells between them (at most the straight line, within 8 %, and a norm,
//! without a square root per edge) times the least cost per metre of base travel (a
//! drive's `L · k_Δθ` over its length with `P ≥ 1`, a base shift's `β · res` over its
//! longest link), plus the orientation groups between them times a turn's least cost,
//! all less [`AIM_SLACK`]. Every edge changes either the position (drives, base shifts)
//! or the group (turns), and changes `H` by at most its weight: `H` is consistent, so
//! keys never decrease along the search and a node whose key is below every key still
//! queued has its distance for good. Later queries resume the same search (its order
//! is still keys, so every node it finalises is exact): `D` is the same function as
//! the Dijkstra's, bit for bit, and so are the plans. The queue is a bucket queue
//! (Dial's; FIFO within a bucket): keys within a bucket are taken in any order, so a
//! node may be expanded before a cheaper way to it in the same bucket is found and is
//! then reopened (under 1 % of the expansions on the repository's courses); a node is
//! final only once its key's bucket is behind the queue. Measured (issue 67's note):
//! `flat`'s first path settles 123 k nodes instead of 1.14 M, generated `headings`
//! courses 10–40 times fewer; where the pose costs are far above 1 per metre (clutter,
//! the platform) the bound is weak and the count nearly the Dijkstra's.

use crate::cost::{CostMaps, DrivingStencil};
use crate::planner::driving::DrivingConfig;
use crate::planner::lattice::{Lattice, LatticeState};
use crate::search::Cost;
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// Queue entries a query takes between looks at the clock (see
/// [`CostToGo::set_deadline`]).
const SLICE: usize = 1024;
/// Relative slack on `P` for the driving graph's `f32` pose-cost cache.
const POSE_SLACK: f64 = 1e-6;
/// Relative slack on relaxed edge weights (edges are rounded up with 10⁻¹²).
const WEIGHT_SLACK: f64 = 1e-9;
/// Relative slack of the aim bound below the least weights it is made of: far more than
/// their own slacks and the micro-unit roundings of the shortest edge (a 2.5 cm drive
/// weighs 25,000 micro-units; 10⁻³ of it is 25), so that it stays consistent in fixed
/// point.
const AIM_SLACK: f64 = 1e-3;
/// 1/√2 in 16-bit fixed point, rounded down (46340.95).
const FRAC_1_SQRT_2_Q16: u64 = 46_340;
/// Default for the most (cell, group) nodes searched with more than one orientation
/// group (8 bytes each: 64 MB at the limit, a 9 m × 9 m map with 64 groups); larger
/// maps get one group, the minimum over all orientations.
pub const MAX_ORIENTED_NODES: usize = 1 << 23;
/// Default orientation groups of the cost-to-go (see the module docs): one per
/// orientation. Coarser groups settle faster but guide ARA*'s schedule worse: the
/// platform's first solution at ε = 3 took 19,971 expansions (0.71 s) with 64 groups,
/// 133,435 (1.18 s) with 16 and 232,488 (1.71 s) with 8, its cost after 10 s 78.5
/// against 101.2. As the greedy probe's heuristic alone, 8 groups brought the platform's
/// first path from 261 to 69 ms and halved the median over 54 generated courses (0.92 →
/// 0.48 s), but made the mixed courses' slower (median 2.2 → 3.4 s) and one flight in
/// six 1.4–3 times slower, its path up to twice as costly: not taken.
pub const ORIENTATION_GROUPS: usize = 64;

/// The lazily computed backward search over base cells (see the module docs).
#[derive(Debug)]
pub struct CostToGo {
    lattice: Lattice,
    /// Orientation groups, one layer of nodes each (see the module docs).
    layers: usize,
    /// Orientations per group.
    group: usize,
    /// Drive moves `(di, dj)`.
    moves: Vec<(i32, i32)>,
    /// The most cells a move goes along either axis (2 for the paper's neighbourhoods).
    move_reach: i32,
    /// `L · k_Δθ` per (layer, move), row-major by layer: the least of the driving graph's
    /// move weights over the layer's orientations.
    move_weight: Vec<f64>,
    /// Wheel travel of one orientation step, m (turn edges between layers).
    turn_length: f64,
    /// Per layer: the cell steps a base shift's chain may take (see the module docs).
    shift_links: Vec<Vec<(i32, i32)>>,
    /// Weight of one link of a base shift, `β · res` rounded down.
    shift_step: Cost,
    /// `(sin, cos)` of each orientation's yaw, as `Pose2::theta.sin_cos()` gives them.
    trig: Vec<(f64, f64)>,
    /// The aim bound's weights ([`CostToGo::aim_bound`]), whole micro-units (rounded
    /// down): per cell of straight-line distance and per orientation group turned.
    aim_per_cell: u64,
    aim_per_layer: u64,
    search: RefCell<Search>,
    /// When the searches must stop growing (the plan's time limit).
    deadline: Cell<Option<Instant>>,
}

/// The resumable part of the search.
#[derive(Debug)]
struct Search {
    /// Per orientation, the cells its driving pose cost looks up (`None`: ask the float
    /// path); made at the first query, which brings the maps.
    stencils: Vec<Option<DrivingStencil>>,
    /// Per node (`layer · cells + cell`, cells row-major `j · nx + i`: a layer's cells
    /// lie together, as drive edges join them), its record: see [`NodeRecord`].
    nodes: Vec<u64>,
    queue: Buckets,
    /// Nodes settled so far (expanded at their current distance).
    settled: usize,
    /// The node the search is aimed at, `(i, j, layer)`: the first query's (`None`
    /// before it, when nothing is queued yet).
    aim: Option<(i32, i32, usize)>,
    /// The goal's nodes, queued when the first query sets the aim.
    roots: Vec<usize>,
    /// Set when the deadline passed: a lower bound on `D` of every unsettled node.
    frozen: Option<Cost>,
    /// Distances from this on are not kept ([`MAX_DIST`]; lower in tests).
    cap: Cost,
    /// Whether a relaxation reached `cap` (see [`CostToGo::relax`]).
    capped: bool,
}

impl CostToGo {
    /// The cost-to-go on `lattice` toward `goal` (cell, and orientation if it is fixed),
    /// with the driving moves, k_Δθ and turn length of `driving` and `shift_step`, the
    /// weight β · res of one link of a base shift (see the module docs); `layers`
    /// orientation groups (a divisor of the lattice's orientations, else one group), or
    /// one if that would make more than `max_nodes` nodes. Nothing is computed until the
    /// first query.
    pub fn new(
        lattice: Lattice,
        driving: &DrivingConfig,
        shift_step: Cost,
        goal: (i16, i16, Option<u8>),
        (layers, max_nodes): (usize, usize),
    ) -> Self {
        let cells = usize::from(lattice.nx) * usize::from(lattice.ny);
        let orientations = usize::from(lattice.orientations).max(1);
        let layers = if layers >= 1
            && orientations.is_multiple_of(layers)
            && cells.saturating_mul(layers) <= max_nodes
        {
            layers
        } else {
            1
        };
        let group = orientations / layers;
        let res = lattice.resolution;
        let all = driving.neighbourhood.moves();
        let moves: Vec<(i32, i32)> =
            all.iter().map(|m| (i32::from(m.di), i32::from(m.dj))).collect();
        let move_reach = moves.iter().map(|&(di, dj)| di.abs().max(dj.abs())).max().unwrap_or(0);
        let mut move_weight = Vec::with_capacity(layers * all.len());
        let mut shift_links = Vec::with_capacity(layers);
        for t in 0..layers {
            let headings: Vec<f64> =
                members(t, group, orientations).map(|k| lattice.yaw(k as u8)).collect();
            for m in &all {
                // As `DrivingGraph::new` computes it, so the weights agree bit for bit;
                // the least over the group's orientations.
                let k_theta = headings
                    .iter()
                    .map(|&h| driving.orientation.factor(m.direction - h))
                    .fold(f64::INFINITY, f64::min);
                move_weight.push(m.cells * res * k_theta);
            }
            let mut links: Vec<(i32, i32)> =
                headings.iter().flat_map(|&h| forward_links(h)).collect();
            links.sort_unstable();
            links.dedup();
            shift_links.push(links);
        }
        let turn_length =
            if layers > 1 { driving.turn_radius_m * lattice.orientation_step() } else { 0.0 };
        let shift_step = shift_step.max(Cost(1));
        let n = cells * layers;
        let (gi, gj, gt) = goal;
        let mut roots = Vec::new();
        if lattice.contains(i32::from(gi), i32::from(gj)) {
            let g = gj as usize * usize::from(lattice.nx) + gi as usize;
            let sources: Vec<usize> = match gt {
                Some(t) => vec![layer_of(usize::from(t), group, layers)],
                None => (0..layers).collect(),
            };
            roots = sources.into_iter().map(|t| t * cells + g).collect();
        }
        let width = min_weight(&lattice, &move_weight, turn_length, shift_step);
        let search = Search::new(n, Buckets::new(width), &roots);
        let (aim_per_cell, aim_per_layer) =
            aim_weights((&moves, &move_weight), (&shift_links, shift_step), turn_length, res);
        Self {
            lattice,
            layers,
            group,
            moves,
            move_reach,
            move_weight,
            turn_length,
            shift_links,
            shift_step,
            trig: (0..lattice.orientations).map(|k| lattice.yaw(k as u8).sin_cos()).collect(),
            aim_per_cell,
            aim_per_layer,
            search: RefCell::new(search),
            deadline: Cell::new(None),
        }
    }

    /// `D` of a state at cell (i, j) with orientation `theta`: a lower bound on the
    /// driving, turning and base-shift costs from it to the goal. Zero off the lattice
    /// (no bound). The first query aims the search (see "Aim" in the module docs).
    pub fn get(&self, maps: &CostMaps, i: i16, j: i16, theta: u8) -> Cost {
        if !self.lattice.contains(i32::from(i), i32::from(j)) {
            return Cost::ZERO;
        }
        let cell = j as usize * usize::from(self.lattice.nx) + i as usize;
        let layer = layer_of(usize::from(theta), self.group, self.layers);
        let node = layer * self.cells() + cell;
        let at = (i32::from(i), i32::from(j), layer);
        let mut search = self.search.borrow_mut();
        let aim = match search.aim {
            Some(aim) => aim,
            None => self.start(&mut search, at),
        };
        let h = self.aim_bound(aim, at);
        loop {
            if search.is_final(node, h) {
                return search.nodes[node].dist();
            }
            if !search.open() {
                break;
            }
            if self.deadline.get().is_some_and(|t| Instant::now() >= t) {
                search.freeze();
                break;
            }
            self.run_until(&mut search, maps, (node, h), SLICE);
        }
        match search.frozen {
            // Every node keyed below the floor is final, so this one's key `D + H` is
            // at least the floor: `min(D, floor − H)`, consistent (see the module docs).
            Some(floor) => floor.saturating_sub(h),
            // The queue ran empty: past the distances a record keeps (`min(D,
            // MAX_DIST)`, consistent like the frozen bound), or no path at all.
            None if search.capped => search.cap,
            None => Cost::INFINITY,
        }
    }

    /// Aims the search at node `aim` (the first query's) and queues the goal's nodes;
    /// returns the aim.
    fn start(&self, search: &mut Search, aim: (i32, i32, usize)) -> (i32, i32, usize) {
        search.aim = Some(aim);
        for r in std::mem::take(&mut search.roots) {
            search.queue.push(self.aim_bound(aim, self.coords(r)), r as u32);
        }
        aim
    }

    /// Cell (i, j) and layer of node `node`.
    fn coords(&self, node: usize) -> (i32, i32, usize) {
        let (nx, cells) = (usize::from(self.lattice.nx), self.cells());
        let cell = node % cells;
        ((cell % nx) as i32, (cell / nx) as i32, node / cells)
    }

    /// `H`, the aim bound: a lower bound on the relaxed graph's distance between node
    /// `at` and the aim, `(i, j, layer)` (see "Aim" in the module docs), in micro-units,
    /// rounded down: the straight line between the cells times the least cost a metre
    /// of base travel takes, plus the orientation groups between them times a turn's
    /// least cost. Consistent: no edge changes it by more than its weight.
    #[inline(always)]
    fn aim_bound(&self, aim: (i32, i32, usize), at: (i32, i32, usize)) -> Cost {
        Cost(self.aim_turns(aim.2, at.2) + self.aim_cells(aim, at.0, at.1))
    }

    /// The aim bound's turn part: the orientation groups between `layer` and the aim's
    /// `aim_layer`, the short way round, at a turn's least cost.
    #[inline(always)]
    fn aim_turns(&self, aim_layer: usize, layer: usize) -> u64 {
        let dt = layer.abs_diff(aim_layer);
        dt.min(self.layers - dt) as u64 * self.aim_per_layer
    }

    /// The aim bound's position part: the octagonal norm `max(|Δi|, |Δj|, (|Δi| + |Δj|)
    /// / √2)` of the cells from the aim to (a, b) (within 8 % below the straight line and
    /// a norm itself, so consistent) at the least cost per cell, in 16-bit fixed point
    /// rounded down: integer operations only, as it runs for every queued node.
    #[inline(always)]
    fn aim_cells(&self, aim: (i32, i32, usize), a: i32, b: i32) -> u64 {
        let (di, dj) =
            (u64::from((a - aim.0).unsigned_abs()), u64::from((b - aim.1).unsigned_abs()));
        let norm = (di.max(dj) << 16).max((di + dj) * FRAC_1_SQRT_2_Q16);
        (norm * self.aim_per_cell) >> 16
    }

    /// Stops growing the search once `deadline` has passed (checked every 1024 queue
    /// entries, [`SLICE`]), so a plan's time limit holds however far the first queries reach. From
    /// then on an unsettled node gets the frontier's distance `L` instead of `D`: every
    /// unsettled node has `D ≥ L`, so this is `min(D, L)`, consistent like `D` (the
    /// minimum of a consistent heuristic and a constant is), and fixed from then on
    /// (queries before settled their nodes, whose `D` never changes).
    pub fn set_deadline(&self, deadline: Option<Instant>) {
        self.deadline.set(deadline);
    }

    /// Lets a search the deadline stopped grow again (its queue is kept): for a new
    /// search on the same tables, whose queries then get `D` itself until its own
    /// deadline. Never within one search: a node's bound must not change under it.
    pub fn thaw(&self) {
        self.search.borrow_mut().frozen = None;
    }

    /// Whether the deadline stopped the search (see [`CostToGo::set_deadline`]).
    pub fn frozen(&self) -> bool {
        self.search.borrow().frozen.is_some()
    }

    /// Whether the search has more than one orientation group (else: one for all, and no
    /// turn edges).
    pub fn oriented(&self) -> bool {
        self.layers > 1
    }

    /// Nodes settled so far (for reports).
    pub fn settled(&self) -> usize {
        self.search.borrow().settled
    }

    /// `P` of a node (computed on first use): the smallest driving pose cost over its
    /// orientation group, raised to 1, less the cache slack; +∞ if none is finite.
    #[inline]
    fn pose_bound(&self, search: &mut Search, maps: &CostMaps, node: usize) -> f64 {
        if let Some(v) = search.nodes[node].pose() {
            return f64::from(v);
        }
        self.compute_pose_bound(search, maps, node)
    }

    /// [`Self::pose_bound`] of a node not yet computed.
    #[inline(never)]
    fn compute_pose_bound(&self, search: &mut Search, maps: &CostMaps, node: usize) -> f64 {
        let (i, j, layer) = self.coords(node);
        let (i, j) = (i as usize, j as usize);
        let orientations = usize::from(self.lattice.orientations).max(1);
        let mut best = f64::INFINITY;
        for theta in members(layer, self.group, orientations) {
            let cost = match &search.stencils[theta] {
                Some(stencil) => maps.driving_pose_cost_at(i, j, stencil),
                None => {
                    let pose =
                        self.lattice.pose(LatticeState::new(i as i16, j as i16, theta as u8));
                    maps.driving_pose_cost_sc(&pose, self.trig[theta])
                }
            };
            if let Some(cost) = cost.finite() {
                best = best.min(cost.max(1.0));
            }
        }
        // Rounded toward zero by the slack, then to f32 (within 6·10⁻⁸ of it): below
        // whatever the driving graph's f32 cache holds for the pose.
        let stored =
            if best.is_finite() { (best * (1.0 - POSE_SLACK)) as f32 } else { f32::INFINITY };
        search.nodes[node].set_pose(stored);
        f64::from(stored)
    }

    /// Cells of the lattice (nodes per layer).
    fn cells(&self) -> usize {
        usize::from(self.lattice.nx) * usize::from(self.lattice.ny)
    }

    /// Resumes the search for at most `budget` queue entries, until node `target` (with
    /// aim bound `target_h`) is final or the queue is empty.
    fn run_until(
        &self,
        search: &mut Search,
        maps: &CostMaps,
        (target, target_h): (usize, Cost),
        budget: usize,
    ) {
        if search.stencils.is_empty() {
            search.stencils = (0..self.lattice.orientations)
                .map(|k| maps.driving_stencil(self.lattice.yaw(k as u8)))
                .collect();
        }
        let Some(aim) = search.aim else { return };
        let (nx, ny) = (i32::from(self.lattice.nx), i32::from(self.lattice.ny));
        let (layers, cells) = (self.layers, self.cells());
        for _ in 0..budget {
            if search.is_final(target, target_h) {
                return;
            }
            // The next entry; stale ones (the node was expanded since, at this distance
            // or a lower one: a lower key never lies in a later bucket) are skipped.
            let Some(c) = search.queue.pop() else { return };
            if let Some(f) = search.queue.ahead(PREFETCH_AHEAD) {
                prefetch_neighbourhood(&search.nodes, f as usize, nx as usize, cells);
            }
            let c = c as usize;
            if search.nodes[c].done() {
                continue;
            }
            let d = search.nodes[c].dist();
            search.nodes[c].set_done();
            search.settled += 1;
            let (t, cell) = (c / cells, c % cells);
            let layer = t * cells;
            let (ci, cj) = ((cell % nx as usize) as i32, (cell / nx as usize) as i32);
            let node_at = |a: i32, b: i32| layer + (b * nx + a) as usize;
            // The aim bound's turn part of c's layer, which drives and shifts keep.
            let turns = self.aim_turns(aim.2, t);
            // Base shifts into c: from c minus a link of its layer.
            for &(di, dj) in &self.shift_links[t] {
                let (a, b) = (ci - di, cj - dj);
                if a >= 0 && b >= 0 && a < nx && b < ny {
                    let w = d.saturating_add(self.shift_step);
                    self.relax(search, aim, node_at(a, b), w, (a, b), turns);
                }
            }
            let pc = self.pose_bound(search, maps, c);
            if !pc.is_finite() {
                continue;
            }
            // Drives into c: from a = c − m for every move m, same orientation.
            let row = t * self.moves.len();
            let weights = &self.move_weight[row..row + self.moves.len()];
            // A node as far inside the map as a move reaches needs no test per move
            // (nearly all of them; a predictable branch).
            let r = self.move_reach;
            let inside = ci >= r && cj >= r && ci + r < nx && cj + r < ny;
            for (&(di, dj), &length) in self.moves.iter().zip(weights) {
                let (a, b) = (ci - di, cj - dj);
                if !inside && (a < 0 || b < 0 || a >= nx || b >= ny) {
                    continue;
                }
                // A settled neighbour needs no test of its own: `relax` leaves it
                // unless d + w is lower (the test was an unpredictable branch per
                // edge; the cold search 5 % sooner without it).
                let n = node_at(a, b);
                let pa = self.pose_bound(search, maps, n);
                if pa.is_finite() {
                    let w = relaxed_weight(length, pa, pc);
                    self.relax(search, aim, n, d.saturating_add(w), (a, b), turns);
                }
            }
            // Turns on the spot into c: from the neighbouring orientations.
            if layers > 1 {
                for t2 in [(t + 1) % layers, (t + layers - 1) % layers] {
                    let n = t2 * cells + cell;
                    let pa = self.pose_bound(search, maps, n);
                    if pa.is_finite() {
                        let w = relaxed_weight(self.turn_length, pa, pc);
                        let turns = self.aim_turns(aim.2, t2);
                        self.relax(search, aim, n, d.saturating_add(w), (ci, cj), turns);
                    }
                }
            }
        }
    }

    /// Lowers node `n`'s (at cell (a, b), `turns` the aim bound's turn part of its
    /// layer, toward `aim`) tentative distance to `d` and queues it under its key `d + H`, if `d` is
    /// lower. A node expanded within the bucket being taken may be
    /// lowered so (the keys of a bucket are taken in any order) and is reopened; one
    /// final never is. A `d` from [`MAX_DIST`] on is not kept but marks the search
    /// capped: once its queue runs empty, every node it did not settle lies at least
    /// `MAX_DIST` away (or has no path), and gets that bound (see [`Self::get`]).
    #[inline(always)]
    fn relax(
        &self,
        search: &mut Search,
        aim: (i32, i32, usize),
        n: usize,
        d: Cost,
        (a, b): (i32, i32),
        turns: u64,
    ) {
        let record = &mut search.nodes[n];
        if d < record.dist() {
            if d >= search.cap {
                search.capped = true;
                return;
            }
            if record.done() {
                record.clear_done();
                search.settled -= 1;
            }
            record.set_dist(d);
            let key = d.saturating_add(Cost(turns + self.aim_cells(aim, a, b)));
            search.queue.push(key, n as u32);
        }
    }
}

/// The aim bound's weights (see "Aim" in the module docs), micro-units per cell of
/// straight-line distance and per orientation group turned: the least cost per metre
/// of the drives (`L · k_Δθ` over the move's length, `P ≥ 1`) and of the base shifts'
/// links (`β · res` over the longest link), and a turn's wheel travel (`P ≥ 1`), all
/// less [`AIM_SLACK`] for the slacks and roundings of the edge weights.
fn aim_weights(
    (moves, move_weight): (&[(i32, i32)], &[f64]),
    (shift_links, shift_step): (&[Vec<(i32, i32)>], Cost),
    turn_length: f64,
    res: f64,
) -> (u64, u64) {
    let length = |&(di, dj): &(i32, i32)| f64::from(di).hypot(f64::from(dj)) * res;
    let mut per_m = 1.0f64;
    for (k, w) in move_weight.iter().enumerate() {
        per_m = per_m.min(w / length(&moves[k % moves.len()]));
    }
    if !shift_step.is_infinite() {
        let longest = shift_links.iter().flatten().map(length).fold(0.0, f64::max);
        if longest > 0.0 {
            per_m = per_m.min(shift_step.to_f64() / longest);
        }
    }
    let scale = (1.0 - AIM_SLACK) * Cost::SCALE as f64;
    ((per_m * res * scale) as u64, (turn_length * scale) as u64)
}

impl Search {
    /// A search with `roots` at distance 0, queued when it is aimed
    /// ([`CostToGo::start`]).
    fn new(n: usize, queue: Buckets, roots: &[usize]) -> Self {
        let mut nodes = vec![0u64; n];
        for &r in roots {
            nodes[r].set_dist(Cost::ZERO);
        }
        Self {
            stencils: Vec::new(),
            nodes,
            queue,
            settled: 0,
            aim: None,
            roots: roots.to_vec(),
            frozen: None,
            cap: MAX_DIST,
            capped: false,
        }
    }

    /// Stops the search: every node not final has a key at least the current bucket's
    /// lower edge.
    fn freeze(&mut self) {
        if self.frozen.is_none() {
            self.queue.advance();
            self.frozen = Some(self.queue.floor());
        }
    }

    /// Whether node `n` (aim bound `h`) has its distance for good: expanded, and its key
    /// below every key still queued (the buckets before the first non-empty one are
    /// done, and a key never drops below the bucket it was relaxed from).
    #[inline]
    fn is_final(&mut self, n: usize, h: Cost) -> bool {
        let record = self.nodes[n];
        if !record.done() {
            return false;
        }
        let floor = match self.frozen {
            Some(floor) => floor,
            None if !self.queue.advance() => return true,
            None => self.queue.floor(),
        };
        record.dist().saturating_add(h) < floor
    }

    /// Whether the search can go on: not frozen, and something queued.
    fn open(&self) -> bool {
        self.frozen.is_none() && self.queue.len > 0
    }
}

/// A node's search state in 8 bytes, eight to a cache line, so that the 20 drive
/// neighbours of a node (five rows of five cells of its layer) take one or two lines a
/// row (three arrays took three cache misses per touched node, 16-byte records two lines
/// a row: the records' loads are most of the search's time): bits 0–31 the tentative
/// distance plus one (0: none yet; distances from [`MAX_DIST`] on are not kept, see
/// [`CostToGo::relax`]), bits 32–62 `P` as `f32` bits (`P ≥ 1` or +∞ is positive, so its
/// sign bit is not kept; 0.0: not computed yet, never a value), bit 63 settled. All-zero
/// when untouched, so `vec![0u64; n]` is a zeroed allocation the system hands out
/// lazily: pages are touched only where the search goes.
trait NodeRecord {
    fn dist(self) -> Cost;
    /// Sets a distance below [`MAX_DIST`].
    fn set_dist(&mut self, d: Cost);
    fn pose(self) -> Option<f32>;
    /// Sets a `P` that is positive (sign bit clear), as every one is.
    fn set_pose(&mut self, p: f32);
    fn done(self) -> bool;
    fn set_done(&mut self);
    fn clear_done(&mut self);
}

/// The bits of a [`NodeRecord`]'s distance.
const DIST_FIELD: u64 = u32::MAX as u64;
/// Distances kept in a [`NodeRecord`] lie below this (4294.97 cost units: many times
/// any course's; a search that would go past it is capped there instead, its unsettled
/// nodes answered with this bound, see [`CostToGo::relax`]).
const MAX_DIST: Cost = Cost(u32::MAX as u64 - 1);
/// The bits of a [`NodeRecord`]'s `P`.
const POSE_FIELD: u64 = (u32::MAX as u64 >> 1) << 32;
/// Bit 63 of a [`NodeRecord`]: settled.
const DONE: u64 = 1 << 63;

impl NodeRecord for u64 {
    #[inline]
    fn dist(self) -> Cost {
        match self & DIST_FIELD {
            0 => Cost::INFINITY,
            v => Cost(v - 1),
        }
    }

    #[inline]
    fn set_dist(&mut self, d: Cost) {
        debug_assert!(d < MAX_DIST);
        *self = (*self & !DIST_FIELD) | (d.0 + 1);
    }

    #[inline]
    fn pose(self) -> Option<f32> {
        let v = f32::from_bits(((self & POSE_FIELD) >> 32) as u32);
        (v != 0.0).then_some(v)
    }

    #[inline]
    fn set_pose(&mut self, p: f32) {
        debug_assert!(p.is_sign_positive());
        *self = (*self & !POSE_FIELD) | ((u64::from(p.to_bits()) << 32) & POSE_FIELD);
    }

    #[inline]
    fn done(self) -> bool {
        self & DONE != 0
    }

    #[inline]
    fn set_done(&mut self) {
        *self |= DONE;
    }

    #[inline]
    fn clear_done(&mut self) {
        *self &= !DONE;
    }
}

/// Queue entries between the one being taken and the one whose records are prefetched.
const PREFETCH_AHEAD: usize = 8;

/// Asks the cache for the records node `f`'s edges will touch: its own, the rows of its
/// layer its drives reach (two cells either side, two rows up and down) and its
/// neighbouring layers' (turns). A hint only: no effect on any result.
#[inline]
fn prefetch_neighbourhood(nodes: &[u64], f: usize, nx: usize, cells: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let at = |k: usize| {
            if let Some(r) = nodes.get(k) {
                // SAFETY: a prefetch is a hint that never faults; SSE is baseline on x86-64.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(r).cast()) };
            }
        };
        // Off-the-array indices (rows above the first wrap around) are skipped by `at`.
        for r in [-2, -1, 0, 1, 2isize] {
            let row = f.wrapping_add_signed(r.wrapping_mul(nx as isize));
            at(row.wrapping_sub(2));
            at(row.wrapping_add(2));
        }
        at(f.wrapping_sub(cells));
        at(f.wrapping_add(cells));
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (nodes, f, nx, cells);
}

/// The relaxed weight of an edge `length` long between nodes of pose bounds `pa` and
/// `pc` (finite, at least 1 less the slacks): `length · (pa + pc) / 2` less the weight
/// slack, floored to the micro-unit. Every edge the search relaxes goes through here (20
/// drives a node), so the conversion is one signed cast: on a positive finite weight far
/// below 2⁶³ micro-units it is [`Cost::from_f64_floor`] without that function's tests
/// for NaN, sign and overflow, and without the unsigned cast's range fix-up, which took
/// a sixth of the search's instructions (the same value, bit for bit).
#[inline]
fn relaxed_weight(length: f64, pa: f64, pc: f64) -> Cost {
    let w = length * 0.5 * (pa + pc) * (1.0 - WEIGHT_SLACK);
    debug_assert!(w.is_finite() && w >= 0.0);
    let micro = w * Cost::SCALE as f64;
    debug_assert_eq!(Cost(micro as i64 as u64), Cost::from_f64_floor(w));
    Cost(micro as i64 as u64)
}

/// The group (layer) of orientation `k`: groups of `group` consecutive orientations,
/// centred on the multiples of `group` (orientation 0 is in the middle of group 0).
fn layer_of(k: usize, group: usize, layers: usize) -> usize {
    (k + group / 2) / group % layers
}

/// The orientations of group `t` (see [`layer_of`]), of `n` in all.
fn members(t: usize, group: usize, n: usize) -> impl Iterator<Item = usize> {
    (0..group).map(move |r| (t * group + n + r - group / 2) % n)
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

/// Dial's bucket queue: bucket k holds the nodes queued with a key in
/// `[k · width, (k + 1) · width)`, taken first in, first out. The keys of a consistent
/// A* never fall below the bucket being taken, so once the queue has moved past a
/// bucket every node keyed in it is final (see "Aim" in the module docs); within the
/// bucket, first in, first out reopens fewer nodes than last in, first out (on
/// `ramp_far` 0.5 % of the expansions against 15 %). Deterministic, and cheaper than a
/// binary heap of millions of entries. The width is a power of two (the largest not
/// above the lightest edge), so that a bucket is a shift, not a division per queued
/// node: splitting it further (2, 4 or 16 buckets to the edge) reopened almost nothing
/// but was no faster, in more buckets' allocations.
#[derive(Debug)]
struct Buckets {
    /// log₂ of the width.
    shift: u32,
    /// Indexed by absolute bucket number; emptied buckets keep their allocation.
    buckets: Vec<Vec<u32>>,
    /// The bucket being taken from.
    current: usize,
    /// The next entry of the current bucket (entries are taken first in, first out).
    head: usize,
    len: usize,
}

impl Buckets {
    fn new(width: Cost) -> Self {
        let shift = width.0.max(1).ilog2();
        Self { shift, buckets: Vec::new(), current: 0, head: 0, len: 0 }
    }

    #[inline]
    fn bucket(&self, d: Cost) -> usize {
        usize::try_from(d.0 >> self.shift).unwrap_or(usize::MAX)
    }

    fn push(&mut self, d: Cost, node: u32) {
        let b = self.bucket(d);
        if b == usize::MAX {
            return;
        }
        // A key below the bucket being taken (none, with a consistent aim bound) goes
        // into it, never behind it where no pop would find it.
        let b = b.max(self.current);
        if b >= self.buckets.len() {
            self.buckets.resize_with(b + 1, Vec::new);
        }
        self.buckets[b].push(node);
        self.len += 1;
    }

    /// A lower bound on the key of every entry not yet taken: the current bucket's
    /// lower edge.
    fn floor(&self) -> Cost {
        Cost((self.current as u64).saturating_mul(1 << self.shift))
    }

    /// Moves to the first bucket that holds an entry not yet taken; false if none does.
    fn advance(&mut self) -> bool {
        while self.len > 0 {
            if self.buckets.get(self.current).is_some_and(|b| self.head < b.len()) {
                return true;
            }
            if let Some(b) = self.buckets.get_mut(self.current) {
                b.clear();
            }
            self.current += 1;
            self.head = 0;
        }
        false
    }

    /// The entry `k` places after the next one in the current bucket, if it holds one
    /// (for prefetching the records it will touch).
    fn ahead(&self, k: usize) -> Option<u32> {
        self.buckets.get(self.current)?.get(self.head + k + 1).copied()
    }

    fn pop(&mut self) -> Option<u32> {
        if !self.advance() {
            return None;
        }
        let n = self.buckets[self.current][self.head];
        self.head += 1;
        self.len -= 1;
        Some(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::planner::lattice::Neighbourhood;
    use crate::robot::RobotDescription;
    use crate::scenario::Primitive;
    use crate::scenario::terrain::Block;
    use crate::terrain::rasterise;

    fn setup() -> (CostMaps, Lattice, DrivingConfig) {
        let robot = RobotDescription::reference();
        let prims = [
            Primitive::Box(Block {
                center: [1.8, 0.0],
                size: [2.0, 2.0],
                height: 0.2,
                yaw_deg: 0.0,
            }),
            Primitive::Box(Block {
                center: [0.5, 0.5],
                size: [0.2, 0.2],
                height: 0.1,
                yaw_deg: 20.0,
            }),
        ];
        let m = rasterise(&prims, [-0.8, -0.8], [3.2, 1.6], 0.025).expect("map");
        let maps = CostMaps::build(&m, &robot, &Params::default()).expect("maps");
        let lattice = Lattice::for_map(maps.heights(), 64).expect("lattice");
        let driving =
            DrivingConfig::new(&Params::default(), &robot.neutral_footprint(), Neighbourhood::N16);
        (maps, lattice, driving)
    }

    const GOAL: (i16, i16, Option<u8>) = (100, 32, Some(0));

    /// The cost-to-go of [`setup`]'s world toward [`GOAL`] with `groups` orientation
    /// groups and a base-shift link of 0.3.
    fn grouped(lattice: Lattice, driving: &DrivingConfig, groups: usize) -> CostToGo {
        CostToGo::new(lattice, driving, Cost::from_f64_floor(0.3), GOAL, (groups, usize::MAX))
    }

    #[test]
    fn a_node_record_keeps_its_three_fields_apart() {
        let mut r = 0u64;
        assert_eq!((r.dist(), r.pose(), r.done()), (Cost::INFINITY, None, false));
        r.set_pose(f32::INFINITY);
        r.set_dist(Cost(MAX_DIST.0 - 1));
        assert_eq!(
            (r.dist(), r.pose(), r.done()),
            (Cost(MAX_DIST.0 - 1), Some(f32::INFINITY), false)
        );
        // Every bit of a P is kept (the same f32, the last mantissa bit included).
        let p = f32::from_bits(1.5f32.to_bits() | 1);
        r.set_pose(p);
        assert_eq!(
            (r.dist(), r.pose().map(f32::to_bits)),
            (Cost(MAX_DIST.0 - 1), Some(p.to_bits()))
        );
        r.set_dist(Cost::ZERO);
        r.set_done();
        r.set_pose(1.25);
        assert_eq!((r.dist(), r.pose(), r.done()), (Cost::ZERO, Some(1.25), true));
    }

    #[test]
    fn coarser_groups_are_below_one_per_orientation() {
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let fine = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
        assert!(fine.oriented());
        let probes = [(10, 32), (40, 20), (60, 50), (99, 32), (120, 10)];
        let mut below = 0;
        for (groups, max_nodes) in [(16, usize::MAX), (8, usize::MAX), (2, usize::MAX), (64, 0)] {
            let coarse = CostToGo::new(lattice, &driving, step, GOAL, (groups, max_nodes));
            // Too many nodes, or one group asked for: one layer, no turn edges.
            assert_eq!(coarse.oriented(), max_nodes > 0);
            for (i, j) in probes {
                for t in (0..64).step_by(5) {
                    let (c, f) = (coarse.get(&maps, i, j, t), fine.get(&maps, i, j, t));
                    assert!(c <= f, "{groups} groups at ({i}, {j}, {t}): {c} > {f}");
                    below += usize::from(c < f);
                }
            }
            assert_eq!(coarse.get(&maps, GOAL.0, GOAL.1, 0), Cost::ZERO);
        }
        // Not all equal: the groups do relax the bound somewhere.
        assert!(below > 0);
    }

    #[test]
    fn orientation_groups_are_centred_on_their_first_orientation() {
        // 64 orientations in 8 groups of 8: group 0 holds 60..63 and 0..3.
        assert_eq!(members(0, 8, 64).collect::<Vec<_>>(), [60, 61, 62, 63, 0, 1, 2, 3]);
        assert_eq!(members(7, 8, 64).collect::<Vec<_>>(), [52, 53, 54, 55, 56, 57, 58, 59]);
        for k in 0..64 {
            let t = layer_of(k, 8, 8);
            assert!(members(t, 8, 64).any(|m| m == k), "{k} not in its group {t}");
        }
        assert_eq!(layer_of(0, 64, 1), 0);
        assert_eq!(members(0, 64, 64).count(), 64);
    }

    /// The relaxed graph's edges into node `c` of `ctg` (the in-edges `run_until`
    /// relaxes), as (from, weight), with `poses` caching `P`.
    fn in_edges(
        ctg: &CostToGo,
        maps: &CostMaps,
        poses: &mut Search,
        c: usize,
    ) -> Vec<(usize, Cost)> {
        let (layers, cells) = (ctg.layers, ctg.cells());
        let (nx, ny) = (i32::from(ctg.lattice.nx), i32::from(ctg.lattice.ny));
        let (t, cell) = (c / cells, c % cells);
        let (ci, cj) = ((cell % nx as usize) as i32, (cell / nx as usize) as i32);
        let mut edges: Vec<(usize, Cost)> = Vec::new();
        let inside = |a: i32, b: i32| a >= 0 && b >= 0 && a < nx && b < ny;
        for &(di, dj) in &ctg.shift_links[t] {
            if inside(ci - di, cj - dj) {
                edges.push((t * cells + ((cj - dj) * nx + ci - di) as usize, ctg.shift_step));
            }
        }
        let pc = ctg.pose_bound(poses, maps, c);
        if pc.is_finite() {
            let mut neighbours: Vec<(usize, f64)> = Vec::new();
            for (k, &(di, dj)) in ctg.moves.iter().enumerate() {
                if inside(ci - di, cj - dj) {
                    let n = t * cells + ((cj - dj) * nx + ci - di) as usize;
                    neighbours.push((n, ctg.move_weight[t * ctg.moves.len() + k]));
                }
            }
            if layers > 1 {
                for t2 in [(t + 1) % layers, (t + layers - 1) % layers] {
                    neighbours.push((t2 * cells + cell, ctg.turn_length));
                }
            }
            for (n, length) in neighbours {
                let pa = ctg.pose_bound(poses, maps, n);
                if pa.is_finite() {
                    let w = Cost::from_f64_floor(length * 0.5 * (pa + pc) * (1.0 - WEIGHT_SLACK));
                    edges.push((n, w));
                }
            }
        }
        edges
    }

    /// A search record set that only caches `P` for [`in_edges`].
    fn pose_cache(ctg: &CostToGo, maps: &CostMaps) -> Search {
        let mut poses = Search::new(ctg.layers * ctg.cells(), Buckets::new(Cost(1)), &[]);
        poses.stencils = (0..ctg.lattice.orientations)
            .map(|k| maps.driving_stencil(ctg.lattice.yaw(k as u8)))
            .collect();
        poses
    }

    /// Dijkstra's distances over the relaxed graph of `ctg` (the same in-edges as
    /// `run_until`), with a binary heap and no pruning: the reference the bucket queue and
    /// its shortcuts must reproduce.
    fn reference_distances(ctg: &CostToGo, maps: &CostMaps, root: usize) -> Vec<Cost> {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let mut poses = pose_cache(ctg, maps);
        let mut dist = vec![Cost::INFINITY; ctg.layers * ctg.cells()];
        let mut heap = BinaryHeap::from([Reverse((Cost::ZERO, root))]);
        dist[root] = Cost::ZERO;
        while let Some(Reverse((d, c))) = heap.pop() {
            if d > dist[c] {
                continue;
            }
            for (n, w) in in_edges(ctg, maps, &mut poses, c) {
                let nd = d.saturating_add(w);
                if nd < dist[n] {
                    dist[n] = nd;
                    heap.push(Reverse((nd, n)));
                }
            }
        }
        dist
    }

    /// The node of cell (i, j) and orientation `t` in `ctg`.
    fn node_of(ctg: &CostToGo, i: i16, j: i16, t: u8) -> usize {
        layer_of(usize::from(t), ctg.group, ctg.layers) * ctg.cells()
            + j as usize * usize::from(ctg.lattice.nx)
            + i as usize
    }

    #[test]
    fn the_aim_bound_is_the_octagonal_norm_and_the_turns_at_their_least_cost() {
        let (_, lattice, driving) = setup();
        let ctg =
            CostToGo::new(lattice, &driving, Cost::from_f64_floor(0.3), GOAL, (64, usize::MAX));
        // Drives cost at least their length (k_Δθ ≥ 1, P ≥ 1); a base-shift link 0.3 per
        // √2 · 2.5 cm at most, far more: 1 per metre, 0.025 a cell, less the slack:
        // ⌊24,975⌋ micro-units.
        assert_eq!(ctg.aim_per_cell, 24_975);
        let turn = (ctg.turn_length * (1.0 - AIM_SLACK) * 1e6) as u64;
        assert_eq!(ctg.aim_per_layer, turn);
        // (3, 4) cells apart: max(4, 7 / √2 = 4.9497) cells, in 16-bit fixed point
        // ⌊7 · 46,340 · 24,975 / 65,536⌋ = 123,617 (the float product is 123,619.6);
        // and two orientations either way (the short way round from 1 to 63).
        let want = Cost(123_617 + 2 * turn);
        assert_eq!(ctg.aim_bound((10, 10, 1), (13, 14, 63)), want);
        assert_eq!(ctg.aim_bound((13, 14, 63), (10, 10, 1)), want);
        // Along an axis: the straight line, 8 cells.
        assert_eq!(ctg.aim_bound((10, 10, 0), (10, 2, 0)), Cost(8 * 24_975));
        assert_eq!(ctg.aim_bound((10, 10, 5), (10, 10, 5)), Cost::ZERO);
    }

    #[test]
    fn the_aim_bound_is_consistent_on_every_relaxed_edge() {
        // For every edge n -> c the search relaxes (from c), a key never drops:
        // H(c) <= w + H(n), for aims on the map's corners, the box and the goal.
        let (maps, lattice, driving) = setup();
        for groups in [64, 8, 1] {
            let ctg = grouped(lattice, &driving, groups);
            let mut poses = pose_cache(&ctg, &maps);
            let (nx, ny) = (i32::from(lattice.nx), i32::from(lattice.ny));
            let cells = ctg.cells();
            let aims = [(0, 0, 0), (nx - 1, ny - 1, ctg.layers / 2), (100, 32, 0), (60, 50, 1)];
            let mut edges = 0;
            for c in (0..ctg.layers * cells).step_by(7) {
                for (n, w) in in_edges(&ctg, &maps, &mut poses, c) {
                    for &aim in &aims {
                        let aim = (aim.0, aim.1, aim.2 % ctg.layers);
                        let (hc, hn) =
                            (ctg.aim_bound(aim, ctg.coords(c)), ctg.aim_bound(aim, ctg.coords(n)));
                        assert!(
                            hc <= w.saturating_add(hn),
                            "{groups}: {c} <- {n}: {hc} > {w} + {hn}"
                        );
                    }
                    edges += 1;
                }
            }
            assert!(edges > 10_000, "{edges}");
        }
    }

    #[test]
    fn an_aimed_search_answers_dijkstras_distances_wherever_it_is_aimed() {
        // The first query aims the search; every later one resumes it and must still get
        // the reference's distance. Aimed at a node, the first answer settles fewer
        // nodes than a Dijkstra, which settles every node nearer the goal.
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let probe = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
        let want = reference_distances(&probe, &maps, node_of(&probe, GOAL.0, GOAL.1, 0));
        let (nx, ny) = (i16::try_from(lattice.nx).unwrap(), i16::try_from(lattice.ny).unwrap());
        // With one group per orientation, a node's layer is its orientation.
        let cell_of = |n: usize| {
            let (i, j, t) = probe.coords(n);
            (i as i16, j as i16, t as u8)
        };
        // The farthest node with a path, one at the median distance, one straight behind
        // the goal and the goal itself.
        let mut finite: Vec<(Cost, usize)> = want
            .iter()
            .enumerate()
            .filter(|(_, d)| !d.is_infinite())
            .map(|(n, &d)| (d, n))
            .collect();
        finite.sort_unstable();
        let aims = [
            cell_of(finite[finite.len() - 1].1),
            cell_of(finite[finite.len() / 2].1),
            (90, 32, 0),
            (GOAL.0, GOAL.1, 0),
        ];
        for (ai, aj, at) in aims {
            let ctg = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
            let d_aim = want[node_of(&ctg, ai, aj, at)];
            assert_eq!(ctg.get(&maps, ai, aj, at), d_aim);
            let nearer = want.iter().filter(|&&d| d <= d_aim).count();
            // Straight behind the goal at its heading, on level ground, the aim's bound
            // is nearly exact: a Dijkstra settles 517 nodes, the aimed search 11.
            if (ai, aj, at) == (90, 32, 0) {
                let settled = ctg.settled();
                assert!(
                    settled * 10 < nearer,
                    "aim ({ai}, {aj}): {settled} settled, {nearer} nearer"
                );
            }
            for t in (0..64u8).map(|k| (u32::from(k) * 28 % 64) as u8).step_by(3) {
                for j in (0..ny).map(|k| k * 7 % ny).step_by(2) {
                    for i in (0..nx).step_by(3) {
                        let got = ctg.get(&maps, i, j, t);
                        let d = want[node_of(&ctg, i, j, t)];
                        assert_eq!(got, d, "aim ({ai}, {aj}, {at}): ({i}, {j}, {t})");
                    }
                }
            }
        }
    }

    #[test]
    fn the_bucket_queue_settles_dijkstras_distances() {
        // Every fourth orientation of every cell against the reference, queried in a
        // scattered order (each query resumes the lazy search where the last stopped).
        let (maps, lattice, driving) = setup();
        for groups in [64, 8, 1] {
            let ctg = grouped(lattice, &driving, groups);
            let (gi, gj, _) = GOAL;
            let root = layer_of(0, ctg.group, ctg.layers) * ctg.cells()
                + gj as usize * usize::from(lattice.nx)
                + gi as usize;
            let want = reference_distances(&ctg, &maps, root);
            let (nx, ny) = (i16::try_from(lattice.nx).unwrap(), i16::try_from(lattice.ny).unwrap());
            let mut finite = 0;
            // A scattered order of orientations and rows (every fourth orientation).
            for t in (0..16u8).map(|k| (u32::from(k) * 28 % 64) as u8) {
                for j in (0..ny).map(|k| k * 5 % ny) {
                    for i in 0..nx {
                        let node = layer_of(usize::from(t), ctg.group, ctg.layers) * ctg.cells()
                            + j as usize * usize::from(lattice.nx)
                            + i as usize;
                        let got = ctg.get(&maps, i, j, t);
                        assert_eq!(got, want[node], "{groups} groups at ({i}, {j}, {t})");
                        finite += usize::from(!got.is_infinite());
                    }
                }
            }
            assert!(finite > 1000, "{groups} groups: {finite} finite");
        }
    }

    #[test]
    fn a_past_deadline_freezes_at_a_lower_bound() {
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let exact = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
        let frozen = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
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

    #[test]
    fn distances_past_the_records_cap_get_the_cap() {
        // A cap at about the median distance (instead of MAX_DIST's 4295 cost units, which
        // no test map reaches): below it the distances are the reference's, from it on
        // every node gets the cap, min(D, cap), nodes with no path too (once capped, the
        // search cannot tell them from far ones; the cap bounds both).
        let (maps, lattice, driving) = setup();
        let step = Cost::from_f64_floor(0.3);
        let ctg = CostToGo::new(lattice, &driving, step, GOAL, (64, usize::MAX));
        let (gi, gj, _) = GOAL;
        let root = gj as usize * usize::from(lattice.nx) + gi as usize;
        let want = reference_distances(&ctg, &maps, root);
        let mut finite: Vec<Cost> = want.iter().copied().filter(|d| !d.is_infinite()).collect();
        finite.sort_unstable();
        let cap = finite[finite.len() / 2];
        ctg.search.borrow_mut().cap = cap;
        let (nx, ny) = (i16::try_from(lattice.nx).unwrap(), i16::try_from(lattice.ny).unwrap());
        let (mut below, mut capped) = (0, 0);
        for t in (0..64u8).step_by(7) {
            for j in (0..ny).step_by(3) {
                for i in 0..nx {
                    let node = usize::from(t) * ctg.cells()
                        + j as usize * usize::from(lattice.nx)
                        + i as usize;
                    let got = ctg.get(&maps, i, j, t);
                    let d = want[node];
                    assert_eq!(got, d.min(cap), "({i}, {j}, {t})");
                    below += usize::from(d < cap);
                    capped += usize::from(d >= cap && !d.is_infinite());
                }
            }
        }
        assert!(below > 1000 && capped > 1000, "{below} below, {capped} capped");
        assert!(!ctg.frozen());
    }
}
