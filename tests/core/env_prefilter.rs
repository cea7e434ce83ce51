//! Prefiltered specular levels and irradiance against an `f64` brute-force
//! integration of their definitions (src/env/prefilter/mod.rs): over a
//! fine grid of directions on a smooth environment given as a function,
//! and over every level-0 texel of an environment with a small sun.

use parvo::env::cube::face_direction;
use parvo::env::prefilter::{
    Integration, Lobe, alpha, irradiance, sh9, sh9_irradiance, specular, texel_solid_angle,
};
use parvo::{ChannelType, ColorSpace, Format, MipChain, MipOptions, Texture};

/// A smooth environment: a sky gradient, a warm lobe and a cool band.
fn env(d: [f64; 3]) -> [f64; 3] {
    let sun = [0.48, 0.6, 0.64];
    let s = (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]).max(0.0);
    let lobe = s.powi(8);
    [
        0.2 + 0.3 * d[1].max(0.0) + 0.9 * lobe,
        0.25 + 0.25 * d[1] + 0.5 * lobe + 0.2 * (3.0 * d[0]).sin() * d[2],
        0.5 + 0.4 * d[1] - 0.1 * d[0],
    ]
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / l)
}

/// The environment on six `n × n` faces with box mips.
fn cube(n: u32) -> Vec<MipChain> {
    cube_of(n, env)
}

/// The environment `e` on six `n × n` faces (texel centres) with box mips.
fn cube_of(n: u32, e: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<MipChain> {
    (0..6)
        .map(|f| {
            let mut v = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    let d = unit(face_direction(
                        f,
                        (i as f64 + 0.5) / n as f64,
                        (j as f64 + 0.5) / n as f64,
                    ));
                    let c = e(d);
                    v.extend([c[0] as f32, c[1] as f32, c[2] as f32, 1.0]);
                }
            }
            let fmt = Format::new(4, ChannelType::F32, ColorSpace::Linear);
            let t = Texture::from_f32(n, n, fmt, v).unwrap();
            parvo::mip::build(t, &MipOptions::default()).unwrap()
        })
        .collect()
}

/// A fine quadrature of the sphere: (direction, solid angle) of every
/// texel of six `n × n` faces; the solid angles sum to 4π.
fn quadrature(n: u32) -> Vec<([f64; 3], f64)> {
    let mut q = Vec::new();
    for f in 0..6 {
        for j in 0..n {
            for i in 0..n {
                let d = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / n as f64,
                    (j as f64 + 0.5) / n as f64,
                ));
                q.push((d, texel_solid_angle(n, i, j)));
            }
        }
    }
    q
}

