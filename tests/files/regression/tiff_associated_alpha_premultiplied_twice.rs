//! Issue 18 #3: a TIFF with ExtraSamples = 1 (associated alpha, what
//! OpenImageIO and maketx write) was taken as straight and premultiplied
//! again: colour 0.25 / alpha 0.5 came out 0.125 (maketx: 0.25), and
//! re-mipping a maketx `.tx` darkened colour by 1/alpha. ExtraSamples now
//! decides: 1 associated, 2 unassociated, 0 not alpha at all.

use super::util::{TagValue, ok, parvo, png_u16, s, write_exr, write_tiff_u8};
use tiff::encoder::colortype::RGBA8;

const EXTRA_SAMPLES: u16 = 338;

fn rgba(path: &std::path::Path, extra: Option<u16>) {
    let px: Vec<u8> = [64u8, 32, 16, 128].repeat(4 * 4);
    let tags: Vec<(u16, TagValue)> = extra
        .map(|e| vec![(EXTRA_SAMPLES, TagValue::Short(vec![e]))])
        .unwrap_or_default();
    write_tiff_u8::<RGBA8>(path, &[(4, 4, px)], &tags);
}

fn exr_level0(path: &std::path::Path) -> Vec<f32> {
    parvo::io::load(s(path), &parvo::io::Limits::default())
        .unwrap()
        .base()
        .to_linear()[..4]
        .to_vec()
}

#[test]
fn extra_samples_decide_the_alpha_association() {
    let dir = tempfile::tempdir().unwrap();
    let _ = write_exr;
    let (c, a) = (64.0f32 / 255.0, 128.0f32 / 255.0);
    for (extra, want_exr_r, want_png_r, what) in [
        // Associated: EXR (premultiplied) keeps 0.25; PNG (straight) 0.5.
        (Some(1), c, c / a, "associated"),
        // Unassociated: EXR premultiplies to 0.125; PNG keeps 0.25.
        (Some(2), c * a, c, "unassociated"),
        // No tag: OpenImageIO's assumption, associated.
        (None, c, c / a, "no ExtraSamples"),
    ] {
        let src = dir.path().join(format!("{what}.tif"));
        rgba(&src, extra);
        let exr = dir.path().join(format!("{what}.exr"));
        ok(&parvo(&["mip", s(&src), "-o", s(&exr), "--type", "f32"]));
        let v = exr_level0(&exr);
        assert!(
            (v[0] - want_exr_r).abs() < 1e-6,
            "{what}: EXR R {} vs {want_exr_r}",
            v[0]
        );
        assert!((v[3] - a).abs() < 1e-6, "{what}: EXR A");
        let png = dir.path().join(format!("{what}_{{level}}.png"));
        ok(&parvo(&["mip", s(&src), "-o", s(&png)]));
        let (_, _, _, p) = png_u16(&dir.path().join(format!("{what}_0.png")));
        let got = p[0] as f32 / 65535.0;
        assert!(
            (got - want_png_r).abs() <= 0.5 / 255.0 + 1e-6,
            "{what}: PNG R {got} vs {want_png_r}"
        );
    }
    // ExtraSamples = 0: the fourth channel is not alpha but data, read as
    // a fourth channel (tiff_rgb_data_sample_dropped.rs).
    let src = dir.path().join("data.tif");
    rgba(&src, Some(0));
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().channels(), 4);
    assert!(!l.base().format().has_alpha());
}
