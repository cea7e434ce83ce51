//! Issue 18 #9: the EXIF orientation of JPEG and TIFF files was ignored.
//! It is now applied on load (as image viewers and `oiiotool --autoorient`
//! do), said on stderr and in `info`, and `--no-auto-orient` keeps the
//! stored order.

use super::util::{TagValue, ok, parvo, s, write_tiff_u8};
use tiff::encoder::colortype::Gray8;

/// EXIF payload (a little-endian TIFF structure) with one Orientation tag.
fn exif(orientation: u16) -> Vec<u8> {
    let mut b = b"II*\0".to_vec();
    b.extend(8u32.to_le_bytes());
    b.extend(1u16.to_le_bytes()); // one entry
    b.extend(0x0112u16.to_le_bytes()); // Orientation
    b.extend(3u16.to_le_bytes()); // SHORT
    b.extend(1u32.to_le_bytes());
    b.extend(orientation.to_le_bytes());
    b.extend([0, 0]);
    b.extend(0u32.to_le_bytes()); // no next IFD
    b
}

#[test]
fn jpeg_exif_orientation_6_turns_the_image_clockwise() {
    use image::ImageEncoder;
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("o.jpg");
    // 32x16 stored: left half black, right half white. Orientation 6 means
    // the stored image is turned 90° clockwise for display: 16x32, the
    // stored left half (black) becomes the top half.
    let px: Vec<u8> = (0..16)
        .flat_map(|_| (0..32).map(|x| if x < 16 { 0 } else { 255 }))
        .collect();
    let mut bytes = Vec::new();
    let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 95);
    enc.set_exif_metadata(exif(6)).unwrap();
    enc.write_image(&px, 32, 16, image::ExtendedColorType::L8)
        .unwrap();
    std::fs::write(&src, &bytes).unwrap();
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    let b = l.base();
    assert_eq!((b.width(), b.height()), (16, 32));
    let v = b.to_linear();
    assert!(v[16 * 4 + 8] < 0.05, "top half black: {}", v[16 * 4 + 8]);
    assert!(
        v[16 * 28 + 8] > 0.9,
        "bottom half white: {}",
        v[16 * 28 + 8]
    );
    assert_eq!(l.info.attribute("Orientation"), Some("6"));
    let keep = parvo::io::load_with(
        s(&src),
        &parvo::io::Limits::default(),
        &parvo::io::LoadOptions {
            auto_orient: false,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((keep.base().width(), keep.base().height()), (32, 16));
    let r = parvo(&["mip", s(&src), "-o", s(&dir.path().join("o.exr"))]);
    ok(&r);
    assert!(String::from_utf8_lossy(&r.stderr).contains("EXIF orientation 6 applied"));
}

#[test]
fn every_tiff_orientation_maps_the_stored_corners_as_exif_defines() {
    let dir = tempfile::tempdir().unwrap();
    // Stored 3x2: a b c / d e f. Displayed (row-major) per orientation, from
    // the EXIF definitions of where row 0 and column 0 go.
    let stored: Vec<u8> = vec![1, 2, 3, 4, 5, 6];
    let want: [(u16, (u32, u32), [u8; 6]); 8] = [
        (1, (3, 2), [1, 2, 3, 4, 5, 6]),
        (2, (3, 2), [3, 2, 1, 6, 5, 4]),
        (3, (3, 2), [6, 5, 4, 3, 2, 1]),
        (4, (3, 2), [4, 5, 6, 1, 2, 3]),
        (5, (2, 3), [1, 4, 2, 5, 3, 6]),
        (6, (2, 3), [4, 1, 5, 2, 6, 3]),
        (7, (2, 3), [6, 3, 5, 2, 4, 1]),
        (8, (2, 3), [3, 6, 2, 5, 1, 4]),
    ];
    for (code, size, texels) in want {
        let src = dir.path().join(format!("o{code}.tif"));
        write_tiff_u8::<Gray8>(
            &src,
            &[(3, 2, stored.clone())],
            &[(274, TagValue::Short(vec![code]))],
        );
        let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
        let b = l.base();
        assert_eq!((b.width(), b.height()), size, "orientation {code}");
        let got: Vec<u8> = b
            .to_linear()
            .iter()
            .map(|v| (v * 255.0).round() as u8)
            .collect();
        assert_eq!(got, texels, "orientation {code}");
    }
}
