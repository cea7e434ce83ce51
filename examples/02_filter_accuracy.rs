//! Accuracy of each filter against the supersampled reference on a
//! perspective ground plane, printed as the markdown table the README
//! shows:
//!
//! ```text
//! cargo run --release --example 02_filter_accuracy
//! ```
//!
//! Scene: the ground `plane` 15° below the horizon, 256 × 192 pixels, built-in
//! checker and zone plate of 256², box mips, repeat wrapping. Only pixels
//! whose footprint is at most 32 texels long are scored: the reference
//! (64 × 64 bilinear lookups over the footprint parallelogram, cells of at
//! most half a texel) resolves those without aliasing itself. Score: RMSE
//! of linear RGB.
//!
//! The reference is a *box* filter over the pixel footprint. EWA's
//! Gaussian (weight `exp(−2r²) − exp(−2)` out to the ellipse of the
//! derivative vectors, SPEC.md) is softer: truncated at r = 1 its per-axis
//! σ is 0.37 of a pixel spacing against the box's 0.29, before the blur of
//! the mip level it reads. It wins where aliasing dominates (the zone
//! plate) and loses on sharp edges (the checker); `tests/sample_accuracy.rs`
//! asserts the zone-plate win on this scene and documents the checker.

use parvo::sample::{Query, Sampler, SamplerOptions, footprint};
use parvo::scene::metrics::rmse;
use parvo::scene::{Frame, Plane, RasterOrder, Scene};
use parvo::{MipOptions, builtin, mip};

/// Longest footprint (level-0 texels) the 64×64 reference resolves (cells
/// of at most half a texel).
const MAX_RHO: f64 = 32.0;

fn scene(w: u32, h: u32) -> Vec<Query> {
    let plane = Scene::Plane(Plane {
        pitch: 15f64.to_radians(),
        fov_y: 60f64.to_radians(),
        uv_per_unit: 0.25,
        max_distance: 1e9,
        ..Plane::default()
    });
    let t = SamplerOptions::trilinear();
    plane
        .queries(Frame::new(w, h), (256, 256), RasterOrder::Scanline)
        .into_iter()
        .map(|(_, q)| q)
        .filter(|q| {
            let fp = footprint(q, 256, 256, &t);
            fp.rho_x.max(fp.rho_y) <= MAX_RHO
        })
        .collect()
}

fn main() -> Result<(), parvo::Error> {
    let queries = scene(256, 192);
    let filters = [
        SamplerOptions::nearest(),
        SamplerOptions::bilinear(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(2),
        SamplerOptions::aniso(4),
        SamplerOptions::aniso(8),
        SamplerOptions::aniso(16),
        SamplerOptions::ewa(),
    ];
    let textures = ["builtin:checker:256", "builtin:zoneplate:256"];
    let mut table = vec![vec![0.0f64; textures.len()]; filters.len()];
    // Per footprint size: bin b holds ρmax in (2^(b−1), 2^b] (bin 0: ≤ 1).
    let t = SamplerOptions::trilinear();
    let bins: Vec<usize> = queries
        .iter()
        .map(|q| {
            let fp = footprint(q, 256, 256, &t);
            fp.rho_x.max(fp.rho_y).log2().ceil().clamp(0.0, 5.0) as usize
        })
        .collect();
    let binned = [2, 6, 7]; // trilinear, aniso16, ewa
    let mut by_bin = vec![vec![[0.0f64; 6]; binned.len()]; textures.len()];
    for (t, name) in textures.iter().enumerate() {
        let chain = mip::build(builtin::load(name)?, &MipOptions::default())?;
        let reference = Sampler::new(&chain, SamplerOptions::supersample(64))?;
        let mut want = vec![[0f32; 4]; queries.len()];
        reference.sample_batch(&queries, &mut want)?;
        for (f, o) in filters.iter().enumerate() {
            let s = Sampler::from_linear(reference.chain().clone(), *o)?;
            let mut got = vec![[0f32; 4]; queries.len()];
            s.sample_batch(&queries, &mut got)?;
            table[f][t] = rmse(&want, &got);
            if let Some(k) = binned.iter().position(|&b| b == f) {
                for (b, row) in by_bin[t][k].iter_mut().enumerate() {
                    let (w, g): (Vec<_>, Vec<_>) = (0..queries.len())
                        .filter(|&i| bins[i] == b)
                        .map(|i| (want[i], got[i]))
                        .unzip();
                    *row = rmse(&w, &g);
                }
            }
        }
    }
    println!(
        "RMSE against the 64×64 supersampled reference, {} ground-plane pixels (linear RGB):\n",
        queries.len()
    );
    println!("| filter | checker 256² | zone plate 256² |");
    println!("|---|---:|---:|");
    for (f, o) in filters.iter().enumerate() {
        println!("| {} | {:.5} | {:.5} |", o.name(), table[f][0], table[f][1]);
    }
    let counts: Vec<usize> = (0..6)
        .map(|b| bins.iter().filter(|&&x| x == b).count())
        .collect();
    println!("\nThe same RMSE by footprint length ρmax (level-0 texels):\n");
    println!(
        "| texture | filter | ≤ 1 ({}) | 1–2 ({}) | 2–4 ({}) | 4–8 ({}) | 8–16 ({}) | 16–32 ({}) |",
        counts[0], counts[1], counts[2], counts[3], counts[4], counts[5]
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    for (t, name) in textures.iter().enumerate() {
        for (k, &f) in binned.iter().enumerate() {
            let cells: Vec<String> = by_bin[t][k].iter().map(|e| format!("{e:.4}")).collect();
            println!("| {name} | {} | {} |", filters[f].name(), cells.join(" | "));
        }
    }
    Ok(())
}
