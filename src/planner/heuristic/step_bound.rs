//! A lower bound on the step costs still needed to reach the goal: the informed part of
//! the hybrid graph's heuristic ([`crate::planner::HybridGraph`]), computed once per plan.
//!
//! **Idea.** Every foot stands on a cell of finite foot cost C_F (eq. 1) in every state
//! of the hybrid graph, and the only manoeuvre that carries a foot across untraversable
//! terrain is an abstract step (Sec. V). So we split the finite-C_F cells into
//! *components* — sets a foot can roll between without stepping — and lower-bound, per
//! component and per foot, the sum of the step costs C_S (eq. 5, times the step-related
//! factor) that foot still has to pay before it stands where the goal pose puts it. The
//! four feet's bounds add up, because each step moves exactly one foot.
//!
//! **Components.** Two finite-C_F cells are *linked* when they are at most `R` cells
//! apart along each axis (Chebyshev distance ≤ R); components are the connected sets of
//! this relation. R bounds how far a foot's cell jumps in one manoeuvre that is not a
//! step:
//! - a driving move translates the base, hence every foot, by at most 2 cells per axis
//!   (the 16- / 20-neighbourhood);
//! - a turn on the spot moves a foot on a chord of `2 r sin(Δθ/2)` (r its distance from
//!   the base centre, Δθ one orientation step), so its cell by at most
//!   `⌈chord / res⌉` per axis;
//! - a base shift leaves the feet where they stand up to the snap of the base to its
//!   cell (half a cell diagonal, ≤ 1 cell per axis);
//! - front foot forward and foot to neutral drive one foot along a line whose every
//!   cell (sampled each `res`) has finite C_F: consecutive cells ≤ 1 apart per axis;
//!
//! with one cell added against float rounding: `R = max(2, ⌈chord / res⌉) + 1`. Both
//! ends of each of these manoeuvres are finite-C_F cells (they are states' feet, or line
//! cells checked finite), so they never change a foot's component.
//!
//! **Step edges between components.** A step of one foot from cell a (component A) to
//! cell b (component B) costs `f · C_S` with `C_S = k7 · L + k8 · (C_F(b) − 1) + k9 · ΔH`
//! (eq. 5; f the step-related factor). Each term is bounded below from the components
//! alone:
//! - `ΔH ≥ |H(b) − H(a)|` (ΔH_step is the largest height difference over the cells the
//!   foot passes, the landing cell included) `≥ gap(A, B)`, the distance between the
//!   components' height intervals `[min H, max H]`; a pair whose gap exceeds the largest
//!   step height (criterion 3) has no step at all;
//! - `C_F(b) ≥ min C_F over B`;
//! - `L = d · res` with d ≥ 2 (the foot crosses at least one infinite cell and lands on
//!   a finite one after it); between different components the cell centres are more
//!   than R cells apart along some axis, so `|c_b − c_a| ≥ (R + 1) · res` and, with both
//!   foot positions within half a cell diagonal of their cell centres,
//!   `L ≥ (R + 1 − √2) · res`. On maps of at most [`MAX_DISTANCE_TRANSFORMS`]
//!   components a tighter bound replaces it: the octile distance transform of each
//!   component B gives the octile distance d from every cell to B, at most 1.0824 times
//!   the Euclidean one, so a step from a near cell of A to B is at least
//!   `min_a d / 1.0824 − √2` cells long (≈ 0.22 m between a floor and a 0.2 m platform,
//!   whose untraversable band is 2 r_F wide);
//! - a step starts only from a foot within `step_obstacle_distance_m` of an infinite
//!   cell (criterion 1), so only components holding a cell of the graph's conservative
//!   "near an obstacle" layer have outgoing step edges;
//! - a step is no longer than a leg's range of foot offsets (from its reach behind
//!   neutral to its reach ahead), so a pair whose lower bound on L exceeds that has no
//!   edge. Without it the bound let a foot on a stair's first tread "step" across a
//!   1.3 m plateau to the floor beyond at the cost of its 0.1 m rise, where the plateau
//!   itself had to pay for its 0.3 m drop: the heuristic fell by 40 % going back down
//!   the stairs, and the greedy probe searched there (generated mixed courses stopped
//!   at the 120 s limit).
//!
//! Of the k7 term only the share `1 − λ` enters `w`: the share λ pays for the
//! foot-offset potential of the hybrid heuristic ([`offset_potential`]).
//!
//! The component graph with these edge weights `w(A, B)` (B = A included) is searched
//! backwards from the component of each goal foot (Dijkstra, dense, O(K²) for K
//! components): `S_k(A)` is the cheapest chain of steps from A to foot k's goal
//! component.
//!
//! **Consistency.** For a step of foot k from a ∈ A to b ∈ B: `S_k(A) ≤ w(A, B) + S_k(B)`
//! (Dijkstra) `≤ c + S_k(B)`, and the other feet's terms do not change. Every other
//! manoeuvre leaves all four components, hence the bound, unchanged. So `Σ_k S_k` is
//! consistent on its own with respect to the step edges and invariant on all others; it
//! is zero at the goal. Added to the driving part of the heuristic (the larger of the
//! Euclidean distance plus turn and the cost-to-go of `cost_to_go`, consistent with
//! respect to drives, turns and base shifts and unchanged by steps and foot moves), the
//! sum is consistent for every edge of the hybrid graph. Weights are
//! rounded down to the micro-unit with a relative slack of 10⁻⁹ (edges round up), and
//! the Dijkstra sums integers, so the bound holds exactly in fixed point.
//!
//! Maps with more than [`MAX_COMPONENTS`] components get no step bound (the bound is
//! then zero everywhere, which is trivially consistent): the O(K²) search would cost
//! more than it saves.
//!
//! **What the bound leaves out, and why.** Most of a platform plan's cost beyond the
//! steps is driving with a foot close to an edge (C_F in the hundreds, eq. 1). A
//! per-foot "rolling" bound (κ · C_F per metre a foot rolls, κ = k5 + k4/4 from eq. 4)
//! would cover it for drives, turns and foot moves, but not for base shifts: a base
//! shift snaps the base to the cell holding its exact end, so all four feet jump up to
//! half a cell diagonal, repeatedly, for as little as `f · k10 · res` (one cell, C_B = 1).
//! Consistency then caps the rolling weight at C_F ≈ 5, and base shifts are possible
//! wherever a foot can come close to any obstacle (walls included), i.e. almost
//! everywhere. The driving cost is bounded per base pose instead, by the cost-to-go of
//! `cost_to_go` (drives at their real pose costs; base shifts at `f · k10` per cell plus
//! the rise of the foot-offset potential, `f · (k10 + 4 k11 · C_F,min)` ≈ 10.75 per
//! metre with the paper's constants: what a crawl of base shifts and foot moves costs at
//! the least).

