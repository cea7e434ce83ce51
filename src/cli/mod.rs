//! Command-line front end: one file per subcommand, beside the pieces
//! they share (`args`, `words`, `progress`, `lookup`), which import no
//! subcommand: files import downward only. Each subcommand's
//! `run` returns the process exit code; errors that stop a whole command
//! are printed here as one line and exit with 1.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod args;
mod cachesim;
mod env;
mod env_mip;
mod images;
mod info;
mod lookup;
mod mip;
mod progress;
mod render;
mod sample;
mod texture;
mod tradeoff;
mod words;

/// Texture filtering and mipmap processing.
#[derive(Parser, Debug)]
#[command(name = "parvo", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// No doc comments on the variants: clap would take them as the
// subcommands' `about` and clear the `long_about` (exit codes, syntax,
// limits) each `*Args` gives with its own `#[command]`.
#[derive(Subcommand, Debug)]
enum Command {
    Mip(mip::MipArgs),
    Info(info::InfoArgs),
    Sample(sample::SampleArgs),
    Cachesim(Box<cachesim::CachesimArgs>),
    Render(render::RenderArgs),
    Tradeoff(Box<tradeoff::TradeoffArgs>),
}

/// Exit status of a process whose output pipe closed (128 + SIGPIPE, as a
/// shell reports a filter the signal ended).
const CLOSED_PIPE: i32 = 141;

/// `parvo … | head`: once the reader has gone, a write to stdout fails
/// with a broken pipe, which `println!` turns into a panic and a
/// backtrace. End the process quietly instead, as a Unix filter ends,
/// with the temporary files being written removed (the destinations are
/// only ever replaced whole). Other panics keep the default report.
fn quiet_on_closed_stdout() {
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        // std's words: "failed printing to stdout: Broken pipe (os error 32)".
        if message.starts_with("failed printing to stdout")
            && message.to_ascii_lowercase().contains("broken pipe")
        {
            parvo::io::atomic::remove_temporary_files();
            std::process::exit(CLOSED_PIPE);
        }
        report(info);
    }));
}

pub fn main() -> ExitCode {
    quiet_on_closed_stdout();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Mip(a) => mip::run(a),
        Command::Info(a) => info::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Cachesim(a) => cachesim::run(*a),
        Command::Render(a) => render::run(a),
        Command::Tradeoff(a) => tradeoff::run(*a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("parvo: {}", words::words(format!("{e:#}")));
            ExitCode::from(1)
        }
    }
}
