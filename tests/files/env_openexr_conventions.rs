//! OpenEXR's own environment maps read as OpenEXR defines them
//! (`ImfEnvmap.cpp`), checked against an implementation of that file's
//! formulas written here, not against parvo's reading.
//!
//! Lat-long (`LatLongMap`): `latLong(dir)` gives latitude
//! `asin(y/|d|)` (the `acos` form near the poles) and longitude
//! `atan2(x, z)`; `pixelPosition(dataWindow, latLong)` puts them at
//! `x = (lon/(−2π) + ½)(w − 1)`, `y = (lat/(−π) + ½)(h − 1)`: the first row
//! on the +y pole, the last on −y, the first and last columns on the same
//! meridian. A bilinear lookup at that continuous position is what
//! `exrenvmap` reads for each of its samples and what OpenImageIO's
//! `environment()` follows on such files (`oiio:sampleborder` 1).
//!
//! Cube (`CubeMap`): six faces stacked +X, −X, +Y, −Y, +Z, −Z;
//! `faceAndPixelPosition` scales the minor/major ratios by `sof − 1` (the
//! outermost texel centres lie on the cube's edges) and `pixelPosition`
//! lays each face out with its own axes, mirrored against GL's faces.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use parvo::env::{CubeSampler, DirQuery, LatLongSampler, Placement, latlong};
use parvo::io::source::interpret;
use parvo::io::{self, EnvironmentMaps, LoadOptions};
use parvo::sample::{Method, MipMode, SamplerOptions, TexelFilter};
use parvo::{ImageKind, MipChain, Texture};

fn openexr_image(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer/openexr-images")
        .join(name)
}

fn load(p: &Path) -> io::Loaded {
    let options = LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..LoadOptions::default()
    };
    io::load_with(p.to_str().unwrap(), &io::Limits::default(), &options).unwrap()
}

/// `LatLongMap::latLong(dir)`, as ImfEnvmap.cpp computes it.
fn imf_lat_long(d: [f64; 3]) -> (f64, f64) {
    let r = (d[2] * d[2] + d[0] * d[0]).sqrt();
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let lat = if r < d[1].abs() {
        (r / len).acos() * d[1].signum()
    } else {
        (d[1] / len).asin()
    };
    let lon = if d[2] == 0.0 && d[0] == 0.0 {
        0.0
    } else {
        d[0].atan2(d[2])
    };
    (lat, lon)
}

/// `LatLongMap::pixelPosition(dataWindow, latLong)` for a `w`×`h` data
/// window at (0, 0).
fn imf_pixel_position(w: u32, h: u32, (lat, lon): (f64, f64)) -> (f64, f64) {
    let x = lon / (-2.0 * PI) + 0.5;
    let y = lat / (-PI) + 0.5;
    (x * (w - 1) as f64, y * (h - 1) as f64)
}

/// An image's texels in linear `f64` RGBA, converted once.
struct Linear {
    w: i64,
    texels: Vec<[f64; 4]>,
}

impl Linear {
    fn of(t: &Texture) -> Linear {
        let ch = t.format().channels as usize;
        let texels = t
            .to_linear()
            .chunks(ch)
            .map(|p| {
                let mut v = [0.0, 0.0, 0.0, 1.0];
                for c in 0..ch.min(4) {
                    v[c] = p[c] as f64;
                }
                v
            })
            .collect();
        Linear {
            w: t.width() as i64,
            texels,
        }
    }

    /// Bilinear at a continuous pixel position, column indices clamped to
    /// the image and row indices to `rows` (as exrenvmap's
    /// `EnvmapImage::sample` clamps them: the whole image for a lat-long
    /// map, one face's rows for a cube strip).
    fn bilinear(&self, (x, y): (f64, f64), (lo, hi): (i64, i64)) -> [f64; 4] {
        let texel = |i: i64, j: i64| {
            self.texels[(j.clamp(lo, hi) * self.w + i.clamp(0, self.w - 1)) as usize]
        };
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = (x - x0, y - y0);
        let (i, j) = (x0 as i64, y0 as i64);
        let (t00, t10, t01, t11) = (
            texel(i, j),
            texel(i + 1, j),
            texel(i, j + 1),
            texel(i + 1, j + 1),
        );
        std::array::from_fn(|c| {
            let top = t00[c] * (1.0 - a) + t10[c] * a;
            let bottom = t01[c] * (1.0 - a) + t11[c] * a;
            top * (1.0 - b) + bottom * b
        })
    }

