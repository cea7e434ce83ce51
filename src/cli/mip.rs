//! `parvo mip` (being written; see its issue).

use std::process::ExitCode;

/// Arguments of `parvo mip`.
#[derive(clap::Args, Debug)]
pub struct MipArgs {}

pub fn run(_args: MipArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`parvo mip` is not implemented yet")
}
