//! Generic graph search: A* and ARA* over a small trait. Knows nothing of robots.
//!
//! The hybrid locomotion planner (`planner`) implements [`SearchGraph`] for its pose
//! lattice (the paper's "neighbour client") and calls [`astar`] or [`arastar`]
//! (Klamt & Behnke 2017, Sec. V and VII-B). The design follows SBPL's split — the search
//! knows states only as opaque values, the graph owns successors, costs and the
//! heuristic; parameters and results are plain structs — with one algorithm per file as
//! in the `pathfinding` crate, and Nav2 smac's cancel check and expansion log.
//!
//! - [`cost`]: [`Cost`], fixed-point costs (10⁶ micro-units per unit, saturating).
//! - [`graph`]: the [`SearchGraph`] trait and its contract (admissible / consistent h).
//! - [`params`]: [`SearchParams`] (ε schedule, time / expansion / state limits).
//! - [`result`]: [`SearchResult`], [`Solution`], [`Termination`], [`Hooks`].
//! - `astar`: optimal A* with re-opening.
//! - `arastar`: ARA* (Likhachev, Gordon & Thrun 2003).
//! - `engine`, `nodes`, `open_list` (private): the shared `ImprovePath` loop, compact
//!   node records behind a deterministic hash map, and the lazy-deletion binary heap.
//!
//! # Determinism
//! Costs and keys are integers; OPEN ties are broken by smaller `h`, then by discovery
//! order; no hash map is ever iterated. The same graph (with deterministic successor
//! order) gives the same paths bit for bit.
//!
//! # Example
//! ```
//! # use momaro::search::*;
//! /// A line 0 → 1 → … → 10, each step costing one unit.
//! struct Line;
//! impl SearchGraph for Line {
//!     type State = u32;
//!     fn successors(&mut self, s: u32, out: &mut Vec<(u32, Cost)>) {
//!         if s < 10 { out.push((s + 1, Cost::ONE)); }
//!     }
//!     fn heuristic(&self, s: u32) -> Cost { Cost(u64::from(10 - s.min(10)) * Cost::SCALE) }
//!     fn is_goal(&self, s: u32) -> bool { s == 10 }
//! }
//! let result = arastar(&mut Line, 0, &SearchParams::default()).unwrap();
//! assert_eq!(result.best().unwrap().cost, Cost::from_f64(10.0));
//! assert_eq!(result.termination, Termination::OptimalProven);
//! ```

pub mod fixed_point;
pub mod graph;
pub mod params;
pub mod result;

mod arastar;
mod astar;
mod engine;
mod nodes;
mod open_list;

#[cfg(test)]
mod tests;

pub use arastar::{arastar, arastar_with_hooks};
pub use astar::{astar, astar_with_hooks};
pub use fixed_point::Cost;
pub use graph::SearchGraph;
pub use nodes::{FxBuild, FxHasher};
pub use params::{Algorithm, EPS_SCALE, ParamsError, SearchParams};
pub use result::{
    ExpandHook, Expansion, Hooks, SearchError, SearchResult, Solution, SolutionHook, Termination,
};
