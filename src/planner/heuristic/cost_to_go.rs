//! The base-pose cost-to-go: the hybrid heuristic's informed lower bound on the driving,
//! turning and base-shift costs still to come ([`crate::planner::HybridGraph`], issue 15). A
//! backward Dijkstra from the goal over (cell, orientation) nodes of the lattice — the
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
//! rise, and edges that keep the base pose need none; so Dijkstra's
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
//! instead), and the links are all eight neighbours. What `G` buys is search work: the
//! first query of a plan settles every node nearer the goal than the start, about the
//! whole floor of a course times `G` (the platform: 1.03 M nodes at `G` = 64), and a
//! `P` is a handful of look-ups ([`CostMaps::driving_stencil`]), so the nodes are the
//! cost (see [`ORIENTATION_GROUPS`] for the measured choice).
//!
//! **Laziness.** Like the obstacle heuristic of Nav2's Smac planner, the Dijkstra runs
//! only as far as the queries need: a query for an unsettled node resumes the queue
//! until that node is settled, and `P` is computed per node when the search first
//! touches it. The graph (and with it this search) lives for one plan, so every ARA*
//! iteration reuses what earlier ones settled. The queue is a bucket queue (Dial's
//! algorithm; buckets no wider than the lightest edge), exact like a binary heap. The
//! nodes' records keep distances below [`MAX_DIST`]; a search that would go past it
//! answers `min(D, MAX_DIST)` instead, consistent like a deadline's frozen bound
//! ([`CostToGo::set_deadline`]).

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

