//! What the CLI's commands do, as library functions returning serialisable summaries, so
//! tests call exactly what users run.

pub mod sim;