    /// All rows.
    fn rows(&self) -> (i64, i64) {
        (0, self.texels.len() as i64 / self.w - 1)
    }
}

/// Directions over the whole sphere, fixed seed, the poles and the seam
/// meridian included.
fn directions(n: usize) -> Vec<[f64; 3]> {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut v: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = 2.0 * PI * next();
            let r = (1.0 - z * z).sqrt();
            [r * phi.cos(), z, r * phi.sin()]
        })
        .collect();
    v.extend([
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.3, 0.2, -1.0],
        [-0.3, 0.2, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    ]);
    v
}

fn level0_bilinear() -> SamplerOptions {
    SamplerOptions {
        method: Method::Texel,
        mag: TexelFilter::Linear,
        min: TexelFilter::Linear,
        mip: MipMode::None,
        ..SamplerOptions::default()
    }
}

/// An OpenEXR lat-long file is read with OpenEXR's placement, and a
/// bilinear lookup at level 0 equals ImfEnvmap's pixel position read
/// bilinearly, for directions everywhere (poles and the seam included).
#[test]
fn openexr_lat_long_lookups_equal_imf_envmap() {
    let path = openexr_image("WavyLinesLatLong.exr");
    let loaded = load(&path);
    let source = interpret(loaded, "WavyLinesLatLong.exr", None).unwrap();
    assert_eq!(source.kind, ImageKind::LatLong);
    assert_eq!(source.placement, Placement::Edges);
    let base = source.images[0][0].clone();
    // Level 0 alone: the lookups below read level 0 only.
    let chain = MipChain::from_levels(vec![base.clone()], parvo::MipOptions::default()).unwrap();
    let sampler = LatLongSampler::new(&chain, level0_bilinear())
        .unwrap()
        .with_placement(source.placement);
    let (w, h) = (base.width(), base.height());
    let image = Linear::of(&base);
    let mut worst = 0.0f64;
    for d in directions(2000) {
        let want = image.bilinear(imf_pixel_position(w, h, imf_lat_long(d)), image.rows());
        let got = sampler.sample(&DirQuery::point(d.map(|c| c as f32)));
        for c in 0..4 {
            let err = (got[c] as f64 - want[c]).abs() / want[c].abs().max(1.0);
            worst = worst.max(err);
        }
    }
    assert!(
        worst < 2e-4,
        "largest relative difference from ImfEnvmap's lookup: {worst}"
    );
}

/// The same lookups with the centred placement (what parvo read before)
/// differ from OpenEXR's by far more: the check above can tell the two.
#[test]
fn the_centred_placement_is_not_openexr_s() {
    let loaded = load(&openexr_image("WavyLinesLatLong.exr"));
    let base = loaded.base().clone();
    let chain = latlong::build_chain(base.clone()).unwrap();
    let centred = LatLongSampler::new(&chain, level0_bilinear()).unwrap();
    let (w, h) = (base.width(), base.height());
    let image = Linear::of(&base);
    let mut worst = 0.0f64;
    for d in directions(2000) {
        let want = image.bilinear(imf_pixel_position(w, h, imf_lat_long(d)), image.rows());
        let got = centred.sample(&DirQuery::point(d.map(|c| c as f32)));
        for c in 0..3 {
            worst = worst.max((got[c] as f64 - want[c]).abs() / want[c].abs().max(1.0));
        }
    }
    assert!(worst > 1e-2, "centred and OpenEXR placement agree: {worst}");
}

/// Files without OpenEXR's `envmap` (a plain image read as a lat-long
/// map, maketx's centred convention) keep the centred placement.
#[test]
fn a_hinted_lat_long_map_is_centred() {
    let loaded = load(&openexr_image("GrayRampsHorizontal.exr"));
    let source = interpret(loaded, "x", Some(io::Environment::LatLong)).unwrap();
    assert_eq!(source.kind, ImageKind::LatLong);
    assert_eq!(source.placement, Placement::Centred);
}

