//! The robot's manoeuvres, one unit each: how the planner offers a manoeuvre (its
//! successors in the hybrid lattice, checked by the motion generator's own expansion,
//! and which heuristic term bounds it), and how the motion generator expands it into
//! keyframes.
//!
//! - [`drive`]: driving and turning on the spot in the neutral footprint (Fig. 4).
//! - [`step`]: the abstract step (Fig. 5, 6a), its lazy checks and its motion (Sec. VI-A).
//! - [`base_shift`]: the longitudinal base shift (Fig. 6b) and its variants for stairs
//!   and descents.
//! - [`wheel_move`]: front foot forward and foot to neutral (Fig. 6c, d).
//! - [`unit`]: what a unit is ([`Unit`]); [`registry`]: the units, in the planner's
//!   order ([`MANOEUVRES`]).
//!
//! Adding a manoeuvre: a new file implementing [`Unit`] (and `planner::Manoeuvre` for
//! its planner side), and one entry in [`MANOEUVRES`].

pub mod base_shift;
pub mod drive;
pub mod registry;
pub mod step;
pub mod unit;
pub mod wheel_move;

#[cfg(test)]
mod tests;

pub use registry::{ALL, MANOEUVRES, Manoeuvres, unit_for};
pub use unit::Unit;
