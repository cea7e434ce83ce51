//! Integer tables at the extremes of SPEC's bit rule: exactly full, one
//! size too big (refused, never wrapped), and the automatic choice.

use parvo::sat::{self, AccumulatorKind, Rect, SummedAreaTable};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{Error, Texture, Wrap};

fn grey(ty: ChannelType) -> Format {
    Format::new(1, ty, ColorSpace::Linear)
}

fn all_max_u8(w: u32, h: u32) -> Texture {
    Texture::from_u8(w, h, grey(ChannelType::U8), vec![255; (w * h) as usize]).unwrap()
}

fn all_max_u16(w: u32, h: u32) -> Texture {
    Texture::from_u16(w, h, grey(ChannelType::U16), vec![65535; (w * h) as usize]).unwrap()
}

#[test]
fn u32_table_is_exact_for_8bit_4096_squared() {
    let tex = all_max_u8(4096, 4096);
    assert_eq!(sat::choose(&tex.format(), 4096, 4096), AccumulatorKind::U32);
    let t = SummedAreaTable::<u32>::build(&tex).unwrap();
    // 255·4096² = 4 278 190 080 < 2³²: the far corner holds it exactly.
    assert_eq!(t.raw_sum(0, 0, 4096, 4096)[0], 4_278_190_080);
    assert_eq!(*t.entries().last().unwrap(), 4_278_190_080);
    assert_eq!(t.raw_sum(4095, 4095, 4096, 4096)[0], 255);
    assert_eq!(t.raw_sum(4000, 4090, 4096, 4096)[0], 255 * 96 * 6);
    let avg = t.average(
        Rect::texels(4093, 4093, 4096, 4096),
        Wrap::default(),
        [0.0; 4],
    );
    assert_eq!(avg[0], 1.0);
    assert_eq!(t.memory_bytes(), 4097 * 4097 * 4);
}

#[test]
fn u32_request_for_8bit_8192_squared_is_refused() {
    let tex = all_max_u8(8192, 8192);
    let err = SummedAreaTable::<u32>::build(&tex).unwrap_err();
    assert!(matches!(err, Error::InvalidOption(_)), "{err}");
    assert!(err.to_string().contains("34 bits"), "{err}");
    assert!(sat::build(&tex, Some(AccumulatorKind::U32)).is_err());
}

#[test]
fn u64_is_chosen_and_exact_for_8bit_8192_squared() {
    let tex = all_max_u8(8192, 8192);
    assert_eq!(sat::choose(&tex.format(), 8192, 8192), AccumulatorKind::U64);
    let t = sat::build(&tex, None).unwrap();
    assert_eq!(t.kind(), AccumulatorKind::U64);
    let sat::AnySat::U64(t) = t else {
        unreachable!()
    };
    assert_eq!(t.raw_sum(0, 0, 8192, 8192)[0], 255 * 8192 * 8192);
    assert_eq!(t.raw_sum(8191, 8191, 8192, 8192)[0], 255);
}

#[test]
fn u64_table_is_exact_for_16bit_4096_squared() {
    let tex = all_max_u16(4096, 4096);
    assert_eq!(sat::choose(&tex.format(), 4096, 4096), AccumulatorKind::U64);
    assert!(SummedAreaTable::<u32>::build(&tex).is_err());
    let t = SummedAreaTable::<u64>::build(&tex).unwrap();
    assert_eq!(t.raw_sum(0, 0, 4096, 4096)[0], 65535 * 4096 * 4096);
    assert_eq!(t.raw_sum(4095, 4095, 4096, 4096)[0], 65535);
    let s = t.sum_box(Rect::texels(4094, 4095, 4096, 4096), Wrap::default());
    assert_eq!(s.sum[0], 2.0 * 65535.0);
    assert_eq!(s.error, 0.0);
}

#[test]
fn u64_table_is_exact_for_16bit_65536_by_256() {
    let tex = all_max_u16(65536, 256);
    assert_eq!(sat::choose(&tex.format(), 65536, 256), AccumulatorKind::U64);
    assert!(SummedAreaTable::<u32>::build(&tex).is_err());
    let t = SummedAreaTable::<u64>::build(&tex).unwrap();
    assert_eq!(t.raw_sum(0, 0, 65536, 256)[0], 65535 * 65536 * 256);
    assert_eq!(t.raw_sum(65535, 255, 65536, 256)[0], 65535);
    assert_eq!(t.raw_sum(1, 1, 65535, 255)[0], 65535 * 65534 * 254);
}

#[test]
fn straight_alpha_doubles_the_value_bits() {
    // colour × alpha products: 8-bit RGBA straight needs 16 + log2(w·h).
    let f = Format::new(4, ChannelType::U8, ColorSpace::Linear);
    assert_eq!(sat::value_bits(&f), 16);
    assert_eq!(sat::choose(&f, 256, 256), AccumulatorKind::U32);
    assert_eq!(sat::choose(&f, 256, 257), AccumulatorKind::U64);
    let tex = Texture::from_u8(256, 257, f, vec![255; 256 * 257 * 4]).unwrap();
    assert!(SummedAreaTable::<u32>::build(&tex).is_err());
    let t = SummedAreaTable::<u64>::build(&tex).unwrap();
    assert_eq!(
        t.raw_sum(0, 0, 256, 257),
        [
            255 * 255 * 256 * 257,
            255 * 255 * 256 * 257,
            255 * 255 * 256 * 257,
            255 * 256 * 257
        ]
    );
}

#[test]
fn integer_tables_refuse_srgb_and_float_data() {
    let srgb = Texture::from_u8(
        4,
        4,
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        vec![9; 48],
    )
    .unwrap();
    assert!(SummedAreaTable::<u64>::build(&srgb).is_err());
    assert_eq!(
        sat::build(&srgb, None).unwrap().kind(),
        AccumulatorKind::F64
    );
    let fl = Texture::from_f32(2, 2, grey(ChannelType::F32), vec![0.5; 4]).unwrap();
    assert!(SummedAreaTable::<u64>::build(&fl).is_err());
    assert_eq!(sat::build(&fl, None).unwrap().kind(), AccumulatorKind::F64);
}

#[test]
fn float_tables_refuse_non_finite_input_and_f32_overflow() {
    let f = grey(ChannelType::F32);
    let nan = Texture::from_f32(3, 2, f, vec![0.0, 1.0, 2.0, f32::NAN, 0.0, 0.0]).unwrap();
    let err = sat::build(&nan, None).unwrap_err();
    assert!(
        matches!(
            err,
            Error::NonFinite {
                x: 0,
                y: 1,
                channel: 0,
                ..
            }
        ),
        "{err}"
    );
    let big = Texture::from_f32(2, 2, f, vec![3e38; 4]).unwrap();
    assert!(SummedAreaTable::<f32>::build(&big).is_err());
    // f64 holds it: no infinity, no NaN.
    let t = SummedAreaTable::<f64>::build(&big).unwrap();
    let avg = t.average(Rect::texels(0, 0, 2, 2), Wrap::default(), [0.0; 4]);
    assert_eq!(avg[0], 3e38);
}

#[test]
fn u128_tables_work_when_asked_for() {
    let tex = all_max_u16(300, 7);
    let t = SummedAreaTable::<u128>::build(&tex).unwrap();
    assert_eq!(t.raw_sum(0, 0, 300, 7)[0], 65535 * 2100);
    assert_eq!(t.memory_bytes(), 301 * 8 * 16);
}