use crate::cost::{Cost as CostValue, CostMaps};
use crate::search::Cost;

/// Tolerance of the step height criterion (criterion 3), m: heights built from sums of
/// floats sit a few ulps off their nominal value (three 0.1 m rises make a plateau
/// 0.30000000000000004 m high), and a drop of the paper's largest step height must stay
/// a step. Far below any physical meaning.
pub const STEP_HEIGHT_TOLERANCE_M: f64 = 1e-9;

/// Largest number of components for which the step bound is computed.
pub const MAX_COMPONENTS: usize = 2048;

/// "No component": the cell's foot cost is not finite.
const NONE: u32 = u32::MAX;

/// The constants of the step cost the bound needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepBoundParams {
    /// Factor on every step-related manoeuvre (Sec. V, Fig. 7).
    pub step_cost_factor: f64,
    /// k7 (eq. 5): weight on the step length.
    pub k7: f64,
    /// k8 (eq. 5): weight on the foothold cost.
    pub k8: f64,
    /// k9 (eq. 5): weight on the step height.
    pub k9: f64,
    /// Criterion 3: largest height difference of a step, m.
    pub max_step_height_m: f64,
    /// Link radius R, cells (see the module docs).
    pub link_cells: usize,
    /// Longest step any foot can make, m: the widest range of a leg's foot offsets
    /// (its reach behind and ahead of neutral). Components farther apart have no step
    /// edge.
    pub max_step_length_m: f64,
    /// k10: base shift weight (C_BS).
    pub k10: f64,
    /// k11 (eq. 6): single foot move weight.
    pub k11: f64,
}

