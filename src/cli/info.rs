//! `parvo info` (being written; see its issue).

use std::process::ExitCode;

/// Arguments of `parvo info`.
#[derive(clap::Args, Debug)]
pub struct InfoArgs {}

pub fn run(_args: InfoArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`parvo info` is not implemented yet")
}
