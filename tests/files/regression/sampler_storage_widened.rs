//! Issue 28 ("parvo inside a rasterizer"): memory grew on sampling. The
//! sampler's prepared chain widened every texel: a grey `u8` 512² chain
//! (349,525 stored bytes) became 1,404,244 bytes (RGBA8 plus the decode
//! table), an RGB `f16` 512² chain (2,097,150 bytes) became 5,592,400
//! (RGBA `f32`). The prepared chain must stay within 1.1× the stored bytes.

use parvo::mip::{self, MipOptions};
use parvo::sample::{Sampler, SamplerOptions};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::texture::Texture;

/// A 512² chain of `format` (a smooth ramp; the values do not matter here).
fn chain(format: Format) -> mip::MipChain {
    let n = 512u32;
    let ch = format.channels as usize;
    let lin: Vec<f32> = (0..(n * n) as usize * ch)
        .map(|i| ((i / ch) % n as usize) as f32 / n as f32)
        .collect();
    let t = Texture::from_linear(n, n, format, &lin).unwrap();
    mip::build(t, &MipOptions::default()).unwrap()
}

#[test]
fn grey_u8_and_rgb_f16_chains_are_not_widened_for_sampling() {
    for (format, stored_in_issue) in [
        (Format::new(1, ChannelType::U8, ColorSpace::Srgb), 349_525),
        (
            Format::new(3, ChannelType::F16, ColorSpace::Linear),
            2_097_150,
        ),
    ] {
        let c = chain(format);
        let stored: usize = c.levels().iter().map(|t| t.byte_len()).sum();
        assert_eq!(stored, stored_in_issue, "{format}");
        let s = Sampler::new(&c, SamplerOptions::trilinear()).unwrap();
        let prepared = s.chain().memory_bytes();
        assert!(
            prepared as f64 <= 1.1 * stored as f64,
            "{format}: {stored} stored bytes became {prepared} prepared"
        );
    }
}
