//! The closed loop as a library (paper Sec. IX, issue 7): plan a scenario's mission,
//! expand it into keyframes, and execute it in MuJoCo one control tick at a time until the
//! goal is reached or the scenario's time budget runs out.
//!
//! Each 10 ms control tick ([`ClosedLoop::step`]) the step executor
//! (`control::step_executor`) gets the measured base pose (optionally with seeded noise),
//! joints, steering, MuJoCo's CoM and the wheels MuJoCo reports in contact ([`io`]), and
//! returns leg, steering and wheel targets: drive runs with the B-spline path follower,
//! steps and other manoeuvres by tracking the keyframes, with the margin checked before
//! each lift and contact confirmed before weight goes back onto a placed foot. When the
//! executor leaves the plan (step aborted or failed, drift), the robot returns to the
//! driving posture and the loop replans from the simulated pose ([`mission`]: ARA*,
//! time-limited; a bounded number of times). The stability monitor measures the margin of
//! MuJoCo's CoM over the wheels in contact, and keeps measuring for
//! [`run::WATCH_AFTER_STOP_S`] after a failure stops the run; the scenario's expectations
//! decide the verdict ([`summary`]).
//!
//! - [`options`]: what a run may be asked ([`RunOptions`]), pushes and pose noise.
//! - [`mission`]: plan and expand, leaving out what the generator rejects.
//! - [`io`]: the simulation ↔ controller exchange of one tick.
//! - [`run`]: [`ClosedLoop`], and [`run()`] / [`execute`] that drive it to its end.
//! - [`summary`]: [`RunSummary`], [`RunError`] and the expectations.
//!
//! `momaro run`, `check` and `envelope` are thin commands over [`run()`].

pub mod io;
pub mod mission;
pub mod options;
pub mod run;
pub mod summary;

pub use io::stand_at_start;
pub use mission::{Mission, expand_mission, plan_mission};
pub use options::{PoseNoise, Push, PushWhen, RunOptions};
pub use run::{ClosedLoop, Tick, WATCH_AFTER_STOP_S, execute, run};
pub use summary::{ExpectationResult, FailureKind, RunError, RunSummary, StepMargin};
