//! The `slidebase` command line: parses arguments and dispatches; no physics here.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    match cli::main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, no backtrace: these are user errors (bad flags, bad files) or a
            // solver that reports why it stopped.
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
