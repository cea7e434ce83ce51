//! Rendering a scene with a sampler, timing it, and the per-pixel images
//! the accuracy metrics compare (row-major, `None` where a pixel issued no
//! query).

use std::time::Instant;

use rayon::prelude::*;

use super::metrics::{Scores, scores};
use super::reference::Reference;
use super::{Frame, Scene};
use crate::error::Result;
use crate::sample::{Query, Sampler, SamplerOptions, TexelSink, mip_linear, mip_nearest};
use crate::store::TextureStore;

/// An image of linear RGBA values, `None` where the scene shows nothing.
pub type Image = Vec<Option<[f32; 4]>>;

/// Every pixel's query (row-major) with the camera moved by `offset`
/// pixels, `None` where there is none.
pub fn queries(
    scene: &Scene,
    frame: Frame,
    tex: (u32, u32),
    offset: (f64, f64),
) -> Vec<Option<Query>> {
    let view = scene.view(frame, tex);
    let view = &view;
    (0..frame.height)
        .into_par_iter()
        .flat_map_iter(|py| {
            (0..frame.width).map(move |px| {
                view.query_at(px as f64 + 0.5 + offset.0, py as f64 + 0.5 + offset.1)
            })
        })
        .collect()
}

/// The image `sampler` renders (in parallel).
pub fn render(sampler: &Sampler, qs: &[Option<Query>]) -> Image {
    let dense: Vec<Query> = qs.iter().flatten().copied().collect();
    let mut out = vec![[0f32; 4]; dense.len()];
    // A valid sampler and equal lengths cannot fail.
    let _ = sampler.sample_batch(&dense, &mut out);
    let mut it = out.into_iter();
    qs.iter().map(|q| q.and_then(|_| it.next())).collect()
}

/// The reference image of `scene` (camera moved by `offset` pixels) for
/// the texture in `store`, in parallel, without progress reports.
pub fn reference_image(
    store: &TextureStore,
    reference: &Reference,
    scene: &Scene,
    frame: Frame,
    offset: (f64, f64),
) -> Result<Image> {
    let level0 = store.reference_sampler(store.options().wrap)?;
    Ok(reference.render(scene, frame, offset, &level0, &|_| {}))
}

/// The image the filter `options` renders of `scene` (camera moved by
/// `offset`) from the texture in `store`, with the store's wrap mode,
/// building what the filter reads.
pub fn filter_image(
    store: &TextureStore,
    mut options: SamplerOptions,
    scene: &Scene,
    frame: Frame,
    offset: (f64, f64),
) -> Result<Image> {
    options.wrap = store.options().wrap;
    let s = store.sampler(options)?;
    let b = store.base();
    Ok(render(
        &s,
        &queries(scene, frame, (b.width(), b.height()), offset),
    ))
}

/// [`Scores`] of the filter `options` on `scene` against `reference`
/// (the reference image of the same scene and frame).
pub fn accuracy(
    store: &TextureStore,
    options: SamplerOptions,
    scene: &Scene,
    frame: Frame,
    reference: &Image,
) -> Result<Scores> {
    Ok(scores(
        reference,
        &filter_image(store, options, scene, frame, (0.0, 0.0))?,
    ))
}

/// Median wall time per query of each sampler, in nanoseconds: `runs`
/// rounds, each timing every sampler once in turn (so a drift of the
/// machine's speed during the measurement reaches all of them alike), of
/// the untraced fast path over `queries` on the calling thread. Each
/// timing repeats the whole slice until it lasts at least [`MIN_TIMING`]
/// (a cheap filter takes about a millisecond per frame, short enough for
/// one interrupt to move it by tens of per cent); one untimed pass per
/// sampler first.
pub fn ns_per_query(samplers: &[&Sampler], queries: &[Query], runs: usize) -> Vec<f64> {
    let mut out = vec![[0f32; 4]; queries.len()];
    let mut pass = |s: &Sampler| {
        let t = Instant::now();
        let _ = s.sample_slice(queries, &mut out);
        std::hint::black_box(&out);
        t.elapsed().as_secs_f64()
    };
    let reps: Vec<usize> = samplers
        .iter()
        .map(|s| ((MIN_TIMING / pass(s).max(1e-9)).ceil() as usize).clamp(1, 1000))
        .collect();
    let mut times = vec![Vec::new(); samplers.len()];
    for _ in 0..runs.max(1) {
        for ((s, &n), t) in samplers.iter().zip(&reps).zip(&mut times) {
            t.push((0..n).map(|_| pass(s)).sum::<f64>() / n as f64);
        }
    }
    times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2] * 1e9 / queries.len().max(1) as f64
        })
        .collect()
}

