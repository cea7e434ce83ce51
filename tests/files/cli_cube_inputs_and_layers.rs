//! Issue 30's leftovers through the commands a user runs: `parvo mip
//! --env cube` and `parvo sample --direction --env cube` take a cube map
//! as a horizontal strip, a horizontal cross or a vertical cross (the
//! faces cut as `env::cube::faces_from_image` cuts them, which
//! `tests/core/cube_layouts.rs` checks against GL's face directions), any other
//! aspect refused naming the layouts; and `parvo sample --layer` samples
//! one layer of a 2-D array, or with `--direction` one cube of a cube-map
//! array, bit for bit as the library's `ArraySampler` and `CubeSampler`
//! do, with GL's rounding of the layer, and an array without `--layer`
//! refused.

use std::path::Path;
use std::process::Output;

use crate::cli_common;

use parvo::ImageKind;
use parvo::env::cube::{CubeLayout, build_faces, faces_from_image};
use parvo::env::{ArraySampler, CubeSampler, DirQuery};
use parvo::io::{self, EnvironmentMaps, LoadOptions, OutputKind, SaveOptions};
use parvo::mip::Rounding;
use parvo::sample::{Filter, Query, Sampler, SamplerOptions};
use parvo::{ChannelType, ColorSpace, Format, MipOptions, Texture};

