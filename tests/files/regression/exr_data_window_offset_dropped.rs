//! Issue 18 #10: an EXR whose data window is not at (0, 0) inside a larger
//! display window lost its offset silently. It is now placed in the
//! display window, black outside, as maketx pads it, and stderr says so.

use super::util::{ok, parvo, s, write_exr_with};

#[test]
fn the_data_window_is_placed_in_the_display_window() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("win.exr");
    // A 3x2 data window at (2, 1) in a 6x4 display window.
    let v: Vec<f32> = (1..=6).map(|i| i as f32).collect();
    write_exr_with(
        &src,
        &[("Y", v)],
        3,
        2,
        exr::prelude::LayerAttributes::default(),
        Some((2, 1, 6, 4)),
    );
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    let b = l.base();
    assert_eq!((b.width(), b.height()), (6, 4));
    #[rustfmt::skip]
    let want = [
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 1.0, 2.0, 3.0, 0.0,
        0.0, 0.0, 4.0, 5.0, 6.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ];
    assert_eq!(b.to_linear(), want);
    let r = parvo(&["mip", s(&src), "-o", s(&dir.path().join("o.exr"))]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("placed in the display window"), "{err}");
    // Overscan beyond the display window is cropped, and said.
    let src = dir.path().join("over.exr");
    write_exr_with(
        &src,
        &[("Y", vec![1.0; 16])],
        4,
        4,
        exr::prelude::LayerAttributes::default(),
        Some((-1, 0, 2, 2)),
    );
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear(), [1.0; 4]);
    assert!(
        l.info.notes[0].contains("12 texels outside the display window are cropped"),
        "{:?}",
        l.info.notes
    );
}