/// `CubeMap::faceAndPixelPosition` then `CubeMap::pixelPosition`
/// (ImfEnvmap.cpp) for a strip of `sof`-texel faces: the face and the
/// continuous position in the whole strip image.
fn imf_cube_pixel(d: [f64; 3], sof: u32) -> (usize, (f64, f64)) {
    let (ax, ay, az) = (d[0].abs(), d[1].abs(), d[2].abs());
    let s = (sof - 1) as f64;
    let (face, pif) = if ax >= ay && ax >= az {
        let pif = ((d[1] / ax + 1.0) / 2.0 * s, (d[2] / ax + 1.0) / 2.0 * s);
        (if d[0] > 0.0 { 0 } else { 1 }, pif)
    } else if ay >= az {
        let pif = ((d[0] / ay + 1.0) / 2.0 * s, (d[2] / ay + 1.0) / 2.0 * s);
        (if d[1] > 0.0 { 2 } else { 3 }, pif)
    } else {
        let pif = ((d[0] / az + 1.0) / 2.0 * s, (d[1] / az + 1.0) / 2.0 * s);
        (if d[2] > 0.0 { 4 } else { 5 }, pif)
    };
    // dataWindowForFace: columns 0..sof-1, rows face*sof .. face*sof+sof-1.
    let (min_x, max_x) = (0.0, s);
    let (min_y, max_y) = ((face as u32 * sof) as f64, (face as u32 * sof) as f64 + s);
    let pos = match face {
        0 => (min_x + pif.1, max_y - pif.0),
        1 => (max_x - pif.1, max_y - pif.0),
        2 => (min_x + pif.0, max_y - pif.1),
        3 => (min_x + pif.0, min_y + pif.1),
        4 => (max_x - pif.0, max_y - pif.1),
        _ => (min_x + pif.0, max_y - pif.1),
    };
    (face, pos)
}

/// A cube sampler over level 0 of `faces` (GL's order and orientation).
fn cube_sampler(faces: &[Vec<Texture>], placement: Placement) -> CubeSampler {
    let chains: Vec<MipChain> = faces
        .iter()
        .map(|l| MipChain::from_levels(vec![l[0].clone()], parvo::MipOptions::default()).unwrap())
        .collect();
    CubeSampler::new(&chains, level0_bilinear())
        .unwrap()
        .with_placement(placement)
}

/// An OpenEXR cube strip is read as OpenEXR defines its faces (mirrored
/// against GL's) and texels (centres on the cube's edges): bilinear
/// lookups equal ImfEnvmap's position read bilinearly in the strip.
#[test]
fn openexr_cube_lookups_equal_imf_envmap() {
    let loaded = load(&openexr_image("WavyLinesCube.exr"));
    let strip = loaded.base().clone();
    let source = interpret(loaded, "WavyLinesCube.exr", None).unwrap();
    assert_eq!(source.kind, ImageKind::Cube);
    assert_eq!(source.placement, Placement::Edges);
    let sampler = cube_sampler(&source.images, source.placement);
    let sof = strip.width();
    let image = Linear::of(&strip);
    let mut worst = 0.0f64;
    for d in directions(2000) {
        let (face, pos) = imf_cube_pixel(d, sof);
        let first = (face as u32 * sof) as i64;
        let want = image.bilinear(pos, (first, first + sof as i64 - 1));
        let got = sampler.sample(&DirQuery::point(d.map(|c| c as f32)));
        for c in 0..4 {
            worst = worst.max((got[c] as f64 - want[c]).abs() / want[c].abs().max(1.0));
        }
    }
    assert!(
        worst < 2e-4,
        "largest relative difference from ImfEnvmap's cube lookup: {worst}"
    );
}

