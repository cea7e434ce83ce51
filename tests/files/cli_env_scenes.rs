//! The `sky` and `sphere` scenes through the commands a user runs:
//! `render`, `tradeoff` and `cachesim` read the texture as a lat-long map
//! (s repeats, t clamps), the built-in `sky` stands in for its texels in
//! `cachesim` exactly (same counts as the same image from a PNG file), a
//! cube map is refused with a way to convert it, and on the sphere,
//! anisotropic filtering is closer to the reference than trilinear.

use crate::cli_common;
use cli_common::{ok, parvo};

#[test]
fn cachesim_of_the_builtin_sky_equals_the_same_image_from_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("sky.png");
    let t = parvo::builtin::load("builtin:sky:512").unwrap();
    assert_eq!((t.width(), t.height()), (512, 256));
    let parvo::texel::Texels::U8(rgba) = t.texels() else {
        panic!("the sky is RGBA8")
    };
    image::save_buffer(&png, rgba, 512, 256, image::ColorType::Rgba8).unwrap();
    for scene in ["sky", "sphere"] {
        let run = |tex: &str| -> serde_json::Value {
            serde_json::from_str(&ok(&parvo(&[
                "cachesim",
                "--scene",
                scene,
                "--size",
                "96x64",
                "--texture",
                tex,
                "--filter",
                "trilinear",
                "--cache",
                "4K:64:2",
                "--json",
            ])))
            .unwrap()
        };
        let (a, b) = (run("builtin:sky:512"), run(png.to_str().unwrap()));
        assert!(a["accesses"].as_u64().unwrap() > 0);
        for k in [
            "pixels",
            "accesses",
            "hits",
            "misses",
            "cold_misses",
            "conflict_misses",
        ] {
            assert_eq!(a[k], b[k], "{scene}: {k}");
        }
    }
}

#[test]
fn on_the_sphere_aniso16_is_closer_to_the_reference_than_trilinear() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    ok(&parvo(&[
        "tradeoff",
        "--scene",
        "sphere",
        "--texture",
        "builtin:sky:1024",
        "--size",
        "96x96",
        "--runs",
        "1",
        "--filters",
        "trilinear,aniso16",
        "--out",
        out.to_str().unwrap(),
    ]));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(r["scene"], "sphere");
    assert_eq!(r["texture_size"], serde_json::json!([1024, 512]));
    let psnr = |name: &str| {
        r["filters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == name)
            .unwrap()["psnr_db"]
            .as_f64()
            .unwrap()
    };
    assert!(
        psnr("aniso16") > psnr("trilinear") + 0.5,
        "aniso16 {} dB, trilinear {} dB",
        psnr("aniso16"),
        psnr("trilinear")
    );
}

#[test]
fn render_draws_the_sphere_and_a_cube_map_is_refused_with_a_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("s.png");
    ok(&parvo(&[
        "render",
        "--scene",
        "sphere",
        "--texture",
        "builtin:sky:256",
        "--size",
        "48x40",
        "--filter",
        "aniso16",
        "-o",
        png.to_str().unwrap(),
    ]));
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (48, 40));
    // The corners are off the sphere, the centre on it.
    assert_ne!(img.get_pixel(24, 20), img.get_pixel(0, 0));
    let cube = dir.path().join("cube.ktx2");
    ok(&parvo(&[
        "mip",
        "--env",
        "cube",
        "builtin:sky:64",
        "--face-size",
        "16",
        "-o",
        cube.to_str().unwrap(),
    ]));
    let r = parvo(&[
        "render",
        "--scene",
        "sky",
        "--texture",
        cube.to_str().unwrap(),
        "--size",
        "16x16",
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("lat-long") && err.contains("--env latlong"),
        "the error says what to do: {err}"
    );
}
