//! Every text parser on arbitrary text: option values (layouts, cache
//! specs, scenes, orders, frames, wrap modes, filters, sampler names,
//! `builtin:` names) and trace lines. Parsing never panics; what parses
//! prints back to something that parses to the same value.
//!
//! The body of `fuzz/fuzz_targets/parsers.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/parsers` and every kept artifact in the checks-on test build.

use parvo::Wrap;
use parvo::cache::layout::Layout;
use parvo::cache::sim::CacheConfig;
use parvo::mip::MipFilter;
use parvo::sample::SamplerOptions;
use parvo::scene::{Frame, RasterOrder, Scene};

/// One input of the `parsers` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    let Ok(s) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(l) = s.parse::<Layout>() {
        assert_eq!(
            l.to_string().parse::<Layout>().ok(),
            Some(l),
            "layout {s:?}"
        );
    }
    let _ = s.parse::<CacheConfig>();
    if let Ok(sc) = s.parse::<Scene>() {
        let _ = sc.to_string().parse::<Scene>();
    }
    let _ = s.parse::<RasterOrder>();
    let _ = s.parse::<Frame>();
    let _ = s.parse::<Wrap>();
    let _ = s.parse::<MipFilter>();
    let _ = SamplerOptions::from_name(s);
    // Parse only: generating a built-in may be large.
    let _ = parvo::builtin::parse(s);
    let _ = parvo::cache::run::read_trace(s.as_bytes(), &mut |_| {});
}