/// The relative differences between lookups on the cube file and on the
/// lat-long file of one environment (OpenEXR's WavyLines pair), at
/// directions away from the cube's edges: (median, 90th percentile).
fn pair_agreement(cube: &CubeSampler, ll: &LatLongSampler) -> (f64, f64) {
    let mut diffs: Vec<f64> = directions(2000)
        .into_iter()
        .filter(|d| {
            let mut a = d.map(f64::abs);
            a.sort_by(f64::total_cmp);
            a[1] / a[2] <= 0.95
        })
        .map(|d| {
            let q = DirQuery::point(d.map(|c| c as f32));
            let (a, b) = (cube.sample(&q), ll.sample(&q));
            (0..3)
                .map(|c| (a[c] - b[c]).abs() as f64 / (a[c].abs().max(b[c].abs()) as f64).max(1e-6))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    diffs.sort_by(f64::total_cmp);
    let at = |p: f64| diffs[((diffs.len() - 1) as f64 * p) as usize];
    (at(0.5), at(0.9))
}

/// The cube and the lat-long file of one environment look alike through
/// parvo once both are read as OpenEXR defines them; read as GL's faces
/// with centred texels (parvo's reading before), they do not.
#[test]
fn openexr_cube_and_lat_long_of_one_environment_agree() {
    let cube_src = interpret(load(&openexr_image("WavyLinesCube.exr")), "c", None).unwrap();
    let ll_src = interpret(load(&openexr_image("WavyLinesLatLong.exr")), "l", None).unwrap();
    let ll_base = ll_src.images[0][0].clone();
    let ll_chain = MipChain::from_levels(vec![ll_base], parvo::MipOptions::default()).unwrap();
    let ll = LatLongSampler::new(&ll_chain, level0_bilinear())
        .unwrap()
        .with_placement(ll_src.placement);
    let cube = cube_sampler(&cube_src.images, cube_src.placement);
    let (median, p90) = pair_agreement(&cube, &ll);
    // The faces as the strip stores them (GL's reading), centred.
    let strip = load(&openexr_image("WavyLinesCube.exr")).base().clone();
    let gl: Vec<Vec<Texture>> = parvo::env::cube::faces_from_strip(&strip)
        .unwrap()
        .into_iter()
        .map(|f| vec![f])
        .collect();
    let (old_median, old_p90) = pair_agreement(&cube_sampler(&gl, Placement::Centred), &ll);
    eprintln!(
        "WavyLines cube vs lat-long: median {median:.4}, p90 {p90:.4}; \
         GL's reading: median {old_median:.4}, p90 {old_p90:.4}"
    );
    assert!(median <= 0.02, "median relative difference {median}");
    assert!(
        p90 < 0.5 * old_p90,
        "p90 {p90} against GL's reading's {old_p90}"
    );
}

// --- Placement through the pipeline, against the definitions ---
//
// Files whose texels hold a smooth environment `smooth_env` exactly where
// each convention places them (OpenEXR's `CubeMap`/`LatLongMap` texel
// directions, GL's face centres, maketx's lat-long centres), run through
// `parvo mip`; every texel of the output must hold the environment at
// the direction its own convention gives it. Reading one convention as
// the other is off by half a texel: ~0.4 × half a texel's angle.

fn smooth_env(d: [f64; 3]) -> [f64; 3] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    [
        0.5 + 0.4 * d[0] / n,
        0.5 + 0.3 * d[1] / n + 0.1 * (d[0] * d[2]) / (n * n),
        0.5 + 0.4 * d[2] / n,
    ]
}

/// The direction of texel `(x, y)` (integer position within face `face`)
/// of an OpenEXR cube strip of `sof`-texel faces: `CubeMap::direction` of
/// `pixelPosition`'s inverse, checked against [`imf_cube_pixel`].
fn imf_cube_direction(face: usize, x: u32, y: u32, sof: u32) -> [f64; 3] {
    let s = (sof - 1) as f64;
    let (x, y) = (x as f64, y as f64);
    let (p0, p1) = match face {
        0 => (s - y, x),
        1 => (s - y, s - x),
        2 => (x, s - y),
        3 => (x, y),
        4 => (s - x, s - y),
        _ => (x, s - y),
    };
    let (u, v) = (2.0 * p0 / s - 1.0, 2.0 * p1 / s - 1.0);
    let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    let d = match face / 2 {
        0 => [sign, u, v],
        1 => [u, sign, v],
        _ => [u, v, sign],
    };
    // Off the cube's edges (where a direction has one face), the forward
    // mapping gives the texel back.
    if u.abs() < 1.0 && v.abs() < 1.0 {
        let (f, (px, py)) = imf_cube_pixel(d, sof);
        assert_eq!(f, face);
        assert!((px - x).abs() < 1e-9 && (py - (face as u32 * sof) as f64 - y).abs() < 1e-9);
    }
    d
}

/// The direction of the centre of texel `(i, j)` of GL's face `f`
/// (`n`×`n`): the inverse of the cube-map face selection table of the GL
/// specification (8.13), s = (sc/|ma| + 1)/2, t = (tc/|ma| + 1)/2.
fn gl_face_direction(f: usize, i: u32, j: u32, n: u32) -> [f64; 3] {
    let a = 2.0 * (i as f64 + 0.5) / n as f64 - 1.0;
    let b = 2.0 * (j as f64 + 0.5) / n as f64 - 1.0;
    match f {
        0 => [1.0, -b, -a],
        1 => [-1.0, -b, a],
        2 => [a, 1.0, b],
        3 => [a, -1.0, -b],
        4 => [a, -b, 1.0],
        _ => [-a, -b, -1.0],
    }
}

/// The direction of a lat-long map's position `(s, t)` (fractions of the
/// map; longitude +π at s = 0, the +y pole at t = 0):
/// `LatLongMap::direction`.
fn lat_long_direction(s: f64, t: f64) -> [f64; 3] {
    let lon = -2.0 * PI * (s - 0.5);
    let lat = -PI * (t - 0.5);
    [lon.sin() * lat.cos(), lat.sin(), lon.cos() * lat.cos()]
}

fn rgb_f32() -> parvo::Format {
    parvo::Format::new(3, parvo::ChannelType::F32, parvo::ColorSpace::Linear)
}

/// A `w`×`h` RGB f32 image holding `smooth_env` at `dir(x, y)`.
fn image_of(w: u32, h: u32, dir: impl Fn(u32, u32) -> [f64; 3]) -> Texture {
    let mut v = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            v.extend(smooth_env(dir(x, y)).map(|c| c as f32));
        }
    }
    Texture::from_linear(w, h, rgb_f32(), &v).unwrap()
}