/// One component's summary.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Component {
    min_h: f64,
    max_h: f64,
    min_cf: f64,
    /// Holds a cell of the "near an obstacle" layer: steps may start here.
    near: bool,
}

/// Per-cell components and per-foot step bounds (see the module docs).
#[derive(Debug, Clone)]
pub struct StepBound {
    /// Component per cell (row-major, as the height map), [`NONE`] where C_F is not finite.
    comp: Vec<u32>,
    /// Per foot (FL, FR, RL, RR), per component: the step cost still needed, S_k.
    per_foot: [Vec<Cost>; 4],
    components: usize,
    /// Weight c of the foot-offset potential per cell of offset, rounded down.
    offset_per_cell: Cost,
}

impl StepBound {
    /// A bound that is zero everywhere.
    pub fn zero() -> Self {
        Self {
            comp: Vec::new(),
            per_foot: Default::default(),
            components: 0,
            offset_per_cell: Cost::ZERO,
        }
    }

    /// Builds the bound on `maps` for the goal foot positions `goal_feet` (one array of
    /// four per accepted goal orientation; foot k of every entry is a source for foot k).
    /// `near` is the graph's per-cell "near an obstacle" layer (a superset of the cells
    /// from which criterion 1 allows a step).
    pub fn build(
        maps: &CostMaps,
        near: &[bool],
        params: &StepBoundParams,
        goal_feet: &[[[f64; 2]; 4]],
    ) -> Self {
        let hm = maps.heights();
        let (nx, ny) = hm.dims();
        let res = hm.resolution();
        let r = params.link_cells.max(1) as isize;
        let finite = |i: usize, j: usize| match maps.foot_cost_cell(i, j) {
            CostValue::Finite(c) => hm.get(i, j).map(|h| (c, h)),
            _ => None,
        };
        // Components: breadth-first over linked finite cells.
        let mut comp = vec![NONE; nx * ny];
        let mut comps: Vec<Component> = Vec::new();
        let mut queue = Vec::new();
        for j0 in 0..ny {
            for i0 in 0..nx {
                if comp[j0 * nx + i0] != NONE {
                    continue;
                }
                let Some((cf, h)) = finite(i0, j0) else { continue };
                if comps.len() >= MAX_COMPONENTS {
                    return Self::zero();
                }
                let id = comps.len() as u32;
                let mut c = Component { min_h: h, max_h: h, min_cf: cf, near: false };
                comp[j0 * nx + i0] = id;
                queue.clear();
                queue.push((i0, j0));
                while let Some((i, j)) = queue.pop() {
                    let (cf, h) = finite(i, j).unwrap_or((f64::INFINITY, f64::NAN));
                    c.min_h = c.min_h.min(h);
                    c.max_h = c.max_h.max(h);
                    c.min_cf = c.min_cf.min(cf);
                    c.near |= near.get(j * nx + i).copied().unwrap_or(false);
                    let (i, j) = (i as isize, j as isize);
                    for b in (j - r).max(0)..=(j + r).min(ny as isize - 1) {
                        for a in (i - r).max(0)..=(i + r).min(nx as isize - 1) {
                            let k = b as usize * nx + a as usize;
                            if comp[k] == NONE && finite(a as usize, b as usize).is_some() {
                                comp[k] = id;
                                queue.push((a as usize, b as usize));
                            }
                        }
                    }
                }
                comps.push(c);
            }
        }
        let k = comps.len();
        let l_other = ((r as f64 + 1.0 - std::f64::consts::SQRT_2) * res).max(2.0 * res);
        let l_same = 2.0 * res;
        let gaps = min_step_lengths(&comp, &comps, nx, ny, res, near);
        let min_cf = comps.iter().map(|c| c.min_cf).fold(f64::INFINITY, f64::min);
        let (offset_per_m, lambda) = offset_potential(params, min_cf);
        let k7 = params.k7 * (1.0 - lambda);
        let crossings = Crossings::build(hm, &comp, &comps, params.max_step_height_m);
        let weight = |a: usize, b: usize| -> Option<Cost> {
            let (ca, cb) = (&comps[a], &comps[b]);
            if !ca.near || !crossings.may_step(a, b) {
                return None;
            }
            let gap = (cb.min_h - ca.max_h).max(ca.min_h - cb.max_h).max(0.0);
            if gap > params.max_step_height_m + STEP_HEIGHT_TOLERANCE_M {
                return None;
            }
            let l = if a == b {
                l_same
            } else {
                gaps.as_ref().map_or(l_other, |g| g.get(a, b)).max(l_other)
            };
            if l > params.max_step_length_m {
                return None;
            }
            let c_s = k7 * l + params.k8 * (cb.min_cf - 1.0) + params.k9 * gap;
            Some(Cost::from_f64_floor(params.step_cost_factor * c_s * (1.0 - 1e-9)))
        };
        let per_foot = std::array::from_fn(|foot| {
            let mut dist = vec![Cost::INFINITY; k];
            for feet in goal_feet {
                let [x, y] = feet[foot];
                if let Some((i, j)) = hm.cell_of(x, y) {
                    let c = comp[j * nx + i];
                    if c != NONE {
                        dist[c as usize] = Cost::ZERO;
                    }
                }
            }
            // Dense Dijkstra over the component graph, edges reversed.
            let mut done = vec![false; k];
            loop {
                let next = (0..k)
                    .filter(|&c| !done[c] && !dist[c].is_infinite())
                    .min_by_key(|&c| (dist[c], c));
                let Some(b) = next else { break };
                done[b] = true;
                for a in 0..k {
                    if done[a] {
                        continue;
                    }
                    if let Some(w) = weight(a, b) {
                        let d = dist[b].saturating_add(w);
                        if d < dist[a] {
                            dist[a] = d;
                        }
                    }
                }
            }
            dist
        });
        let offset_per_cell = Cost::from_f64_floor(offset_per_m * res * (1.0 - 1e-9));
        Self { comp, per_foot, components: k, offset_per_cell }
    }

