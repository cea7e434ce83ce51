//! Normal and roughness chains of arbitrary normal maps: any size,
//! two to four channels, 8-bit, 16-bit, half or f32 texels of arbitrary
//! bits (zero vectors, NaN and infinite codes), every NaN policy and mip
//! filter, and a constant or mapped base roughness of arbitrary value.
//! Building either succeeds or refuses with an error, never panics; what
//! it builds has one level per chain size, unit normals, and roughness in
//! [0, 1] (finite exponents for Blinn-Phong).
//!
//! The body of `fuzz/fuzz_targets/normal_roughness.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/normal_roughness` and every kept artifact in the checks-on test build.

use parvo::mip::roughness::{self, BaseRoughness, NormalChannels, Specular};
use parvo::mip::{MipFilter, MipOptions, NanPolicy, normal};
use parvo::texel::{ChannelType, ColorSpace, Format, Texels};
use parvo::texture::Texture;

fn texture(w: u32, h: u32, ch: u8, ty: ChannelType, b: &[u8]) -> Option<Texture> {
    let n = (w * h * ch as u32) as usize;
    let f = Format::new(ch, ty, ColorSpace::Linear);
    let t = match ty {
        ChannelType::U8 => Texture::from_u8(w, h, f, b.get(..n)?.to_vec()),
        ChannelType::U16 => Texture::from_u16(
            w,
            h,
            f,
            b.get(..2 * n)?
                .chunks_exact(2)
                .map(|b| u16::from_le_bytes([b[0], b[1]]))
                .collect(),
        ),
        ChannelType::F16 => Texture::from_f16(
            w,
            h,
            f,
            b.get(..2 * n)?
                .chunks_exact(2)
                .map(|b| half::f16::from_le_bytes([b[0], b[1]]))
                .collect(),
        ),
        _ => Texture::from_f32(
            w,
            h,
            f,
            b.get(..4 * n)?
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        ),
    };
    t.ok()
}

/// One input of the `normal_roughness` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    if data.len() < 12 {
        return;
    }
    let (w, h) = (1 + data[0] as u32 % 17, 1 + data[1] as u32 % 17);
    let ch = 2 + data[2] % 3;
    let types = [
        ChannelType::U8,
        ChannelType::U16,
        ChannelType::F16,
        ChannelType::F32,
    ];
    let ty = types[data[3] as usize % 4];
    let options = MipOptions {
        filter: MipFilter::ALL[data[4] as usize % MipFilter::ALL.len()],
        nan_policy: [NanPolicy::Error, NanPolicy::Black, NanPolicy::Neighbors]
            [data[5] as usize % 3],
        ..MipOptions::default()
    };
    let base_value = f32::from_le_bytes([data[6], data[7], data[8], data[9]]);
    let mode = data[10];
    let Some(tex) = texture(w, h, ch, ty, &data[12..]) else {
        return;
    };
    let sizes = parvo::mip::level_sizes(w, h, options.rounding, options.max_levels);
    // The normal chain alone (three or four channels).
    if ch >= 3
        && let Ok(levels) = normal::build_levels(&tex, &options, &mut |_| {})
    {
        assert_eq!(levels.len(), sizes.len());
        for l in &levels {
            let Texels::F32(v) = l.texels() else {
                panic!("normal levels are f32")
            };
            for n in v.chunks_exact(ch as usize) {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-4, "|n| = {len}: {n:?}");
            }
        }
    }
    // Normal and roughness chains.
    let channels = if ch == 2 || mode & 1 == 1 {
        NormalChannels::Xy
    } else {
        NormalChannels::Xyz
    };
    let map = texture(w, h, 1, ChannelType::U8, &data[12..]);
    let base = match (mode >> 1) % 3 {
        0 => BaseRoughness::Constant(base_value),
        1 => match &map {
            Some(m) => BaseRoughness::Map(m),
            None => return,
        },
        _ => BaseRoughness::Constant(0.5),
    };
    let specular = if mode & 8 == 8 {
        Specular::BlinnPhong(base_value)
    } else {
        Specular::Roughness
    };
    let Ok(rc) = roughness::build(&tex, channels, base, specular, &options, &mut |_| {}) else {
        return;
    };
    assert_eq!(rc.normals.len(), sizes.len());
    assert_eq!(rc.specular.len(), sizes.len());
    for l in &rc.specular {
        let Texels::F32(v) = l.texels() else {
            panic!("specular levels are f32")
        };
        for &s in v {
            match specular {
                Specular::Roughness => assert!((0.0..=1.0).contains(&s), "roughness {s}"),
                Specular::BlinnPhong(_) => assert!(s.is_finite() && s >= 0.0, "exponent {s}"),
            }
        }
    }
}
