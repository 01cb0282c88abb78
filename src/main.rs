//! The `momaro` binary: parses the command line and maps outcomes to exit codes:
//! 0 success, 1 a run that failed its checks or a runtime error, 2 invalid input.

use clap::Parser as _;
use momaro::cli::{self, BadInput};
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.chain().any(|c| c.is::<BadInput>()) {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
