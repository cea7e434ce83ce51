//! Found in the issue 16 audit of allocations fed by headers: a KTX2 file
//! was held to `--max-alloc` by twice its own size, not by what decoding
//! allocates. A supercompressed level inflates to thousands of times its
//! bytes and a block-compressed one decodes to 4-16 times its blocks, so a
//! file of a few kilobytes decoded to any size below the width and height
//! limits. And a level's declared `uncompressedByteLength` was allocated
//! before it was compared with the level's size: a few bytes asked for a
//! terabyte. Now the decoded texels of every level, the file and the
//! inflated level are checked from the header first, and the declared
//! length must be the level's size before anything is inflated.

use parvo::compress::{BlockChain, BlockFormat};
use parvo::io::ktx2::{self, Supercompression};
use parvo::io::{Limits, SaveOptions};
use parvo::texel::AlphaMode;

fn zstd() -> SaveOptions {
    SaveOptions {
        ktx2: parvo::io::ktx2::Ktx2Options {
            supercompression: Some(Supercompression::Zstd(19)),
        },
        ..SaveOptions::default()
    }
}

/// A 4096² BC1 level of zero blocks: 8 MiB of blocks in a file of a few
/// hundred bytes, 64 MiB once decoded to RGBA8.
#[test]
fn a_supercompressed_bc1_level_is_held_to_max_alloc_by_its_decoded_size() {
    let chain = BlockChain {
        format: BlockFormat::Bc1,
        srgb: false,
        alpha: AlphaMode::None,
        width: 4096,
        height: 4096,
        levels: vec![vec![0u8; 4096 / 4 * 4096 / 4 * 8]],
    };
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bomb.ktx2");
    ktx2::save_blocks(&chain, &p, &zstd()).unwrap();
    let file = std::fs::metadata(&p).unwrap().len();
    assert!(file < 64 << 10, "the file is {file} bytes");
    let limits = |mib: u64| Limits {
        max_alloc: mib << 20,
        ..Limits::default()
    };
    let err = match ktx2::load(&p, &limits(32)) {
        Ok(l) => panic!(
            "decoded {}x{} texels under a 32 MiB limit",
            l.levels[0].width(),
            l.levels[0].height()
        ),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("limit exceeded"), "{err}");
    // 64 MiB of texels, the 8 MiB inflated level and the file fit in 80.
    let l = ktx2::load(&p, &limits(80)).unwrap();
    assert_eq!((l.levels[0].width(), l.levels[0].height()), (4096, 4096));
}

/// The level index's `uncompressedByteLength` of an 8x8 RGBA8 level
/// (256 bytes) patched to 1 TiB: refused as a bad file, with no limits at
/// all, before the length is allocated (zlib's output buffer of that
/// length aborted the process; zstd sizes its buffer from the frame).
#[test]
fn a_declared_uncompressed_length_is_checked_before_it_is_allocated() {
    let tex = parvo::builtin::load("builtin:checker:8").unwrap();
    for scheme in [Supercompression::Zlib(6), Supercompression::Zstd(3)] {
        let opts = SaveOptions {
            ktx2: parvo::io::ktx2::Ktx2Options {
                supercompression: Some(scheme),
            },
            ..SaveOptions::default()
        };
        let mut b = Vec::new();
        ktx2::write_to(std::slice::from_ref(&tex), &opts, &mut b).unwrap();
        // The level index follows the 80-byte header: byteOffset,
        // byteLength, uncompressedByteLength (u64 each) per level.
        assert_eq!(u64::from_le_bytes(b[96..104].try_into().unwrap()), 256);
        refuses_patched_lengths(&b, scheme);
    }
}

fn refuses_patched_lengths(b: &[u8], scheme: Supercompression) {
    for declared in [1u64 << 40, 255, 257] {
        let mut bad = b.to_vec();
        bad[96..104].copy_from_slice(&declared.to_le_bytes());
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.ktx2");
        std::fs::write(&p, &bad).unwrap();
        let err = match ktx2::load(&p, &Limits::none()) {
            Ok(_) => panic!("{scheme:?}: a declared length of {declared} was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            err.contains(&format!("declares {declared} bytes uncompressed")),
            "{scheme:?}: {err}"
        );
    }
}
