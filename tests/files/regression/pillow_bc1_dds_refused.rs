//! Issue 27 #7: Pillow's `Tests/images/bc1.dds` and `bc1_typeless.dds` were
//! refused ("resource dimension 0 is not a 2-D texture"). Their DX10
//! headers leave the resource dimension and array size at 0; Pillow reads
//! both (and OpenImageIO 3.2 reads `bc1.dds`) from the header's width and
//! height. `bc1_typeless.dds` is `bc1.dds` with DXGI format 70
//! (`BC1_TYPELESS`) in place of 71 (`BC1_UNORM`), as Pillow made it ("hex
//! edited"); typeless formats are read as UNORM, as Pillow reads them
//! (OpenImageIO 3.2.2 refuses this one: "Unsupported DXGI format: 70"), and
//! said so.
//!
//! The reference is Pillow's own decode of the file, the PNG its test
//! compares with (read here with the `image` crate). BC1's interpolated
//! colours may round either way: Pillow and OpenImageIO 3.2.2 differ by up
//! to 2 codes on this file, parvo by at most 1 from each, so 1 code is the
//! tolerance.

use std::path::{Path, PathBuf};

use parvo::io::{self, Limits};

use super::util::{parvo, s};

fn peer(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer")
        .join(name)
}

#[test]
fn pillow_bc1_dds_with_resource_dimension_0_reads_as_pillow_decodes_it() {
    let bc1 = std::fs::read(peer("pillow_bc1.dds")).unwrap();
    // The header as Pillow ships it: fourCC DX10, DXGI 71, dimension 0,
    // array size 0.
    let word = |b: &[u8], i: usize| u32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap());
    assert_eq!(&bc1[84..88], b"DX10");
    assert_eq!((word(&bc1, 32), word(&bc1, 33), word(&bc1, 35)), (71, 0, 0));
    let mut typeless = bc1.clone();
    typeless[128..132].copy_from_slice(&70u32.to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    let p_typeless = dir.path().join("bc1_typeless.dds");
    std::fs::write(&p_typeless, &typeless).unwrap();

    let reference = image::open(peer("pillow_dxt1-rgb-4bbp-noalpha_MipMaps-1.png"))
        .unwrap()
        .to_rgba8();
    for (path, typeless) in [(peer("pillow_bc1.dds"), false), (p_typeless, true)] {
        let l = io::load(s(&path), &Limits::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let t = &l.levels[0];
        assert_eq!((t.width(), t.height()), (256, 256));
        assert_eq!(t.format().channels, 4);
        let parvo::Texels::U8(v) = t.texels() else {
            panic!("BC1 decodes to u8");
        };
        let mut worst = 0i32;
        for (i, px) in reference.pixels().enumerate() {
            for c in 0..4 {
                worst = worst.max((v[4 * i + c] as i32 - px[c] as i32).abs());
            }
        }
        assert!(worst <= 1, "{}: off by {worst} codes", path.display());
        // Typeless is read as UNORM, and the note says so.
        let said = l.info.notes.iter().any(|n| n.contains("BC1_TYPELESS"));
        assert_eq!(said, typeless, "{:?}", l.info.notes);
        if typeless {
            assert!(l.info.notes.iter().any(|n| n.contains("BC1_UNORM")));
        }
        // And from the command line.
        let r = parvo(&["info", s(&path)]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
}

#[test]
fn other_resource_dimensions_are_named() {
    // Dimension 4 (3-D) and 1 (buffer) are refused in words; 2 (1-D) with
    // a height of 1 is a row of texels.
    let bc1 = std::fs::read(peer("pillow_bc1.dds")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (dim, want) in [
        (4u32, Some("volume (3-D) textures are not supported")),
        (1, Some("a buffer, not a texture")),
        (9, Some("resource dimension is 9")),
        (2, Some("1-D texture, but the height is 256")),
        (3, None),
    ] {
        let mut b = bc1.clone();
        b[132..136].copy_from_slice(&dim.to_le_bytes());
        let p = dir.path().join(format!("d{dim}.dds"));
        std::fs::write(&p, &b).unwrap();
        match (io::load(s(&p), &Limits::default()), want) {
            (Err(e), Some(w)) => assert!(e.to_string().contains(w), "{dim}: {e}"),
            (Ok(_), None) => {}
            (r, w) => panic!("dimension {dim}: {:?} (wanted {w:?})", r.map(|_| ())),
        }
    }
}
