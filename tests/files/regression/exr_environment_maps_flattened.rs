//! Issue 27 #12: OpenEXR environment maps (`envmap` cube or lat-long,
//! `textureformat` "CubeFace Environment" / "LatLong Environment", as
//! openexr-images' KernerEnvCube.exr and KernerEnvLatLong.exr) were
//! silently flattened: `parvo mip` filtered a cube's six-face strip as one
//! image, blending the faces into each other, and wrote it back as "Plain
//! Texture" with periodic wrap. `mip` first refused them with an error
//! naming the kind; since issue 30 it builds them as what they are (each
//! cube face filtered on its own, the output marked as an environment)
//! and refuses only outputs that cannot hold the kind. `info` reads them
//! and says what they are. A maketx `.tx` lat-long map (TIFF) is built
//! as one too; a `.tx` cube (faces laid out 3x2) is refused in words.

use super::util::{TagValue, ok, parvo, s, write_tiff_u8};
use exr::prelude::*;

/// A tiled RGBA half EXR of `w`×`h` (the Kerner files' channels and
/// tiling; they are mip-mapped too) with the given layer attributes.
fn env_exr(path: &std::path::Path, w: usize, h: usize, attrs: LayerAttributes) {
    let layer = Layer::new(
        (w, h),
        attrs,
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::Tiles(Vec2(8, 8)),
            line_order: LineOrder::Increasing,
        },
        SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            // Each cube face its own colour.
            let face = (y / w) as f32;
            (
                f16::from_f32(face / 6.0),
                f16::from_f32(x as f32 / w as f32),
                f16::from_f32(0.5),
                f16::ONE,
            )
        }),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// `mip` keeps the environment an environment (never a plain texture);
/// an output that cannot hold its kind is refused, saying `why`, and
/// nothing is written; `info` says what it is.
fn not_flattened(src: &std::path::Path, kind: &str, id: &str, plain_out: &str, why: &str) {
    let out = src.with_extension("out.exr");
    ok(&parvo(&["mip", s(src), "-o", s(&out)]));
    let j: serde_json::Value =
        serde_json::from_str(&ok(&parvo(&["info", "--json", s(&out)]))).unwrap();
    assert_eq!(
        j["kind"], id,
        "the output is still a {kind} environment map"
    );
    let bad = src.with_file_name(plain_out);
    let r = parvo(&["mip", s(src), "-o", s(&bad)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(
        r.status.code(),
        Some(1),
        "a plain output must be refused: {err}"
    );
    assert!(err.contains(why), "the error says why: {err}");
    assert!(!bad.exists(), "nothing is written");
    assert!(
        !src.with_file_name("plain_0.png").exists(),
        "nothing is written"
    );
    let j: serde_json::Value =
        serde_json::from_str(&ok(&parvo(&["info", "--json", s(src)]))).unwrap();
    assert_eq!(j["status"], "ok");
    let notes = j["notes"].to_string();
    assert!(
        notes.contains(&format!("{kind} environment map")),
        "info says what it is: {notes}"
    );
}

#[test]
fn a_cube_face_exr_is_built_as_a_cube_map_and_described_by_info() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("cube.exr");
    let attrs = LayerAttributes {
        environment_map: Some(attribute::EnvironmentMap::Cube),
        ..LayerAttributes::default()
    };
    env_exr(&src, 16, 96, attrs);
    // One PNG per level holds a cube map's faces only with {face} in the
    // name.
    not_flattened(
        &src,
        "cube-face",
        "cube",
        "plain_{level}.png",
        "needs {face}",
    );
    // No face blends into another: level 1 of face f keeps its red, f/6.
    let out = src.with_extension("out.exr");
    let lvl1 = parvo::io::load_with(
        s(&out),
        &parvo::io::Limits::default(),
        &parvo::io::LoadOptions {
            environment: parvo::io::EnvironmentMaps::Accept,
            ..Default::default()
        },
    )
    .unwrap()
    .levels[1]
        .clone();
    // (Two texels off the face edges: the edge fix-up averages edge
    // texels with the texels across the edge, by design, and OpenEXR's
    // placement puts the next texels half a texel further out.)
    for (f, face) in parvo::env::cube::faces_from_strip(&lvl1)
        .unwrap()
        .iter()
        .enumerate()
    {
        let n = face.width();
        for j in 2..n - 2 {
            for i in 2..n - 2 {
                let t = face.texel_linear(i, j);
                assert!(
                    (t[0] - f as f32 / 6.0).abs() < 1e-3,
                    "face {f} texel ({i},{j}): {t:?}"
                );
            }
        }
    }
    let j: serde_json::Value =
        serde_json::from_str(&ok(&parvo(&["info", "--json", s(&src)]))).unwrap();
    // The six faces are read as stored, not cropped or padded.
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(16), Some(96))
    );
    assert!(j["notes"].to_string().contains("six 16x16 faces"));
}

#[test]
fn a_lat_long_exr_named_by_textureformat_is_built_as_a_lat_long_map() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("latlong.exr");
    let mut attrs = LayerAttributes::default();
    attrs.other.insert(
        Text::from("textureformat"),
        AttributeValue::Text(Text::from("LatLong Environment")),
    );
    env_exr(&src, 32, 16, attrs);
    not_flattened(&src, "lat-long", "latlong", "plain.ktx2", "cannot store a");
}

/// A maketx-style `.tx` (TIFF mip levels) tagged with `textureformat`.
fn maketx_tiff(path: &std::path::Path, format: &str, w: u32, h: u32) {
    use tiff::encoder::colortype::RGB8;
    let mut dirs = vec![];
    let (mut lw, mut lh) = (w, h);
    loop {
        dirs.push((lw, lh, vec![100; (lw * lh * 3) as usize]));
        if lw == 1 && lh == 1 {
            break;
        }
        (lw, lh) = ((lw / 2).max(1), (lh / 2).max(1));
    }
    write_tiff_u8::<RGB8>(path, &dirs, &[(33302, TagValue::Ascii(format.into()))]);
}

#[test]
fn a_maketx_lat_long_tiff_is_built_as_a_lat_long_map() {
    // maketx --envlatl writes a .tx: `mip` builds it as the lat-long map it
    // is (the output an environment map), never as a flat image.
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("env.tx");
    maketx_tiff(&src, "LatLong Environment", 8, 4);
    not_flattened(&src, "lat-long", "latlong", "plain.ktx2", "cannot store a");
}

#[test]
fn a_maketx_cube_face_tiff_is_refused_by_mip() {
    // maketx lays a TIFF cube's faces out 3x2, which parvo does not build
    // from: refused in words rather than flattened.
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("cube.tx");
    maketx_tiff(&src, "CubeFace Environment", 24, 16);
    let out = src.with_extension("out.exr");
    let r = parvo(&["mip", s(&src), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "mip must refuse: {err}");
    assert!(
        err.contains("cube-face environment map"),
        "the error names the kind: {err}"
    );
    assert!(!out.exists(), "nothing is written");
}

#[test]
fn a_plain_texture_exr_is_not_taken_for_an_environment_map() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("plain.exr");
    let mut attrs = LayerAttributes::default();
    attrs.other.insert(
        Text::from("textureformat"),
        AttributeValue::Text(Text::from("Plain Texture")),
    );
    env_exr(&src, 16, 8, attrs);
    ok(&parvo(&[
        "mip",
        s(&src),
        "-o",
        s(&dir.path().join("o.exr")),
    ]));
}
