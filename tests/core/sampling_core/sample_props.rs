//! Property tests over random textures, options and queries, extremes
//! included: every result is finite, lies within the range of the texels it
//! could have read (a convex combination), and the work per query is
//! bounded. No panic anywhere.

use proptest::prelude::*;

use parvo::sample::ewa::MAX_RADIUS;
use parvo::sample::{
    Filter, LinearChain, Method, MipMode, Query, Sampler, SamplerOptions, TexelCounter, TexelFilter,
};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Texture, Wrap, WrapMode, mip};

fn extreme() -> impl Strategy<Value = f32> {
    prop_oneof![
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        Just(1e30f32),
        Just(-1e30f32),
        Just(0.0f32),
        Just(-0.0f32),
        Just(1e6f32),
        Just(-1e6f32),
        Just(1e-30f32),
        Just(f32::MAX),
        Just(f32::MIN_POSITIVE),
    ]
}

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![6 => -3.0f32..3.0, 1 => extreme()]
}

fn deriv() -> impl Strategy<Value = f32> {
    prop_oneof![4 => -0.05f32..0.05, 2 => -2.0f32..2.0, 1 => extreme()]
}

fn query() -> impl Strategy<Value = Query> {
    (coord(), coord(), deriv(), deriv(), deriv(), deriv(), 0u8..4).prop_map(
        |(u, v, a, b, c, d, shape)| match shape {
            // Collinear pair.
            0 => Query::new(u, v, a, b, 3.0 * a, 3.0 * b),
            // One zero vector.
            1 => Query::new(u, v, a, b, 0.0, 0.0),
            _ => Query::new(u, v, a, b, c, d),
        },
    )
}

fn wrap_mode() -> impl Strategy<Value = WrapMode> {
    prop_oneof![
        Just(WrapMode::Repeat),
        Just(WrapMode::MirroredRepeat),
        Just(WrapMode::ClampToEdge),
        Just(WrapMode::ClampToBorder),
        Just(WrapMode::MirrorClampToEdge),
    ]
}

fn options() -> impl Strategy<Value = SamplerOptions> {
    (
        prop_oneof![
            Just(Filter::Nearest),
            Just(Filter::Bilinear),
            Just(Filter::Trilinear),
            Just(Filter::Aniso),
            Just(Filter::Ewa),
            Just(Filter::Supersample),
        ],
        1u32..=16,
        (wrap_mode(), wrap_mode()),
        (-4.0f32..4.0, -2.0f32..3.0, 0.0f32..20.0),
        prop::array::uniform4(0.0f32..1.0),
        (0u8..3, 0u8..2, 0u8..2, any::<bool>()),
        1u32..5,
    )
        .prop_map(
            |(f, n, (wu, wv), (bias, lmin, lspan), border, (mip, mag, min, custom), ss)| {
                let mut o = SamplerOptions::preset(f, n);
                o.wrap = Wrap { u: wu, v: wv };
                o.lod_bias = bias;
                o.border = border;
                o.supersample = ss;
                if custom {
                    o.lod_min = lmin;
                    o.lod_max = lmin + lspan;
                    o.mip = [MipMode::None, MipMode::Nearest, MipMode::Linear][mip as usize];
                    o.mag = [TexelFilter::Nearest, TexelFilter::Linear][mag as usize];
                    o.min = [TexelFilter::Nearest, TexelFilter::Linear][min as usize];
                }
                o
            },
        )
}

fn format() -> impl Strategy<Value = Format> {
    (
        1u8..=4,
        prop_oneof![
            Just(ChannelType::U8),
            Just(ChannelType::U16),
            Just(ChannelType::F16),
            Just(ChannelType::F32),
        ],
        any::<bool>(),
    )
        .prop_map(|(c, t, srgb)| {
            let cs = if srgb {
                ColorSpace::Srgb
            } else {
                ColorSpace::Linear
            };
            Format::new(c, t, cs)
        })
}

fn texture() -> impl Strategy<Value = Texture> {
    (1u32..=9, 1u32..=9, format(), any::<u64>()).prop_map(|(w, h, f, seed)| {
        let mut s = seed | 1;
        let n = (w * h * f.channels as u32) as usize;
        let v: Vec<f32> = (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                let x = (s >> 40) as f32 / (1u64 << 24) as f32;
                if f.channel_type.is_float() {
                    x * 40.0 - 20.0
                } else {
                    x
                }
            })
            .collect();
        Texture::from_linear(w, h, f, &v).unwrap()
    })
}

/// Per-channel range of every decoded texel of every level (and the
/// border colour when a border mode is in use).
fn range(chain: &LinearChain, o: &SamplerOptions) -> ([f32; 4], [f32; 4]) {
    let mut lo = [f32::INFINITY; 4];
    let mut hi = [f32::NEG_INFINITY; 4];
    let mut add = |t: [f32; 4]| {
        for c in 0..4 {
            lo[c] = lo[c].min(t[c]);
            hi[c] = hi[c].max(t[c]);
        }
    };
    for k in 0..chain.len() {
        let (w, h) = chain.level_size(k).unwrap();
        for y in 0..h {
            for x in 0..w {
                add(chain.texel(k, x, y).unwrap());
            }
        }
    }
    if o.wrap.u == WrapMode::ClampToBorder || o.wrap.v == WrapMode::ClampToBorder {
        add(o.border);
    }
    (lo, hi)
}

fn max_reads(o: &SamplerOptions) -> u64 {
    match o.method {
        Method::Texel => 16 * 8,
        Method::Supersample => 4 * (o.supersample as u64).pow(2),
        // Two levels, each an ellipse of semi-axes ≤ MAX_RADIUS (+1 for
        // the reconstruction variance), rows rounded out.
        _ => {
            let r = MAX_RADIUS + 2.0;
            2 * (std::f64::consts::PI * r * r + 4.0 * r) as u64
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn results_are_finite_convex_and_bounded(
        tex in texture(),
        o in options(),
        queries in prop::collection::vec(query(), 1..12),
    ) {
        let chain = mip::build(tex, &MipOptions::default()).unwrap();
        let s = Sampler::new(&chain, o).unwrap();
        let (lo, hi) = range(s.chain(), &o);
        prop_assume!(lo.iter().chain(&hi).all(|x| x.is_finite()));
        for q in &queries {
            let mut count = TexelCounter::default();
            let got = s.sample_traced(q, &mut count);
            let tol = |c: usize| 1e-5 * (1.0f32).max(lo[c].abs()).max(hi[c].abs());
            for c in 0..4 {
                prop_assert!(got[c].is_finite(), "{} {q:?} -> {got:?}", o.name());
                prop_assert!(
                    got[c] >= lo[c] - tol(c) && got[c] <= hi[c] + tol(c),
                    "{} {q:?} channel {c}: {} outside [{}, {}]", o.name(), got[c], lo[c], hi[c]
                );
            }
            prop_assert!(count.count <= max_reads(&o), "{} {q:?} read {} texels", o.name(), count.count);
            // The untraced path gives the same colour.
            let again = s.sample(q);
            prop_assert!(got.iter().zip(&again).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}
