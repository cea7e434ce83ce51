//! Found by the `decode_and_mip` fuzz target: an OpenEXR file with an 8x8
//! data window in an 83886074x8 display window passed the decoder limits
//! (only the data window was checked) and placing level 0 in its display
//! window allocated about 18 GB. The display window is now held to the
//! limits as well. The file is the fuzzer's input (its first byte picks
//! the extension in the target).

use parvo::io::{self, Limits};

const INPUT: &[u8] = include_bytes!("../../../fuzz/seeds/decode_and_mip/exr_display_window_huge");

#[test]
fn a_huge_display_window_is_refused_by_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("dw.exr");
    std::fs::write(&p, &INPUT[1..]).unwrap();
    for limits in [
        Limits::default(),
        Limits {
            max_width: 512,
            max_height: 512,
            max_alloc: 16 << 20,
        },
    ] {
        let err = match io::load(p.to_str().unwrap(), &limits) {
            Ok(l) => panic!(
                "loaded a {}x{} level",
                l.levels[0].width(),
                l.levels[0].height()
            ),
            Err(e) => e.to_string(),
        };
        assert!(err.contains("83886074x8"), "{err}");
    }
}
