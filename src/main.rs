//! The `parvo` command-line tool. Exit codes: 0 success; 1 some input
//! failed (the others were still processed); 2 usage error.

// Errors are reported with context, never as panics. Tests may unwrap.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

use std::process::ExitCode;

mod cli;

fn main() -> ExitCode {
    cli::main()
}
