//! Issue 18 #7: `parvo sample` wrapped around (repeat) at u = 0 on a file
//! that `mip --wrap clamp` had recorded as clamp; OpenImageIO's texture
//! system honours the file's modes. The file's modes are now the default
//! and `--wrap` overrides them.

use super::util::{ok, parvo, parvo_stdin, s};

#[test]
fn sampling_uses_the_files_wrap_modes_unless_told_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    // A 4x1 ramp 0, 1/3, 2/3, 1 as a linear f32 EXR, clamp recorded.
    let src = dir.path().join("ramp.exr");
    let v = vec![0.0f32, 1.0 / 3.0, 2.0 / 3.0, 1.0];
    super::util::write_exr(&src, &[("Y", v)], 4, 1);
    let out = dir.path().join("ramp_clamp.exr");
    ok(&parvo(&[
        "mip",
        s(&src),
        "-o",
        s(&out),
        "--wrap",
        "clamp",
        "--type",
        "f32",
    ]));
    // Bilinear at u = 0 (half a texel left of texel 0's centre): clamp
    // gives texel 0 (0), repeat blends texel 3 in (0.5).
    let q = "0 0.5 0 0 0 0\n";
    let at = |extra: &[&str]| -> f32 {
        let mut a = vec!["sample", s(&out), "--filter", "bilinear"];
        a.extend_from_slice(extra);
        ok(&parvo_stdin(&a, q)).trim().parse().unwrap()
    };
    assert_eq!(at(&[]), 0.0, "the recorded clamp");
    assert_eq!(at(&["--wrap", "repeat"]), 0.5, "--wrap overrides");
}
