//! Step motion generation (Klamt & Behnke 2017, Sec. VI) and the robot's manoeuvres: the
//! abstract path of the hybrid planner expanded into a timed sequence of statically
//! stable, kinematically feasible keyframes — the contract the step executor consumes.
//!
//! - [`manoeuvres`]: one unit per manoeuvre (drive and turn, step, base shift, wheel
//!   moves): its successors in the planner's lattice, checked by the generator's own
//!   expansion, its heuristic relaxation, and its expansion into keyframes.
//! - [`expander`]: the engine the units append keyframes to, checking every keyframe and
//!   interpolated point (IK, leg clearance, CoM margin) and timing them.
//! - [`expand`]: [`expand_path`], the walk over a path.
//! - [`roll`]: the base roll of eqs. 6–8 (lateral CoM alignment), a pure function.
//! - [`keyframe`]: [`Keyframe`], [`Phase`], [`DetailedPath`] (serialisable).
//!
//! Postures, their CoM and the standing rule are the `posture` module's.

pub mod expand;
pub mod expander;
pub mod keyframe;
pub mod manoeuvres;
pub mod roll;

pub use expand::expand_path;
pub use expander::{Expander, MotionError};
pub use keyframe::{DetailedPath, Keyframe, Phase};
pub use manoeuvres::Manoeuvres;
pub use roll::{RollError, RollSolution, roll_for_lateral_com};
