//! What the CLI's commands do, as library functions returning serialisable summaries, so
//! tests call exactly what users run.

pub mod bench;
pub mod check;
pub mod costmap;
pub mod detailed;
pub mod envelope;
pub mod generate;
pub mod plan;
pub mod plan_recording;
pub mod run;
pub mod scaling;
pub mod sim;
