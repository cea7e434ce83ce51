//! "Error, but no panic": every loader on truncated and bit-flipped files
//! of each format returns a value or an error, never panics (fixed seeds).

use parvo::io::{self, Limits, OutputKind, SaveOptions};
use parvo::mip::{self, MipOptions, Rounding};
use parvo::texel::{ChannelType, ColorSpace, Format};

fn files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let base = parvo::builtin::load("builtin:zoneplate:24").unwrap();
    let f16 = base
        .convert(Format::new(4, ChannelType::F16, ColorSpace::Linear))
        .unwrap();
    let chain8 = mip::build(base.clone(), &MipOptions::default()).unwrap();
    let chain16 = mip::build(f16, &MipOptions::default()).unwrap();
    let mut out = Vec::new();
    for (name, kind, levels) in [
        ("a.exr", OutputKind::EXR, chain16.levels()),
        ("a.ktx2", OutputKind::KTX2, chain8.levels()),
        ("a.dds", OutputKind::DDS, chain8.levels()),
        ("a_{level}.png", OutputKind::PNG_LEVELS, chain8.levels()),
    ] {
        let p = dir.join(name);
        io::save(levels, Rounding::Down, &p, kind, &SaveOptions::default()).unwrap();
        out.push(if kind == OutputKind::PNG_LEVELS {
            io::png_levels::level_path(&p, 0)
        } else {
            p
        });
    }
    out
}

#[test]
fn corrupt_files_are_errors_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    let limits = Limits {
        max_alloc: 64 << 20,
        ..Limits::default()
    };
    let mut seed = 0x5eed_u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) as usize
    };
    let mut errors = 0;
    let mut cases = 0;
    for src in files(dir.path()) {
        let good = std::fs::read(&src).unwrap();
        assert!(io::load(src.to_str().unwrap(), &limits).is_ok());
        let bad = dir.path().join(format!(
            "bad.{}",
            src.extension().unwrap().to_string_lossy()
        ));
        for i in 0..60 {
            let mut b = good.clone();
            if i % 3 == 0 {
                b.truncate(next() % good.len());
            } else {
                for _ in 0..1 + i % 4 {
                    let at = next() % b.len();
                    b[at] ^= 1 << (next() % 8);
                }
            }
            std::fs::write(&bad, &b).unwrap();
            let r = std::panic::catch_unwind(|| io::load(bad.to_str().unwrap(), &limits));
            let r = r.unwrap_or_else(|_| panic!("{} case {i} panicked", src.display()));
            cases += 1;
            errors += usize::from(r.is_err());
        }
    }
    assert_eq!(cases, 240);
    assert!(errors > 60, "most corruptions must be detected ({errors})");
}
