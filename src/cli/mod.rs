//! The command line: clap definitions ([`args`]) and one function per command, each a thin
//! call into `jobs` (or `closed_loop`) and the printing of its summary. Errors surface here
//! as `anyhow` with context; `main` maps them to exit codes ([`report`]).

/// Prints a line to stdout; a closed pipe (`momaro ... | head`) is not an error worth a
/// panic, so write errors are ignored.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

pub mod args;
pub mod bench;
pub mod plan;
pub mod report;
pub mod suite;
pub mod world;

pub use args::{Cli, Command};
pub use report::BadInput;

use args::{BenchCommand, EnvelopeCommand};

/// Runs the command `cli` names: `Ok(false)` for a run that failed its checks (exit 1).
///
/// # Errors
/// Bad input ([`BadInput`], exit 2) or a job that could not be carried out (exit 1).
pub fn run(cli: Cli) -> anyhow::Result<bool> {
    match cli.command {
        Command::Sim(a) => world::sim(a),
        Command::Costmap(a) => world::costmap(a),
        Command::Plan(a) => plan::plan(a),
        Command::Run(a) => plan::run(a),
        Command::Check(a) => suite::check_cmd(a),
        Command::Envelope(EnvelopeCommand::Stairs(a)) => suite::envelope_stairs_cmd(a),
        Command::Bench(BenchCommand::Plan(a)) => bench::bench_plan(a),
        Command::Bench(BenchCommand::Probe(a)) => bench::bench_probe(a),
        Command::Bench(BenchCommand::Sim(a)) => bench::bench_sim(a),
        Command::Bench(BenchCommand::Scaling(a)) => bench::bench_scaling(a),
        Command::Generate(a) => world::generate(a),
        Command::Urdf(a) => world::urdf(a),
    }
}