    /// The weight c of the foot-offset potential per cell of offset (fixed point).
    pub fn offset_per_cell(&self) -> Cost {
        self.offset_per_cell
    }

    /// Number of components (0 for the zero bound).
    pub fn components(&self) -> usize {
        self.components
    }

    /// Σ_k S_k over the feet at world positions `feet` (FL, FR, RL, RR) on the map of
    /// `maps`: the step cost still needed. A foot off the map or on a cell of non-finite
    /// foot cost adds nothing; a foot that cannot reach its goal component makes the
    /// bound [`Cost::INFINITY`].
    #[inline]
    pub fn lower_bound(&self, maps: &CostMaps, feet: &[[f64; 2]; 4]) -> Cost {
        if self.components == 0 {
            return Cost::ZERO;
        }
        let hm = maps.heights();
        let mut sum = Cost::ZERO;
        for (k, f) in feet.iter().enumerate() {
            let Some((i, j)) = hm.cell_of(f[0], f[1]) else { continue };
            let c = self.comp[j * hm.nx() + i];
            if c != NONE {
                sum = sum.saturating_add(self.per_foot[k][c as usize]);
            }
        }
        sum
    }

    /// Whether some foot standing on cell `k` (row-major) could still reach its goal
    /// component, so that a state with a foot there can reach the goal at all: every cell
    /// where the bound is off, none of non-finite foot cost. A foot on any other cell
    /// makes [`Self::lower_bound`] infinite.
    pub fn live(&self, k: usize) -> bool {
        if self.components == 0 {
            return true;
        }
        self.comp.get(k).is_some_and(|&c| {
            c != NONE
                && self.per_foot.iter().any(|s| s.get(c as usize).is_some_and(|v| !v.is_infinite()))
        })
    }

