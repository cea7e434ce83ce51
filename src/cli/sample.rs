//! `parvo sample` (being written; see its issue).

use std::process::ExitCode;

/// Arguments of `parvo sample`.
#[derive(clap::Args, Debug)]
pub struct SampleArgs {}

pub fn run(_args: SampleArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`parvo sample` is not implemented yet")
}
