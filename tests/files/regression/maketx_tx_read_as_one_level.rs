//! Issue 18 #4: maketx's default output, the `.tx` file (a tiled,
//! mip-mapped TIFF), read as one level with no tiles, no wrap modes and
//! straight alpha. Every directory of a TIFF with Pixar's `textureformat`
//! tag is now a mip level, with the `wrapmodes` tag and the tiling (the
//! tiled maketx file itself is checked in scripts/interop/tiff.py).

use super::util::{TagValue, ok, parvo, s, write_tiff_u8};
use tiff::encoder::colortype::Gray8;

#[test]
fn a_textureformat_tiff_reads_with_every_level_and_its_wrap_modes() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("t.tx");
    // 5x3 → 2x1 → 1x1, each level a constant 10·(k + 1).
    let dirs: Vec<(u32, u32, Vec<u8>)> = [(5u32, 3u32), (2, 1), (1, 1)]
        .iter()
        .enumerate()
        .map(|(k, &(w, h))| (w, h, vec![10 * (k as u8 + 1); (w * h) as usize]))
        .collect();
    let tags = [
        (33302, TagValue::Ascii("Plain Texture".into())),
        (33303, TagValue::Ascii("clamp,mirror".into())),
    ];
    write_tiff_u8::<Gray8>(&src, &dirs, &tags);
    let j: serde_json::Value =
        serde_json::from_str(&ok(&parvo(&["info", "--json", s(&src)]))).unwrap();
    let levels: Vec<(u64, u64)> = j["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| (l["width"].as_u64().unwrap(), l["height"].as_u64().unwrap()))
        .collect();
    assert_eq!(levels, [(5, 3), (2, 1), (1, 1)]);
    assert_eq!(j["wrapmodes"], "clamp,mirror");
    assert_eq!(j["attributes"]["textureformat"], "Plain Texture");
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    for (k, lv) in l.levels.iter().enumerate() {
        let want = 10.0 * (k as f32 + 1.0) / 255.0;
        assert!(
            lv.to_linear().iter().all(|&v| (v - want).abs() < 1e-6),
            "level {k}"
        );
    }
    // Without the tag the directories are pages, not levels.
    let pages = dir.path().join("pages.tif");
    write_tiff_u8::<Gray8>(&pages, &dirs, &[]);
    let r = parvo(&["mip", s(&pages), "-o", s(&dir.path().join("o.exr"))]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("multi-page TIFF: using page 0 of 3"), "{err}");
    let o = dir.path().join("p1.exr");
    ok(&parvo(&["mip", s(&pages), "-o", s(&o), "--subimage", "1"]));
    let l = parvo::io::load(s(&o), &parvo::io::Limits::default()).unwrap();
    assert_eq!((l.base().width(), l.base().height()), (2, 1));
}
