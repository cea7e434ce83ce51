//! Summed-area tables: build throughput (texels/s) of parvo's banded
//! parallel build against a plain sequential two-pass prefix sum, in the
//! same run; query throughput (queries/s) of rectangle sums and the SAT
//! sampler.
//!
//! ```text
//! cargo bench --bench sat -- --warm-up-time 1 --measurement-time 2
//! ```

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use parvo::sat::{Rect, SatSampler, SummedAreaTable};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{Texture, Wrap};

const N: u32 = 4096;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn grey(ty: ChannelType) -> Format {
    Format::new(1, ty, ColorSpace::Linear)
}

/// The textbook build: row prefix sums, then column sums, one thread.
fn plain<T: Copy, A: Copy + Default + std::ops::Add<Output = A>>(
    src: &[T],
    w: usize,
    h: usize,
    conv: impl Fn(T) -> A,
) -> Vec<A> {
    let stride = w + 1;
    let mut t = vec![A::default(); stride * (h + 1)];
    for y in 0..h {
        let row = &mut t[(y + 1) * stride..(y + 2) * stride];
        let mut run = A::default();
        for x in 0..w {
            run = run + conv(src[y * w + x]);
            row[x + 1] = run;
        }
    }
    for y in 1..=h {
        let (above, rest) = t.split_at_mut(y * stride);
        let above = &above[(y - 1) * stride..];
        for (d, &a) in rest[..stride].iter_mut().zip(above) {
            *d = *d + a;
        }
    }
    t
}

fn build(c: &mut Criterion) {
    let mut rng = Rng(1);
    let n = (N * N) as usize;
    let u8s: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
    let u16s: Vec<u16> = (0..n).map(|_| rng.next() as u16).collect();
    let f32s: Vec<f32> = (0..n).map(|_| rng.unit()).collect();
    let t8 = Texture::from_u8(N, N, grey(ChannelType::U8), u8s.clone()).unwrap();
    let t16 = Texture::from_u16(N, N, grey(ChannelType::U16), u16s.clone()).unwrap();
    let tf = Texture::from_f32(N, N, grey(ChannelType::F32), f32s.clone()).unwrap();
    let (w, h) = (N as usize, N as usize);

    let mut g = c.benchmark_group("sat_build_4096");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(10);
    g.bench_function("u8_to_u32/parvo", |b| {
        b.iter(|| SummedAreaTable::<u32>::build(black_box(&t8)).unwrap())
    });
    g.bench_function("u8_to_u32/plain_two_pass", |b| {
        b.iter(|| plain(black_box(&u8s), w, h, |v| v as u32))
    });
    g.bench_function("u16_to_u64/parvo", |b| {
        b.iter(|| SummedAreaTable::<u64>::build(black_box(&t16)).unwrap())
    });
    g.bench_function("u16_to_u64/plain_two_pass", |b| {
        b.iter(|| plain(black_box(&u16s), w, h, |v| v as u64))
    });
    g.bench_function("f32_to_f64/parvo", |b| {
        b.iter(|| SummedAreaTable::<f64>::build(black_box(&tf)).unwrap())
    });
    g.bench_function("f32_to_f64/plain_two_pass", |b| {
        b.iter(|| plain(black_box(&f32s), w, h, |v| v as f64))
    });
    g.finish();
}

fn queries(c: &mut Criterion) {
    let mut rng = Rng(2);
    let n = 1024u32;
    let v: Vec<u8> = (0..n * n * 4).map(|_| rng.next() as u8).collect();
    let tex =
        Texture::from_u8(n, n, Format::new(4, ChannelType::U8, ColorSpace::Linear), v).unwrap();
    let table = SummedAreaTable::<u64>::build(&tex).unwrap();
    let sampler = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    const Q: usize = 4096;
    let whole: Vec<(u32, u32, u32, u32)> = (0..Q)
        .map(|_| {
            let x0 = (rng.next() % (n as u64 - 64)) as u32;
            let y0 = (rng.next() % (n as u64 - 64)) as u32;
            (
                x0,
                y0,
                x0 + 1 + (rng.next() % 63) as u32,
                y0 + 1 + (rng.next() % 63) as u32,
            )
        })
        .collect();
    let frac: Vec<Rect> = (0..Q)
        .map(|_| {
            let (x, y) = (rng.unit() as f64 * n as f64, rng.unit() as f64 * n as f64);
            let (hx, hy) = (rng.unit() as f64 * 30.0, rng.unit() as f64 * 30.0);
            Rect::new(x - hx, y - hy, x + hx, y + hy)
        })
        .collect();
    let footprints: Vec<[f32; 6]> = (0..Q)
        .map(|_| {
            let s = 0.02 * rng.unit();
            [
                rng.unit(),
                rng.unit(),
                s,
                0.3 * s * rng.unit(),
                -0.2 * s,
                0.25 * s,
            ]
        })
        .collect();

    let mut g = c.benchmark_group("sat_query_1024_rgba8");
    g.throughput(Throughput::Elements(Q as u64));
    g.bench_function("raw_sum_whole_texels", |b| {
        b.iter(|| {
            let mut acc = 0u64;
            for &(x0, y0, x1, y1) in &whole {
                acc = acc.wrapping_add(table.raw_sum(x0, y0, x1, y1)[0]);
            }
            acc
        })
    });
    g.bench_function("average_fractional_repeat", |b| {
        b.iter(|| {
            let mut acc = 0f32;
            for &r in &frac {
                acc += table.average(black_box(r), Wrap::default(), [0.0; 4])[0];
            }
            acc
        })
    });
    g.bench_function("sampler_sat", |b| {
        b.iter(|| {
            let mut acc = 0f32;
            for q in &footprints {
                acc += sampler.sample(q[0], q[1], q[2], q[3], q[4], q[5])[0];
            }
            acc
        })
    });
    for slices in [4u32, 8] {
        g.bench_with_input(
            BenchmarkId::new("sampler_sat_aniso", slices),
            &slices,
            |b, &k| {
                b.iter(|| {
                    let mut acc = 0f32;
                    for q in &footprints {
                        acc += sampler.sample_aniso(q[0], q[1], q[2], q[3], q[4], q[5], k)[0];
                    }
                    acc
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, build, queries);
criterion_main!(benches);
