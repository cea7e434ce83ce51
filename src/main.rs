//! The `parvo` command-line tool. Exit codes: 0 success; 1 some input
//! failed (the others were still processed); 2 usage error.

use std::process::ExitCode;

mod cli;

fn main() -> ExitCode {
    cli::main()
}
