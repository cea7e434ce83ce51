//! Issue 18 #1: `parvo mip rgba.exr -o 'lv_{level}.png'` kept the EXR's
//! premultiplied colour in the PNG, whose alpha is straight by definition
//! (texel (0.147, 0.121, 0.096, a = 0.244) came out as 0.147, oiiotool
//! writes 0.147 / 0.244 = 0.602). KTX2 and DDS keep the association and
//! say so in their headers.

use super::util::{ok, parvo, png_u16, s, write_exr};

#[test]
fn png_levels_of_a_premultiplied_exr_are_unpremultiplied() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("rgba.exr");
    let n = 4 * 2;
    let px = [0.147f32, 0.121, 0.096, 0.244];
    let ch = |c: usize| vec![px[c]; n];
    write_exr(
        &src,
        &[("R", ch(0)), ("G", ch(1)), ("B", ch(2)), ("A", ch(3))],
        4,
        2,
    );
    let out = dir.path().join("lv_{level}.png");
    ok(&parvo(&["mip", s(&src), "-o", s(&out)]));
    // A float source gives 16-bit linear PNG codes.
    let (w, h, c, v) = png_u16(&dir.path().join("lv_0.png"));
    assert_eq!((w, h, c), (4, 2, 4));
    let code = |x: f64| (x * 65535.0).round() as u16;
    let want = [
        code(0.147f32 as f64 / 0.244f32 as f64),
        code(0.121f32 as f64 / 0.244f32 as f64),
        code(0.096f32 as f64 / 0.244f32 as f64),
        code(0.244f32 as f64),
    ];
    for p in v.chunks(4) {
        for (got, want) in p.iter().zip(want) {
            assert!(got.abs_diff(want) <= 1, "{p:?} vs {want:?}");
        }
    }
    // The last level (1x1) of a constant image is the same texel.
    let (_, _, _, v) = png_u16(&dir.path().join("lv_2.png"));
    assert!(v[0].abs_diff(want[0]) <= 1, "{v:?}");
}

#[test]
fn ktx2_and_dds_keep_premultiplied_colour_and_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("rgba.exr");
    let ch = |v: f32| vec![v; 4];
    write_exr(
        &src,
        &[
            ("R", ch(0.1)),
            ("G", ch(0.2)),
            ("B", ch(0.3)),
            ("A", ch(0.5)),
        ],
        2,
        2,
    );
    for name in ["o.ktx2", "o.dds"] {
        let out = dir.path().join(name);
        ok(&parvo(&["mip", s(&src), "-o", s(&out)]));
        let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
        assert_eq!(
            l.base().format().alpha,
            parvo::AlphaMode::Premultiplied,
            "{name}"
        );
        let v = l.base().to_linear();
        assert!(
            (v[0] - 0.1).abs() < 1e-3 && (v[3] - 0.5).abs() < 1e-3,
            "{name}: {v:?}"
        );
    }
}
