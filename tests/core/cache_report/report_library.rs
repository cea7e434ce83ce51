//! The trade-off report and the cache sweep as library calls, without the
//! command line, checked against independent references: the plain cache
//! model (`cache::reference`) fed a trace recorded query by query, images
//! rendered through `scene::render`'s own entry points, and the metrics
//! restated here from their SPEC.md definitions.

use std::collections::HashSet;

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::reference::PlainSimulator;
use parvo::cache::run::{AddressSink, SAT_LEVEL, unpack};
use parvo::cache::sim::{CacheConfig, Outcome};
use parvo::cache::sweep::{SweepSettings, cache_grid, sweep};
use parvo::sample::{Query, Sampler, SamplerOptions, TexelSink};
use parvo::scene::render::{Image, filter_image, reference_image};
use parvo::scene::{Frame, RasterOrder, Scene};
use parvo::store::TextureStore;
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::tradeoff::{self, Progress, Rendered, Settings};
use parvo::{MipOptions, Texture, builtin, mip};

/// Line outcomes of the plain model for every access of `accesses`
/// (packed, `cache::run`'s form): (accesses, hits, cold, capacity,
/// conflict).
fn plain_counts(
    accesses: &[u64],
    cache: &CacheConfig,
    texel: u64,
    sat: u64,
) -> (u64, u64, u64, u64, u64) {
    let mut sim = PlainSimulator::new(cache);
    let mut c = (0, 0, 0, 0, 0);
    for &a in accesses {
        let (addr, level) = unpack(a);
        let bytes = if level == SAT_LEVEL { sat } else { texel };
        for (_, o) in sim.access(addr, bytes) {
            c.0 += 1;
            match o {
                Outcome::Hit => c.1 += 1,
                Outcome::Cold => c.2 += 1,
                Outcome::Capacity => c.3 += 1,
                Outcome::Conflict => c.4 += 1,
                Outcome::Miss => panic!("the plain model classifies every miss"),
            }
        }
    }
    c
}

/// Every read of the frame, one query at a time in raster order (the
/// library records them in parallel chunks), and the pixels that issued
/// a query.
fn trace_one_by_one(
    sampler: &Sampler,
    layout: &ChainLayout,
    scene: Scene,
    frame: Frame,
    order: RasterOrder,
) -> (Vec<u64>, u64) {
    let tex = sampler.chain().level_size(0).unwrap();
    let mut sink = AddressSink::new(layout);
    let mut pixels = 0;
    for (x, y) in order.pixels(frame) {
        if let Some(q) = scene.query(frame, tex, x, y) {
            sampler.sample_traced(&q, &mut sink);
            pixels += 1;
        }
    }
    (sink.out, pixels)
}

fn options(name: &str) -> SamplerOptions {
    SamplerOptions::from_name(name).unwrap()
}