/// The largest difference between `t`'s texels and `smooth_env` at
/// `dir(x, y)`, over the rows `rows`.
fn worst_against(
    t: &Texture,
    rows: std::ops::Range<u32>,
    dir: impl Fn(u32, u32) -> [f64; 3],
) -> f64 {
    let lin = t.to_linear();
    let mut worst = 0.0f64;
    for y in rows {
        for x in 0..t.width() {
            let want = smooth_env(dir(x, y));
            let i = ((y * t.width() + x) * 3) as usize;
            for c in 0..3 {
                worst = worst.max((lin[i + c] as f64 - want[c]).abs());
            }
        }
    }
    worst
}

fn mip(args: &[&str]) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
        .arg("mip")
        .args(args)
        .args(["--type", "f32"])
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// OpenEXR's cube strip to a KTX2 cube (GL's faces, centred texels) and
/// a KTX2 cube to OpenEXR's strip: every output texel holds the
/// environment where its container places it.
#[test]
fn cube_texels_are_placed_as_each_container_defines_them() {
    let dir = tempfile::tempdir().unwrap();
    let n = 32;
    // An OpenEXR strip, texels at ImfEnvmap's directions.
    let strip = image_of(n, 6 * n, |x, y| {
        imf_cube_direction((y / n) as usize, x, y % n, n)
    });
    let exr = dir.path().join("imf.exr");
    io::exr::save_environment(
        std::slice::from_ref(&strip),
        parvo::mip::Rounding::Down,
        &exr,
        &io::SaveOptions::default(),
        io::Environment::Cube,
    )
    .unwrap();
    let ktx2 = dir.path().join("gl.ktx2");
    mip(&[s(&exr), "-o", s(&ktx2)]);
    let faces = load(&ktx2).into_images();
    let got = (0..6)
        .map(|f| worst_against(&faces[f][0], 0..n, |i, j| gl_face_direction(f, i, j, n)))
        .fold(0.0, f64::max);
    // The strip's faces (mirrored to GL's) read as centred, unresampled:
    // what parvo wrote before.
    let as_is =
        io::exr::mirror_cube_faces(&parvo::env::cube::faces_from_strip(&strip).unwrap()).unwrap();
    let before = (0..6)
        .map(|f| worst_against(&as_is[f], 0..n, |i, j| gl_face_direction(f, i, j, n)))
        .fold(0.0, f64::max);
    eprintln!("OpenEXR strip -> KTX2: worst {got:.2e}; unresampled {before:.2e}");
    assert!(got < 5e-4 && got * 10.0 < before, "{got} against {before}");

    // Back: a KTX2 cube of GL's centres to an OpenEXR strip.
    let gl: Vec<Vec<Texture>> = (0..6)
        .map(|f| vec![image_of(n, n, |i, j| gl_face_direction(f, i, j, n))])
        .collect();
    let refs: Vec<&[Texture]> = gl.iter().map(Vec::as_slice).collect();
    let src = dir.path().join("src.ktx2");
    io::save_images(
        &refs,
        ImageKind::Cube,
        parvo::mip::Rounding::Down,
        &src,
        io::OutputKind::KTX2,
        &io::SaveOptions::default(),
    )
    .unwrap();
    let out = dir.path().join("out.exr");
    mip(&[s(&src), "-o", s(&out)]);
    let back = load(&out).base().clone();
    let got = worst_against(&back, 0..6 * n, |x, y| {
        imf_cube_direction((y / n) as usize, x, y % n, n)
    });
    eprintln!("KTX2 -> OpenEXR strip: worst {got:.2e} (edges and corners included)");
    assert!(got < 5e-4 && got * 10.0 < before, "{got} against {before}");
}

