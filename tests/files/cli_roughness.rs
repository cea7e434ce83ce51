//! `parvo mip --normal-map --roughness …` end to end: the roughness file
//! (or the packed alpha) holds the library's chain (`mip::roughness`,
//! itself tested against the SPEC formulas in `normal_roughness.rs`) in
//! the output's precision; a flat map keeps the base roughness; bad
//! arguments are usage errors and failed jobs write nothing.

use std::path::Path;
use std::process::{Command, Output};

use parvo::mip::roughness::{self, BaseRoughness, NormalChannels, Specular};
use parvo::texel::{ChannelType, ColorSpace, Format, Texels};
use parvo::{MipOptions, Texture};

fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .expect("run parvo")
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A bumpy RGB8 normal map as PNG, and the same codes as a texture.
fn bumpy_png(path: &Path, n: u32) -> Texture {
    let mut codes = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let (fx, fy) = (x as f64 * 0.9, y as f64 * 0.7);
            let (gx, gy) = (
                0.8 * fx.sin() * (fy * 0.5).cos(),
                0.6 * (fx * 0.3).cos() * fy.sin(),
            );
            let l = (gx * gx + gy * gy + 1.0).sqrt();
            for c in [-gx / l, -gy / l, 1.0 / l] {
                codes.push(((c + 1.0) * 0.5 * 255.0).round() as u8);
            }
        }
    }
    image::RgbImage::from_raw(n, n, codes.clone())
        .unwrap()
        .save(path)
        .unwrap();
    Texture::from_u8(
        n,
        n,
        Format::new(3, ChannelType::U8, ColorSpace::Linear),
        codes,
    )
    .unwrap()
}

fn levels(path: &Path) -> Vec<Texture> {
    parvo::io::load(path.to_str().unwrap(), &parvo::io::Limits::default())
        .unwrap()
        .levels
}

fn linear(t: &Texture) -> Vec<f32> {
    t.to_linear()
}

#[test]
fn the_roughness_file_and_the_packed_alpha_hold_the_librarys_chain() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("n.png");
    let tex = bumpy_png(&png, 64);
    let want = roughness::build(
        &tex,
        NormalChannels::Xyz,
        BaseRoughness::Constant(0.25),
        Specular::Roughness,
        &MipOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    let (exr, rexr) = (dir.path().join("n.exr"), dir.path().join("r.exr"));
    ok(&parvo(&[
        "mip",
        png.to_str().unwrap(),
        "--normal-map",
        "--roughness",
        "0.25",
        "-o",
        exr.to_str().unwrap(),
        "--roughness-out",
        rexr.to_str().unwrap(),
    ]));
    let got = levels(&rexr);
    assert_eq!(got.len(), want.specular.len());
    let mut grew = false;
    for (k, (g, w)) in got.iter().zip(&want.specular).enumerate() {
        assert_eq!(g.channels(), 1);
        let Texels::F32(w) = w.texels() else { panic!() };
        for (a, b) in linear(g).iter().zip(w) {
            // f16: 11 significant bits.
            assert!((a - b).abs() <= b.abs() * 1e-3, "level {k}: {a} vs {b}");
        }
        grew |= w.iter().any(|&a| a > 0.26);
    }
    assert!(grew, "the test map is too smooth");
    // The normal output has three channels and unit vectors.
    let n = levels(&exr);
    assert_eq!(n[0].channels(), 3);

    // Packed into the alpha of an 8-bit KTX2.
    let ktx = dir.path().join("n.ktx2");
    ok(&parvo(&[
        "mip",
        png.to_str().unwrap(),
        "--normal-map",
        "--roughness",
        "0.25",
        "-o",
        ktx.to_str().unwrap(),
        "--pack-roughness",
        "A",
    ]));
    let packed = levels(&ktx);
    for (k, (g, w)) in packed.iter().zip(&want.specular).enumerate() {
        assert_eq!(g.channels(), 4);
        let Texels::U8(c) = g.texels() else {
            panic!("not u8")
        };
        let Texels::F32(w) = w.texels() else { panic!() };
        for (px, b) in c.chunks_exact(4).zip(w) {
            assert!(
                (px[3] as f32 / 255.0 - b).abs() <= 0.5 / 255.0 + 1e-6,
                "level {k}"
            );
        }
    }
}

#[test]
fn a_flat_map_keeps_the_base_roughness_and_pngs_levels_work() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("flat.png");
    image::RgbImage::from_pixel(40, 24, image::Rgb([128, 100, 230]))
        .save(&png)
        .unwrap();
    let out = dir.path().join("n_{level}.png");
    let rout = dir.path().join("r_{level}.png");
    ok(&parvo(&[
        "mip",
        png.to_str().unwrap(),
        "--normal-map",
        "--roughness",
        "0.6",
        "--filter",
        "kaiser",
        "-o",
        out.to_str().unwrap(),
        "--roughness-out",
        rout.to_str().unwrap(),
    ]));
    for k in 0..6 {
        let p = dir.path().join(format!("r_{k}.png"));
        let img = image::open(&p).unwrap().to_luma8();
        assert!(
            img.pixels().all(|p| p.0[0] == 153),
            "level {k}: 0.6 is code 153"
        );
    }
}