/// Every sweep row equals the plain cache model run on a trace recorded
/// query by query; the rows are filters × layouts × caches in order; and
/// under LRU, more sets of the same associativity never miss more
/// (each finer set sees a subsequence of a coarser set's stream).
#[test]
fn a_sweep_matches_the_plain_cache_model_and_lru_misses_fall_with_size() {
    let chain = mip::build(
        builtin::load("builtin:zoneplate:100").unwrap(),
        &MipOptions::default(),
    )
    .unwrap();
    let filters = ["trilinear", "aniso4", "sat", "nearest"];
    let layouts: Vec<Layout> = ["linear", "morton", "blocked:4x4:16x16"]
        .iter()
        .map(|l| l.parse().unwrap())
        .collect();
    let sizes = [1024, 2048, 4096, 8192, 3 * 1024];
    let caches = cache_grid(&sizes, &[32, 64], &[1, 4, 16], 0x5eed, None);
    // 1K of 64-byte lines has 16 lines: 16 ways is fully associative; 3K
    // of 32-byte lines in 16 ways has 6 sets; every combination is valid
    // here but none repeats.
    assert!(caches.iter().all(|c| c.validate().is_ok()));
    assert_eq!(caches.len(), sizes.len() * 2 * 3);
    let settings = SweepSettings {
        scene: "rotate:20:1.7".parse().unwrap(),
        frame: Frame::new(41, 29),
        order: "hilbert".parse().unwrap(),
        filters: filters
            .iter()
            .map(|f| (f.to_string(), options(f)))
            .collect(),
        layouts: layouts.clone(),
        caches: caches.clone(),
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows = sweep(&chain, None, &settings, &|| {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(rows.len(), filters.len() * layouts.len() * caches.len());
    assert_eq!(done.into_inner(), rows.len());

    let mut k = 0;
    for f in filters {
        let sampler = Sampler::new(&chain, options(f)).unwrap();
        for &layout in &layouts {
            let cl = ChainLayout::for_sampler_stored(&chain, &sampler, layout, None);
            let (trace, pixels) = trace_one_by_one(
                &sampler,
                &cl,
                settings.scene,
                settings.frame,
                settings.order,
            );
            assert!(pixels > 0 && !trace.is_empty());
            let sat = cl.sat_entry().unwrap_or(cl.texel());
            for cache in &caches {
                let row = &rows[k];
                k += 1;
                assert_eq!(
                    (row.filter.as_str(), row.layout, row.cache),
                    (f, layout, *cache)
                );
                let what = format!("{f} {layout} {cache}");
                assert_eq!(row.run.pixels, pixels, "{what}");
                assert_eq!(row.run.reads, trace.len() as u64, "{what}");
                let t = &row.run.stats.total;
                let (accesses, hits, cold, capacity, conflict) =
                    plain_counts(&trace, cache, cl.texel(), sat);
                assert_eq!(
                    (t.accesses, t.hits, t.cold, t.capacity, t.conflict),
                    (accesses, hits, cold, capacity, conflict),
                    "{what}"
                );
                assert_eq!(t.bytes_fetched, t.misses * cache.line, "{what}");
            }
        }
    }

    // LRU inclusion: same line and ways, twice the sets.
    for a in &rows {
        for b in &rows {
            if a.filter == b.filter
                && a.layout == b.layout
                && a.cache.line == b.cache.line
                && a.cache.ways == b.cache.ways
                && b.cache.size == 2 * a.cache.size
            {
                let (ma, mb) = (a.run.stats.total.misses, b.run.stats.total.misses);
                assert!(
                    mb <= ma,
                    "{} {}: {} misses {ma}, {} misses {mb}",
                    a.filter,
                    a.layout,
                    a.cache,
                    b.cache,
                );
            }
        }
    }
}

/// RMSE, PSNR and largest error over R, G, B of the pixels both images
/// have (SPEC.md), restated.
fn metrics(reference: &Image, got: &Image) -> (f64, f64, f64) {
    let mut d2 = Vec::new();
    let mut max = 0f64;
    for (r, g) in reference.iter().zip(got) {
        if let (Some(r), Some(g)) = (r, g) {
            for c in 0..3 {
                let d = (r[c] as f64 - g[c] as f64).abs();
                d2.push(d * d);
                max = max.max(d);
            }
        }
    }
    let mse = d2.iter().sum::<f64>() / d2.len() as f64;
    (mse.sqrt(), -10.0 * mse.log10(), max)
}

/// The 99th percentile of the per-pixel mean absolute error, at least 1e-4.
fn percentile_99(reference: &Image, got: &Image) -> f64 {
    let mut e: Vec<f64> = reference
        .iter()
        .zip(got)
        .filter_map(|(r, g)| {
            let (r, g) = (r.as_ref()?, g.as_ref()?);
            Some((0..3).map(|c| (r[c] - g[c]).abs() as f64).sum::<f64>() / 3.0)
        })
        .collect();
    e.sort_by(f64::total_cmp);
    e[(e.len() * 99 / 100).min(e.len() - 1)].max(1e-4)
}

/// Counts reads and the 64×64 tiles they fall in, per level.
#[derive(Default)]
struct Reads {
    n: u64,
    tiles: HashSet<(u32, u32, u32)>,
}

impl TexelSink for Reads {
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        self.n += 1;
        self.tiles.insert((level, x / 64, y / 64));
    }
    fn sat_entry(&mut self, _x: u32, _y: u32) {
        self.n += 1;
    }
}

/// What the callback of `tradeoff::run` saw.
struct Seen {
    reference: Option<Image>,
    rows: Vec<(String, Image)>,
    steps: Vec<String>,
    advances: usize,
}

fn run_report(store: &TextureStore, settings: &Settings) -> (tradeoff::Report, Seen) {
    let steps = std::sync::Mutex::new((Vec::new(), 0usize));
    let progress = |p: Progress<'_>| {
        let mut s = steps.lock().unwrap();
        match p {
            Progress::Step(m) => s.0.push(m.to_string()),
            Progress::Advance => s.1 += 1,
        }
    };
    let mut reference = None;
    let mut rows = Vec::new();
    let report = tradeoff::run(store, settings, &progress, &mut |r| {
        match r {
            Rendered::Reference(img) => reference = Some(img.clone()),
            Rendered::Filter { row, image, .. } => rows.push((row.name.clone(), image.clone())),
        }
        Ok::<(), parvo::Error>(())
    })
    .unwrap();
    let (steps, advances) = steps.into_inner().unwrap();
    let seen = Seen {
        reference,
        rows,
        steps,
        advances,
    };
    (report, seen)
}

/// The report's rows, recomputed one by one: each filter's frame rendered
/// again through `scene::render`, its scores from the SPEC formulas, its
/// flicker from the shifted frames, its reads and tiles counted query by
/// query, its traffic from the plain cache model; only what the filters
/// read is built.
#[test]
fn the_tradeoff_report_matches_its_rows_recomputed_independently() {
    let store = TextureStore::new(
        builtin::load("builtin:zoneplate:100").unwrap(),
        MipOptions::default(),
    );
    let names = ["nearest", "trilinear", "aniso4", "ewa"];
    let scene: Scene = "rotate:25:1.6".parse().unwrap();
    let frame = Frame::new(37, 23);
    let mut settings = Settings::new(scene, frame, names.map(options).to_vec()).unwrap();
    settings.runs = 1;
    let (report, seen) = run_report(&store, &settings);

    assert_eq!(
        report
            .rows
            .iter()
            .map(|r| r.name.as_str())
            .collect::<Vec<_>>(),
        names
    );
    assert_eq!(seen.advances as u64, tradeoff::progress_total(&settings));
    assert_eq!(seen.steps[..2], ["reference", "timing"]);
    assert!(!report.built.sat && report.built.mip_levels > 0);
    assert_eq!(report.texture_size, (100, 100));

    let ref0 = reference_image(&store, &settings.reference, &scene, frame, (0.0, 0.0)).unwrap();
    let shift = settings.flicker_shift;
    let ref1 = reference_image(&store, &settings.reference, &scene, frame, shift).unwrap();
    assert!(seen.reference.as_ref() == Some(&ref0));
    assert_eq!(report.pixels, ref0.iter().flatten().count());
    let rms = |a: &Image, b: &Image| metrics(a, b).0;

    for ((row, (seen_name, seen_image)), name) in report.rows.iter().zip(&seen.rows).zip(names) {
        let o = options(name);
        let img0 = filter_image(&store, o, &scene, frame, (0.0, 0.0)).unwrap();
        let img1 = filter_image(&store, o, &scene, frame, shift).unwrap();
        assert_eq!(seen_name, name);
        assert!(*seen_image == img0, "{name}: the frame handed over");
        let (rmse, psnr, max) = metrics(&ref0, &img0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
        assert!(close(row.rmse, rmse), "{name}: rmse {} vs {rmse}", row.rmse);
        assert!(
            close(row.psnr_db, psnr),
            "{name}: psnr {} vs {psnr}",
            row.psnr_db
        );
        assert!(close(row.max_error, max), "{name}");
        assert!(
            close(row.error_scale, percentile_99(&ref0, &img0)),
            "{name}"
        );
        let fl = rms(&img0, &img1) - rms(&ref0, &ref1);
        assert!(
            close(row.flicker, fl),
            "{name}: flicker {} vs {fl}",
            row.flicker
        );
        assert!(row.ns_per_pixel > 0.0 && row.ns_per_pixel.is_finite());

        // Reads and tiles, query by query.
        let sampler = store.sampler(o).unwrap();
        let tex = (100, 100);
        let mut reads = Reads::default();
        let qs: Vec<Query> = (0..frame.height)
            .flat_map(|y| (0..frame.width).map(move |x| (x, y)))
            .filter_map(|(x, y)| scene.query(frame, tex, x, y))
            .collect();
        for q in &qs {
            sampler.sample_traced(q, &mut reads);
        }
        let px = report.pixels as f64;
        assert!(close(row.texels_per_pixel, reads.n as f64 / px), "{name}");
        for t in &row.working_set {
            let want = reads
                .tiles
                .iter()
                .filter(|k| k.0 as usize == t.level)
                .count();
            assert_eq!(t.touched, want, "{name} level {}", t.level);
            let (w, h) = sampler.chain().level_size(t.level).unwrap();
            assert_eq!(t.tiles, (w.div_ceil(64) * h.div_ceil(64)) as usize);
        }
        assert_eq!(row.working_set.len(), sampler.chain().len());

        // Traffic: the plain model on the frame's reads in the settings'
        // order.
        let chain = store.chain_for(&o).unwrap();
        let cl = ChainLayout::for_sampler_stored(chain, &sampler, settings.layout, None);
        let (trace, pixels) = trace_one_by_one(&sampler, &cl, scene, frame, settings.order);
        assert_eq!(pixels as usize, report.pixels);
        let (accesses, hits, ..) = plain_counts(&trace, &settings.cache, cl.texel(), cl.texel());
        let bytes = (accesses - hits) * settings.cache.line;
        assert!(close(row.bytes_per_pixel, bytes as f64 / px), "{name}");
    }
}

/// A texture of one colour: every filter's weights sum to one, so every
/// row's error against the reference is zero to rounding; and asking for
/// `sat` builds the table.
#[test]
fn a_constant_texture_has_no_error_in_any_row() {
    let (w, h) = (45, 31);
    let texel = [0.25f32, 0.5, 0.75, 1.0];
    let data: Vec<f32> = (0..w * h).flat_map(|_| texel).collect();
    let tex = Texture::from_linear(
        w,
        h,
        Format::new(4, ChannelType::F32, ColorSpace::Linear),
        &data,
    )
    .unwrap();
    let store = TextureStore::new(tex, MipOptions::default());
    let names = ["nearest", "bilinear", "trilinear", "aniso16", "ewa", "sat"];
    let mut settings = Settings::new(
        "tunnel".parse().unwrap(),
        Frame::new(30, 20),
        names.map(options).to_vec(),
    )
    .unwrap();
    settings.runs = 1;
    let (report, _) = run_report(&store, &settings);
    assert!(report.built.sat && report.built.sat_bytes > 0);
    for r in &report.rows {
        assert!(r.max_error < 1e-5, "{}: max error {}", r.name, r.max_error);
        assert!(r.psnr_db > 90.0, "{}: {} dB", r.name, r.psnr_db);
        assert!(r.flicker.abs() < 1e-5, "{}", r.name);
    }
}

/// The rows of the block-compressed chain: one per filter, named
/// `FILTER+bc1`, storing BC1; they read the same texels as the plain rows
/// (a footprint does not depend on texel values) and fetch whole 8-byte
/// blocks.
#[cfg(feature = "encode")]
#[test]
fn compressed_rows_follow_the_plain_ones() {
    use parvo::compress::{BlockFormat, Quality};
    let store = TextureStore::new(
        builtin::load("builtin:photo:96").unwrap(),
        MipOptions::default(),
    );
    let names = ["bilinear", "aniso8"];
    let mut settings = Settings::new(
        "plane".parse().unwrap(),
        Frame::new(40, 30),
        names.map(options).to_vec(),
    )
    .unwrap();
    settings.runs = 1;
    settings.compress = Some((BlockFormat::Bc1, Quality::Fast));
    let (report, seen) = run_report(&store, &settings);
    assert_eq!(report.rows.len(), 4);
    assert_eq!(seen.rows.len(), 4);
    assert!(seen.steps.iter().any(|s| s == "BC1 encode"));
    for (plain, c) in report.rows[..2].iter().zip(&report.rows[2..]) {
        assert_eq!(c.name, format!("{}+bc1", plain.name));
        assert!(c.stored.starts_with("BC1"), "{}", c.stored);
        assert!(!plain.stored.starts_with("BC"), "{}", plain.stored);
        assert_eq!(c.texels_per_pixel, plain.texels_per_pixel);
        assert_eq!(c.working_set, plain.working_set);
        assert!(c.rmse.is_finite() && c.rmse > 0.0);
    }
}