fn parvo(args: &[&str], stdin: &str) -> Output {
    cli_common::parvo_with_input(args, stdin)
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn failed(o: &Output, what: &str) -> String {
    assert!(!o.status.success(), "{what} succeeded");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn values(o: &Output) -> Vec<Vec<f32>> {
    String::from_utf8(o.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| l.split(' ').map(|t| t.parse().unwrap()).collect())
        .collect()
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// xorshift, fixed seed.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
}

fn random(w: u32, h: u32, format: Format, seed: u64) -> Texture {
    let mut r = Rng(seed);
    let v: Vec<f32> = (0..w * h * format.channels as u32).map(|_| r.f()).collect();
    Texture::from_linear(w, h, format, &v).unwrap()
}

fn load(p: &Path) -> io::Loaded {
    let o = LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..LoadOptions::default()
    };
    io::load_with(p.to_str().unwrap(), &io::Limits::default(), &o).unwrap()
}

fn save(t: Texture, p: &Path, kind: OutputKind) {
    io::save(&[t], Rounding::Down, p, kind, &SaveOptions::default()).unwrap();
}

/// Directions all over the sphere, many near edges and corners, with
/// small derivatives, and their CLI lines.
fn directions(count: usize, seed: u64) -> (Vec<DirQuery>, String) {
    let mut r = Rng(seed);
    let qs: Vec<DirQuery> = (0..count)
        .map(|_| {
            let mut c = || 2.0 * r.f() - 1.0;
            let d = [c(), c(), c()];
            let e = 0.02 * c();
            DirQuery::new(d, [e, 0.01, 0.0], [0.0, e.abs(), 0.015])
        })
        .collect();
    let text = qs
        .iter()
        .map(|q| {
            let n: Vec<String> = q
                .dir
                .iter()
                .chain(&q.ddx)
                .chain(&q.ddy)
                .map(|x| x.to_string())
                .collect();
            n.join(" ") + "\n"
        })
        .collect();
    (qs, text)
}

/// Face size 5 and 7 (awkward sizes) in each new layout: `parvo mip
/// --env cube` writes a cube map whose level-0 faces are the faces cut
/// from the image, and `parvo sample --direction --env cube` looks the
/// image up exactly as `CubeSampler` does on those faces, mip-mapped
/// per face, for nearest, trilinear and EWA.
#[test]
fn crosses_and_strips_are_read_as_cube_maps_by_mip_and_sample() {
    let dir = tempfile::tempdir().unwrap();
    // RGB f16: OpenEXR would premultiply colour by alpha.
    let f16 = Format::new(3, ChannelType::F16, ColorSpace::Linear);
    let (qs, input) = directions(300, 11);
    let mut seed = 1;
    for layout in [
        CubeLayout::HorizontalStrip,
        CubeLayout::HorizontalCross,
        CubeLayout::VerticalCross,
    ] {
        for n in [5u32, 7] {
            seed += 1;
            let (a, b) = layout.cells();
            let image = random(a * n, b * n, f16, seed);
            let src = dir.path().join(format!("{seed}.exr"));
            save(image, &src, OutputKind::EXR);
            let src_s = src.to_str().unwrap();
            let what = format!("{layout} {n}");
            // The library's reading of the same file.
            let faces = faces_from_image(load(&src).base()).unwrap();

            let out = dir.path().join(format!("{seed}.ktx2"));
            let o = parvo(
                &["mip", src_s, "--env", "cube", "-o", out.to_str().unwrap()],
                "",
            );
            ok(&o, &what);
            let back = load(&out);
            assert_eq!(back.info.kind, ImageKind::Cube, "{what}");
            let level0: Vec<Texture> = back
                .into_images()
                .into_iter()
                .map(|l| l.into_iter().next().unwrap())
                .collect();
            assert_eq!(level0, faces, "{what}: level-0 faces");

            let chains = build_faces(faces, &MipOptions::default()).unwrap();
            for filter in ["nearest", "trilinear", "ewa"] {
                let o = parvo(
                    &[
                        "sample",
                        src_s,
                        "--direction",
                        "--env",
                        "cube",
                        "--filter",
                        filter,
                    ],
                    &input,
                );
                ok(&o, &what);
                let got = values(&o);
                let options = SamplerOptions::preset(filter.parse::<Filter>().unwrap(), 16);
                let s = CubeSampler::new(&chains, options).unwrap();
                assert_eq!(got.len(), qs.len());
                for (q, g) in qs.iter().zip(&got) {
                    let want = s.sample(q);
                    assert_eq!(bits(g), bits(&want[..3]), "{what} {filter} {q:?}");
                }
            }
        }
    }
}

/// An image of no cube layout's aspect is refused by both commands, the
/// message naming every layout read.
#[test]
fn other_aspects_are_refused_naming_the_layouts() {
    let dir = tempfile::tempdir().unwrap();
    let f16 = Format::new(3, ChannelType::F16, ColorSpace::Linear);
    let src = dir.path().join("odd.exr");
    save(random(10, 7, f16, 5), &src, OutputKind::EXR);
    let src_s = src.to_str().unwrap();
    let out = dir.path().join("o.ktx2");
    let mip = parvo(
        &["mip", src_s, "--env", "cube", "-o", out.to_str().unwrap()],
        "",
    );
    let sample = parvo(
        &["sample", src_s, "--direction", "--env", "cube"],
        "1 0 0 0 0 0 0 0 0\n",
    );
    for (e, what) in [
        (failed(&mip, "mip"), "mip"),
        (failed(&sample, "sample"), "sample"),
    ] {
        for needle in [
            "10x7",
            "vertical strip w x 6w",
            "horizontal strip 6w x w",
            "horizontal cross 4w x 3w",
            "vertical cross 3w x 4w",
        ] {
            assert!(e.contains(needle), "{what}: no `{needle}` in {e}");
        }
    }
    assert!(!out.exists());
}

/// 2-D queries and their CLI lines.
fn queries(count: usize, seed: u64) -> (Vec<Query>, String) {
    let mut r = Rng(seed);
    let qs: Vec<Query> = (0..count)
        .map(|_| {
            let u = 3.0 * r.f() - 1.0;
            let v = 3.0 * r.f() - 1.0;
            let d = 0.3 * r.f();
            Query::new(u, v, d, 0.02, -0.01, 0.5 * d)
        })
        .collect();
    let text = qs
        .iter()
        .map(|q| {
            format!(
                "{} {} {} {} {} {}\n",
                q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy
            )
        })
        .collect();
    (qs, text)
}

/// A three-layer array written by parvo (KTX2 and DDS, RGBA8 with its
/// levels): `--layer L` samples the layer GL's rounding picks (1.6 reads
/// layer 2, −3 layer 0, 9 the last), bit for bit as `ArraySampler` (and,
/// with `--level`, as that layer's `sample_level`); without `--layer` the
/// file is refused saying how many layers it has.
#[test]
fn layer_picks_an_array_layer_as_gl_rounds_it() {
    let dir = tempfile::tempdir().unwrap();
    let rgba = Format::new(4, ChannelType::U8, ColorSpace::Srgb)
        .with_alpha(parvo::texel::AlphaMode::Straight);
    let images: Vec<Vec<Texture>> = (0..3)
        .map(|i| {
            parvo::mip::build(random(12, 7, rgba, 70 + i), &MipOptions::default())
                .unwrap()
                .into_levels()
        })
        .collect();
    let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
    let (qs, input) = queries(200, 3);
    for (kind, ext) in [(OutputKind::KTX2, "ktx2"), (OutputKind::DDS, "dds")] {
        let path = dir.path().join(format!("array.{ext}"));
        io::save_images(
            &refs,
            ImageKind::Array { layers: 3 },
            Rounding::Down,
            &path,
            kind,
            &SaveOptions::default(),
        )
        .unwrap();
        let p = path.to_str().unwrap();
        let loaded = load(&path);
        assert_eq!(loaded.info.kind, ImageKind::Array { layers: 3 }, "{p}");
        let chains = loaded.into_image_chains().unwrap();
        for filter in ["trilinear", "aniso"] {
            let options = SamplerOptions {
                wrap: chains[0].options().wrap,
                ..SamplerOptions::preset(filter.parse::<Filter>().unwrap(), 16)
            };
            let array = ArraySampler::new(&chains, options).unwrap();
            for (layer, picked) in [("0", 0), ("1.6", 2), ("1.4", 1), ("-3", 0), ("9", 2)] {
                let l: f32 = layer.parse().unwrap();
                assert_eq!(array.layer_index(l), picked);
                let o = parvo(&["sample", p, "--filter", filter, "--layer", layer], &input);
                ok(&o, &format!("{p} --layer {layer}"));
                let got = values(&o);
                assert_eq!(got.len(), qs.len());
                for (q, g) in qs.iter().zip(&got) {
                    assert_eq!(
                        bits(g),
                        bits(&array.sample(q, l)),
                        "{p} {filter} --layer {layer} {q:?}"
                    );
                }
            }
        }
        // textureLod on layer 1.
        let o = parvo(&["sample", p, "--layer", "1", "--level", "1.3"], &input);
        ok(&o, "--level");
        let layer1 = Sampler::new(
            &chains[1],
            SamplerOptions {
                wrap: chains[1].options().wrap,
                ..SamplerOptions::trilinear()
            },
        )
        .unwrap();
        for (q, g) in qs.iter().zip(&values(&o)) {
            assert_eq!(bits(g), bits(&layer1.sample_level(q.u, q.v, 1.3)));
        }
        // Nothing picked silently.
        let e = failed(&parvo(&["sample", p], &input), "no --layer");
        assert!(
            e.contains("3 layers") && e.contains("--layer") && e.contains("0 to 2"),
            "{e}"
        );
    }
    // --layer on a texture that is not an array.
    let png = dir.path().join("plain.png");
    let px: Vec<u8> = (0..8 * 8 * 4).map(|i| (i * 37 % 251) as u8).collect();
    image::save_buffer(&png, &px, 8, 8, image::ColorType::Rgba8).unwrap();
    let e = failed(
        &parvo(
            &["sample", png.to_str().unwrap(), "--layer", "1"],
            "0.5 0.5 0 0 0 0\n",
        ),
        "--layer on a 2-D image",
    );
    assert!(e.contains("--layer") && e.contains("not an array"), "{e}");
}

/// A cube-map array of two cubes written by parvo: `--direction --layer
/// C` looks up cube C (GL's rounding) bit for bit as `CubeSampler` on
/// that cube's faces; without `--layer` the file is refused saying how
/// many cubes it has, and without `--direction` told to use it.
#[test]
fn layer_picks_the_cube_of_a_cube_map_array() {
    let dir = tempfile::tempdir().unwrap();
    let f16 = Format::new(4, ChannelType::F16, ColorSpace::Linear);
    let images: Vec<Vec<Texture>> = (0..12)
        .map(|i| {
            parvo::mip::build(random(7, 7, f16, 100 + i), &MipOptions::default())
                .unwrap()
                .into_levels()
        })
        .collect();
    let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
    let path = dir.path().join("cubes.ktx2");
    io::save_images(
        &refs,
        ImageKind::CubeArray { cubes: 2 },
        Rounding::Down,
        &path,
        OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap();
    let p = path.to_str().unwrap();
    let chains = load(&path).into_image_chains().unwrap();
    let (qs, input) = directions(300, 21);
    for (layer, cube) in [("0", 0usize), ("0.7", 1), ("1", 1), ("-1", 0)] {
        for filter in ["bilinear", "trilinear", "ewa"] {
            let options = SamplerOptions::preset(filter.parse::<Filter>().unwrap(), 16);
            let s = CubeSampler::new(&chains[6 * cube..6 * cube + 6], options).unwrap();
            let o = parvo(
                &[
                    "sample",
                    p,
                    "--direction",
                    "--filter",
                    filter,
                    "--layer",
                    layer,
                ],
                &input,
            );
            ok(&o, &format!("--layer {layer}"));
            let got = values(&o);
            assert_eq!(got.len(), qs.len());
            for (q, g) in qs.iter().zip(&got) {
                assert_eq!(
                    bits(g),
                    bits(&s.sample(q)),
                    "--layer {layer} {filter} {q:?}"
                );
            }
        }
    }
    let e = failed(&parvo(&["sample", p, "--direction"], &input), "no --layer");
    assert!(e.contains("2 cubes") && e.contains("--layer"), "{e}");
    let e = failed(
        &parvo(&["sample", p, "--layer", "1"], "0.5 0.5 0 0 0 0\n"),
        "no --direction",
    );
    assert!(e.contains("--direction"), "{e}");
}
