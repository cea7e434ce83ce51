//! Issue 18 #12: a multi-part EXR (or multi-page TIFF) was read as its
//! first part without a word. The choice is now said on stderr and
//! `--subimage N` picks another.

use super::util::{ok, parvo, s};
use exr::prelude::*;

#[test]
fn a_multi_part_exr_says_which_part_and_subimage_picks_another() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("parts.exr");
    let layer = |name: &str, v: f32| {
        Layer::new(
            (2, 2),
            LayerAttributes::named(name),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
                "Y",
                FlatSamples::F32(vec![v; 4]),
            )])),
        )
    };
    Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((2, 2))),
        vec![layer("first", 0.25), layer("second", 0.75)],
    )
    .write()
    .to_file(&src)
    .unwrap();
    let out = dir.path().join("o.exr");
    let r = parvo(&["mip", s(&src), "-o", s(&out)]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("using part 0 (`first`) of 2"), "{err}");
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear(), [0.25; 4]);
    ok(&parvo(&["mip", s(&src), "-o", s(&out), "--subimage", "1"]));
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear(), [0.75; 4]);
    let r = parvo(&["mip", s(&src), "-o", s(&out), "--subimage", "2"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("the file has 2 parts"));
}

#[test]
fn a_multi_page_tiff_says_which_page_and_subimage_picks_another() {
    use tiff::encoder::colortype::Gray8;
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("pages.tif");
    let mut e = tiff::encoder::TiffEncoder::new(std::fs::File::create(&src).unwrap()).unwrap();
    e.write_image::<Gray8>(2, 2, &[10; 4]).unwrap();
    e.write_image::<Gray8>(3, 1, &[200; 3]).unwrap();
    drop(e);
    let out = dir.path().join("o.exr");
    let r = parvo(&["mip", s(&src), "-o", s(&out)]);
    ok(&r);
    assert!(String::from_utf8_lossy(&r.stderr).contains("multi-page TIFF: using page 0 of 2"));
    ok(&parvo(&["mip", s(&src), "-o", s(&out), "--subimage", "1"]));
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert_eq!((l.base().width(), l.base().height()), (3, 1));
    assert!(
        l.base()
            .to_linear()
            .iter()
            .all(|&v| (v - 200.0 / 255.0).abs() < 1e-3)
    );
}
