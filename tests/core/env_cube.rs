//! Cube maps by direction: face selection and derivatives against GL's
//! table and finite differences, seamless texels against a brute-force
//! nearest-direction search, every filter against a smooth function of
//! the direction, and interior lookups against the 2-D sampler.

use parvo::env::cube::{FACE_NAMES, face_direction, face_query, face_st, select_face};
use parvo::env::{ArraySampler, CubeSampler, DirQuery};
use parvo::sample::{Method, Query, Sampler, SamplerOptions};
use parvo::wrap::{Wrap, WrapMode};
use parvo::{ChannelType, ColorSpace, Format, MipChain, MipOptions, Texture};

fn rgba_f32() -> Format {
    Format::new(4, ChannelType::F32, ColorSpace::Linear)
}

/// Six faces of size `n` whose texel at each centre is `f(direction)`,
/// with full box chains.
fn cube_of(n: u32, f: impl Fn([f64; 3]) -> [f32; 4]) -> Vec<MipChain> {
    (0..6)
        .map(|face| {
            let mut v = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    let s = (i as f64 + 0.5) / n as f64;
                    let t = (j as f64 + 0.5) / n as f64;
                    v.extend(f(unit(face_direction(face, s, t))));
                }
            }
            let tex = Texture::from_f32(n, n, rgba_f32(), v).unwrap();
            parvo::mip::build(tex, &MipOptions::default()).unwrap()
        })
        .collect()
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / l)
}

/// A smooth function of the direction (linear in its components).
fn smooth(d: [f64; 3]) -> [f32; 4] {
    [
        (0.5 + 0.4 * d[0]) as f32,
        (0.5 + 0.3 * d[1] - 0.1 * d[2]) as f32,
        (0.5 + 0.45 * d[2]) as f32,
        1.0,
    ]
}

/// xorshift, fixed seed.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn dir(&mut self) -> [f64; 3] {
        [
            self.f() * 2.0 - 1.0,
            self.f() * 2.0 - 1.0,
            self.f() * 2.0 - 1.0,
        ]
    }
}

#[test]
fn faces_follow_gl_table_8_19_on_hand_worked_directions() {
    // (direction, face, s, t) worked from GL 4.6 Table 8.19 by hand:
    // s = (sc/|ma| + 1)/2, t = (tc/|ma| + 1)/2.
    let cases: [([f64; 3], usize, f64, f64); 6] = [
        // +X: sc = −rz = 0.25, tc = −ry = −0.5
        ([1.0, 0.5, -0.25], 0, 0.625, 0.25),
        // −X (|ma| = 2): sc = rz = 0.5, tc = −ry = −1
        ([-2.0, 1.0, 0.5], 1, 0.625, 0.25),
        // +Y: sc = rx = 0.5, tc = rz = −0.5
        ([0.5, 1.0, -0.5], 2, 0.75, 0.25),
        // −Y: sc = rx = −0.5, tc = −rz = −0.25
        ([-0.5, -1.0, 0.25], 3, 0.25, 0.375),
        // +Z: sc = rx = 0.5, tc = −ry = 0.5
        ([0.5, -0.5, 1.0], 4, 0.75, 0.75),
        // −Z: sc = −rx = −0.5, tc = −ry = 0.25
        ([0.5, -0.25, -1.0], 5, 0.25, 0.625),
    ];
    for (d, face, s, t) in cases {
        assert_eq!(select_face(d), face, "{d:?}");
        let (gs, gt) = face_st(face, d);
        assert!(
            (gs - s).abs() < 1e-12 && (gt - t).abs() < 1e-12,
            "{} {d:?}: ({gs}, {gt}) != ({s}, {t})",
            FACE_NAMES[face]
        );
        let back = face_direction(face, s, t);
        let scale = d.iter().fold(0f64, |m, c| m.max(c.abs()));
        for c in 0..3 {
            assert!((back[c] * scale - d[c]).abs() < 1e-12);
        }
    }
}