    /// The foot-offset potential Φ = c · Σ_k (o_k⁻ − o_k⁺) of a footprint with offsets
    /// `o` (cells; o⁻ = max(−o, 0), o⁺ = max(o, 0)), as its two parts `(c · Σ o⁻,
    /// c · Σ o⁺)`: the heuristic adds the first and subtracts the second (see
    /// [`offset_potential`]). Exact integers: c is a whole number of micro-units.
    #[inline]
    pub fn offset_potential(&self, o: &[i8; 4]) -> (Cost, Cost) {
        offsets_weighed(o, self.offset_per_cell)
    }
}

/// The feet's offsets `o` (cells) weighed at `per_cell` a cell, as the two parts
/// `(per_cell · Σ o⁻, per_cell · Σ o⁺)` (o⁻ = max(−o, 0), o⁺ = max(o, 0)): Φ's at c
/// ([`StepBound::offset_potential`]), the probe's greedy estimate's at its own weight.
#[inline]
pub fn offsets_weighed(o: &[i8; 4], per_cell: Cost) -> (Cost, Cost) {
    let (behind, ahead) = o.iter().fold((0u64, 0u64), |(behind, ahead), &v| {
        let cells = u64::from(v.unsigned_abs());
        if v < 0 { (behind + cells, ahead) } else { (behind, ahead + cells) }
    });
    (Cost(per_cell.0.saturating_mul(behind)), Cost(per_cell.0.saturating_mul(ahead)))
}

/// Which component pairs a step could join at all (criterion 3 over the whole swing).
///
/// A step of a foot standing at height `h0` samples the cells along its line every cell
/// width and stops at the first whose height differs from `h0` by more than the largest
/// step height, or that is unknown (`HybridGraph::best_step`). So every cell it passes,
/// the landing cell included, is known and at most `max_h(A) + max_step` high, and
/// consecutive ones touch (8-neighbours). Per threshold `t = max_h(A) + max_step` the
/// known cells at most `t` high split into 8-connected *passes*; a step from A can land
/// only in a component B that has a cell in a pass holding a cell of A. A wall more than
/// a step height above both sides is thus no step edge, however thin: a room walled in
/// by it has an infinite step bound, and the search ends at once with no path.
struct Crossings {
    /// Per component: index of its threshold in `passes`, or `None` (no filter).
    threshold: Vec<Option<usize>>,
    /// Per threshold, per component: the passes its cells lie in (sorted).
    passes: Vec<Vec<Vec<u32>>>,
}

/// Most distinct thresholds [`Crossings`] labels; beyond it the filter is off (every
/// pair may step), which is sound.
const MAX_THRESHOLDS: usize = 64;

