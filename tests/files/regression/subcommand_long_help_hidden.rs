//! Found while linking docs/limits.md from `parvo mip --help` (issue 16):
//! no subcommand's `--help` showed its long description (exit codes, the
//! cache spec and layout syntax, the outputs written), because the doc
//! comments on the CLI's subcommand enum replaced each command's
//! `about` and cleared its `long_about`. `-h` keeps the one-line summary.

use super::util::parvo;

#[test]
fn every_subcommand_help_shows_its_long_description() {
    for (cmd, long) in [
        ("mip", "docs/limits.md"),
        ("mip", "Exit codes: 0 every input succeeded"),
        ("info", "Exit codes: 0 every file read"),
        ("sample", "one per line: `u v dudx dvdx dudy dvdy`"),
        ("cachesim", "Cache spec: SIZE:LINE:WAYS[:POLICY]"),
        ("render", "--filter reference: the scene's exact mapping"),
        ("tradeoff", "DIR/report.json"),
    ] {
        let o = parvo(&[cmd, "--help"]);
        assert!(o.status.success(), "{cmd} --help");
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains(long), "{cmd} --help lacks `{long}`:\n{text}");
        let short = parvo(&[cmd, "-h"]);
        let short = String::from_utf8_lossy(&short.stdout);
        assert!(!short.contains(long), "{cmd} -h shows the long text");
    }
}