#[test]
fn face_derivatives_equal_finite_differences() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut checked = 0;
    for _ in 0..2000 {
        let d = rng.dir();
        let ddx = rng.dir().map(|c| c * 1e-3);
        let ddy = rng.dir().map(|c| c * 1e-3);
        let q = DirQuery::new(
            d.map(|c| c as f32),
            ddx.map(|c| c as f32),
            ddy.map(|c| c as f32),
        );
        // The query holds f32 values: difference from those.
        let (d, ddx, ddy) = (
            q.dir.map(f64::from),
            q.ddx.map(f64::from),
            q.ddy.map(|c| c as f64),
        );
        let (f, fq) = face_query(&q);
        let h = 1e-4;
        let at = |e: [f64; 3], k: f64| face_st(f, std::array::from_fn(|c| d[c] + k * e[c]));
        for (e, ds, dt) in [(ddx, fq.dudx, fq.dvdx), (ddy, fq.dudy, fq.dvdy)] {
            let (s1, t1) = at(e, h);
            let (s0, t0) = at(e, -h);
            let (fs, ft) = ((s1 - s0) / (2.0 * h), (t1 - t0) / (2.0 * h));
            let tol = 1e-6 + 1e-4 * fs.abs().max(ft.abs());
            assert!(
                (fs - ds as f64).abs() < tol && (ft - dt as f64).abs() < tol,
                "{d:?} face {f}: ({ds}, {dt}) vs differences ({fs}, {ft})"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 4000);
}

/// The face and texel whose centre direction is closest in angle to `d`,
/// by searching every texel of every face.
fn nearest_texel_brute(n: u32, d: [f64; 3]) -> (usize, u32, u32) {
    let d = unit(d);
    let mut best = (f64::MIN, (0, 0, 0));
    for f in 0..6 {
        for j in 0..n {
            for i in 0..n {
                let c = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / n as f64,
                    (j as f64 + 0.5) / n as f64,
                ));
                let dot = c[0] * d[0] + c[1] * d[1] + c[2] * d[2];
                if dot > best.0 {
                    best = (dot, (f, i, j));
                }
            }
        }
    }
    best.1
}

#[test]
fn texels_past_an_edge_are_the_neighbour_faces_edge_texels() {
    // Each texel gets a unique value: its face and index.
    for n in [1u32, 3, 4, 7] {
        let faces: Vec<MipChain> = (0..6)
            .map(|f| {
                let v: Vec<f32> = (0..n * n)
                    .flat_map(|k| [f as f32, (k % n) as f32, (k / n) as f32, 1.0])
                    .collect();
                MipChain::from_levels(
                    vec![Texture::from_f32(n, n, rgba_f32(), v).unwrap()],
                    MipOptions::default(),
                )
                .unwrap()
            })
            .collect();
        let c = CubeSampler::new(&faces, SamplerOptions::bilinear()).unwrap();
        let n_i = n as i64;
        for (f, name) in FACE_NAMES.iter().enumerate() {
            for k in 0..n_i {
                // One step past each of the four edges, along the edge.
                for (i, j) in [(-1, k), (n_i, k), (k, -1), (k, n_i)] {
                    let got = c.texel_seamless(f, 0, i, j);
                    // The texel just past the edge, a hair outside the
                    // face, is the nearest texel to the direction through
                    // the edge point itself (the same row along the edge).
                    let s = ((i.clamp(0, n_i - 1) as f64 + 0.5) / n as f64).clamp(1e-9, 1.0 - 1e-9);
                    let t = ((j.clamp(0, n_i - 1) as f64 + 0.5) / n as f64).clamp(1e-9, 1.0 - 1e-9);
                    let (s, t) = match (i, j) {
                        (-1, _) => (-1e-6, t),
                        (x, _) if x == n_i => (1.0 + 1e-6, t),
                        (_, -1) => (s, -1e-6),
                        _ => (s, 1.0 + 1e-6),
                    };
                    let want = nearest_texel_brute(n, face_direction(f, s, t));
                    assert_ne!(want.0, f, "past the edge is another face");
                    assert_eq!(
                        got,
                        [want.0 as f32, want.1 as f32, want.2 as f32, 1.0],
                        "n {n}, face {name}, texel ({i}, {j})"
                    );
                }
            }
            // A corner texel is the average of the three around the corner.
            let got = c.texel_seamless(f, 0, -1, -1);
            let three = [
                c.texel_seamless(f, 0, 0, 0),
                c.texel_seamless(f, 0, -1, 0),
                c.texel_seamless(f, 0, 0, -1),
            ];
            for ch in 0..4 {
                let avg = (three[0][ch] + three[1][ch] + three[2][ch]) / 3.0;
                assert!((got[ch] - avg).abs() < 1e-6);
            }
        }
    }
}

fn max_err(a: [f32; 4], b: [f32; 4]) -> f32 {
    (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max)
}