impl Crossings {
    fn build(
        hm: &crate::terrain::HeightMap,
        comp: &[u32],
        comps: &[Component],
        max_step: f64,
    ) -> Self {
        let (nx, ny) = hm.dims();
        let k = comps.len();
        // Thresholds to the millimetre, rounded up (a larger threshold only merges), with
        // the criterion's tolerance.
        let key =
            |c: &Component| ((c.max_h + max_step + STEP_HEIGHT_TOLERANCE_M) * 1000.0).ceil() as i64;
        let mut keys: Vec<i64> = comps.iter().map(key).collect();
        keys.sort_unstable();
        keys.dedup();
        if keys.len() > MAX_THRESHOLDS {
            return Self { threshold: vec![None; k], passes: Vec::new() };
        }
        let threshold = comps.iter().map(|c| keys.binary_search(&key(c)).ok()).collect::<Vec<_>>();
        let heights = hm.as_slice();
        let mut passes = Vec::with_capacity(keys.len());
        let mut label = vec![u32::MAX; nx * ny];
        let mut stack = Vec::new();
        for &kk in &keys {
            let t = kk as f64 / 1000.0;
            label.fill(u32::MAX);
            let mut next = 0u32;
            for start in 0..nx * ny {
                let h = heights[start];
                if label[start] != u32::MAX || h.is_nan() || h > t {
                    continue;
                }
                label[start] = next;
                stack.push(start);
                while let Some(c) = stack.pop() {
                    let (i, j) = ((c % nx) as isize, (c / nx) as isize);
                    for b in (j - 1).max(0)..=(j + 1).min(ny as isize - 1) {
                        for a in (i - 1).max(0)..=(i + 1).min(nx as isize - 1) {
                            let n = b as usize * nx + a as usize;
                            if label[n] == u32::MAX && heights[n] <= t {
                                label[n] = next;
                                stack.push(n);
                            }
                        }
                    }
                }
                next += 1;
            }
            let mut per_comp: Vec<Vec<u32>> = vec![Vec::new(); k];
            for (c, &id) in comp.iter().enumerate() {
                if id != NONE && label[c] != u32::MAX {
                    per_comp[id as usize].push(label[c]);
                }
            }
            for v in &mut per_comp {
                v.sort_unstable();
                v.dedup();
            }
            passes.push(per_comp);
        }
        Self { threshold, passes }
    }

    /// Whether a step from component `a` could land in component `b`.
    fn may_step(&self, a: usize, b: usize) -> bool {
        let Some(t) = self.threshold.get(a).copied().flatten() else { return true };
        let (pa, pb) = (&self.passes[t][a], &self.passes[t][b]);
        // Sorted: a merge finds a shared pass.
        let (mut x, mut y) = (0, 0);
        while x < pa.len() && y < pb.len() {
            match pa[x].cmp(&pb[y]) {
                std::cmp::Ordering::Equal => return true,
                std::cmp::Ordering::Less => x += 1,
                std::cmp::Ordering::Greater => y += 1,
            }
        }
        false
    }
}

/// Lower bounds on step lengths between components, from octile distance transforms.
struct StepLengths {
    /// Row-major `[a · k + b]`, m.
    lengths: Vec<f64>,
    k: usize,
}

impl StepLengths {
    fn get(&self, a: usize, b: usize) -> f64 {
        self.lengths[a * self.k + b]
    }
}

/// Largest number of components for which `min_step_lengths` runs a distance transform
/// per component (each is two passes over the map).
pub const MAX_DISTANCE_TRANSFORMS: usize = 32;

