//! Step motion generation (Klamt & Behnke 2017, Sec. VI): the abstract path of the hybrid
//! planner expanded into a timed sequence of statically stable, kinematically feasible
//! keyframes — the contract the step executor consumes.
//!
//! - [`roll`]: the base roll of eqs. 6–8 (lateral CoM alignment), a pure function.
//! - [`keyframe`]: [`Keyframe`], [`Phase`], [`DetailedPath`] (serialisable).
//! - [`expand`]: [`expand_path`], the expansion itself (see its docs for every manoeuvre).
//!
//! Postures, their CoM and the standing rule are the `posture` module's.

pub mod expand;
pub mod keyframe;
pub mod roll;

pub use expand::{MotionError, expand_path};
pub use keyframe::{DetailedPath, Keyframe, Phase};
pub use roll::{RollError, RollSolution, roll_for_lateral_com};
