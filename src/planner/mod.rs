//! The hybrid driving-stepping planner (Klamt & Behnke 2017, Sec. V and VII): the paper's
//! "neighbour client" and its front end. It turns cost queries (`cost::CostMaps`) into a
//! [`crate::search::SearchGraph`] that the generic A* / ARA* of `search` search, and
//! plans on a scenario's world.
//!
//! - [`lattice`]: discrete poses `(i, j, θ index, footprint)` on the height map's grid,
//!   and the 16- / 20-neighbourhood driving moves.
//! - [`orientation`]: the orientation cost factor k_Δθ (Fig. 8).
//! - [`driving`]: the driving graph (moves and turns on the spot, their costs, the
//!   heuristic) and `plan_driving`.
//! - [`footprint`]: footprints (per-leg longitudinal foot offsets) interned as small ids.
//! - [`cost_to_go`]: the driving part of the hybrid heuristic — a lazy backward Dijkstra
//!   over base cells whose edges relax drives (the smallest pose cost over orientations,
//!   eq. 4) and base shifts; consistent on every manoeuvre.
//! - [`heuristic`]: the informed part of the hybrid heuristic — a lower bound on the step
//!   costs (eq. 5) each foot still needs, and the foot-offset potential; built once per
//!   graph.
//! - [`reachability`]: base cells where the body and legs fit at all, and their
//!   connected regions: states outside the goal's region get an infinite heuristic, so
//!   closed rooms and doorways narrower than the robot are "no path" at once.
//! - [`way`]: how far the feet still have to go over terrain they could climb (no rise
//!   or drop between neighbouring cells beyond a step): the probe's greedy list counts it
//!   where it is longer than the straight line; not a bound.
//! - [`options`], [`world`], [`plan`]: the front end: a plan's options and errors, the
//!   prepared world (height map, cost maps, start and goal) shared by a job's plans, and
//!   the search and its summary.
//! - [`hybrid`]: the full hybrid graph — driving plus abstract steps, base shifts and
//!   single-foot moves (Sec. V), with their costs C_S (eq. 5), C_BS and C_FM (eq. 6).

pub mod cost_to_go;
pub mod driving;
pub mod footprint;
pub mod heuristic;
pub mod hybrid;
pub mod lattice;
pub mod options;
pub mod orientation;
pub mod plan;
pub mod reachability;
pub mod way;
pub mod world;

#[cfg(test)]
mod tests;

pub use driving::{
    DrivingConfig, DrivingGoal, DrivingGraph, DrivingPlanError, PoseCostSource, plan_driving,
};
pub use footprint::{FootOffsets, FootprintTable, NEUTRAL_OFFSETS};
pub use hybrid::{
    HeuristicCache, HeuristicParts, HybridConfig, HybridGraph, ManoeuvreStats, PoseKey,
    base_shift_cost, foot_move_cost, step_cost,
};
pub use lattice::{Lattice, LatticeError, LatticeState, Move, NEUTRAL_FOOTPRINT, Neighbourhood};
pub use options::{ParamOverrides, PlanError, PlanOptions};
pub use orientation::OrientationFactor;
pub use plan::{PlanSummary, run, run_on};
pub use world::{Prepared, nearest_start, prepare, prepare_for};