/// The lazily computed backward Dijkstra over base cells (see the module docs).
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
    /// Nodes settled so far.
    settled: usize,
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
            search: RefCell::new(search),
            deadline: Cell::new(None),
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
        let layer = layer_of(usize::from(theta), self.group, self.layers);
        let node = layer * self.cells() + cell;
        let mut search = self.search.borrow_mut();
        while !search.nodes[node].done() && search.open() {
            if self.deadline.get().is_some_and(|t| Instant::now() >= t) {
                search.freeze();
                break;
            }
            self.run_until(&mut search, maps, node, SLICE);
        }
        if search.nodes[node].done() {
            search.nodes[node].dist()
        } else {
            // Frozen: the frontier's bound; else the queue ran empty: past the distances
            // a record keeps (`min(D, MAX_DIST)`, consistent like the frozen bound), or
            // no path at all.
            search.frozen.unwrap_or(if search.capped { search.cap } else { Cost::INFINITY })
        }
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
        let nx = usize::from(self.lattice.nx);
        let cells = self.cells();
        let cell = node % cells;
        let (i, j) = (cell % nx, cell / nx);
        let orientations = usize::from(self.lattice.orientations).max(1);
        let mut best = f64::INFINITY;
        for theta in members(node / cells, self.group, orientations) {
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

    /// Resumes the Dijkstra until node `target` is settled or the queue is empty.
    fn run_until(&self, search: &mut Search, maps: &CostMaps, target: usize, budget: usize) {
        if search.stencils.is_empty() {
            search.stencils = (0..self.lattice.orientations)
                .map(|k| maps.driving_stencil(self.lattice.yaw(k as u8)))
                .collect();
        }
        let (nx, ny) = (i32::from(self.lattice.nx), i32::from(self.lattice.ny));
        let (layers, cells) = (self.layers, self.cells());
        for _ in 0..budget {
            // The next entry; stale ones (the node was settled, or queued again lower)
            // are skipped.
            let Some(c) = search.queue.pop() else { return };
            if let Some(f) = search.queue.ahead(PREFETCH_AHEAD) {
                prefetch_neighbourhood(&search.nodes, f as usize, nx as usize, cells);
            }
            let c = c as usize;
            let d = search.nodes[c].dist();
            if search.nodes[c].done() || !search.queue.holds(d) {
                continue;
            }
            search.nodes[c].set_done();
            search.settled += 1;
            let (t, cell) = (c / cells, c % cells);
            let layer = t * cells;
            let (ci, cj) = ((cell % nx as usize) as i32, (cell / nx as usize) as i32);
            let node_at = |a: i32, b: i32| layer + (b * nx + a) as usize;
            // Base shifts into c: from c minus a link of its layer.
            for &(di, dj) in &self.shift_links[t] {
                let (a, b) = (ci - di, cj - dj);
                if a >= 0 && b >= 0 && a < nx && b < ny {
                    Self::relax(search, node_at(a, b), d.saturating_add(self.shift_step));
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
                // A settled neighbour needs no test of its own: its distance is below
                // d + w (d lies in the bucket being taken and w is no lighter than a
                // bucket is wide), so `relax` leaves it (the test was an unpredictable
                // branch per edge; the cold search 5 % sooner without it).
                let n = node_at(a, b);
                let pa = self.pose_bound(search, maps, n);
                if pa.is_finite() {
                    Self::relax(search, n, d.saturating_add(relaxed_weight(length, pa, pc)));
                }
            }
            // Turns on the spot into c: from the neighbouring orientations.
            if layers > 1 {
                for t2 in [(t + 1) % layers, (t + layers - 1) % layers] {
                    let n = t2 * cells + cell;
                    let pa = self.pose_bound(search, maps, n);
                    if pa.is_finite() {
                        let w = relaxed_weight(self.turn_length, pa, pc);
                        Self::relax(search, n, d.saturating_add(w));
                    }
                }
            }
            if c == target {
                return;
            }
        }
    }

    /// Lowers node `n`'s tentative distance to `d` and queues it, if `d` is lower. Never
    /// reopens a settled node: `d` (a distance of the bucket being taken plus an edge) is
    /// above every settled distance. A `d` from [`MAX_DIST`] on is not kept but marks the
    /// search capped: once its queue runs empty, every node it did not settle lies at
    /// least `MAX_DIST` away (or has no path), and gets that bound (see [`Self::get`]).
    #[inline]
    fn relax(search: &mut Search, n: usize, d: Cost) {
        let record = &mut search.nodes[n];
        if d < record.dist() {
            if d >= search.cap {
                search.capped = true;
                return;
            }
            record.set_dist(d);
            search.queue.push(d, n as u32);
        }
    }
}

impl Search {
    /// A search with `roots` at distance 0.
    fn new(n: usize, mut queue: Buckets, roots: &[usize]) -> Self {
        let mut nodes = vec![0u64; n];
        for &r in roots {
            nodes[r].set_dist(Cost::ZERO);
            queue.push(Cost::ZERO, r as u32);
        }
        Self {
            stencils: Vec::new(),
            nodes,
            queue,
            settled: 0,
            frozen: None,
            cap: MAX_DIST,
            capped: false,
        }
    }

    /// Stops the search: every node not settled is at least as far as the current
    /// bucket's lower edge.
    fn freeze(&mut self) {
        if self.frozen.is_none() {
            self.frozen = Some(self.queue.floor());
        }
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

/// Dial's bucket queue: bucket k holds the nodes queued with a distance in
/// `[k · width, (k + 1) · width)`. With `width` at most the smallest edge weight, a node
/// relaxed from bucket k lands in a later bucket, so every node of the current bucket is
/// final when it is taken, in any order: the distances are exactly Dijkstra's (and the
/// same on every run). Cheaper than a binary heap of millions of entries. The width is a
/// power of two (the largest not above the weight asked for), so that a bucket is a
/// shift, not a division per queued node.
#[derive(Debug)]
struct Buckets {
    /// log₂ of the width.
    shift: u32,
    /// Indexed by absolute bucket number; emptied buckets keep their allocation.
    buckets: Vec<Vec<u32>>,
    /// The bucket being taken from.
    current: usize,
    len: usize,
}

impl Buckets {
    fn new(width: Cost) -> Self {
        Self { shift: width.0.max(1).ilog2(), buckets: Vec::new(), current: 0, len: 0 }
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
        if b >= self.buckets.len() {
            self.buckets.resize_with(b + 1, Vec::new);
        }
        self.buckets[b].push(node);
        self.len += 1;
    }

    /// A lower bound on the distance of every node not yet taken: the current bucket's
    /// lower edge.
    fn floor(&self) -> Cost {
        Cost((self.current as u64).saturating_mul(1 << self.shift))
    }

    /// Whether a node queued at distance `d` belongs to the bucket being taken (else
    /// its entry is stale).
    fn holds(&self, d: Cost) -> bool {
        self.bucket(d) == self.current
    }

    /// The entry `k` places after the next one in the current bucket, if it holds one
    /// (for prefetching the records it will touch).
    fn ahead(&self, k: usize) -> Option<u32> {
        let bucket = self.buckets.get(self.current)?;
        bucket.len().checked_sub(k + 1).map(|i| bucket[i])
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

    /// Dijkstra's distances over the relaxed graph of `ctg` (the same in-edges as
    /// `run_until`), with a binary heap and no pruning: the reference the bucket queue and
    /// its shortcuts must reproduce.
    fn reference_distances(ctg: &CostToGo, maps: &CostMaps, root: usize) -> Vec<Cost> {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let (layers, cells) = (ctg.layers, ctg.cells());
        let (nx, ny) = (i32::from(ctg.lattice.nx), i32::from(ctg.lattice.ny));
        let mut poses = Search::new(layers * cells, Buckets::new(Cost(1)), &[]);
        poses.stencils = (0..ctg.lattice.orientations)
            .map(|k| maps.driving_stencil(ctg.lattice.yaw(k as u8)))
            .collect();
        let mut dist = vec![Cost::INFINITY; layers * cells];
        let mut heap = BinaryHeap::from([Reverse((Cost::ZERO, root))]);
        dist[root] = Cost::ZERO;
        while let Some(Reverse((d, c))) = heap.pop() {
            if d > dist[c] {
                continue;
            }
            let (t, cell) = (c / cells, c % cells);
            let (ci, cj) = ((cell % nx as usize) as i32, (cell / nx as usize) as i32);
            let mut edges: Vec<(usize, Cost)> = Vec::new();
            let inside = |a: i32, b: i32| a >= 0 && b >= 0 && a < nx && b < ny;
            for &(di, dj) in &ctg.shift_links[t] {
                if inside(ci - di, cj - dj) {
                    edges.push((t * cells + ((cj - dj) * nx + ci - di) as usize, ctg.shift_step));
                }
            }
            let pc = ctg.pose_bound(&mut poses, maps, c);
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
                    let pa = ctg.pose_bound(&mut poses, maps, n);
                    if pa.is_finite() {
                        let w =
                            Cost::from_f64_floor(length * 0.5 * (pa + pc) * (1.0 - WEIGHT_SLACK));
                        edges.push((n, w));
                    }
                }
            }
            for (n, w) in edges {
                let nd = d.saturating_add(w);
                if nd < dist[n] {
                    dist[n] = nd;
                    heap.push(Reverse((nd, n)));
                }
            }
        }
        dist
    }

    #[test]
    fn the_bucket_queue_settles_dijkstras_distances() {
        // Every fourth orientation of every cell against the reference, queried in a
        // scattered order (each query resumes the lazy search where the last stopped).
        let (maps, lattice, driving) = setup();
        for groups in [64, 8, 1] {
            let ctg = CostToGo::new(
                lattice,
                &driving,
                Cost::from_f64_floor(0.3),
                GOAL,
                (groups, usize::MAX),
            );
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
