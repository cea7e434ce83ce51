//! Block decoding of arbitrary bytes (every format, arbitrary sizes) and
//! encoding of arbitrary texels (every encodable format, arbitrary sizes
//! with partial blocks): decode never panics on short or hostile data, and
//! what is encoded decodes to a level of the same size.
//!
//! The body of `fuzz/fuzz_targets/compress.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/compress` and every kept artifact in the checks-on test build.

use parvo::compress::{BlockFormat, Quality, decode, encode::encode, input_format, prepare};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use parvo::texture::Texture;

const FORMATS: [BlockFormat; 10] = [
    BlockFormat::Bc1,
    BlockFormat::Bc2,
    BlockFormat::Bc3,
    BlockFormat::Bc4 { signed: false },
    BlockFormat::Bc4 { signed: true },
    BlockFormat::Bc5 { signed: false },
    BlockFormat::Bc5 { signed: true },
    BlockFormat::Bc6h { signed: false },
    BlockFormat::Bc6h { signed: true },
    BlockFormat::Bc7,
];

/// One input of the `compress` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    if data.len() < 4 {
        return;
    }
    let f = FORMATS[data[0] as usize % FORMATS.len()];
    let (w, h) = (1 + data[1] as u32 % 40, 1 + data[2] as u32 % 40);
    let rest = &data[4..];
    // Decoding arbitrary blocks.
    if let Ok(t) = decode(f, data[3] & 1 == 1, AlphaMode::Straight, w, h, rest) {
        assert_eq!((t.width(), t.height()), (w, h));
    }
    // Encoding arbitrary RGBA8 texels (as many as the bytes give).
    if !parvo::compress::can_encode(f) {
        return;
    }
    let n = (w * h * 4) as usize;
    if rest.len() < n {
        return;
    }
    let src = Texture::from_u8(
        w,
        h,
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        rest[..n].to_vec(),
    )
    .expect("valid texture");
    let want = input_format(f, ColorSpace::Srgb, Some(AlphaMode::Straight));
    let input = prepare(&src, f, want).expect("prepare");
    let q = [Quality::Fast, Quality::Normal, Quality::Slow][data[3] as usize % 3];
    let blocks = encode(f, q, &input).expect("encode");
    assert_eq!(blocks.len() as u64, f.level_bytes(w, h));
    let d = decode(
        f,
        want.color_space == ColorSpace::Srgb,
        want.alpha,
        w,
        h,
        &blocks,
    )
    .expect("decode what was encoded");
    assert_eq!((d.width(), d.height()), (w, h));
}
