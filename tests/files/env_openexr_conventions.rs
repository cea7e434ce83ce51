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
