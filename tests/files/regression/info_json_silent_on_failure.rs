//! Issue 18, smaller points: `info --json` printed nothing for a file that
//! failed (`mip --json` prints an object with the error); a container that
//! cannot store the asked type exited 1 like a failed input instead of 2
//! (usage); an opaque RGB or grey DDS said nothing about its alpha.

use super::util::{ok, parvo, s};

#[test]
fn info_json_prints_an_object_for_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"not a png").unwrap();
    let r = parvo(&["info", "--json", "builtin:checker:8", s(&bad)]);
    assert_eq!(r.status.code(), Some(1));
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&r.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0]["status"], "ok");
    assert_eq!(lines[1]["status"], "failed");
    assert_eq!(lines[1]["file"], s(&bad));
    assert!(lines[1]["error"].as_str().unwrap().len() > 5);
}

#[test]
fn a_type_the_container_cannot_store_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    for (name, ty) in [("o.exr", "u8"), ("o_{level}.png", "f16")] {
        let out = dir.path().join(name);
        let r = parvo(&["mip", "builtin:checker:8", "-o", s(&out), "--type", ty]);
        assert_eq!(r.status.code(), Some(2), "{name} --type {ty}");
        assert!(String::from_utf8_lossy(&r.stderr).contains("cannot store"));
    }
}

#[test]
fn opaque_rgb_and_grey_dds_record_alpha_mode_opaque() {
    let dir = tempfile::tempdir().unwrap();
    for (name, src) in [("rgb.dds", "rgb.png"), ("grey.dds", "grey.png")] {
        let p = dir.path().join(src);
        let (px, ty) = if src == "rgb.png" {
            (vec![10u8; 4 * 4 * 3], image::ExtendedColorType::Rgb8)
        } else {
            (vec![10u8; 4 * 4], image::ExtendedColorType::L8)
        };
        image::save_buffer(&p, &px, 4, 4, ty).unwrap();
        let out = dir.path().join(name);
        // 8-bit PNG said to be sRGB: stored as R8G8B8A8_UNORM_SRGB, alpha
        // 255 (an untagged grey file is data by default since issue 53,
        // stored as R8).
        ok(&parvo(&["mip", s(&p), "--color", "srgb", "-o", s(&out)]));
        let b = std::fs::read(&out).unwrap();
        let word = |i: usize| u32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
        assert_eq!(word(32), 29, "{name}: DXGI R8G8B8A8_UNORM_SRGB");
        assert_eq!(word(36), 3, "{name}: DDS_ALPHA_MODE_OPAQUE");
        let j: serde_json::Value =
            serde_json::from_str(&ok(&parvo(&["info", "--json", s(&out)]))).unwrap();
        assert_eq!(j["attributes"]["dds:alphaMode"], "opaque", "{name}");
    }
}