/// Shortest single timing of [`ns_per_query`], seconds.
pub const MIN_TIMING: f64 = 0.02;

/// Counts the texels a lookup reads per mip level.
#[derive(Default)]
struct LevelCounter {
    counts: Vec<u32>,
}

impl TexelSink for LevelCounter {
    #[inline]
    fn texel(&mut self, level: u32, _x: u32, _y: u32) {
        let k = level as usize;
        if k >= self.counts.len() {
            self.counts.resize(k + 1, 0);
        }
        self.counts[k] += 1;
    }
}

/// The colour of mip level `k` in `--show-levels` images.
pub fn level_colour(k: usize) -> [f32; 3] {
    const P: [[f32; 3]; 12] = [
        [0.90, 0.10, 0.10],
        [0.95, 0.55, 0.05],
        [0.95, 0.90, 0.10],
        [0.20, 0.80, 0.20],
        [0.10, 0.80, 0.80],
        [0.15, 0.35, 0.95],
        [0.55, 0.20, 0.90],
        [0.90, 0.20, 0.75],
        [0.60, 0.40, 0.20],
        [0.50, 0.50, 0.50],
        [0.95, 0.95, 0.95],
        [0.10, 0.10, 0.10],
    ];
    P[k.min(P.len() - 1)]
}

/// The `--show-levels` tint of every pixel: the colour of the mip level
/// it read, blended by the filter's own level weights (λ's fraction for
/// linear mip filtering, the probes sharing λ), or by the texels read per
/// level for filters without one λ (EWA, the reference's and SAT's level
/// 0), scaled by the rendered luminance so the texture stays visible.
pub fn show_levels(sampler: &Sampler, qs: &[Option<Query>], img: &Image) -> Vec<Option<[f32; 3]>> {
    use crate::sample::{Method, MipMode};
    let o = *sampler.options();
    let levels = sampler.chain().len();
    let q_last = levels.saturating_sub(1);
    qs.par_iter()
        .zip(img.par_iter())
        .map(|(q, c)| {
            let (q, c) = (q.as_ref()?, c.as_ref()?);
            let mut mix = [0f32; 3];
            let mut add = |k: usize, w: f32| {
                let p = level_colour(k);
                for i in 0..3 {
                    mix[i] += w * p[i];
                }
            };
            if o.method == Method::Texel {
                let fp = sampler.footprint(q);
                let lam = fp.lambda;
                if lam <= 0.0 || o.mip == MipMode::None || levels == 1 {
                    add(0, 1.0);
                } else if o.mip == MipMode::Nearest {
                    add(mip_nearest(lam, q_last), 1.0);
                } else {
                    let (hi, lo, delta) = mip_linear(lam, q_last);
                    add(hi, 1.0 - delta);
                    add(lo, delta);
                }
            } else {
                let mut sink = LevelCounter::default();
                let _ = sampler.sample_traced(q, &mut sink);
                let total: u32 = sink.counts.iter().sum();
                for (k, &n) in sink.counts.iter().enumerate() {
                    if n > 0 {
                        add(k, n as f32 / total.max(1) as f32);
                    }
                }
            }
            let luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            let shade = 0.35 + 0.65 * luma.clamp(0.0, 1.0);
            Some(mix.map(|m| m * shade))
        })
        .collect()
}
