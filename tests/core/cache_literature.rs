//! Results from the texture-cache literature, reproduced with the scenes
//! and the cache model (the README's tables come from the same runs via
//! `parvo cachesim`):
//! - mipmapping cuts the bytes per pixel of a minified texture against
//!   level-0-only bilinear (the lecture's question);
//! - a tiled layout beats a linear one for `rotate:30` in scanline order;
//! - tiled raster order beats scanline, and blocked layout plus tiled order
//!   is best of the four combinations (Hakura & Gupta 1997);
//! - at λ = k + δ, with a cache that holds the frame's texels and lines of
//!   one texel, trilinear reads 8 texels but fetches 1.25·2^(2δ) new ones
//!   per pixel (SPEC.md).

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::run::{RunStats, SceneSetup};
use parvo::cache::sim::CacheConfig;
use parvo::sample::{Sampler, SamplerOptions};
use parvo::scene::{Frame, RasterOrder, Scene};
use parvo::{MipChain, MipOptions, builtin, mip};

fn chain(size: u32) -> MipChain {
    mip::build(
        builtin::load(&format!("builtin:checker:{size}")).unwrap(),
        &MipOptions::default(),
    )
    .unwrap()
}

fn run(
    chain: &MipChain,
    filter: &str,
    scene: &str,
    frame: (u32, u32),
    layout: &str,
    order: &str,
    cache: &str,
) -> RunStats {
    let sampler = Sampler::new(chain, SamplerOptions::from_name(filter).unwrap()).unwrap();
    let layout = ChainLayout::for_sampler(chain, &sampler, layout.parse::<Layout>().unwrap());
    let setup = SceneSetup {
        sampler: &sampler,
        layout: &layout,
        scene: scene.parse::<Scene>().unwrap(),
        frame: Frame::new(frame.0, frame.1),
        order: order.parse::<RasterOrder>().unwrap(),
    };
    let c: CacheConfig = cache.parse().unwrap();
    setup
        .simulate(&c, None, &mut |_| Ok(()), &|_, _| {})
        .unwrap()
}

fn bytes_per_pixel(r: &RunStats) -> f64 {
    r.stats.bytes_from_memory() as f64 / r.pixels as f64
}

#[test]
fn mipmapping_cuts_the_bytes_per_pixel_of_a_minified_texture() {
    let c = chain(4096);
    for (scene, frame) in [("rotate:30:4", (512, 512)), ("plane", (512, 384))] {
        let base = bytes_per_pixel(&run(
            &c,
            "bilinear-nomip",
            scene,
            frame,
            "tiled:4x4",
            "scanline",
            "16K:64:4",
        ));
        let mip = bytes_per_pixel(&run(
            &c,
            "trilinear",
            scene,
            frame,
            "tiled:4x4",
            "scanline",
            "16K:64:4",
        ));
        // Measured: rotate 81.5 → 4.1, plane 94.2 → 6.9 bytes per pixel.
        assert!(
            mip * 5.0 < base,
            "{scene}: level 0 only {base:.2}, trilinear {mip:.2} bytes per pixel"
        );
    }
}

#[test]
fn a_tiled_layout_beats_a_linear_one_for_a_rotated_texture_in_scanline_order() {
    let c = chain(2048);
    let linear = bytes_per_pixel(&run(
        &c,
        "bilinear",
        "rotate:30",
        (512, 512),
        "linear",
        "scanline",
        "16K:64:4",
    ));
    let tiled = bytes_per_pixel(&run(
        &c,
        "bilinear",
        "rotate:30",
        (512, 512),
        "tiled:4x4",
        "scanline",
        "16K:64:4",
    ));
    // Measured: 39.1 against 4.1.
    assert!(tiled * 2.0 < linear, "linear {linear:.2}, tiled {tiled:.2}");
}

#[test]
fn tiled_order_and_blocked_layout_each_help_and_together_most() {
    let c = chain(2048);
    let b = |layout: &str, order: &str| {
        bytes_per_pixel(&run(
            &c,
            "bilinear",
            "rotate:30",
            (1024, 1024),
            layout,
            order,
            "4K:64:4",
        ))
    };
    let (ls, lt) = (b("linear", "scanline"), b("linear", "tiled:8"));
    let (bs, bt) = (
        b("blocked:4x4:32x32", "scanline"),
        b("blocked:4x4:32x32", "tiled:8"),
    );
    // Measured: 39.3, 30.4, 25.7, 6.7.
    assert!(
        lt < ls,
        "tiled order helps a linear layout: {ls:.2} → {lt:.2}"
    );
    assert!(
        bs < ls,
        "a blocked layout helps scanline order: {ls:.2} → {bs:.2}"
    );
    assert!(
        bt < bs && bt < lt,
        "both together are best: {bt:.2} (others {ls:.2} {lt:.2} {bs:.2})"
    );
}

#[test]
fn trilinear_fetches_one_and_a_quarter_times_four_to_the_delta_new_texels_per_pixel() {
    let c = chain(4096);
    for (k, delta) in [(1.0f64, 0.05f64), (1.0, 0.5), (2.0, 0.05), (2.0, 0.5)] {
        let scale = (k + delta).exp2();
        let r = run(
            &c,
            "trilinear",
            &format!("rotate:30:{scale}"),
            (512, 512),
            "linear",
            "scanline",
            "16M:4:16",
        );
        let per_pixel = r.stats.total.misses as f64 / r.pixels as f64;
        let want = 1.25 * (2.0 * delta).exp2();
        assert!(
            (per_pixel / want - 1.0).abs() < 0.03,
            "λ = {}: {per_pixel:.4} new texels per pixel, SPEC {want:.4}",
            k + delta
        );
        assert_eq!(r.reads, 8 * r.pixels, "8 texel reads per pixel");
    }
}
