//! Mip-chain build throughput (texels of level 0 per second) against
//! fast_image_resize, `image` and a plain memcpy of the level-0 bytes, in
//! the same run. `scripts/bench-table.py mip` turns the results into the
//! README table.
//!
//! Thread counts: `t1` runs inside a one-thread rayon pool, `t2` inside a
//! two-thread pool (this machine has 2 cores); fast_image_resize is built
//! with its `rayon` feature so it parallelises in the same pools.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use fast_image_resize as fir;
use parvo::mip::{self, MipFilter, MipOptions};
use parvo::{ChannelType, ColorSpace, Format, Texture};

fn pool(n: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .unwrap()
}

/// Opaque RGBA8 noise-plus-gradient test image (deterministic).
fn rgba8(n: u32) -> Vec<u8> {
    let mut s = 0x1234_5678u32;
    let mut v = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            v.extend_from_slice(&[(x ^ y) as u8, (s >> 24) as u8, ((x + y) >> 4) as u8, 255]);
        }
    }
    v
}

fn fir_chain(base: &fir::images::Image, alg: fir::ResizeAlg) -> usize {
    let mut resizer = fir::Resizer::new();
    let opts = fir::ResizeOptions::new().resize_alg(alg).use_alpha(false);
    let mut levels: Vec<fir::images::Image> = Vec::new();
    let (mut w, mut h) = (base.width(), base.height());
    while w > 1 || h > 1 {
        w = (w / 2).max(1);
        h = (h / 2).max(1);
        let mut dst = fir::images::Image::new(w, h, base.pixel_type());
        match levels.last() {
            None => resizer.resize(base, &mut dst, &opts).unwrap(),
            Some(prev) => resizer.resize(prev, &mut dst, &opts).unwrap(),
        }
        levels.push(dst);
    }
    levels.len()
}

fn image_chain(base: &image::RgbaImage) -> usize {
    let mut prev = base.clone();
    let mut n = 0;
    while prev.width() > 1 || prev.height() > 1 {
        let (w, h) = ((prev.width() / 2).max(1), (prev.height() / 2).max(1));
        prev = image::imageops::resize(&prev, w, h, image::imageops::FilterType::Triangle);
        n += 1;
    }
    n
}

fn bench_chains(c: &mut Criterion) {
    for n in [4096u32, 1024] {
        let mut g = c.benchmark_group(format!("mip_chain_{n}"));
        g.throughput(Throughput::Elements(n as u64 * n as u64));
        g.sample_size(if n == 4096 { 20 } else { 40 });
        let bytes = rgba8(n);
        let linear8 = Texture::from_u8(
            n,
            n,
            Format::new(4, ChannelType::U8, ColorSpace::Linear),
            bytes.clone(),
        )
        .unwrap();
        let srgb8 = Texture::from_u8(
            n,
            n,
            Format::new(4, ChannelType::U8, ColorSpace::Srgb),
            bytes.clone(),
        )
        .unwrap();
        let f32tex = linear8
            .convert(Format::new(4, ChannelType::F32, ColorSpace::Linear))
            .unwrap();
        let parvo::Texels::F32(f32vals) = f32tex.texels().clone() else {
            unreachable!()
        };
        let f32bytes: Vec<u8> = f32vals.iter().flat_map(|v| v.to_ne_bytes()).collect();

        let mut dst8 = vec![0u8; bytes.len()];
        g.bench_function("memcpy_rgba8", |b| {
            b.iter(|| dst8.copy_from_slice(black_box(&bytes)))
        });
        let mut dst32 = vec![0f32; f32vals.len()];
        g.bench_function("memcpy_rgba_f32", |b| {
            b.iter(|| dst32.copy_from_slice(black_box(&f32vals)))
        });
        drop((dst8, dst32));

        let fir8 =
            fir::images::Image::from_vec_u8(n, n, bytes.clone(), fir::PixelType::U8x4).unwrap();
        let fir32 = fir::images::Image::from_vec_u8(n, n, f32bytes, fir::PixelType::F32x4).unwrap();
        let img = image::RgbaImage::from_raw(n, n, bytes.clone()).unwrap();
        let box_alg = fir::ResizeAlg::Convolution(fir::FilterType::Box);
        let lanczos = fir::ResizeAlg::Convolution(fir::FilterType::Lanczos3);

        for threads in [1usize, 2] {
            let p = pool(threads);
            let t = format!("t{threads}");
            let run = |tex: &Texture, filter: MipFilter| {
                let opts = MipOptions::with_filter(filter);
                p.install(|| {
                    mip::build_reduced_levels(black_box(tex), &opts)
                        .unwrap()
                        .len()
                })
            };
            g.bench_function(BenchmarkId::new("parvo_box_rgba8_linear", &t), |b| {
                b.iter(|| run(&linear8, MipFilter::Box))
            });
            g.bench_function(BenchmarkId::new("parvo_box_rgba8_srgb", &t), |b| {
                b.iter(|| run(&srgb8, MipFilter::Box))
            });
            // Each level rounded to 8 bits and reduced from that (what
            // parvo did before issue 27): the cost of rounding once.
            g.bench_function(BenchmarkId::new("chained_box_rgba8_srgb", &t), |b| {
                b.iter(|| {
                    p.install(|| {
                        let opts = MipOptions::default();
                        let sizes = mip::level_sizes(n, n, opts.rounding, None);
                        let (w1, h1) = sizes[1];
                        let mut prev = mip::reduce(black_box(&srgb8), w1, h1, &opts).unwrap();
                        for &(w, h) in &sizes[2..] {
                            prev = mip::reduce(&prev, w, h, &opts).unwrap();
                        }
                        prev.width()
                    })
                })
            });
            g.bench_function(BenchmarkId::new("parvo_box_rgba_f32", &t), |b| {
                b.iter(|| run(&f32tex, MipFilter::Box))
            });
            g.bench_function(BenchmarkId::new("parvo_kaiser_rgba_f32", &t), |b| {
                b.iter(|| run(&f32tex, MipFilter::Kaiser))
            });
            g.bench_function(BenchmarkId::new("parvo_kaiser_rgba8_srgb", &t), |b| {
                b.iter(|| run(&srgb8, MipFilter::Kaiser))
            });
            g.bench_function(BenchmarkId::new("fir_box_rgba8", &t), |b| {
                b.iter(|| p.install(|| fir_chain(&fir8, box_alg)))
            });
            g.bench_function(BenchmarkId::new("fir_lanczos3_rgba8", &t), |b| {
                b.iter(|| p.install(|| fir_chain(&fir8, lanczos)))
            });
            g.bench_function(BenchmarkId::new("fir_lanczos3_rgba_f32", &t), |b| {
                b.iter(|| p.install(|| fir_chain(&fir32, lanczos)))
            });
            if threads == 1 {
                // `image` is single-threaded.
                g.bench_function(BenchmarkId::new("image_triangle_rgba8", &t), |b| {
                    b.iter(|| image_chain(&img))
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, bench_chains);
criterion_main!(benches);
