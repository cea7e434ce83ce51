//! Prefiltered environment levels against an `f64` brute-force integral of
//! their lobe over level 0, on an OpenEXR cube map (default: openexr-images'
//! KernerEnvCube.exr, a sky with a sun 174× its mean): relative RMS error
//! and time per level, for the quadrature and for filtered importance
//! sampling at 64, 512 and 1,024 samples. Prints the README's table.
//!
//! `cargo run --release --example 06_prefilter_accuracy -- [CUBE.exr] [TEXELS]`
//! (TEXELS: output texels checked per level, default 256, spread over the
//! six faces at fixed positions).

use std::time::Instant;

use parvo::MipOptions;
use parvo::env::cube::{build_faces, face_direction};
use parvo::env::prefilter::{
    Integration, Lobe, alpha, irradiance, specular, texels_with_solid_angles,
};
use parvo::io::{Environment, EnvironmentMaps, Limits, LoadOptions, load_with, source::interpret};
use rayon::prelude::*;

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / l)
}

/// Up to `count` (face, i, j) positions of an `m × m` cube level, fixed
/// (a multiplicative hash of the index): every texel when there are fewer.
fn positions(m: u32, count: usize) -> Vec<(usize, u32, u32)> {
    let all = 6 * (m as usize) * (m as usize);
    let pick = |k: usize| {
        let f = k / (m * m) as usize;
        let r = k % (m * m) as usize;
        (f, (r % m as usize) as u32, (r / m as usize) as u32)
    };
    if all <= count {
        return (0..all).map(pick).collect();
    }
    (0..count)
        .map(|k| pick((k as u64 * 2_654_435_761 % all as u64) as usize))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .cloned()
        .unwrap_or_else(|| "tests/data/peer/openexr-images/KernerEnvCube.exr".into());
    let count: usize = args.get(1).map_or(256, |s| s.parse().expect("TEXELS"));
    let options = LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..LoadOptions::default()
    };
    let loaded = load_with(&path, &Limits::default(), &options).expect("load");
    let source = interpret(loaded, &path, Some(Environment::Cube)).expect("a cube map");
    let faces = build_faces(source.bases().cloned().collect(), &MipOptions::default()).unwrap();
    let n = faces[0].levels()[0].width();
    let levels = faces[0].len();
    let texels = texels_with_solid_angles(&faces, 0);
    println!("{path}: {n}² faces, {levels} levels, {count} texels checked per level");
    let brute = |dir: [f64; 3], w: &(dyn Fn(f64) -> f64 + Sync)| -> [f64; 3] {
        let (mut acc, mut den) = ([0f64; 3], 0f64);
        for (d, omega, l) in &texels {
            let x = w(dir[0] * d[0] + dir[1] * d[1] + dir[2] * d[2]) * omega;
            if x > 0.0 {
                for c in 0..3 {
                    acc[c] += l[c] as f64 * x;
                }
                den += x;
            }
        }
        acc.map(|a| a / den)
    };
    // Relative RMS error: sqrt(mean over texels of ‖got − want‖² /
    // ‖want‖²), RGB.
    let error = |got: &dyn Fn(usize, u32, u32) -> [f32; 4],
                 pos: &[(usize, u32, u32)],
                 want: &[[f64; 3]]| {
        let mut sum = 0.0;
        for (&(f, i, j), w) in pos.iter().zip(want) {
            let g = got(f, i, j);
            let e: f64 = (0..3).map(|c| (g[c] as f64 - w[c]).powi(2)).sum();
            let m: f64 = (0..3).map(|c| w[c].powi(2)).sum();
            sum += e / m.max(1e-30);
        }
        100.0 * (sum / pos.len() as f64).sqrt()
    };
    // A third argument `quadrature` leaves out the sampled columns.
    let methods: Vec<Integration> = if args.get(2).is_some_and(|a| a == "quadrature") {
        vec![Integration::Quadrature]
    } else {
        vec![
            Integration::Quadrature,
            Integration::Sampled(64),
            Integration::Sampled(512),
            Integration::Sampled(1024),
        ]
    };
    for lobe in [Lobe::Ggx, Lobe::Beckmann] {
        let mut results = Vec::new();
        for &how in &methods {
            let t = Instant::now();
            let pre = specular(&faces, lobe, how).unwrap();
            results.push((how, t.elapsed().as_secs_f64(), pre));
        }
        println!(
            "\n{} | α | {}",
            lobe.name(),
            methods
                .iter()
                .map(|m| m.describe())
                .collect::<Vec<_>>()
                .join(" | ")
        );
        for k in 1..levels {
            let a = alpha(k, levels);
            let m = (n >> k).max(1);
            let pos = positions(m, count);
            let w = |c: f64| lobe.weight(a, c);
            let want: Vec<[f64; 3]> = pos
                .par_iter()
                .map(|&(f, i, j)| {
                    let d = unit(face_direction(
                        f,
                        (i as f64 + 0.5) / m as f64,
                        (j as f64 + 0.5) / m as f64,
                    ));
                    brute(d, &w)
                })
                .collect();
            let errs: Vec<String> = results
                .iter()
                .map(|(_, _, pre)| {
                    let got = |f: usize, i, j| pre[f].level(k).unwrap().texel_linear(i, j);
                    format!("{:.2} %", error(&got, &pos, &want))
                })
                .collect();
            println!("level {k} ({m}²) | {a:.4} | {}", errs.join(" | "));
        }
        println!(
            "time | | {}",
            results
                .iter()
                .map(|(_, t, _)| format!("{t:.2} s"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    // Irradiance (32² faces).
    let t = Instant::now();
    let irr = irradiance(&faces, 32).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let pos = positions(32, count);
    let want: Vec<[f64; 3]> = pos
        .par_iter()
        .map(|&(f, i, j)| {
            let d = unit(face_direction(
                f,
                (i as f64 + 0.5) / 32.0,
                (j as f64 + 0.5) / 32.0,
            ));
            brute(d, &|c: f64| c.max(0.0))
        })
        .collect();
    let got = |f: usize, i, j| irr[f].levels()[0].texel_linear(i, j);
    println!(
        "\nirradiance (32² faces): {:.3} % relative RMS, {secs:.2} s",
        error(&got, &pos, &want)
    );
}
