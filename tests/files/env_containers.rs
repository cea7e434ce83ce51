//! Cube maps, arrays and environment maps in files: the KTX-Software
//! conformance suite's cube, cube-array and array files read as `ktx
//! extract` reads them, written back byte for byte as libktx lays them
//! out, parvo's own files checked field by field against the KTX 2.0
//! specification; OpenEXR cube strips and lat-long maps with their
//! `envmap`; cube edges without seams against a direction-space
//! reference; lat-long <-> cube conversion against an analytic
//! environment; and `parvo mip --env` end to end.

use std::path::{Path, PathBuf};
use std::process::Command;

use parvo::ImageKind;
use parvo::env::cube::{face_direction, face_st, faces_from_strip, fix_edges, select_face};
use parvo::env::{convert, latlong};
use parvo::io::{self, Environment, EnvironmentMaps, LoadOptions, OutputKind, SaveOptions};
use parvo::mip::Rounding;
use parvo::{ChannelType, ColorSpace, Format, MipChain, MipOptions, Texture};

fn cts(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer/ktx-cts")
        .join(name)
}

fn accept() -> LoadOptions {
    LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..LoadOptions::default()
    }
}

fn load(p: &Path) -> io::Loaded {
    io::load_with(p.to_str().unwrap(), &io::Limits::default(), &accept()).unwrap()
}

fn bytes(t: &Texture) -> Vec<u8> {
    io::le_bytes(t.texels()).into_owned()
}

/// Every image's levels as (size, format, bytes): equal even where the
/// texels are NaN (the conformance files hold some).
type Stored = (u32, u32, Format, Vec<u8>);

