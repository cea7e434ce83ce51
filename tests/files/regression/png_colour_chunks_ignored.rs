//! Issue 18 #11: PNG colour chunks were ignored (8-bit was always sRGB,
//! 16-bit always linear) and parvo's PNG levels carried none, so readers
//! could not tell linear levels from sRGB ones. `--color auto` now reads
//! sRGB, cICP and gAMA as OpenImageIO does, and every PNG level says its
//! transfer.

use super::util::{ok, parvo, s};
use parvo::ColorSpace;

fn png(path: &std::path::Path, depth: png::BitDepth, chunk: &str) {
    let f = std::fs::File::create(path).unwrap();
    let mut e = png::Encoder::new(f, 2, 1);
    e.set_color(png::ColorType::Grayscale);
    e.set_depth(depth);
    match chunk {
        "gAMA 1.0" => e.set_source_gamma(png::ScaledFloat::new(1.0)),
        "gAMA 0.45455" => e.set_source_gamma(png::ScaledFloat::from_scaled(45455)),
        "sRGB" => e.set_source_srgb(png::SrgbRenderingIntent::Perceptual),
        _ => {}
    }
    let mut w = e.write_header().unwrap();
    let data: Vec<u8> = if depth == png::BitDepth::Eight {
        vec![10, 200]
    } else {
        vec![0, 10, 200, 0]
    };
    w.write_image_data(&data).unwrap();
}

fn chunks(path: &std::path::Path) -> Vec<String> {
    let d = std::fs::read(path).unwrap();
    let mut i = 8;
    let mut out = Vec::new();
    while i + 8 <= d.len() {
        let n = u32::from_be_bytes(d[i..i + 4].try_into().unwrap()) as usize;
        out.push(String::from_utf8_lossy(&d[i + 4..i + 8]).into_owned());
        i += 12 + n;
    }
    out
}

#[test]
fn png_chunks_decide_the_transfer_and_parvo_writes_them() {
    let dir = tempfile::tempdir().unwrap();
    for (depth, chunk, want) in [
        (png::BitDepth::Eight, "gAMA 1.0", ColorSpace::Linear),
        (png::BitDepth::Eight, "gAMA 0.45455", ColorSpace::Srgb),
        (png::BitDepth::Eight, "none", ColorSpace::Srgb),
        (png::BitDepth::Sixteen, "sRGB", ColorSpace::Srgb),
        (png::BitDepth::Sixteen, "gAMA 1.0", ColorSpace::Linear),
        (png::BitDepth::Sixteen, "none", ColorSpace::Srgb),
    ] {
        let p = dir.path().join("in.png");
        png(&p, depth, chunk);
        let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
        assert_eq!(l.base().format().color_space, want, "{depth:?} {chunk}");
    }
    // parvo's levels carry the chunk of their transfer and read back so.
    for (color, chunk) in [("linear", "gAMA"), ("srgb", "sRGB")] {
        let out = dir.path().join(format!("{color}_{{level}}.png"));
        ok(&parvo(&[
            "mip",
            "builtin:checker:8",
            "--color",
            color,
            "-o",
            s(&out),
        ]));
        let first = dir.path().join(format!("{color}_0.png"));
        let c = chunks(&first);
        assert!(c.iter().any(|n| n == chunk), "{color}: {c:?}");
        let l = parvo::io::load(s(&first), &parvo::io::Limits::default()).unwrap();
        let want = if color == "linear" {
            ColorSpace::Linear
        } else {
            ColorSpace::Srgb
        };
        assert_eq!(l.base().format().color_space, want, "{color}");
    }
}
