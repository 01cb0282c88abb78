//! The hybrid driving-stepping planner (Klamt & Behnke 2017, Sec. V and VII): the paper's
//! "neighbour client" and its front end. It turns cost queries (`cost::CostMaps`) into a
//! [`crate::search::SearchGraph`] that the generic A* / ARA* of `search` search, over the
//! manoeuvres a [`ManoeuvreSet`] gives it (the robot's are `motion::manoeuvres`), and
//! plans on a scenario's world.
//!
//! - [`lattice`]: discrete poses `(i, j, θ index, footprint)` on the height map's grid,
//!   and the 16- / 20-neighbourhood driving moves.
//! - [`orientation`]: the orientation cost factor k_Δθ (Fig. 8).
//! - [`driving`]: the driving graph (moves and turns on the spot, their costs, the
//!   heuristic) and `plan_driving`.
//! - [`footprint`]: footprints (per-leg longitudinal foot offsets) interned as small ids.
//! - [`config`]: the hybrid graph's constants and counters.
//! - [`core`]: what every manoeuvre reads and shares: maps, lattice, footprints, stances
//!   (the shared standing rule), the heuristic's tables.
//! - [`graph`]: the hybrid graph — the [`Manoeuvre`] trait its manoeuvres implement, lazy
//!   edges, and the [`crate::search::SearchGraph`] it is.
//! - [`heuristic`]: the consistent heuristic (cost-to-go, step bound, foot-offset
//!   potential, reachable regions) and the probe's guidance.
//! - [`options`], [`world`], [`plan`]: the front end: a plan's options and errors, the
//!   prepared world (height map, cost maps, start and goal, manoeuvres) shared by a job's
//!   plans, and the search and its summary.

pub mod config;
pub mod core;
pub mod driving;
pub mod footprint;
pub mod graph;
pub mod heuristic;
pub mod lattice;
pub mod options;
pub mod orientation;
pub mod plan;
pub mod world;

#[cfg(test)]
mod tests;

pub use config::{HybridConfig, ManoeuvreStats, PLANNER_MARGIN_SLACK_M};
pub use core::{GraphCore, PoseKey};
pub use driving::{
    DrivingConfig, DrivingGoal, DrivingGraph, DrivingPlanError, PoseCostSource, plan_driving,
};
pub use footprint::{FootOffsets, FootprintTable, NEUTRAL_OFFSETS};
pub use graph::{HybridGraph, Manoeuvre, ManoeuvreSet};
pub use heuristic::{GREEDY_OFFSET_PER_M, HeuristicCache, HeuristicParts};
pub use lattice::{Lattice, LatticeError, LatticeState, Move, NEUTRAL_FOOTPRINT, Neighbourhood};
pub use options::{ParamOverrides, PlanError, PlanOptions};
pub use orientation::OrientationFactor;
pub use plan::{PlanSummary, run, run_on};
pub use world::{
    PAPER_MODEL_FLIGHT_STEPS, Prepared, flight_rule, nearest_start, params_for, prepare,
    prepare_for, scenario_heights, scenario_params, terrain_flights, terrain_models,
};
