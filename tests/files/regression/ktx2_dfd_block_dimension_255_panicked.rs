//! Found by the `decode_and_mip` fuzz target: a KTX2 file whose DFD gives
//! a texel block dimension byte of 255 made the `ktx2` crate's reader
//! panic (`NonZeroU8::new(255 + 1).unwrap()`), so `parvo info` and every
//! loader aborted instead of reporting a bad file.

use parvo::io::{Limits, SaveOptions, ktx2};

#[test]
fn a_dfd_block_dimension_of_255_is_an_error_not_a_panic() {
    let tex = parvo::builtin::load("builtin:checker:8").unwrap();
    let mut b = Vec::new();
    ktx2::write_to(&[tex], &SaveOptions::default(), &mut b).unwrap();
    let dfd = u32::from_le_bytes(b[48..52].try_into().unwrap()) as usize;
    // Total size word, vendor/type, version/size, model/.../flags, then
    // the four texel block dimension bytes.
    for i in 0..4 {
        let mut bad = b.clone();
        bad[dfd + 16 + i] = 255;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.ktx2");
        std::fs::write(&p, &bad).unwrap();
        let err = match ktx2::load(&p, &Limits::default()) {
            Ok(_) => panic!("byte {i}: a block dimension of 256 was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains("texel block dimension"), "{err}");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
            .arg("info")
            .arg(&p)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1));
        assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"));
    }
}