/// `∫ env(l)·w(l) dl / ∫ w(l) dl` by quadrature.
fn brute(q: &[([f64; 3], f64)], w: impl Fn([f64; 3]) -> f64) -> [f64; 3] {
    let mut acc = [0.0; 3];
    let mut wsum = 0.0;
    for &(l, omega) in q {
        let x = w(l) * omega;
        if x > 0.0 {
            let e = env(l);
            for c in 0..3 {
                acc[c] += e[c] * x;
            }
            wsum += x;
        }
    }
    acc.map(|a| a / wsum)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn solid_angles_of_a_face_sum_to_a_sixth_of_the_sphere() {
    for n in [1u32, 3, 16, 33] {
        let sum: f64 = (0..n)
            .flat_map(|j| (0..n).map(move |i| texel_solid_angle(n, i, j)))
            .sum();
        assert!(
            (sum - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-12,
            "n {n}: {sum}"
        );
    }
}

/// The worst error of every level of a prefiltered cube against the
/// brute-force integral, at every texel of every face.
fn worst_per_level(lobe: Lobe, size: u32, samples: u32) -> Vec<(f64, f64)> {
    let faces = cube(size);
    let pre = specular(&faces, lobe, Integration::Sampled(samples)).unwrap();
    let q = quadrature(96);
    let levels = pre[0].len();
    (0..levels)
        .map(|k| {
            let a = alpha(k, levels);
            let mut worst = 0f64;
            for (f, chain) in pre.iter().enumerate() {
                let lv = chain.level(k).unwrap();
                let n = lv.width();
                for j in 0..n {
                    for i in 0..n {
                        let d = unit(face_direction(
                            f,
                            (i as f64 + 0.5) / n as f64,
                            (j as f64 + 0.5) / n as f64,
                        ));
                        let want = if a == 0.0 {
                            env(d)
                        } else {
                            brute(&q, |l| lobe.weight(a, dot(d, l)))
                        };
                        let got = lv.texel_linear(i, j);
                        for c in 0..3 {
                            worst = worst.max((got[c] as f64 - want[c]).abs());
                        }
                    }
                }
            }
            (a, worst)
        })
        .collect()
}

/// Bound: 0.02 (the environment spans about 0 to 1.3): what filtered
/// importance sampling with 512 samples reaches on a 16² environment; the
/// error is largest on the narrow lobes, where the 16² source's bilinear
/// reconstruction of the bright lobe is what is filtered.
#[test]
fn sampled_levels_equal_a_brute_force_integral_of_each_lobe() {
    for lobe in [Lobe::Ggx, Lobe::Beckmann, Lobe::Phong] {
        let per_level = worst_per_level(lobe, 16, 512);
        for (a, worst) in &per_level {
            eprintln!("{}: alpha {a:.4}: worst error {worst:.5}", lobe.name());
        }
        for (a, worst) in per_level {
            assert!(worst < 0.02, "{}: alpha {a}: worst {worst}", lobe.name());
        }
    }
}

#[test]
fn irradiance_and_sh9_equal_the_cosine_integral() {
    let faces = cube(16);
    let irr = irradiance(&faces, 8).unwrap();
    let coef = sh9(&faces).unwrap();
    let q = quadrature(96);
    let (mut worst, mut worst_sh) = (0f64, 0f64);
    for (f, chain) in irr.iter().enumerate() {
        let lv = chain.level(0).unwrap();
        for j in 0..8 {
            for i in 0..8 {
                let n = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / 8.0,
                    (j as f64 + 0.5) / 8.0,
                ));
                // E(n)/π normalised: the cosine-weighted mean.
                let want = brute(&q, |l| dot(n, l).max(0.0));
                let got = lv.texel_linear(i, j);
                let sh = sh9_irradiance(&coef, n);
                for c in 0..3 {
                    worst = worst.max((got[c] as f64 - want[c]).abs());
                    worst_sh = worst_sh.max((sh[c] - want[c]).abs());
                }
            }
        }
    }
    eprintln!("irradiance worst {worst:.2e}, SH9 worst {worst_sh:.2e}");
    assert!(worst < 2e-3, "irradiance: worst {worst}");
    // SH9 truncates the cosine lobe's higher bands (Ramamoorthi and
    // Hanrahan: under 3% of a typical environment's irradiance).
    assert!(worst_sh < 0.03, "SH9: worst {worst_sh}");
}

#[test]
fn a_constant_environment_prefilters_to_itself() {
    let fmt = Format::new(4, ChannelType::F32, ColorSpace::Linear);
    let faces: Vec<MipChain> = (0..6)
        .map(|_| {
            let t = Texture::from_f32(8, 8, fmt, [0.3f32, 0.6, 0.9, 1.0].repeat(64)).unwrap();
            parvo::mip::build(t, &MipOptions::default()).unwrap()
        })
        .collect();
    for lobe in [Lobe::Ggx, Lobe::Beckmann, Lobe::Phong] {
        for how in [Integration::Quadrature, Integration::Sampled(64)] {
            for chain in specular(&faces, lobe, how).unwrap() {
                for lv in chain.levels() {
                    for j in 0..lv.height() {
                        for i in 0..lv.width() {
                            let t = lv.texel_linear(i, j);
                            assert!((t[0] - 0.3).abs() < 1e-5 && (t[2] - 0.9).abs() < 1e-5);
                        }
                    }
                }
            }
        }
    }
    for chain in irradiance(&faces, 4).unwrap() {
        let t = chain.level(0).unwrap().texel_linear(1, 2);
        assert!((t[1] - 0.6).abs() < 1e-6, "{t:?}");
    }
}

