//! Issue 28: `TextureStore` cached its summed-area-table sampler under the
//! first caller's wrap modes and border colour, so a later `sat` sampler
//! with another wrap or border got the first one's addressing. The table
//! holds sums of the texels alone; only the addressing differs. Against a
//! `sat` sampler made directly with each option set, on a box that reaches
//! outside the texture (where wrap and border decide the result).

use parvo::sample::{Filter, Query, Sampler, SamplerOptions};
use parvo::store::TextureStore;
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipChain, MipOptions, Texture, Wrap, WrapMode};

#[test]
fn every_sat_sampler_of_a_store_uses_its_own_wrap_and_border() {
    let (w, h) = (13u32, 7u32);
    let data: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect();
    let tex = Texture::from_u8(
        w,
        h,
        Format::new(4, ChannelType::U8, ColorSpace::Linear),
        data,
    )
    .unwrap();
    let store = TextureStore::new(tex.clone(), MipOptions::default());
    let level0 = MipChain::from_levels(vec![tex], MipOptions::default()).unwrap();
    // A box over the top-left corner, half of it outside the texture.
    let q = Query::new(0.02, 0.03, 0.3, 0.0, 0.0, 0.4);
    let wraps = [
        (WrapMode::Repeat, [0.0; 4]),
        (WrapMode::ClampToBorder, [1.0, 0.0, 0.5, 1.0]),
        (WrapMode::ClampToEdge, [0.0; 4]),
        (WrapMode::MirroredRepeat, [0.0; 4]),
        (WrapMode::ClampToBorder, [0.0, 0.25, 0.0, 0.0]),
    ];
    let mut seen = Vec::new();
    for (mode, border) in wraps {
        let o = SamplerOptions {
            wrap: Wrap { u: mode, v: mode },
            border,
            ..SamplerOptions::preset(Filter::Sat, 1)
        };
        let got = store.sampler(o).unwrap().sample(&q);
        let want = Sampler::new(&level0, o).unwrap().sample(&q);
        assert_eq!(got, want, "{mode:?} border {border:?}");
        seen.push(got);
    }
    // The addressing changes the answer here, so the check above can fail.
    seen.sort_by(|a, b| a.partial_cmp(b).unwrap());
    seen.dedup();
    assert!(seen.len() >= 4, "{seen:?}");
}