/// A lat-long map both ways: OpenEXR's (`envmap`) through `parvo mip` to
/// OpenEXR, whose level 0 comes back as it was and whose level 1 holds
/// the environment at OpenEXR's texel directions; and maketx's centred
/// texels (a plain image read with `--env latlong`) to OpenEXR's. The
/// pole rows of the written map hold what a centred reader finds at the
/// poles (the first and last rows), so they are checked against that.
#[test]
fn lat_long_texels_are_placed_as_each_container_defines_them() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (256, 128);
    let imf_of = |w: u32, h: u32| {
        move |x: u32, y: u32| {
            lat_long_direction(x as f64 / (w - 1) as f64, y as f64 / (h - 1) as f64)
        }
    };
    let imf = imf_of(w, h);
    let centred = |x: u32, y: u32| {
        lat_long_direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64)
    };
    let ll = image_of(w, h, imf);
    let exr = dir.path().join("imf_ll.exr");
    io::exr::save_environment(
        std::slice::from_ref(&ll),
        parvo::mip::Rounding::Down,
        &exr,
        &io::SaveOptions::default(),
        io::Environment::LatLong,
    )
    .unwrap();
    let out = dir.path().join("imf_out.exr");
    mip(&[s(&exr), "-o", s(&out)]);
    let levels = load(&out).levels;
    assert_eq!(levels[0], ll, "level 0 is written as it was read");
    let (w1, h1) = (w / 2, h / 2);
    // Rows two off the poles and nearer the equator (the rows next to a
    // pole row mix in the pole's one value: 1.6e-3 there).
    let rows = 2..h1 - 2;
    let got = worst_against(&levels[1], rows.clone(), imf_of(w1, h1));
    // Level 1 built from OpenEXR's texels read as centred and written as
    // built: what parvo did before.
    let old = latlong::build_chain(ll).unwrap().levels()[1].clone();
    let before = worst_against(&old, rows, imf_of(w1, h1));
    eprintln!("OpenEXR lat-long level 1: worst {got:.2e}; built as centred {before:.2e}");
    assert!(got < 1e-3 && got * 5.0 < before, "{got} against {before}");

    // maketx's centred lat-long to OpenEXR's.
    let src = dir.path().join("centred.exr");
    io::save(
        &[image_of(w, h, centred)],
        parvo::mip::Rounding::Down,
        &src,
        io::OutputKind::EXR,
        &io::SaveOptions::default(),
    )
    .unwrap();
    let out = dir.path().join("placed.exr");
    mip(&[s(&src), "--env", "latlong", "-o", s(&out)]);
    let back = load(&out);
    assert_eq!(back.info.placement, Placement::Edges);
    let back = back.base().clone();
    let got = worst_against(&back, 1..h - 1, imf);
    let written_as_is = worst_against(&image_of(w, h, centred), 1..h - 1, imf);
    eprintln!(
        "centred lat-long -> OpenEXR: worst {got:.2e} off the poles; as given {written_as_is:.2e}"
    );
    assert!(
        got < 5e-4 && got * 10.0 < written_as_is,
        "{got} against {written_as_is}"
    );
    // The pole rows: the first and last centred rows, resampled along
    // the row (each value between two neighbours of that row).
    let src_lin = image_of(w, h, centred).to_linear();
    let lin = back.to_linear();
    for (row, from) in [(0, 0), (h - 1, h - 1)] {
        for x in 0..w {
            let at = |r: u32, i: u32| &src_lin[((r * w + i % w) * 3) as usize..][..3];
            let p = x as f64 * w as f64 / (w - 1) as f64 - 0.5;
            let i0 = p.floor().rem_euclid(w as f64) as u32;
            for c in 0..3 {
                let (a, b) = (at(from, i0)[c], at(from, i0 + 1)[c]);
                let v = lin[((row * w + x) * 3) as usize + c];
                assert!(
                    v >= a.min(b) - 1e-6 && v <= a.max(b) + 1e-6,
                    "pole row {row} texel {x}: {v} not between {a} and {b}"
                );
            }
        }
    }
}