/// The smooth environment with a sun: a disc of radius 0.06 rad at an
/// awkward direction, 400 times brighter than the sky (openexr-images'
/// KernerEnvCube has a sun 174 times its mean), on six `n × n` faces.
fn sunny_cube(n: u32) -> Vec<MipChain> {
    let sun = unit([0.31, 0.77, -0.56]);
    cube_of(n, |d| {
        let c = env(d);
        let s = if dot(d, sun) > 0.06f64.cos() {
            400.0
        } else {
            0.0
        };
        [c[0] + s, c[1] + 0.9 * s, c[2]]
    })
}

/// `Σ L·w·Ω / Σ w·Ω` over every level-0 texel of `faces` (RGB), each at its
/// centre with its exact solid angle: the definition the quadrature sums.
fn over_level0(faces: &[MipChain], w: impl Fn(f64) -> f64, n: [f64; 3]) -> [f64; 3] {
    let (mut acc, mut den) = ([0.0; 3], 0.0);
    for (f, chain) in faces.iter().enumerate() {
        let lv = chain.level(0).unwrap();
        let m = lv.width();
        for j in 0..m {
            for i in 0..m {
                let d = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / m as f64,
                    (j as f64 + 0.5) / m as f64,
                ));
                let x = w(dot(n, d)) * texel_solid_angle(m, i, j);
                if x > 0.0 {
                    let t = lv.texel_linear(i, j);
                    for c in 0..3 {
                        acc[c] += t[c] as f64 * x;
                    }
                    den += x;
                }
            }
        }
    }
    acc.map(|a| a / den)
}

/// Relative RMS error over every texel of `level` (face `f`'s level of
/// size m): sqrt(mean ‖got − want‖² / ‖want‖²).
fn relative_rms(levels: &[&Texture], want: impl Fn([f64; 3]) -> [f64; 3]) -> f64 {
    let (mut sum, mut count) = (0.0, 0);
    for (f, lv) in levels.iter().enumerate() {
        let m = lv.width();
        for j in 0..m {
            for i in 0..m {
                let d = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / m as f64,
                    (j as f64 + 0.5) / m as f64,
                ));
                let w = want(d);
                let g = lv.texel_linear(i, j);
                let e: f64 = (0..3).map(|c| (g[c] as f64 - w[c]).powi(2)).sum();
                sum += e / w.iter().map(|x| x * x).sum::<f64>();
                count += 1;
            }
        }
    }
    (sum / count as f64).sqrt()
}

/// The bound: every level within 1 % relative RMS of the integral
/// of its lobe over level 0, and irradiance within 0.5 %, with a sun that
/// makes sampling noisy (64 samples: several percent; printed). Faces of
/// 40 texels (not a power of two: levels 40, 20, 10, 5, 2, 1).
#[test]
fn quadrature_equals_the_integral_over_level_0_with_a_sun() {
    let faces = sunny_cube(40);
    let levels = faces[0].len();
    for lobe in [Lobe::Ggx, Lobe::Beckmann, Lobe::Phong] {
        let quad = specular(&faces, lobe, Integration::Quadrature).unwrap();
        let sampled = specular(&faces, lobe, Integration::Sampled(64)).unwrap();
        for k in 1..levels {
            let a = alpha(k, levels);
            let want = |n| over_level0(&faces, |c| lobe.weight(a, c), n);
            let of = |pre: &[MipChain]| -> Vec<Texture> {
                pre.iter().map(|c| c.level(k).unwrap().clone()).collect()
            };
            let (q, s) = (of(&quad), of(&sampled));
            let eq = relative_rms(&q.iter().collect::<Vec<_>>(), want);
            let es = relative_rms(&s.iter().collect::<Vec<_>>(), want);
            eprintln!(
                "{} level {k} (alpha {a:.4}): quadrature {:.3} %, 64 samples {:.3} %",
                lobe.name(),
                100.0 * eq,
                100.0 * es
            );
            assert!(eq < 0.01, "{} level {k}: {eq}", lobe.name());
        }
    }
    let irr = irradiance(&faces, 12).unwrap();
    let lv: Vec<&Texture> = irr.iter().map(|c| c.level(0).unwrap()).collect();
    let e = relative_rms(&lv, |n| over_level0(&faces, |c| c.max(0.0), n));
    eprintln!("irradiance: {:.3} %", 100.0 * e);
    assert!(e < 0.005, "irradiance: {e}");
}