fn image_bytes(images: &[Vec<Texture>]) -> Vec<Vec<Stored>> {
    images
        .iter()
        .map(|l| {
            l.iter()
                .map(|t| (t.width(), t.height(), t.format(), bytes(t)))
                .collect()
        })
        .collect()
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

fn rgba_f32() -> Format {
    Format::new(4, ChannelType::F32, ColorSpace::Linear)
}

fn random_faces(n: u32, format: Format, seed: u64) -> Vec<Texture> {
    let mut r = Rng(seed);
    (0..6)
        .map(|_| {
            let v: Vec<f32> = (0..n * n * format.channels as u32).map(|_| r.f()).collect();
            Texture::from_linear(n, n, format, &v).unwrap()
        })
        .collect()
}

fn chains(faces: Vec<Texture>) -> Vec<MipChain> {
    faces
        .into_iter()
        .map(|f| parvo::mip::build(f, &MipOptions::default()).unwrap())
        .collect()
}

/// Every face and layer of the suite's cube, cube-array and array files
/// equals `ktx extract`'s raw output for it (the suite's golden files),
/// level by level.
#[test]
fn conformance_files_read_as_ktx_extract_reads_them() {
    type Golden<'a> = &'a dyn Fn(usize, usize) -> String;
    let cases: [(&str, ImageKind, Golden); 3] = [
        ("valid_R8G8B8A8_UNORM_CUBE_MIP", ImageKind::Cube, &|k, i| {
            format!("output_level{k}_face{i}.raw")
        }),
        (
            "valid_R16G16B16A16_UNORM_CUBE_ARRAY_MIP",
            ImageKind::CubeArray { cubes: 2 },
            // Images are cube by cube: image i is face i % 6 of layer i / 6.
            &|k, i| format!("output_level{k}_face{}_layer{}.raw", i % 6, i / 6),
        ),
        (
            "valid_R8G8B8A8_UNORM_2D_ARRAY_MIP",
            ImageKind::Array { layers: 4 },
            &|k, i| format!("output_level{k}_layer{i}.raw"),
        ),
    ];
    for (name, kind, golden) in cases {
        let l = load(&cts(&format!("{name}.ktx2")));
        assert_eq!(l.info.kind, kind, "{name}");
        assert_eq!(l.images.len() + 1, kind.images(), "{name}");
        let levels = l.levels.len();
        assert_eq!(levels, 4, "{name}");
        for (i, image) in l.into_images().iter().enumerate() {
            assert_eq!(image.len(), levels, "{name} image {i}");
            for (k, t) in image.iter().enumerate() {
                let want = std::fs::read(
                    cts("golden")
                        .join(format!("output_{}", name.trim_start_matches("valid_")))
                        .join(golden(k, i)),
                )
                .unwrap();
                assert_eq!(bytes(t), want, "{name} level {k} image {i}");
            }
        }
    }
}

/// A reader that takes one 2-D image refuses a cube map or an array
/// with what it is, instead of keeping its first face.
#[test]
fn cube_maps_and_arrays_are_refused_where_one_image_is_read() {
    for (name, what) in [
        ("valid_R16G16B16A16_SFLOAT_CUBE.ktx2", "a cube map of six"),
        ("valid_R16G16B16A16_SFLOAT_2D_ARRAY.ktx2", "a 2-D array of"),
        (
            "valid_R16G16B16A16_UNORM_CUBE_ARRAY_MIP.ktx2",
            "an array of 2 cube maps",
        ),
    ] {
        let e = io::load(cts(name).to_str().unwrap(), &io::Limits::default())
            .err()
            .unwrap_or_else(|| panic!("{name} loaded as one image"));
        assert!(e.to_string().contains(what), "{name}: {e}");
    }
}

/// Parsed KTX2 header and level index.
struct Ktx2Layout {
    words: Vec<u32>,
    dfd: (u32, u32),
    kvd: (u32, u32),
    levels: Vec<(u64, u64, u64)>,
}

fn layout(file: &[u8]) -> Ktx2Layout {
    let w = |at: usize| u32::from_le_bytes(file[at..at + 4].try_into().unwrap());
    let q = |at: usize| u64::from_le_bytes(file[at..at + 8].try_into().unwrap());
    let words: Vec<u32> = (0..9).map(|i| w(12 + 4 * i)).collect();
    let count = words[7].max(1) as usize;
    Ktx2Layout {
        dfd: (w(48), w(52)),
        kvd: (w(56), w(60)),
        levels: (0..count)
            .map(|k| (q(80 + 24 * k), q(88 + 24 * k), q(96 + 24 * k)))
            .collect(),
        words,
    }
}

/// parvo's cube maps, cube-map arrays and arrays, checked against the
/// KTX 2.0 specification's rules (what `ktx validate` checks of the
/// header, index and level layout), and their level bytes against the
/// same images as libktx wrote them (the conformance files).
#[test]
fn written_cube_maps_and_arrays_follow_the_ktx2_layout() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "valid_R8G8B8A8_UNORM_CUBE_MIP",
        "valid_R16G16B16A16_UNORM_CUBE_ARRAY_MIP",
        "valid_R8G8B8A8_UNORM_2D_ARRAY_MIP",
        "valid_R16G16B16A16_SFLOAT_CUBE",
        "valid_R16G16B16A16_SFLOAT_2D_ARRAY",
        "valid_R8G8B8A8_SRGB_CUBE",
        "valid_R8G8B8A8_SRGB_2D_ARRAY",
    ] {
        let src_path = cts(&format!("{name}.ktx2"));
        let l = load(&src_path);
        let kind = l.info.kind;
        let texel = l.base().format().texel_bytes() as u64;
        let images = l.into_images();
        let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
        let out = dir.path().join(format!("{name}.ktx2"));
        io::save_images(
            &refs,
            kind,
            Rounding::Down,
            &out,
            OutputKind::KTX2,
            &SaveOptions::default(),
        )
        .unwrap();
        let mine = std::fs::read(&out).unwrap();
        let theirs = std::fs::read(&src_path).unwrap();
        let (a, b) = (layout(&mine), layout(&theirs));
        // vkFormat, typeSize, width, height, depth, layers, faces, levels
        // and supercompression as libktx wrote them.
        assert_eq!(a.words, b.words, "{name} header");
        let (w, h) = (a.words[2], a.words[3].max(1));
        assert_eq!(a.words[4], 0, "{name}: pixelDepth 0 for 2-D images");
        let faces = a.words[6];
        assert!(faces == 1 || faces == 6, "{name}");
        if faces == 6 {
            assert_eq!(w, h, "{name}: cube faces are square");
        }
        let count = kind.images() as u64;
        assert_eq!(count, a.words[5].max(1) as u64 * faces as u64, "{name}");
        // Section 3.9: the DFD right after the level index, key/value
        // data after it, levels aligned to lcm(texel size, 4), smallest
        // level first in the file, nothing after the largest.
        assert_eq!(a.dfd.0 as usize, 80 + 24 * a.levels.len(), "{name}");
        assert_eq!(a.kvd.0, a.dfd.0 + a.dfd.1, "{name}");
        let align = if texel.is_multiple_of(4) {
            texel
        } else {
            texel * 4 / gcd(texel, 4)
        };
        let mut end_of_smaller = (a.kvd.0 + a.kvd.1) as u64;
        for k in (0..a.levels.len()).rev() {
            let (off, len, full) = a.levels[k];
            let (lw, lh) = parvo::mip::level_size(w, h, k as u32, Rounding::Down);
            assert_eq!(
                len,
                lw as u64 * lh as u64 * texel * count,
                "{name} level {k}"
            );
            assert_eq!(full, len, "{name} level {k}: not supercompressed");
            assert_eq!(off % align, 0, "{name} level {k} alignment");
            assert!(off >= end_of_smaller, "{name} level {k} order");
            end_of_smaller = off + len;
            let (o2, l2, _) = b.levels[k];
            assert_eq!(
                &mine[off as usize..(off + len) as usize],
                &theirs[o2 as usize..(o2 + l2) as usize],
                "{name} level {k}: faces and layers in libktx's order"
            );
        }
        assert_eq!(
            end_of_smaller,
            mine.len() as u64,
            "{name}: nothing after level 0"
        );
        // And it reads back as what it was.
        let back = load(&out);
        assert_eq!(back.info.kind, kind, "{name}");
        assert_eq!(
            image_bytes(&back.into_images()),
            image_bytes(&images),
            "{name}"
        );
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Supercompressed cube maps and arrays round-trip (the whole level, all
/// faces and layers, is one zstd stream).
#[test]
fn supercompressed_cube_maps_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let l = load(&cts("valid_R16G16B16A16_UNORM_CUBE_ARRAY_MIP.ktx2"));
    let images = l.into_images();
    let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
    let out = dir.path().join("z.ktx2");
    let opts = SaveOptions {
        ktx2: parvo::io::ktx2::Ktx2Options {
            supercompression: Some(io::ktx2::Supercompression::Zstd(9)),
        },
        ..SaveOptions::default()
    };
    io::save_images(
        &refs,
        ImageKind::CubeArray { cubes: 2 },
        Rounding::Down,
        &out,
        OutputKind::KTX2,
        &opts,
    )
    .unwrap();
    let back = load(&out);
    assert_eq!(back.info.kind, ImageKind::CubeArray { cubes: 2 });
    assert_eq!(back.into_images(), images);
}

/// An OpenEXR cube map is OpenEXR's strip of six faces in every level,
/// marked `envmap` cube; its last levels (1x3, 1x1) exist because the
/// format's level rule asks for them. A lat-long map is marked too.
/// Faces whose levels cannot stay apart in a strip are refused.
#[test]
fn openexr_environments_are_strips_and_lat_long_maps_with_envmap() {
    let dir = tempfile::tempdir().unwrap();
    // RGB: OpenEXR would store colour with alpha premultiplied.
    let f16 = Format::new(3, ChannelType::F16, ColorSpace::Linear);
    let faces = chains(random_faces(8, f16, 7));
    let levels: Vec<Vec<Texture>> = faces.iter().map(|c| c.levels().to_vec()).collect();
    let refs: Vec<&[Texture]> = levels.iter().map(|v| v.as_slice()).collect();
    let out = dir.path().join("cube.exr");
    io::save_images(
        &refs,
        ImageKind::Cube,
        Rounding::Down,
        &out,
        OutputKind::EXR,
        &SaveOptions::default(),
    )
    .unwrap();
    let back = io::load_with(
        out.to_str().unwrap(),
        &io::Limits::default(),
        &LoadOptions {
            environment: EnvironmentMaps::Describe,
            ..LoadOptions::default()
        },
    )
    .unwrap();
    assert_eq!(back.info.environment, Some(Environment::Cube));
    let sizes: Vec<_> = back
        .levels
        .iter()
        .map(|t| (t.width(), t.height()))
        .collect();
    assert_eq!(sizes, [(8, 48), (4, 24), (2, 12), (1, 6), (1, 3), (1, 1)]);
    // The strip holds OpenEXR's faces (mirrored against GL's) with
    // OpenEXR's texel placement: the centred texels given, resampled.
    let placed = io::exr::edges_from_centred(&refs, ImageKind::Cube, 0).unwrap();
    for (k, level) in back.levels.iter().enumerate().take(4) {
        let stacked = io::exr::mirror_cube_faces(&faces_from_strip(level).unwrap()).unwrap();
        for f in 0..6 {
            assert_eq!(stacked[f], placed[f][k], "level {k} face {f}");
        }
    }
    // Texels said to be placed as OpenEXR places them are written as
    // they are.
    let as_given = dir.path().join("as_given.exr");
    let placed_refs: Vec<&[Texture]> = placed.iter().map(Vec::as_slice).collect();
    let edges = SaveOptions {
        placement: parvo::env::Placement::Edges,
        ..SaveOptions::default()
    };
    io::save_images(
        &placed_refs,
        ImageKind::Cube,
        Rounding::Down,
        &as_given,
        OutputKind::EXR,
        &edges,
    )
    .unwrap();
    assert_eq!(
        std::fs::read(&as_given).unwrap(),
        std::fs::read(&out).unwrap()
    );
    // Refused where one image is read: it is not a plain texture.
    assert!(io::load(out.to_str().unwrap(), &io::Limits::default()).is_err());

    // Lat-long: the image as given, marked.
    let ll = Texture::from_linear(16, 8, f16, &vec![0.25; 16 * 8 * 3]).unwrap();
    let chain = latlong::build_chain(ll).unwrap();
    let out = dir.path().join("ll.exr");
    io::save_images(
        &[chain.levels()],
        ImageKind::LatLong,
        Rounding::Down,
        &out,
        OutputKind::EXR,
        &SaveOptions::default(),
    )
    .unwrap();
    let back = load(&out);
    assert_eq!(back.info.environment, Some(Environment::LatLong));
    assert_eq!(back.levels, chain.levels());

    // 6x6 faces: the strip's level 1 (3x18) would be 3x3 faces, level 2
    // (1x9) no whole faces at all.
    let odd = chains(random_faces(6, f16, 8));
    let levels: Vec<Vec<Texture>> = odd.iter().map(|c| c.levels().to_vec()).collect();
    let refs: Vec<&[Texture]> = levels.iter().map(|v| v.as_slice()).collect();
    let e = io::save_images(
        &refs,
        ImageKind::Cube,
        Rounding::Down,
        &dir.path().join("odd.exr"),
        OutputKind::EXR,
        &SaveOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("power-of-two"), "{e}");
    assert!(!dir.path().join("odd.exr").exists());
    // A lat-long map has nowhere to go in KTX2, and says where it can.
    let e = io::save_images(
        &[chain.levels()],
        ImageKind::LatLong,
        Rounding::Down,
        &dir.path().join("ll.ktx2"),
        OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains(".exr"), "{e}");
}

/// The centre directions, as unit vectors, of every level-0 texel.
fn centres(n: u32) -> Vec<(usize, u32, u32, [f64; 3])> {
    let mut v = Vec::new();
    for f in 0..6 {
        for j in 0..n {
            for i in 0..n {
                let d = face_direction(f, (i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                v.push((f, i, j, d));
            }
        }
    }
    v
}

/// The level-`k` cell (face, i, j) a direction falls in.
fn cell(d: [f64; 3], nk: u32) -> (usize, u32, u32) {
    let f = select_face(d);
    let (s, t) = face_st(f, d);
    let idx = |x: f64| ((x * nk as f64).floor() as i64).clamp(0, nk as i64 - 1) as u32;
    (f, idx(s), idx(t))
}

/// The level-`k` texels that touch texel `(f, i, j)` across an edge,
/// found by brute force: the texels of other faces whose centres are
/// nearest to where the next texel past the edge would be centred.
fn across_brute(f: usize, i: i64, j: i64, nk: u32) -> (usize, u32, u32) {
    let n = nk as f64;
    let d = face_direction(f, (i as f64 + 0.5) / n, (j as f64 + 0.5) / n);
    let unit = |d: [f64; 3]| {
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        d.map(|c| c / l)
    };
    let d = unit(d);
    let mut best = (f64::MAX, (0, 0, 0));
    for (g, a, b, c) in centres(nk) {
        if g == f {
            continue;
        }
        let c = unit(c);
        let dist = (0..3).map(|x| (c[x] - d[x]).powi(2)).sum::<f64>();
        if dist < best.0 {
            best = (dist, (g, a, b));
        }
    }
    best.1
}

/// Edge fix-up leaves no seam: at every level from 1 on, the texels on
/// both sides of every edge (three at a corner) are equal, and equal to
/// the direction-space box of level 0 over their cells — the mean of
/// every level-0 texel whose centre direction falls in any of them —
/// within the format's precision (f32: 1e-5; u8 sRGB: one code), colour
/// weighted by the straight alpha as the box filter weights it. The
/// texels off the edges are the plain box chain's.
#[test]
fn cube_edges_have_no_seam_after_fix_up() {
    for (format, n, tol) in [
        (rgba_f32(), 16u32, 1e-5f32),
        (
            Format::new(4, ChannelType::U8, ColorSpace::Srgb),
            32,
            1.0 / 255.0,
        ),
    ] {
        let faces = random_faces(n, format, 11 + n as u64);
        let plain = chains(faces.clone());
        let fixed = fix_edges(plain.clone(), 1).unwrap();
        let lin0: Vec<Vec<f32>> = faces.iter().map(|t| t.to_linear()).collect();
        let texel0 = |(f, i, j): (usize, u32, u32)| {
            let o = (j * n + i) as usize * 4;
            [lin0[f][o], lin0[f][o + 1], lin0[f][o + 2], lin0[f][o + 3]]
        };
        let all0 = centres(n);
        for k in 1..plain[0].len() {
            let nk = n >> k;
            if nk < 2 {
                continue;
            }
            let cells: Vec<(usize, u32, u32)> = all0.iter().map(|c| cell(c.3, nk)).collect();
            for f in 0..6 {
                for j in 0..nk {
                    for i in 0..nk {
                        let (ii, jj, last) = (i as i64, j as i64, nk as i64 - 1);
                        let mut group = vec![(f, i, j)];
                        if ii == 0 || ii == last {
                            group.push(across_brute(
                                f,
                                if ii == 0 { -1 } else { nk as i64 },
                                jj,
                                nk,
                            ));
                        }
                        if jj == 0 || jj == last {
                            group.push(across_brute(
                                f,
                                ii,
                                if jj == 0 { -1 } else { nk as i64 },
                                nk,
                            ));
                        }
                        let got = fixed[f].levels()[k].texel_linear(i, j);
                        if group.len() == 1 {
                            assert_eq!(
                                got,
                                plain[f].levels()[k].texel_linear(i, j),
                                "interior {f} {i} {j}"
                            );
                            continue;
                        }
                        // Colour weighted by (straight) alpha, as the
                        // box filter weights it.
                        let mut acc = [0f64; 4];
                        let mut count = 0;
                        for (t, c) in all0.iter().zip(&cells) {
                            if group.contains(c) {
                                let v = texel0((t.0, t.1, t.2));
                                for x in 0..3 {
                                    acc[x] += v[x] as f64 * v[3] as f64;
                                }
                                acc[3] += v[3] as f64;
                                count += 1;
                            }
                        }
                        let reference = [
                            (acc[0] / acc[3]) as f32,
                            (acc[1] / acc[3]) as f32,
                            (acc[2] / acc[3]) as f32,
                            (acc[3] / count as f64) as f32,
                        ];
                        // Compared as stored: sRGB codes for u8 sRGB colour.
                        let stored = |v: [f32; 4]| -> [f32; 4] {
                            if format.color_space == ColorSpace::Srgb {
                                [srgb(v[0]), srgb(v[1]), srgb(v[2]), v[3]]
                            } else {
                                v
                            }
                        };
                        let want = stored(reference);
                        for &(g, a, b) in &group {
                            let other = stored(fixed[g].levels()[k].texel_linear(a, b));
                            for x in 0..4 {
                                assert!(
                                    (other[x] - want[x]).abs() <= tol * 1.01,
                                    "{format} level {k} face {g} ({a},{b}) of the edge at face {f} \
                                     ({i},{j}): {other:?} vs reference {reference:?}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The sRGB encoding (IEC 61966-2-1) of a linear value.
fn srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0) as f64;
    (if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }) as f32
}

/// A smooth environment (linear in the direction's components).
fn smooth(d: [f64; 3]) -> [f32; 4] {
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = d.map(|c| c / l);
    [
        (0.5 + 0.4 * d[0]) as f32,
        (0.5 + 0.3 * d[1] - 0.1 * d[2]) as f32,
        (0.5 + 0.45 * d[2]) as f32,
        1.0,
    ]
}

/// A lat-long map of a smooth environment becomes a cube map whose texels
/// hold the environment at their centres, and back: orientation (y up,
/// OpenImageIO's s and t) and footprints right on every face.
#[test]
fn lat_long_and_cube_convert_into_each_other() {
    let (w, h) = (256u32, 128u32);
    let mut v = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let d =
                latlong::st_to_direction((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
            v.extend(smooth(d));
        }
    }
    let ll = Texture::from_f32(w, h, rgba_f32(), v).unwrap();
    let chain = latlong::build_chain(ll).unwrap();
    let n = 24;
    let faces = convert::latlong_to_cube(&chain, n).unwrap();
    let mut worst = 0f32;
    for (f, t) in faces.iter().enumerate() {
        for j in 0..n {
            for i in 0..n {
                let d = face_direction(f, (i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let want = smooth(d);
                let got = t.texel_linear(i, j);
                for c in 0..4 {
                    worst = worst.max((got[c] - want[c]).abs());
                }
            }
        }
    }
    assert!(worst < 0.01, "lat-long -> cube off by {worst}");

    let cube = chains(faces);
    let back = convert::cube_to_latlong(&cube, 96, 48).unwrap();
    let mut worst = 0f32;
    for j in 0..48 {
        for i in 0..96 {
            let d = latlong::st_to_direction((i as f64 + 0.5) / 96.0, (j as f64 + 0.5) / 48.0);
            let want = smooth(d);
            let got = back.texel_linear(i, j);
            for c in 0..4 {
                worst = worst.max((got[c] - want[c]).abs());
            }
        }
    }
    assert!(worst < 0.01, "cube -> lat-long off by {worst}");
}

fn parvo(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .unwrap()
}

fn info_json(path: &Path) -> serde_json::Value {
    let o = parvo(&["info", "--json", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// `parvo mip --env`: a cube strip, six face files, a lat-long map and a
/// KTX2 cube map in; cube maps (KTX2, OpenEXR), lat-long maps and
/// prefiltered chains out, each of the kind `parvo info` then reports.
#[test]
fn mip_builds_environment_maps_from_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    // Inputs: a 16x96 strip, its six faces, a 64x32 lat-long map (RGB:
    // OpenEXR would premultiply colour by alpha).
    let f16 = Format::new(3, ChannelType::F16, ColorSpace::Linear);
    let faces = random_faces(16, f16, 3);
    let strip = parvo::env::cube::strip_from_faces(&faces.iter().collect::<Vec<_>>()).unwrap();
    io::save(
        &[strip],
        Rounding::Down,
        &p("strip.exr"),
        OutputKind::EXR,
        &SaveOptions::default(),
    )
    .unwrap();
    let mut face_files = Vec::new();
    for (f, t) in faces.iter().enumerate() {
        let path = p(&format!("face{f}.exr"));
        io::save(
            std::slice::from_ref(t),
            Rounding::Down,
            &path,
            OutputKind::EXR,
            &SaveOptions::default(),
        )
        .unwrap();
        face_files.push(s(&path));
    }
    let ll = Texture::from_linear(64, 32, f16, &vec![0.5; 64 * 32 * 3]).unwrap();
    io::save(
        &[ll],
        Rounding::Down,
        &p("ll.exr"),
        OutputKind::EXR,
        &SaveOptions::default(),
    )
    .unwrap();

    let run = |args: Vec<String>| {
        let a: Vec<&str> = args.iter().map(|x| x.as_str()).collect();
        let o = parvo(&a);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let v = |x: &[&str]| x.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    run(v(&[
        "mip",
        &s(&p("strip.exr")),
        "--env",
        "cube",
        "-o",
        &s(&p("a.ktx2")),
    ]));
    let j = info_json(&p("a.ktx2"));
    assert_eq!(j["kind"], "cube");
    assert_eq!(j["images"], 6);
    assert_eq!(j["levels"].as_array().unwrap().len(), 5);

    let mut six = v(&["mip"]);
    six.extend(face_files.iter().cloned());
    six.extend(v(&["--env", "cube", "-o", &s(&p("b.exr"))]));
    run(six);
    let j = info_json(&p("b.exr"));
    assert_eq!(j["kind"], "cube");
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(16), Some(96))
    );

    // The six files and the strip give the same cube map.
    let a = load(&p("a.ktx2"));
    let b = io::load_with(&s(&p("b.exr")), &io::Limits::default(), &accept()).unwrap();
    // The strip holds OpenEXR's faces (mirrored against GL's), its texels
    // placed as OpenEXR places them.
    let b_faces = io::exr::mirror_cube_faces(&faces_from_strip(&b.levels[1]).unwrap()).unwrap();
    let a_images = a.into_images();
    let a_refs: Vec<&[Texture]> = a_images.iter().map(Vec::as_slice).collect();
    let a_placed = io::exr::edges_from_centred(&a_refs, ImageKind::Cube, 0).unwrap();
    for (f, t) in a_placed.iter().enumerate() {
        let want = t[1].convert(f16).unwrap();
        assert_eq!(b_faces[f], want, "face {f} level 1");
    }

    run(v(&[
        "mip",
        &s(&p("ll.exr")),
        "--env",
        "latlong",
        "-o",
        &s(&p("c.exr")),
    ]));
    assert_eq!(info_json(&p("c.exr"))["kind"], "latlong");
    run(v(&[
        "mip",
        &s(&p("ll.exr")),
        "--env",
        "cube",
        "--face-size",
        "8",
        "-o",
        &s(&p("d.ktx2")),
    ]));
    let j = info_json(&p("d.ktx2"));
    assert_eq!(
        (j["kind"].as_str(), j["width"].as_u64()),
        (Some("cube"), Some(8))
    );

    // A KTX2 cube map in: kept a cube map without --env.
    run(v(&[
        "mip",
        cts("valid_R8G8B8A8_SRGB_CUBE.ktx2").to_str().unwrap(),
        "-o",
        &s(&p("e.ktx2")),
    ]));
    assert_eq!(info_json(&p("e.ktx2"))["kind"], "cube");
    // The same sRGB cube map to OpenEXR: linear floats, said on stderr;
    // to KTX2 (above) it stays sRGB and nothing is said.
    let o = parvo(&[
        "mip",
        cts("valid_R8G8B8A8_SRGB_CUBE.ktx2").to_str().unwrap(),
        "-o",
        &s(&p("e.exr")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("decoded to linear light"), "{err}");
    let j = info_json(&p("e.exr"));
    assert_eq!(
        (j["kind"].as_str(), j["color"].as_str()),
        (Some("cube"), Some("linear"))
    );
    let o = parvo(&[
        "mip",
        cts("valid_R8G8B8A8_SRGB_CUBE.ktx2").to_str().unwrap(),
        "-o",
        &s(&p("e2.ktx2")),
    ]);
    assert!(String::from_utf8_lossy(&o.stderr).is_empty());
    run(v(&[
        "mip",
        cts("valid_R8G8B8A8_SRGB_2D_ARRAY.ktx2").to_str().unwrap(),
        "-o",
        &s(&p("f.ktx2")),
    ]));
    assert_eq!(info_json(&p("f.ktx2"))["kind"], "array");

    // Prefiltered: float levels, each level's roughness recorded in the
    // file and printed with the SH9 coefficients.
    let o = parvo(&[
        "mip",
        &s(&p("strip.exr")),
        "--env",
        "cube",
        "--prefilter",
        "ggx",
        "--irradiance",
        &s(&p("irr.ktx2")),
        "--brdf-lut",
        &s(&p("lut.exr")),
        "--brdf-lut-size",
        "24",
        "--json",
        "-o",
        &s(&p("g.ktx2")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let j = info_json(&p("g.ktx2"));
    assert_eq!(
        (j["kind"].as_str(), j["type"].as_str()),
        (Some("cube"), Some("f16"))
    );
    let levels = j["levels"].as_array().unwrap().len();
    let want: Vec<f64> = (0..levels)
        .map(|k| (k as f64 / (levels - 1) as f64).powi(2))
        .collect();
    let stored: Vec<f64> = j["attributes"]["parvo:roughness"]
        .as_str()
        .unwrap()
        .split(' ')
        .map(|a| a.parse().unwrap())
        .collect();
    let printed: Vec<f64> = out["lighting"]["roughness"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_f64().unwrap())
        .collect();
    for (got, want) in stored.iter().zip(&want).chain(printed.iter().zip(&want)) {
        assert!((got - want).abs() < 1e-6, "{stored:?} {printed:?}");
    }
    assert_eq!((stored.len(), printed.len()), (levels, levels));
    assert_eq!(out["lighting"]["prefilter"], "ggx");
    let sh9 = out["lighting"]["sh9"].as_array().unwrap();
    assert_eq!(sh9.len(), 9);
    // The DC term of a positive environment: positive in every channel.
    assert!(
        sh9[0]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c.as_f64().unwrap() > 0.0)
    );
    // The BRDF table: the library's, stored as f16.
    let lut = parvo::io::load(&s(&p("lut.exr")), &parvo::io::Limits::default()).unwrap();
    let want = parvo::env::prefilter::dfg::table(24).unwrap();
    let got = lut.base();
    assert_eq!((got.width(), got.height()), (24, 24));
    for (i, j) in [(0, 0), (23, 0), (5, 17), (23, 23)] {
        let (g, w) = (got.texel_linear(i, j), want.texel_linear(i, j));
        for c in 0..3 {
            // f16: 11 significant bits, and nothing below 6e-8.
            assert!(
                (g[c] - w[c]).abs() <= w[c].abs() / 1024.0 + 6e-8,
                "{g:?} {w:?}"
            );
        }
    }
    let o = parvo(&[
        "mip",
        &s(&p("strip.exr")),
        "--env",
        "cube",
        "--brdf-lut",
        &s(&p("lut2.png")),
        "-o",
        &s(&p("g2.ktx2")),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--prefilter"));
    assert!(!p("g2.ktx2").exists() && !p("lut2.png").exists());
    let j = info_json(&p("irr.ktx2"));
    assert_eq!(
        (j["kind"].as_str(), j["width"].as_u64()),
        (Some("cube"), Some(32))
    );

    // Errors a user can act on, and nothing written.
    let o = parvo(&[
        "mip",
        &s(&p("ll.exr")),
        "--env",
        "latlong",
        "-o",
        &s(&p("h.ktx2")),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(".exr"), "{err}");
    assert!(!p("h.ktx2").exists());
    let o = parvo(&[
        "mip",
        &s(&p("ll.exr")),
        "-o",
        &s(&p("i.exr")),
        "--prefilter",
        "ggx",
    ]);
    assert!(!o.status.success());
}

/// DDS cube maps and arrays as Direct3D lays them out: the legacy cube
/// flags (all six faces), a DX10 header with `arraySize` (and the cube
/// flag) for arrays — a legacy format moved to its DXGI equivalent —
/// then image after image, each with all its levels. They read back as
/// written, and a reader of one 2-D image refuses them.
#[test]
fn dds_cube_maps_and_arrays_round_trip_image_by_image() {
    let dir = tempfile::tempdir().unwrap();
    let u8s = Format::new(4, ChannelType::U8, ColorSpace::Linear)
        .with_alpha(parvo::texel::AlphaMode::Straight);
    let grey = Format::new(1, ChannelType::U8, ColorSpace::Linear);
    let f16 = Format::new(4, ChannelType::F16, ColorSpace::Linear);
    // (kind, format, size, caps2, DX10 (dxgi, misc flag, array size))
    let cases = [
        (ImageKind::Cube, u8s, 8u32, 0xfe00u32, None),
        (
            ImageKind::Array { layers: 3 },
            u8s,
            6,
            0,
            Some((28u32, 0u32, 3u32)),
        ),
        (
            ImageKind::CubeArray { cubes: 2 },
            f16,
            4,
            0xfe00,
            Some((10, 4, 2)),
        ),
        (ImageKind::Array { layers: 2 }, grey, 5, 0, Some((61, 0, 2))),
    ];
    for (i, (kind, format, n, caps2, dx10)) in cases.into_iter().enumerate() {
        let mut r = Rng(40 + i as u64);
        let images: Vec<Vec<Texture>> = (0..kind.images())
            .map(|_| {
                let v: Vec<f32> = (0..n * n * format.channels as u32).map(|_| r.f()).collect();
                let t = Texture::from_linear(n, n, format, &v).unwrap();
                parvo::mip::build(t, &MipOptions::default())
                    .unwrap()
                    .into_levels()
            })
            .collect();
        let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
        let out = dir.path().join(format!("{i}.dds"));
        io::save_images(
            &refs,
            kind,
            Rounding::Down,
            &out,
            OutputKind::DDS,
            &SaveOptions::default(),
        )
        .unwrap();
        let file = std::fs::read(&out).unwrap();
        let w = |at: usize| u32::from_le_bytes(file[at..at + 4].try_into().unwrap());
        assert_eq!(w(112), caps2, "{kind:?} caps2");
        assert_ne!(w(108) & 0x8, 0, "{kind:?}: DDSCAPS_COMPLEX");
        let mut at = match dx10 {
            None => {
                assert_ne!(&file[84..88], b"DX10", "{kind:?}: legacy header");
                128
            }
            Some((dxgi, misc, count)) => {
                assert_eq!(&file[84..88], b"DX10", "{kind:?}");
                assert_eq!(
                    (w(128), w(132), w(136), w(140)),
                    (dxgi, 3, misc, count),
                    "{kind:?}"
                );
                148
            }
        };
        // Image by image, level by level, in the stored channel count.
        let stored_ch = if format.channels == 1 { 1 } else { 4 };
        for (m, levels) in images.iter().enumerate() {
            for (k, t) in levels.iter().enumerate() {
                let len = t.width() as usize
                    * t.height() as usize
                    * stored_ch
                    * format.channel_type.bytes();
                assert_eq!(
                    &file[at..at + len],
                    &bytes(t)[..],
                    "{kind:?} image {m} level {k}"
                );
                at += len;
            }
        }
        assert_eq!(at, file.len(), "{kind:?}: nothing after the last image");
        let back = load(&out);
        assert_eq!(back.info.kind, kind);
        assert_eq!(back.into_images(), images, "{kind:?}");
        assert!(io::load(out.to_str().unwrap(), &io::Limits::default()).is_err());
    }
}

/// openexr-images' environments (`MultiResolution/WavyLinesCube.exr`,
/// `WavyLinesLatLong.exr`, maketx-style files with their own levels)
/// keep their kind through `parvo mip` (no `--env`: the files say what
/// they are), and level 0 comes back texel for texel to OpenEXR, and as
/// OpenEXR's texels resampled to centred ones in KTX2.
#[test]
fn openexr_images_environments_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let peer = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/peer/openexr-images");
    for (name, kind) in [
        ("WavyLinesCube.exr", "cube"),
        ("WavyLinesLatLong.exr", "latlong"),
    ] {
        let src = peer.join(name);
        assert_eq!(info_json(&src)["kind"], kind, "{name}");
        for ext in ["exr", "ktx2"] {
            if kind == "latlong" && ext == "ktx2" {
                continue;
            }
            let out = dir.path().join(format!("{name}.{ext}"));
            let o = parvo(&["mip", src.to_str().unwrap(), "-o", out.to_str().unwrap()]);
            assert!(
                o.status.success(),
                "{name} -> {ext}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            assert_eq!(info_json(&out)["kind"], kind, "{name} -> {ext}");
            let a = load(&src);
            let b = load(&out);
            let (a0, b0) = if kind == "cube" && ext == "ktx2" {
                // OpenEXR's faces and texel placement; the KTX2 holds GL's
                // faces with centred texels, resampled from OpenEXR's.
                let faces: Vec<Texture> =
                    io::exr::mirror_cube_faces(&faces_from_strip(a.base()).unwrap())
                        .unwrap()
                        .iter()
                        .map(|f| io::exr::centred_from_edges(f).unwrap())
                        .collect();
                let strip = parvo::env::cube::strip_from_faces(
                    &b.into_images().iter().map(|l| &l[0]).collect::<Vec<_>>(),
                )
                .unwrap();
                (
                    parvo::env::cube::strip_from_faces(&faces.iter().collect::<Vec<_>>()).unwrap(),
                    strip,
                )
            } else {
                (a.base().clone(), b.base().clone())
            };
            assert_eq!(
                (a0.width(), a0.height()),
                (b0.width(), b0.height()),
                "{name} -> {ext}"
            );
            assert_eq!(a0.to_linear(), b0.to_linear(), "{name} -> {ext}: level 0");
        }
    }
}

/// An 8-bit sRGB cube map and array as one PNG per face (or layer) and
/// level: the names `{face}` (px nx py ny pz nz) and `{layer}` make, the
/// texels those of the KTX2 the same command writes (sRGB u8 both), and
/// a name without the placeholder refused before anything is built.
#[test]
fn srgb_cube_maps_and_arrays_go_to_png_faces_and_layers() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for (name, template, count) in [
        ("valid_R8G8B8A8_SRGB_CUBE", "cube_{face}_{level}.png", 6),
        ("valid_R8G8B8A8_SRGB_2D_ARRAY", "arr_{layer}_{level}.png", 0),
    ] {
        let src = cts(&format!("{name}.ktx2"));
        let src = src.to_str().unwrap();
        let ktx2 = p(&format!("{name}.ktx2"));
        let o = parvo(&["mip", src, "-o", &ktx2]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let want = load(Path::new(&ktx2)).into_images();
        let count = if count == 0 { want.len() } else { count };
        assert_eq!(want.len(), count, "{name}");
        let o = parvo(&["mip", src, "-o", &p(template)]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let names: Vec<String> = if template.contains("{face}") {
            ["px", "nx", "py", "ny", "pz", "nz"]
                .iter()
                .map(|f| template.replace("{face}", f))
                .collect()
        } else {
            (0..count)
                .map(|i| template.replace("{layer}", &i.to_string()))
                .collect()
        };
        for (i, levels) in want.iter().enumerate() {
            for (k, level) in levels.iter().enumerate() {
                let file = p(&names[i].replace("{level}", &k.to_string()));
                let got = load(Path::new(&file)).into_base();
                assert_eq!(got.format().color_space, ColorSpace::Srgb, "{file}");
                assert_eq!(
                    (got.width(), got.height(), bytes(&got)),
                    (level.width(), level.height(), bytes(level)),
                    "{file}"
                );
            }
            let past = names[i].replace("{level}", &levels.len().to_string());
            assert!(!Path::new(&p(&past)).exists(), "{past}");
        }
        // Without the placeholder: refused, nothing written.
        let plain = p(&format!("{name}_flat_{{level}}.png"));
        let o = parvo(&["mip", src, "-o", &plain]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{name}: {err}");
        let wanted = if count == 6 { "{face}" } else { "{layer}" };
        assert!(err.contains(wanted), "{name}: {err}");
        assert!(!Path::new(&plain.replace("{level}", "0")).exists());
    }
}
