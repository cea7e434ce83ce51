//! Accuracy against the supersampled reference on a perspective ground
//! plane: the scene and the numbers of `examples/02_filter_accuracy.rs`
//! and the README table (256 × 192 pixels, 15° below the horizon, 64 × 64
//! reference, footprints up to 32 texels).
//!
//! Asserted, on the checker and the zone plate: anisotropic 16 beats
//! trilinear, EWA beats trilinear, and on the zone plate EWA beats
//! anisotropic 16.
//!
//! Not asserted, because it does not hold: EWA beating anisotropic 16 on
//! the checker (0.0224 against 0.0171). EWA follows SPEC.md (and pbrt's
//! `MIPMap::EWA`); the gap is the filter shape, not a level or scale
//! error. The reference is a *box* over the pixel footprint; EWA's
//! truncated Gaussian `exp(−2r²) − exp(−2)` over the ellipse of the
//! derivative vectors has a per-axis variance of 0.136·|d|² against the
//! box's 0.083·|d|², and choosing the level from the minor axis adds the
//! mip level's own blur. Measured: EWA on level 0 alone (no mip levels)
//! still loses on the checker (0.0211), and halving the ellipse (radii
//! |d|/2) doubles the error (0.040) — so the softer shape costs on sharp
//! edges and pays where aliasing dominates (the zone plate). At a coarser
//! scene (96 × 72 pixels) EWA loses to anisotropic 16 on both textures.

use parvo::sample::{Query, Sampler, SamplerOptions, footprint};
use parvo::scene::metrics::rmse;
use parvo::scene::{Frame, Plane, RasterOrder, Scene};
use parvo::{MipOptions, builtin, mip};

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

#[test]
fn aniso16_beats_trilinear_and_ewa_beats_aniso16_on_the_zone_plate() {
    let queries = scene(256, 192);
    assert!(queries.len() > 30000, "{} queries", queries.len());
    let filters = [
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(16),
        SamplerOptions::ewa(),
    ];
    let mut results = vec![];
    println!("| filter | checker 256² | zone plate 256² |\n|---|---:|---:|");
    let mut rows = vec![vec![]; filters.len()];
    for name in ["builtin:checker:256", "builtin:zoneplate:256"] {
        let chain = mip::build(builtin::load(name).unwrap(), &MipOptions::default()).unwrap();
        let reference = Sampler::new(&chain, SamplerOptions::supersample(64)).unwrap();
        let mut want = vec![[0f32; 4]; queries.len()];
        reference.sample_batch(&queries, &mut want).unwrap();
        let mut r = vec![];
        for (i, o) in filters.iter().enumerate() {
            let s = Sampler::from_linear(reference.chain().clone(), *o).unwrap();
            let mut got = vec![[0f32; 4]; queries.len()];
            s.sample_batch(&queries, &mut got).unwrap();
            let e = rmse(&want, &got);
            assert!(e.is_finite());
            rows[i].push(e);
            r.push(e);
        }
        results.push(r);
    }
    for (o, r) in filters.iter().zip(&rows) {
        println!("| {} | {:.5} | {:.5} |", o.name(), r[0], r[1]);
    }
    let (checker, zone) = (&results[0], &results[1]);
    // [trilinear, aniso16, ewa]
    assert!(
        checker[1] < checker[0],
        "aniso16 vs trilinear on the checker: {checker:?}"
    );
    assert!(
        zone[1] < zone[0],
        "aniso16 vs trilinear on the zone plate: {zone:?}"
    );
    assert!(
        checker[2] < checker[0] && zone[2] < zone[0],
        "ewa vs trilinear: {results:?}"
    );
    assert!(
        zone[2] < zone[1],
        "ewa vs aniso16 on the zone plate: {zone:?}"
    );
}
