//! Accuracy of each filter against the reference image, per pixel filter,
//! printed as the markdown tables the README shows:
//!
//! ```text
//! cargo run --release --example 02_filter_accuracy
//! ```
//!
//! Scene: `parvo tradeoff`'s default, the ground plane (`Scene::default()`)
//! at 320 × 240, the built-in checker and zone plate at 512², box mips,
//! repeat wrapping. The reference (SPEC.md; `parvo::scene::reference`) is
//! the scene's exact mapping integrated over the pixel filter, bilinear on
//! level 0: once with the gaussian pixel filter (σ = 0.5 pixel, the one
//! EWA's weights assume) and once with the box (the pixel's square, what
//! footprint assembly approximates). Score: PSNR of linear RGB (peak 1),
//! over every pixel that shows the texture, and by footprint length.

use parvo::sample::{SamplerOptions, footprint};
use parvo::scene::metrics::scores;
use parvo::scene::reference::{PixelFilter, Reference};
use parvo::scene::render::{Image, filter_image, queries, reference_image};
use parvo::scene::{Frame, Scene};
use parvo::store::TextureStore;

const FILTERS: [&str; 9] = SamplerOptions::REPORT_FILTERS;

fn main() -> Result<(), parvo::Error> {
    let frame = Frame::new(320, 240);
    let scene = Scene::default();
    let textures = ["builtin:checker:512", "builtin:zoneplate:512"];
    let pixel_filters = [PixelFilter::Gaussian, PixelFilter::Box];
    // psnr[filter][texture][pixel filter]
    let mut psnr = vec![[[0f64; 2]; 2]; FILTERS.len()];
    // Per footprint length: bin b holds ρmax in (2^(b−1), 2^b] (bin 0: ≤ 1,
    // the last: above 32).
    const BINS: usize = 7;
    let binned = ["trilinear", "aniso16", "ewa"];
    let mut by_bin = vec![vec![[0f64; BINS]; binned.len()]; 2 * textures.len()];
    let mut counts = [0usize; BINS];
    let mut pixels = 0;
    for (t, name) in textures.iter().enumerate() {
        let store = TextureStore::load(name, &parvo::io::Limits::default())?;
        let tex = (store.base().width(), store.base().height());
        let qs = queries(&scene, frame, tex, (0.0, 0.0));
        let tri = SamplerOptions::trilinear();
        let bins: Vec<Option<usize>> = qs
            .iter()
            .map(|q| {
                q.map(|q| {
                    let fp = footprint(&q, tex.0, tex.1, &tri);
                    (fp.rho_x.max(fp.rho_y).log2().ceil().max(0.0) as usize).min(BINS - 1)
                })
            })
            .collect();
        if t == 0 {
            for b in bins.iter().flatten() {
                counts[*b] += 1;
            }
            pixels = bins.iter().flatten().count();
        }
        for (p, &pf) in pixel_filters.iter().enumerate() {
            let want = reference_image(&store, &Reference::new(pf), &scene, frame, (0.0, 0.0))?;
            for (f, fname) in FILTERS.iter().enumerate() {
                let o = SamplerOptions::from_name(fname)?;
                let got = filter_image(&store, o, &scene, frame, (0.0, 0.0))?;
                psnr[f][t][p] = scores(&want, &got).psnr_db;
                if let Some(k) = binned.iter().position(|b| b == fname) {
                    for (b, cell) in by_bin[2 * t + p][k].iter_mut().enumerate() {
                        let only = |img: &Image| -> Image {
                            img.iter()
                                .zip(&bins)
                                .map(|(c, &bin)| if bin == Some(b) { *c } else { None })
                                .collect()
                        };
                        *cell = scores(&only(&want), &only(&got)).psnr_db;
                    }
                }
            }
        }
    }
    println!(
        "PSNR (dB, linear RGB) against the reference image, {pixels} ground-plane pixels, {frame}:\n"
    );
    println!(
        "| filter | checker, gaussian | checker, box | zone plate, gaussian | zone plate, box |"
    );
    println!("|---|---:|---:|---:|---:|");
    for (f, name) in FILTERS.iter().enumerate() {
        let p = &psnr[f];
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} |",
            p[0][0], p[0][1], p[1][0], p[1][1]
        );
    }
    println!("\nThe same PSNR by footprint length ρmax (level-0 texels; pixels in brackets):\n");
    let heads: Vec<String> = (0..BINS)
        .map(|b| {
            let range = match b {
                0 => "≤ 1".to_string(),
                b if b == BINS - 1 => format!("> {}", 1 << (b - 1)),
                b => format!("{}–{}", 1 << (b - 1), 1 << b),
            };
            format!("{range} ({})", counts[b])
        })
        .collect();
    println!("| texture | reference | filter | {} |", heads.join(" | "));
    println!("|---|---|---|{}", "---:|".repeat(BINS));
    for (t, tname) in ["checker", "zone plate"].iter().enumerate() {
        for (p, pf) in pixel_filters.iter().enumerate() {
            for (k, fname) in binned.iter().enumerate() {
                let cells: Vec<String> = by_bin[2 * t + p][k]
                    .iter()
                    .map(|e| format!("{e:.1}"))
                    .collect();
                println!("| {tname} | {pf} | {fname} | {} |", cells.join(" | "));
            }
        }
    }
    Ok(())
}