/// `(A, B)` of the split-sum BRDF table by brute force over l: a midpoint
/// sum over (θ_l, φ_l) of the hemisphere around n, in f64, from GGX's D,
/// Smith's height-correlated visibility and Schlick's Fresnel written out
/// here (the definition in src/env/prefilter/dfg.rs).
fn dfg_brute(nov: f64, alpha: f64) -> [f64; 2] {
    use std::f64::consts::PI;
    let a2 = alpha * alpha;
    let v = [(1.0 - nov * nov).sqrt(), 0.0, nov];
    let (nt, np) = (3000, 3000);
    let (dt, dp) = (0.5 * PI / nt as f64, PI / np as f64);
    let (mut a, mut b) = (0.0, 0.0);
    for it in 0..nt {
        let t = (it as f64 + 0.5) * dt;
        let (st, ct) = t.sin_cos();
        for ip in 0..np {
            let p = (ip as f64 + 0.5) * dp;
            let l = [st * p.cos(), st * p.sin(), ct];
            let h = unit([v[0] + l[0], v[1] + l[1], v[2] + l[2]]);
            let (noh, voh, nol) = (h[2], dot(v, h), ct);
            let x = noh * noh * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * x * x);
            let vis = 0.5
                / (nol * (nov * nov * (1.0 - a2) + a2).sqrt()
                    + nov * (nol * nol * (1.0 - a2) + a2).sqrt());
            let fc = (1.0 - voh).powi(5);
            // Both halves of φ: twice the sum over [0, π].
            let f = 2.0 * d * vis * nol * st * dt * dp;
            a += f * (1.0 - fc);
            b += f * fc;
        }
    }
    [a, b]
}

/// The bound: within 1e-3 of the f64 integral at 20 (n·v, α)
/// points; and the table holds `dfg` at its texel centres.
#[test]
fn dfg_table_equals_the_integral() {
    use parvo::env::prefilter::dfg;
    let mut worst = 0f64;
    for nov in [0.05, 0.2, 0.5, 0.8, 1.0] {
        for alpha in [0.08, 0.25, 0.5, 1.0] {
            let got = dfg::dfg(nov, alpha);
            let want = dfg_brute(nov, alpha);
            eprintln!("n.v {nov} alpha {alpha}: {got:.5?} brute {want:.5?}");
            for c in 0..2 {
                worst = worst.max((got[c] - want[c]).abs());
            }
        }
    }
    eprintln!("worst {worst:.2e}");
    // The issue asks 1e-3; the rule reaches about 1e-5.
    assert!(worst < 5e-5, "{worst}");
    let t = dfg::table(16).unwrap();
    for (i, j) in [(0u32, 0u32), (3, 15), (15, 7), (9, 2)] {
        let r = (j as f64 + 0.5) / 16.0;
        let want = dfg::dfg((i as f64 + 0.5) / 16.0, r * r);
        let got = t.texel_linear(i, j);
        assert!((got[0] as f64 - want[0]).abs() < 1e-6 && (got[1] as f64 - want[1]).abs() < 1e-6);
        assert_eq!(got[2], 0.0);
    }
    // A smooth mirror seen head on reflects everything.
    let [a, b] = dfg::dfg(1.0, 1e-4);
    assert!((a + b - 1.0).abs() < 1e-3, "{a} {b}");
}
