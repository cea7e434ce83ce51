//! Command-line front end: one file per subcommand. Each subcommand's
//! `run` returns the process exit code; errors that stop a whole command
//! are printed here as one line and exit with 1.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cachesim;
mod env;
mod env_mip;
mod images;
mod info;
mod mip;
mod render;
mod sample;
mod texture;
mod tradeoff;

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

/// The flag of each setting a library message names.
fn flag(s: parvo::setting::Setting) -> &'static str {
    use parvo::setting::Setting;
    match s {
        Setting::MaxWidth => "--max-width",
        Setting::MaxHeight => "--max-height",
        Setting::MaxAlloc => "--max-alloc",
        Setting::Channels => "--channels",
        Setting::Subimage => "--subimage",
        Setting::Color => "--color",
        Setting::NoAutoOrient => "--no-auto-orient",
        Setting::Wrap => "--wrap",
        Setting::Levels => "--levels",
        Setting::Alpha => "--alpha",
    }
}

/// Library text (an error, a note) in the command line's words: each
/// setting it names as its flag.
pub(crate) fn words(text: impl std::fmt::Display) -> String {
    parvo::setting::respell(&text.to_string(), flag)
}

/// The CLI's words for a library error: the error and, where a flag
/// deals with it, that flag.
pub(crate) fn error_text(e: &parvo::Error) -> String {
    if let parvo::Error::Usage(u) = e {
        return format!("invalid option: {}", mip::usage_text(u));
    }
    let hint = match e {
        parvo::Error::NonFinite { .. } => {
            Some("--fixnan black or --fixnan neighbors replaces such values")
        }
        _ => None,
    };
    match hint {
        Some(h) => format!("{} ({h})", words(e)),
        None => words(e),
    }
}

/// [`error_text`] as an error of the CLI.
pub(crate) fn with_hint(e: parvo::Error) -> anyhow::Error {
    anyhow::anyhow!(error_text(&e))
}

/// Progress bar templates: a count of steps, and a percentage.
pub(crate) const BAR_COUNT: &str = "{bar:40} {pos}/{len} {msg} {elapsed_precise}";
/// Batches of files in `parvo mip`.
pub(crate) const BAR_FILES: &str = "{bar:40} {pos}/{len} files {elapsed_precise} {msg}";
/// A single file's texels in `parvo mip`.
pub(crate) const BAR_PERCENT: &str = "{bar:40} {percent:>3}% {elapsed_precise} {msg}";

/// The progress bar style of one of the templates above.
pub(crate) fn bar_style(template: &str) -> anyhow::Result<indicatif::ProgressStyle> {
    use anyhow::Context;
    indicatif::ProgressStyle::with_template(template)
        .with_context(|| format!("progress bar template `{template}`"))
}

/// Ctrl-C: delete the temporary files being written (destinations are
/// only ever replaced by a complete file) and exit like a shell does.
pub(crate) fn remove_temporary_files_on_interrupt() {
    let _ = ctrlc::set_handler(|| {
        parvo::io::atomic::remove_temporary_files();
        eprintln!("parvo: interrupted; no output was left half-written");
        std::process::exit(130);
    });
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
            eprintln!("parvo: {}", words(format!("{e:#}")));
            ExitCode::from(1)
        }
    }
}

#[cfg(test)]
mod tests {
    /// The bars are drawn only on a terminal, where no test looks: parse
    /// every template here.
    #[test]
    fn progress_bar_templates_parse() {
        for t in [super::BAR_COUNT, super::BAR_FILES, super::BAR_PERCENT] {
            super::bar_style(t).unwrap();
        }
    }
}