/// For every pair (A, B) of components: a lower bound on the length L of a step from a
/// cell of A flagged `near` to a cell of B, `d / 1.0824 − √2 · res` with d the octile
/// distance between their cell centres (the octile distance is at most 1.0824 times the
/// Euclidean one; the feet lie within half a cell diagonal of their cell centres).
/// `None` for maps with more than [`MAX_DISTANCE_TRANSFORMS`] components.
fn min_step_lengths(
    comp: &[u32],
    comps: &[Component],
    nx: usize,
    ny: usize,
    res: f64,
    near: &[bool],
) -> Option<StepLengths> {
    let k = comps.len();
    if k > MAX_DISTANCE_TRANSFORMS {
        return None;
    }
    let octile_over_euclid = (1.0 + (std::f64::consts::SQRT_2 - 1.0).powi(2)).sqrt();
    let mut lengths = vec![0.0; k * k];
    let mut d = vec![0.0_f64; nx * ny];
    let diag = std::f64::consts::SQRT_2;
    for b in 0..k {
        for (v, &c) in d.iter_mut().zip(comp) {
            *v = if c == b as u32 { 0.0 } else { f64::INFINITY };
        }
        // Two-pass chamfer transform with weights 1 and √2: the exact octile distance
        // to the nearest cell of B.
        for j in 0..ny {
            for i in 0..nx {
                let mut v = d[j * nx + i];
                if i > 0 {
                    v = v.min(d[j * nx + i - 1] + 1.0);
                }
                if j > 0 {
                    v = v.min(d[(j - 1) * nx + i] + 1.0);
                    if i > 0 {
                        v = v.min(d[(j - 1) * nx + i - 1] + diag);
                    }
                    if i + 1 < nx {
                        v = v.min(d[(j - 1) * nx + i + 1] + diag);
                    }
                }
                d[j * nx + i] = v;
            }
        }
        for j in (0..ny).rev() {
            for i in (0..nx).rev() {
                let mut v = d[j * nx + i];
                if i + 1 < nx {
                    v = v.min(d[j * nx + i + 1] + 1.0);
                }
                if j + 1 < ny {
                    v = v.min(d[(j + 1) * nx + i] + 1.0);
                    if i + 1 < nx {
                        v = v.min(d[(j + 1) * nx + i + 1] + diag);
                    }
                    if i > 0 {
                        v = v.min(d[(j + 1) * nx + i - 1] + diag);
                    }
                }
                d[j * nx + i] = v;
            }
        }
        let mut best = vec![f64::INFINITY; k];
        for ((&c, &v), &n) in comp.iter().zip(&d).zip(near) {
            if n && c != NONE && v < best[c as usize] {
                best[c as usize] = v;
            }
        }
        for a in 0..k {
            let cells = best[a] / octile_over_euclid - diag;
            lengths[a * k + b] = (cells * res * (1.0 - 1e-9)).max(0.0);
        }
    }
    Some(StepLengths { lengths, k })
}

/// The weight c of the foot-offset potential `Φ = c · Σ_k (o_k⁻ − o_k⁺)` (o_k in metres,
/// o⁻ = max(−o, 0), o⁺ = max(o, 0)) that the hybrid heuristic adds for non-neutral
/// footprints. A foot behind neutral still has to come forward (the goal is neutral);
/// a foot ahead of it has paid in advance for base motion the base-cell cost-to-go
/// (`cost_to_go`) still counts. Φ is consistent on its own share of each manoeuvre:
///
/// - foot to neutral / front foot forward drive one foot by |Δo| at cost
///   `f · k11 · |Δo| · C_F,avg ≥ f · k11 · C_F,min · |Δo|` (eq. 6), and Φ drops by at
///   most `c · |Δo|`;
/// - a step changes one offset by L and costs at least `f · k7 · L` beyond what the step
///   bound uses when the bound keeps only `(1 − λ) · k7`: `c ≤ λ · f · k7`;
/// - a base shift by l cells lowers every offset by l, so Φ *rises* by at least
///   `4 c · l · res` (o⁻ grows or o⁺ shrinks by l, or both add up to l). The cost-to-go
///   spends that rise: its base-shift links weigh `f · k10 · res + 4 c · res`;
/// - drives and turns keep the neutral footprint (Φ = 0).
///
/// Φ is negative for feet ahead of neutral; the heuristic is clamped at zero, and the
/// maximum of zero and a consistent heuristic is consistent.
///
/// Returns `(c, λ)` with λ the smallest share of k7 that pays for c (c = 0 when the
/// constants leave no room). `min_foot_cost` is the smallest finite C_F of the map.
pub fn offset_potential(params: &StepBoundParams, min_foot_cost: f64) -> (f64, f64) {
    let f = params.step_cost_factor;
    let c = (f * params.k11 * min_foot_cost).min(f * params.k7);
    if !(c.is_finite() && c > 0.0) {
        return (0.0, 0.0);
    }
    // c ≤ f · k7 here, so λ ≤ 1.
    (c, (c / (f * params.k7)).min(1.0))
}