#[test]
fn bad_roughness_arguments_are_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("n.png");
    bumpy_png(&png, 32);
    let small = dir.path().join("small.png");
    image::GrayImage::from_pixel(16, 32, image::Luma([100]))
        .save(&small)
        .unwrap();
    let rgba = dir.path().join("rgba.png");
    image::RgbaImage::from_pixel(32, 32, image::Rgba([128, 128, 255, 7]))
        .save(&rgba)
        .unwrap();
    let n = dir.path().join("o.exr");
    let r = dir.path().join("r.exr");
    let (p, ns, rs) = (
        png.to_str().unwrap(),
        n.to_str().unwrap(),
        r.to_str().unwrap(),
    );
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (
            vec!["--roughness", "abc", "--roughness-out", rs],
            2,
            "neither a number",
        ),
        (
            vec!["--roughness", "1.5", "--roughness-out", rs],
            2,
            "from 0 to 1",
        ),
        (vec!["--roughness", "0.3"], 2, "--roughness-out"),
        (
            vec![
                "--roughness",
                small.to_str().unwrap(),
                "--roughness-out",
                rs,
            ],
            1,
            "same size",
        ),
        (
            vec![
                "--roughness",
                "0.3",
                "--roughness-out",
                "r_{level}.png",
                "--specular",
                "blinn-phong:32",
            ],
            2,
            "float",
        ),
        (
            vec![
                "--roughness",
                "0.3",
                "--roughness-out",
                rs,
                "--specular",
                "blinn-phong:x",
            ],
            2,
            "exponent",
        ),
        (
            vec!["--roughness", "0.3", "--pack-roughness", "B"],
            2,
            "only A",
        ),
        (vec!["--normal-map-channels", "xy"], 2, "needs --roughness"),
    ];
    for (extra, code, msg) in cases {
        let mut a = vec!["mip", p, "--normal-map", "-o", ns];
        a.extend(&extra);
        let o = parvo(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {err}");
        assert!(err.contains(msg), "{extra:?}: {err}");
        assert!(!n.exists() && !r.exists(), "{extra:?} wrote something");
    }
    // Packing into the alpha of a map that has one.
    let o = parvo(&[
        "mip",
        rgba.to_str().unwrap(),
        "--normal-map",
        "--roughness",
        "0.3",
        "-o",
        ns,
        "--pack-roughness",
        "A",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("fourth channel"));
    assert!(!n.exists());
}

#[test]
fn two_channel_maps_rebuild_z() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("xy.png");
    // Grey + alpha PNG: x in the first channel, y in the second.
    image::GrayAlphaImage::from_pixel(16, 16, image::LumaA([160, 100]))
        .save(&png)
        .unwrap();
    let out = dir.path().join("n.exr");
    let r = dir.path().join("r.exr");
    ok(&parvo(&[
        "mip",
        png.to_str().unwrap(),
        "--normal-map",
        "--normal-map-channels",
        "xy",
        "--roughness",
        "0.4",
        "-o",
        out.to_str().unwrap(),
        "--roughness-out",
        r.to_str().unwrap(),
    ]));
    let n = levels(&out);
    let v = linear(&n[0]);
    let (x, y) = (160.0f32 / 255.0 * 2.0 - 1.0, 100.0f32 / 255.0 * 2.0 - 1.0);
    let z = (1.0 - x * x - y * y).sqrt();
    for (got, want) in v[..3].iter().zip([x, y, z]) {
        assert!((got - want).abs() < 2e-3, "{got} vs {want}");
    }
}

#[test]
fn render_shade_draws_the_three_shadings_and_refuses_bad_lights() {
    let dir = tempfile::tempdir().unwrap();
    for s in ["truth", "renormalised", "adjusted"] {
        let p = dir.path().join(format!("{s}.png"));
        ok(&parvo(&[
            "render",
            "--shade",
            "cook-torrance",
            "--texture",
            "builtin:bumps:128",
            "--size",
            "48x32",
            "--shading",
            s,
            "-o",
            p.to_str().unwrap(),
        ]));
        let img = image::open(&p).unwrap();
        assert_eq!((img.width(), img.height()), (48, 32));
    }
    let p = dir.path().join("x.png");
    for light in ["1,2", "0,0,-1", "a,b,c"] {
        let o = parvo(&[
            "render",
            "--shade",
            "blinn-phong",
            "--texture",
            "builtin:bumps:64",
            "--light",
            light,
            "-o",
            p.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "--light {light}");
        assert!(!p.exists());
    }
}

#[test]
fn update_skips_only_when_both_files_store_the_fingerprint() {
    let dir = tempfile::tempdir().unwrap();
    let (n, r) = (dir.path().join("n.exr"), dir.path().join("r.exr"));
    let run = |rough: &str| {
        let o = parvo(&[
            "mip",
            "builtin:bumps:64",
            "--normal-map",
            "--roughness",
            rough,
            "-o",
            n.to_str().unwrap(),
            "--roughness-out",
            r.to_str().unwrap(),
            "--update",
        ]);
        ok(&o);
        String::from_utf8_lossy(&o.stdout).contains("(up to date)")
    };
    assert!(!run("0.3"));
    assert!(run("0.3"));
    assert!(!run("0.4"), "a new base roughness rebuilds");
    std::fs::remove_file(&r).unwrap();
    assert!(!run("0.4"), "a missing roughness file rebuilds");
    assert!(r.exists());
}