#[test]
fn every_filter_follows_a_smooth_environment_across_edges_and_corners() {
    let n = 32;
    let faces = cube_of(n, smooth);
    let mut rng = Rng(7);
    let mut options = vec![
        SamplerOptions::nearest(),
        SamplerOptions::bilinear(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(8),
        SamplerOptions::ewa(),
        SamplerOptions::supersample(6),
    ];
    options[5].method = Method::Supersample;
    for o in options {
        let c = CubeSampler::new(&faces, o).unwrap();
        let mut worst = 0f32;
        for k in 0..3000 {
            // Half the directions lie within a texel of an edge or corner.
            let mut d = rng.dir();
            if k % 2 == 0 {
                let a = (rng.f() * 3.0) as usize % 3;
                let b = (a + 1 + (rng.f() * 2.0) as usize % 2) % 3;
                d[b] = d[a].abs().max(0.2) * if d[b] < 0.0 { -1.0 } else { 1.0 };
                d[b] *= 1.0 + (rng.f() - 0.5) * 0.05;
            }
            let scale = 0.5 / n as f64 * rng.f();
            let ddx = rng.dir().map(|c| c * scale);
            let ddy = rng.dir().map(|c| c * scale * 0.3);
            let q = DirQuery::new(
                d.map(|c| c as f32),
                ddx.map(|c| c as f32),
                ddy.map(|c| c as f32),
            );
            let got = c.sample(&q);
            worst = worst.max(max_err(got, smooth(unit(d))));
        }
        // A texel spans about 2/n of a face; the function changes by at
        // most 0.45 per unit of direction, so nearest errs by up to about
        // 0.45·(1/n)·√2 and the filters by much less; a seam (a texel of
        // the wrong face, or a clamp) would err by ~0.1 or more.
        let bound = if o.mag == parvo::sample::TexelFilter::Nearest && o.method == Method::Texel {
            0.03
        } else {
            0.01
        };
        assert!(worst < bound, "{}: worst error {worst}", o.name());
    }
}

#[test]
fn lookups_inside_a_face_equal_the_2d_sampler_on_that_face() {
    let n = 37;
    let faces = cube_of(n, |d| {
        [
            (0.5 + 0.5 * (9.0 * d[0]).sin() * d[1]) as f32,
            (d[2] * d[2]) as f32,
            (0.5 + 0.5 * (5.0 * d[1] + 3.0 * d[2]).cos()) as f32,
            1.0,
        ]
    });
    let mut rng = Rng(99);
    for o in [
        SamplerOptions::bilinear(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(4),
    ] {
        let cube = CubeSampler::new(&faces, o).unwrap();
        let planes: Vec<Sampler> = faces
            .iter()
            .map(|f| {
                let mut o2 = o;
                o2.wrap = Wrap::both(WrapMode::ClampToEdge);
                Sampler::new(f, o2).unwrap()
            })
            .collect();
        let mut compared = 0;
        for _ in 0..2000 {
            let d = rng.dir();
            let scale = 2.0 / n as f64 * rng.f();
            let q = DirQuery::new(
                d.map(|c| c as f32),
                rng.dir().map(|c| (c * scale) as f32),
                rng.dir().map(|c| (c * scale) as f32),
            );
            let (f, fq) = face_query(&q);
            // Far enough inside that no tap of any probe leaves the face:
            // the footprint's extent at the coarsest level read.
            let fp = cube.footprint(&q);
            let level = fp.lambda.max(0.0).ceil() as i32 + 1;
            let margin = (2f64.powi(level) + fp.rho_x.max(fp.rho_y)) / n as f64;
            let inside = |x: f32| (x as f64) > margin && (x as f64) < 1.0 - margin;
            if !(inside(fq.u) && inside(fq.v)) {
                continue;
            }
            let want = planes[f].sample(&Query { ..fq });
            let got = cube.sample(&q);
            assert!(
                max_err(got, want) < 2e-5,
                "{}: face {f} {fq:?}: {got:?} vs {want:?}",
                o.name()
            );
            compared += 1;
        }
        assert!(compared > 300, "{} compared only {compared}", o.name());
    }
}

#[test]
fn a_constant_cube_reads_its_constant_everywhere_with_every_filter() {
    let faces = cube_of(5, |_| [0.25, 0.5, 0.75, 1.0]);
    let mut rng = Rng(3);
    let mut ss = SamplerOptions::supersample(4);
    ss.method = Method::Supersample;
    for o in [
        SamplerOptions::nearest(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(16),
        SamplerOptions::ewa(),
        ss,
    ] {
        let c = CubeSampler::new(&faces, o).unwrap();
        for _ in 0..500 {
            let s = rng.f() * 3.0;
            let q = DirQuery::new(
                rng.dir().map(|c| c as f32),
                rng.dir().map(|c| (c * s) as f32),
                rng.dir().map(|c| (c * s) as f32),
            );
            let got = c.sample(&q);
            assert!(
                max_err(got, [0.25, 0.5, 0.75, 1.0]) < 1e-5,
                "{}: {got:?}",
                o.name()
            );
        }
        // Degenerate directions and derivatives read a face, never NaN.
        for q in [
            DirQuery::point([0.0, 0.0, 0.0]),
            DirQuery::point([f32::NAN, 1.0, 0.0]),
            DirQuery::point([f32::INFINITY, 1.0, f32::NEG_INFINITY]),
            DirQuery::new([1.0, 1.0, 1.0], [f32::NAN; 3], [f32::INFINITY; 3]),
            DirQuery::new([0.0, 1.0, 0.0], [1e30; 3], [0.0; 3]),
        ] {
            let got = c.sample(&q);
            assert!(
                max_err(got, [0.25, 0.5, 0.75, 1.0]) < 1e-5,
                "{}: {q:?} {got:?}",
                o.name()
            );
        }
    }
}

/// Hostile derivatives (NaN, infinite, huge, each alone or mixed with
/// finite ones) give finite values from every filter on a cube whose
/// texels vary, as the 2-D samplers do (a rasterizer's report: the
/// supersample filter returned NaN for 540 of 1,800 such calls).
#[test]
fn hostile_derivatives_give_finite_values_with_every_filter() {
    let faces = cube_of(6, smooth);
    let mut ss = SamplerOptions::supersample(4);
    ss.method = Method::Supersample;
    let bad = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MAX,
        -f32::MAX,
        1e30,
        0.0,
        0.25,
    ];
    let mut rng = Rng(11);
    for o in [
        SamplerOptions::nearest(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(16),
        SamplerOptions::ewa(),
        ss,
    ] {
        let c = CubeSampler::new(&faces, o).unwrap();
        for k in 0..600 {
            let dir = rng.dir().map(|c| c as f32);
            let mut pick = || bad[(rng.f() * bad.len() as f64) as usize % bad.len()];
            let ddx = [pick(), pick(), pick()];
            let ddy = if k % 2 == 0 {
                [0.01, 0.0, 0.0]
            } else {
                [pick(), pick(), pick()]
            };
            let q = DirQuery::new(dir, ddx, ddy);
            let got = c.sample(&q);
            assert!(
                got.iter().all(|v| v.is_finite()),
                "{}: {q:?} -> {got:?}",
                o.name()
            );
        }
    }
}

#[test]
fn mismatched_faces_and_the_summed_area_table_are_refused_with_reasons() {
    let faces = cube_of(4, smooth);
    let e = CubeSampler::new(&faces[..5], SamplerOptions::trilinear()).unwrap_err();
    assert!(e.to_string().contains("6 faces"), "{e}");
    let mut odd = faces.clone();
    odd[3] = cube_of(8, smooth).remove(3);
    let e = CubeSampler::new(&odd, SamplerOptions::trilinear()).unwrap_err();
    assert!(e.to_string().contains("-y"), "{e}");
    let e = CubeSampler::new(&faces, SamplerOptions::sat()).unwrap_err();
    assert!(e.to_string().contains("summed-area"), "{e}");
    let tex = Texture::from_f32(4, 2, rgba_f32(), vec![0.0; 32]).unwrap();
    let flat = parvo::mip::build(tex, &MipOptions::default()).unwrap();
    let e = CubeSampler::new(&vec![flat; 6], SamplerOptions::trilinear()).unwrap_err();
    assert!(e.to_string().contains("square"), "{e}");
}

#[test]
fn array_layers_are_picked_as_gl_rounds_them() {
    let layers: Vec<MipChain> = (0..3)
        .map(|l| {
            let tex = Texture::from_f32(2, 2, rgba_f32(), vec![l as f32; 16]).unwrap();
            parvo::mip::build(tex, &MipOptions::default()).unwrap()
        })
        .collect();
    let a = ArraySampler::new(&layers, SamplerOptions::trilinear()).unwrap();
    // GL: layer = clamp(floor(l + 0.5), 0, d − 1).
    for (l, want) in [
        (-3.0, 0.0),
        (0.49, 0.0),
        (0.5, 1.0),
        (1.2, 1.0),
        (1.5, 2.0),
        (9.0, 2.0),
        (f32::NAN, 0.0),
    ] {
        let got = a.sample(&Query::point(0.3, 0.6), l)[0];
        assert_eq!(got, want, "layer coordinate {l}");
    }
}
