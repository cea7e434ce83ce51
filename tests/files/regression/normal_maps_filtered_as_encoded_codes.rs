//! Issue 18 #2: `parvo mip normal.png -o normal.exr --normal-map` kept
//! level 0 in the 0..1 encoding while levels ≥ 1 were
//! normalize(box(codes)) — codes treated as vectors, decoded normals up to
//! 103° off; float normals written to u8/u16 were stored raw with the
//! negative third clamped to 0; and u8 levels were renormalised after an
//! 8-bit rounding of the level above (1.23° at level 1).
//!
//! The reference here is plain f64: decode codes as 2c − 1, normalise,
//! average each 2×2 block of level-0 unit vectors (box, power of two),
//! normalise.

use super::util::{ok, parvo, png_u16, s, write_exr};

fn normals(w: usize, h: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut st = seed;
    let mut r = || {
        st = st
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (st >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..w * h)
        .map(|_| {
            let (x, y) = (r() * 1.6 - 0.8, r() * 1.6 - 0.8);
            let z = (1.0 - x * x - y * y).max(0.05).sqrt();
            norm([x, y, z])
        })
        .collect()
}

fn norm(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let a = norm(a);
    let b = norm(b);
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Level `k` of the box chain of unit vectors `n0` (w × h, powers of two).
fn reference(n0: &[[f64; 3]], w: usize, k: u32) -> Vec<[f64; 3]> {
    let f = 1usize << k;
    let (lw, lh) = (w / f, n0.len() / w / f);
    let mut out = Vec::new();
    for y in 0..lh {
        for x in 0..lw {
            let mut s = [0.0; 3];
            for j in 0..f {
                for i in 0..f {
                    let n = n0[(y * f + j) * w + x * f + i];
                    (0..3).for_each(|c| s[c] += n[c]);
                }
            }
            out.push(norm(s));
        }
    }
    out
}

/// `n` written as an RGB8 normal map (codes round((n + 1) / 2 · 255)),
/// and the unit vectors those codes decode to (2c − 1, normalised).
fn normal_png(
    dir: &std::path::Path,
    n: &[[f64; 3]],
    w: usize,
    h: usize,
) -> (std::path::PathBuf, Vec<[f64; 3]>) {
    let codes: Vec<u8> = n
        .iter()
        .flat_map(|v| v.map(|c| ((c + 1.0) / 2.0 * 255.0).round() as u8))
        .collect();
    let src = dir.join("normal.png");
    image::save_buffer(
        &src,
        &codes,
        w as u32,
        h as u32,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let decoded = codes
        .chunks(3)
        .map(|c| norm([0, 1, 2].map(|i| c[i] as f64 / 255.0 * 2.0 - 1.0)))
        .collect();
    (src, decoded)
}

#[test]
fn u8_normal_png_to_exr_decodes_codes_and_filters_unit_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (16usize, 8usize);
    let n = normals(w, h, 7);
    let (src, decoded) = normal_png(dir.path(), &n, w, h);
    let out = dir.path().join("normal.exr");
    ok(&parvo(&[
        "mip",
        s(&src),
        "-o",
        s(&out),
        "--normal-map",
        "--type",
        "f32",
    ]));
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    for (k, lv) in l.levels.iter().enumerate() {
        let want = reference(&decoded, w, k as u32);
        let got = lv.to_linear();
        let worst = got
            .chunks(3)
            .zip(&want)
            .map(|(g, r)| angle([g[0] as f64, g[1] as f64, g[2] as f64], *r))
            .fold(0.0, f64::max);
        assert!(worst < 1e-3, "level {k}: {worst}° from the reference");
    }
}

#[test]
fn u8_levels_are_renormalised_without_an_intermediate_rounding() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (32usize, 32usize);
    let n = normals(w, h, 11);
    let (src, decoded) = normal_png(dir.path(), &n, w, h);
    let out = dir.path().join("n_{level}.png");
    ok(&parvo(&["mip", s(&src), "-o", s(&out), "--normal-map"]));
    for k in 1..=3u32 {
        let (_, _, _, v) = png_u16(&dir.path().join(format!("n_{k}.png")));
        let want = reference(&decoded, w, k);
        let worst = v
            .chunks(3)
            .zip(&want)
            .map(|(g, r)| angle([0, 1, 2].map(|c| g[c] as f64 / 65535.0 * 2.0 - 1.0), *r))
            .fold(0.0, f64::max);
        // One 8-bit rounding of a unit vector is at most about
        // atan(sqrt(2) · (1/255)) ≈ 0.32°; the old path reached 1.23°.
        assert!(worst < 0.4, "level {k}: {worst}° from the reference");
    }
}

#[test]
fn float_normals_are_encoded_for_integer_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (8usize, 8usize);
    let n = normals(w, h, 5);
    let ch = |c: usize| n.iter().map(|v| v[c] as f32).collect::<Vec<_>>();
    let src = dir.path().join("normal.exr");
    write_exr(&src, &[("R", ch(0)), ("G", ch(1)), ("B", ch(2))], w, h);
    for (name, ty) in [("n.ktx2", "u8"), ("p_{level}.png", "u16")] {
        let out = dir.path().join(name);
        ok(&parvo(&[
            "mip",
            s(&src),
            "-o",
            s(&out),
            "--normal-map",
            "--type",
            ty,
        ]));
        let first = if name.contains("{level}") {
            dir.path().join("p_0.png")
        } else {
            out.clone()
        };
        let l = parvo::io::load(s(&first), &parvo::io::Limits::default()).unwrap();
        let v = l.base().to_linear();
        let scale = if ty == "u8" { 255.0 } else { 65535.0 };
        for (g, r) in v.chunks(3).zip(&n) {
            for c in 0..3 {
                let want = ((r[c] + 1.0) / 2.0 * scale).round() / scale;
                // Within one code (rounding ties of f32 inputs).
                assert!(
                    (g[c] as f64 - want).abs() < 1.01 / scale,
                    "{name} c{c}: {g:?} vs {want}"
                );
            }
        }
    }
}
