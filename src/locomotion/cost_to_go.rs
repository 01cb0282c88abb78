//! The base-cell cost-to-go: the hybrid heuristic's informed lower bound on the driving
//! and base-shift costs still to come ([`super::HybridGraph`], issue 15). A backward
//! Dijkstra from the goal cell over the x-y cells of the lattice, where every edge costs
//! at most what any manoeuvre of the hybrid graph that moves the base between those
//! cells costs, minimised over orientations and footprints: an exact relaxation, so the
//! distance `D(c)` it computes is consistent on every edge of the hybrid graph.
//!
//! **Which edges move the base.** Of the hybrid graph's manoeuvres (`hybrid` module
//! docs) only drives and base shifts change the base cell. Turns on the spot, abstract
//! steps, "front foot forward" and "foot to neutral" leave the base on its cell, so `D`
//! is the same at both ends of those edges and `D(s) ≤ c(s, t) + D(t)` holds with any
//! cost `c ≥ 0`. (Their costs are what other parts of the heuristic bound: the turn term
//! of the driving heuristic, the step bound and the foot-offset potential of
//! `heuristic`.)
//!
//! **Drive edges.** A drive by move `m` (16- or 20-neighbourhood) from cell a to cell b
//! at any orientation θ costs `L_m · k_Δθ · (C(a, θ) + C(b, θ)) / 2` (`driving` module
//! docs; rounded up to the micro-unit), with `C` the driving pose cost (eq. 4) of the
//! neutral footprint raised to 1, and `k_Δθ ≥ 1` (Fig. 8). The driving graph also drops
//! poses its feasibility model rejects, which only removes edges. So with
//! `P(c) = min_θ max(1, C(c, θ))` over *every* orientation (∞ if no orientation has a
//! finite pose cost) the relaxed edge `a → b` weighs `L_m · (P(a) + P(b)) / 2`. `P` is
//! computed with the very poses (`Lattice::pose`) and the very cost function
//! (`CostMaps::driving_pose_cost`) the driving graph uses, less a relative 10⁻⁶ for the
//! driving graph's `f32` cache of pose costs (relative error ≤ 6·10⁻⁸).
//!
//! **Base-shift edges.** A base shift by `l` cells along the heading moves the base from
//! the centre of cell a to `a + l · res · (cos θ, sin θ)` and snaps it to the cell b
//! holding that point (`hybrid` module docs). Along each axis the cell index changes by
//! `⌊1/2 + l · cos θ⌋` (likewise sin), at most `l` in magnitude: the Chebyshev distance
//! `‖b − a‖∞ ≤ l`. Its cost is `max(f · k10 · l · res · C_B,avg, moved) ≥ f · k10 · l · res`
//! (C_B ≥ 1, eq. 3; f the step-related factor), and it lowers all four foot offsets by
//! l, which raises the foot-offset potential Φ of the heuristic by at least
//! `4 c · l · res` (`heuristic::offset_potential`: a foot behind neutral falls further
//! behind, one ahead has used up its lead). The relaxation links every cell to its eight
//! neighbours with weight `β · res`, `β = f · k10 + 4 c`: a chain of `‖b − a‖∞ ≤ l` such
//! links joins a to b for at most `β · l · res`, and `D` drops by no more than the
//! shift's cost plus Φ's rise. The links are not restricted to cells where the robot can
//! stand, which only weakens the bound (a wall is crossed at `β` per cell instead of
//! walked around): every cell is connected, and `D` is finite on the whole map.
//!
//! **Consistency** (and admissibility: `D(goal) = 0`). For every drive s → t the relaxed
//! graph has a path from cell(s) to cell(t) no heavier than the edge's cost, for every
//! base shift one no heavier than its cost plus Φ's rise, and edges that keep the base
//! cell need none; so Dijkstra's `D(cell(s)) ≤ w(path) + D(cell(t))` gives
//! `D(s) + Φ(s) ≤ c(s, t) + D(t) + Φ(t)` on every edge that moves the base (Φ is zero
//! on drives). The other edges are the business of the other parts of the heuristic. In fixed point: relaxed
//! weights are rounded down (with a relative slack of 10⁻⁹), edges up, and `D` sums
//! integers, so the inequality holds exactly.
//!
//! **Laziness.** Like the obstacle heuristic of Nav2's Smac planner, the Dijkstra runs
//! only as far as the queries need: a query for an unsettled cell resumes the queue
//! until that cell is settled, and `P` is computed per cell when the search first
//! touches it. The graph (and with it this search) lives for one plan, so every ARA*
//! iteration reuses what earlier ones settled.

use super::driving::DrivingConfig;
use super::lattice::{Lattice, LatticeState};
use crate::cost::CostMaps;
use crate::planner::Cost;
use std::cell::RefCell;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Relative slack on `P` for the driving graph's `f32` pose-cost cache.
const POSE_SLACK: f64 = 1e-6;
/// Relative slack on relaxed edge weights (edges are rounded up with 10⁻¹²).
const WEIGHT_SLACK: f64 = 1e-9;
/// Most (cell, orientation) nodes searched with one layer per orientation; larger maps
/// get one layer (the minimum over orientations), at a quarter of the memory per cell.
pub const MAX_ORIENTED_NODES: usize = 1 << 24;

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
    queue: BinaryHeap<Reverse<(Cost, u32)>>,
    /// Nodes settled so far.
    settled: usize,
}

impl CostToGo {
    /// The cost-to-go on `lattice` toward `goal` (cell, and orientation if it is fixed),
    /// with the driving moves, k_Δθ and turn length of `driving` and `shift_step`, the
    /// weight β · res of one link of a base shift (see the module docs). Nothing is
    /// computed until the first query.
    pub fn new(
        lattice: Lattice,
        driving: &DrivingConfig,
        shift_step: Cost,
        goal: (i16, i16, Option<u8>),
    ) -> Self {
        let cells = usize::from(lattice.nx) * usize::from(lattice.ny);
        let orientations = usize::from(lattice.orientations).max(1);
        let layers =
            if cells.saturating_mul(orientations) <= MAX_ORIENTED_NODES { orientations } else { 1 };
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
        let n = cells * layers;
        let mut search = Search {
            pose: vec![0.0; n],
            dist: vec![Cost::INFINITY; n],
            done: vec![false; n],
            queue: BinaryHeap::new(),
            settled: 0,
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
                search.queue.push(Reverse((Cost::ZERO, node as u32)));
            }
        }
        Self {
            lattice,
            layers,
            moves,
            move_weight,
            turn_length: if layers > 1 {
                driving.turn_radius_m * lattice.orientation_step()
            } else {
                0.0
            },
            shift_links,
            shift_step,
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
        if !search.done[node] {
            self.run_until(&mut search, maps, node);
        }
        if search.done[node] { search.dist[node] } else { Cost::INFINITY }
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
            if let Some(cost) = maps.driving_pose_cost(&pose).finite() {
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
        while let Some(Reverse((d, c))) = search.queue.pop() {
            let c = c as usize;
            if search.done[c] || d > search.dist[c] {
                continue;
            }
            search.done[c] = true;
            search.settled += 1;
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
            if c == target {
                return;
            }
        }
    }

    #[inline]
    fn relax(search: &mut Search, n: usize, d: Cost) {
        if !search.done[n] && d < search.dist[n] {
            search.dist[n] = d;
            search.queue.push(Reverse((d, n as u32)));
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
