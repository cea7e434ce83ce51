//! Arbitrary bytes as each input format parvo reads (the first byte picks
//! it) → load under tight limits → mips → every output container written
//! to a temporary directory. Any outcome but a panic is fine: errors are
//! the expected answer to most inputs.
#![no_main]

use libfuzzer_sys::fuzz_target;
use parvo::io::{self, Limits, OutputKind, SaveOptions};
use parvo::mip::{self, MipOptions, Rounding};
use parvo::texel::{ChannelType, ColorSpace, Format};

const EXTS: [&str; 7] = ["png", "jpg", "tif", "hdr", "exr", "ktx2", "dds"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir
        .path()
        .join(format!("in.{}", EXTS[pick as usize % EXTS.len()]));
    std::fs::write(&path, bytes).expect("write input");
    let limits = Limits {
        max_width: 512,
        max_height: 512,
        max_alloc: 16 << 20,
    };
    let Ok(loaded) = io::load(path.to_str().expect("utf-8 path"), &limits) else {
        return;
    };
    let base = loaded.into_base();
    let Ok(chain) = mip::build(base, &MipOptions::default()) else {
        return;
    };
    let levels = chain.into_levels();
    let f = levels[0].format();
    let opts = SaveOptions::default();
    for (kind, name) in [
        (OutputKind::KTX2, "o.ktx2"),
        (OutputKind::DDS, "o.dds"),
        (OutputKind::PNG_LEVELS, "o_{level}.png"),
        (OutputKind::EXR, "o.exr"),
    ] {
        let out_f = match kind {
            OutputKind::EXR => Format::new(f.channels, ChannelType::F16, ColorSpace::Linear),
            OutputKind::PNG_LEVELS if f.channel_type.is_float() => {
                Format::new(f.channels, ChannelType::U16, ColorSpace::Linear)
            }
            OutputKind::KTX2 => io::ktx2::storable(f),
            OutputKind::DDS => io::dds::storable(f),
            _ => f,
        };
        let conv: Vec<_> = levels
            .iter()
            .filter_map(|l| l.convert(out_f.with_alpha(f.alpha)).ok())
            .collect();
        if conv.len() == levels.len() {
            let _ = io::save(&conv, Rounding::Down, &dir.path().join(name), kind, &opts);
        }
    }
});
