//! The fast EWA (weight polynomial, stepped r², direct row and column
//! reads, f32 sums; FMA where the CPU has it) against the exact-weight EWA it replaces, which stays as
//! `Sampler::sample_ewa_exact`: within 1e-3 on every query of every
//! scene, for RGBA8 and f32 storage, every wrap mode, odd texture sizes,
//! for the build the CPU picks (AVX-512 sums of RGBA8 runs where it has
//! them), with the AVX-512 path forbidden, and for the portable build.

use crate::common;

use common::Rng;
use parvo::sample::{Query, Sampler, SamplerOptions};
use parvo::scene::{Frame, RasterOrder, Scene};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Wrap, mip};

#[test]
fn fast_ewa_is_within_1e_3_of_the_exact_weights() {
    let mut rng = Rng(0xe4a);
    let mut worst = 0f32;
    for (w, h, ty, cs) in [
        (256u32, 256u32, ChannelType::U8, ColorSpace::Linear),
        (97, 61, ChannelType::U8, ColorSpace::Linear),
        (83, 130, ChannelType::U8, ColorSpace::Srgb),
        (128, 64, ChannelType::F32, ColorSpace::Linear),
    ] {
        let tex = common::random_texture(&mut rng, w, h, Format::new(4, ty, cs));
        for wrap in ["repeat", "clamp", "mirror", "border"] {
            let wrap: Wrap = wrap.parse().unwrap();
            let chain = mip::build(
                tex.clone(),
                &MipOptions {
                    wrap,
                    ..Default::default()
                },
            )
            .unwrap();
            for aniso in [1, 4, 16] {
                let o = SamplerOptions {
                    wrap,
                    max_aniso: aniso,
                    ..SamplerOptions::ewa()
                };
                // The build the CPU picks (AVX-512 where it has it), and
                // with the AVX-512 path forbidden (AVX2 + FMA there).
                let s = Sampler::new(&chain, o).unwrap();
                let mut s2 = Sampler::new(&chain, o).unwrap();
                s2.set_simd(false);
                let mut qs: Vec<Query> = Vec::new();
                for scene in ["plane", "tunnel", "zoom", "rotate:33:3", "rotate:80:0.5"] {
                    let sc: Scene = scene.parse().unwrap();
                    qs.extend(
                        sc.queries(Frame::new(48, 36), (w, h), RasterOrder::Scanline)
                            .into_iter()
                            .map(|(_, q)| q),
                    );
                }
                for _ in 0..500 {
                    let f = |r: &mut Rng| (r.unit() * 2.0 - 1.0) as f32;
                    let sc = (rng.unit() * 8.0).exp2() as f32 / w as f32;
                    qs.push(Query::new(
                        f(&mut rng) * 3.0,
                        f(&mut rng) * 3.0,
                        f(&mut rng) * sc,
                        f(&mut rng) * sc,
                        f(&mut rng) * sc,
                        f(&mut rng) * sc,
                    ));
                }
                for q in &qs {
                    let b = s.sample_ewa_exact(q);
                    for (path, a) in [("picked", s.sample(q)), ("no AVX-512", s2.sample(q))] {
                        let d = (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max);
                        worst = worst.max(d);
                        assert!(
                            d <= 1e-3,
                            "{path}: {w}x{h} {ty} {cs:?} {wrap:?} aniso {aniso}: {q:?}: {a:?} vs {b:?}"
                        );
                    }
                }
            }
        }
    }
    println!("worst difference {worst:e}");
}

/// The same check with `PARVO_NO_AVX` set, in a child process (the switch
/// is read once per process), so the portable build is held to the exact
/// weights too on a CPU that would otherwise take the AVX2 + FMA one.
#[test]
fn portable_fast_ewa_is_within_1e_3_of_the_exact_weights() {
    if std::env::var_os("PARVO_NO_AVX").is_some() {
        return; // this process is already the portable run
    }
    // The test's name within this binary: its module path less the crate.
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    let name = format!("{module}::fast_ewa_is_within_1e_3_of_the_exact_weights");
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", name.trim_start_matches("::")])
        .env("PARVO_NO_AVX", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("1 passed"),
        "the portable run ran no test: {text}"
    );
}