/// The direction `axis` (0, 1, 2 for x, y, z) with `sign`, plus `t` along
/// world axis `other`.
fn axis_plus(axis: usize, sign: f64, other: usize, t: f64) -> [f32; 3] {
    let mut d = [0.0f32; 3];
    d[axis] = sign as f32;
    d[other] += t as f32;
    d
}

/// The dark red or black of the axis glyphs OpenEXR's orientation maps
/// draw (the text around them is light blue, the rest white).
fn is_glyph(v: [f32; 4]) -> bool {
    v[1] < 0.1 && v[2] < 0.1
}

/// How many lookups along each arm of each face's axis glyph are dark: for
/// every face direction (±x, ±y, ±z) and each other world axis u, the
/// counts along +u and along −u (6 lookups each).
fn arm_counts(look: &dyn Fn([f32; 3]) -> [f32; 4]) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            for other in (0..3).filter(|&o| o != axis) {
                let count = |dir: f64| {
                    (1..=6)
                        .filter(|&k| {
                            is_glyph(look(axis_plus(axis, sign, other, dir * 0.05 * k as f64)))
                        })
                        .count()
                };
                let name = format!(
                    "{}{} face, toward {}",
                    if sign > 0.0 { "+" } else { "-" },
                    ["x", "y", "z"][axis],
                    ["x", "y", "z"][other]
                );
                out.push((name, count(1.0), count(-1.0)));
            }
        }
    }
    out
}

/// OpenEXR's `OrientationCube.exr` and `OrientationLatLong.exr` draw, in
/// the direction of each axis, a glyph whose two dark arms point
/// along the positive directions of the other two axes (`ImfEnvmap.h`:
/// "+X face: Y up, Z right", ...). Read as OpenEXR defines them, every
/// arm is where OpenEXR says, in both files; the strip's faces read as
/// GL's (unmirrored) put the arms of the X and Z faces the wrong way.
#[test]
fn openexr_orientation_maps_show_each_axis_where_openexr_says() {
    let cube_src = interpret(load(&openexr_image("OrientationCube.exr")), "c", None).unwrap();
    let cube = cube_sampler(&cube_src.images, cube_src.placement);
    let ll_src = interpret(load(&openexr_image("OrientationLatLong.exr")), "l", None).unwrap();
    let ll_chain = MipChain::from_levels(
        vec![ll_src.images[0][0].clone()],
        parvo::MipOptions::default(),
    )
    .unwrap();
    let ll = LatLongSampler::new(&ll_chain, level0_bilinear())
        .unwrap()
        .with_placement(ll_src.placement);
    for (file, counts) in [
        ("cube", arm_counts(&|d| cube.sample(&DirQuery::point(d)))),
        ("lat-long", arm_counts(&|d| ll.sample(&DirQuery::point(d)))),
    ] {
        for (name, along, against) in counts {
            assert!(
                along == 6 && against == 0,
                "{file} {name}: {along} of 6 lookups dark along the arm, {against} the other way"
            );
        }
    }
    // GL's reading of the strip: faces unmirrored, texels centred.
    let strip = load(&openexr_image("OrientationCube.exr")).base().clone();
    let gl: Vec<Vec<Texture>> = parvo::env::cube::faces_from_strip(&strip)
        .unwrap()
        .into_iter()
        .map(|f| vec![f])
        .collect();
    let gl = cube_sampler(&gl, Placement::Centred);
    let wrong = arm_counts(&|d| gl.sample(&DirQuery::point(d)))
        .into_iter()
        .filter(|(_, along, against)| *along < 5 || *against > 0)
        .count();
    assert!(wrong >= 4, "GL's reading puts only {wrong} arms wrong");
}
