//! Fuzzing (`fuzz/fuzz_targets/normal_roughness.rs`) found a roughness
//! chain holding −0.0124: the base roughness map's chain is filtered like
//! colour, and at a sharp edge the negative lobes of Kaiser (also Lanczos
//! and Mitchell) ring below 0 and above 1; where the normals are flat the
//! adjusted roughness is that filtered value as it is. Every filter, a
//! map of hard 0/1 stripes under flat normals: every level stays in [0, 1].

use parvo::Texture;
use parvo::mip::roughness::{self, BaseRoughness, NormalChannels, Specular};
use parvo::mip::{MipFilter, MipOptions};
use parvo::texel::{ChannelType, ColorSpace, Format, Texels};

#[test]
fn roughness_from_a_ringing_map_stays_in_0_1() {
    let (w, h) = (37u32, 18u32);
    // Flat normals (+Z as unorm codes 128, 128, 255).
    let normals = Texture::from_u8(
        w,
        h,
        Format::new(3, ChannelType::U8, ColorSpace::Linear),
        (0..w * h).flat_map(|_| [128u8, 128, 255]).collect(),
    )
    .unwrap();
    // Stripes of 0 and 255, three texels wide: edges every few texels.
    let map = Texture::from_u8(
        w,
        h,
        Format::new(1, ChannelType::U8, ColorSpace::Linear),
        (0..w * h)
            .map(|i| {
                if (i % w / 3 + i / w / 4) % 2 == 0 {
                    0
                } else {
                    255
                }
            })
            .collect(),
    )
    .unwrap();
    let mut worst = (f32::MAX, f32::MIN);
    for filter in MipFilter::ALL {
        let options = MipOptions {
            filter,
            ..MipOptions::default()
        };
        let rc = roughness::build(
            &normals,
            NormalChannels::Xyz,
            BaseRoughness::Map(&map),
            Specular::Roughness,
            &options,
            &mut |_| {},
        )
        .unwrap();
        for (k, l) in rc.specular.iter().enumerate() {
            let Texels::F32(v) = l.texels() else {
                panic!("specular levels are f32")
            };
            for &a in v {
                worst = (worst.0.min(a), worst.1.max(a));
                assert!(
                    (0.0..=1.0).contains(&a),
                    "{filter:?} level {k}: roughness {a}"
                );
            }
        }
    }
    // The stripes do reach both ends (the test checks something).
    assert!(worst.0 < 0.05 && worst.1 > 0.95, "{worst:?}");
}
