//! Issue 18 #13: HDR values above 1 written to an 8- or 16-bit output were
//! clipped without a word. The count of clipped texels is now said once
//! per file.

use super::util::{ok, parvo, s, write_exr};

#[test]
fn clipping_float_values_to_a_normalised_type_is_counted_once() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("hdr.exr");
    // 4x2: two texels above 1 (one at 7.5, one at -0.25 below 0).
    let mut v = vec![0.5f32; 8];
    v[1] = 7.5;
    v[6] = -0.25;
    write_exr(&src, &[("Y", v)], 4, 2);
    let r = parvo(&[
        "mip",
        s(&src),
        "-o",
        s(&dir.path().join("o.ktx2")),
        "--type",
        "u8",
    ]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("clipped")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    // Level 0 has 2, level 1 (2x1) has (0.5+7.5+0.5+0.5)/4 = 2.25 in
    // texel 0 and 0.3125 in texel 1 (clean), level 2 (1x1) has 1.28: 4.
    assert!(lines[0].contains("4 of 11 texels"), "{}", lines[0]);
    // A float output keeps them: nothing said.
    let r = parvo(&["mip", s(&src), "-o", s(&dir.path().join("o.exr"))]);
    assert!(!String::from_utf8_lossy(&r.stderr).contains("clipped"));
}
