//! Progress bars and interrupts, as every long command draws and handles
//! them.

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
