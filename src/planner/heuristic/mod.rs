//! The hybrid graph's heuristic (issues 4 and 15) and the guidance of ARA*'s probe.
//!
//! - [`cost_to_go`]: the driving part — a lazy backward search over base cells (an A*
//!   aimed at the first query, the start: Dijkstra's distances, fewer nodes) whose
//!   edges relax drives (the smallest pose cost over orientations, eq. 4), turns and base
//!   shifts; consistent on every manoeuvre.
//! - [`step_bound`]: the informed part — a lower bound on the step costs (eq. 5) each foot
//!   still needs, and the foot-offset potential; built once per graph.
//! - [`reachability`]: base cells where the body and legs fit at all, and their
//!   connected regions: states outside the goal's region get an infinite heuristic, so
//!   closed rooms and doorways narrower than the robot are "no path" at once.
//! - [`way`]: how far the feet still have to go over terrain they could climb (no rise
//!   or drop between neighbouring cells beyond a step): the probe's greedy list counts it
//!   where it is longer than the straight line; not a bound.
//! - [`parts`]: how the terms combine ([`HeuristicParts`]); [`tables`]: building them from
//!   what the graph's manoeuvres say of themselves ([`Relaxation`]), and sharing them
//!   between the graphs of a job ([`HeuristicCache`]).
//!
//! **The heuristic**: `max(h_E, D) + S + Φ`, clamped at zero, where
//!
//! 1. `h_E` is that of `planner::DrivingGraph`: Euclidean distance plus the orientation
//!    difference times the turning radius. Steps and foot moves leave the base in place;
//!    drives and base shifts cost at least the distance they move the base (pose costs
//!    ≥ 1, k_Δθ ≥ 1, and a base shift's cost is at least its move); turns cost at least
//!    their arc;
//! 2. `D` is the cost-to-go of the `cost_to_go` module: a lazy backward search (A*,
//!    exact distances) over (cell, orientation) whose edges relax drives (the pose cost
//!    of eq. 4 at that orientation, k_Δθ), turns and base shifts (f · k10 per cell,
//!    plus Φ's rise);
//!    consistent on every manoeuvre, with Φ on base shifts. The larger of two consistent
//!    heuristics is consistent, and both parts leave the same share of each edge's cost
//!    to the parts below (none of drives and turns, Φ's rise on base shifts, all of
//!    steps and foot moves);
//! 3. `S` is the step bound Σ_k S_k of the `step_bound` module: per foot, the cheapest
//!    chain of steps (C_S, eq. 5, times the step-related factor) from the foot's
//!    component of finite-C_F cells to the component of its goal position. Only a step
//!    moves a foot between components, and it costs at least the bound's drop;
//! 4. `Φ = c · Σ_k (o_k⁻ − o_k⁺)` is the foot-offset potential (offsets in metres; zero
//!    for the neutral footprint): a foot behind neutral still has to come forward, one
//!    ahead has paid in advance for base motion `D` counts. Foot moves pay c per metre by
//!    eq. 6 (C_F ≥ the map's smallest), steps by the share λ of eq. 5's k7 term that `S`
//!    leaves out; a base shift raises Φ (`step_bound::offset_potential`).
//!
//! `S` is zero where no step is needed and Φ for the neutral footprint. The proofs are in
//! the `cost_to_go` and `step_bound` module docs; the manoeuvres' tests
//! (`motion::manoeuvres`) check `h(s) ≤ c(s, t) + h(t)` on sampled edges of every manoeuvre
//! near a platform edge and on random walks over random small maps, and that A*'s optimum
//! does not change.

pub mod cost_to_go;
pub mod parts;
pub mod reachability;
pub mod step_bound;
pub mod tables;
pub mod way;

pub use parts::{GREEDY_OFFSET_PER_M, HeuristicParts};
pub use tables::{HeuristicCache, HeuristicTables, Relaxation};
