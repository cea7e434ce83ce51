//! Issue 18 #5: 257×129 with `--rounding up` to `.ktx2` exited 0 with
//! level 1 stored as 129×65 where KTX2 defines 128×64 (parvo could not
//! read its own file back); to `.dds` it failed with an internal-sounding
//! "ddsfile expects … bytes". Both containers fix their level sizes, so
//! the option is refused before any work, as a usage error.

use super::util::{parvo, s};

#[test]
fn rounding_up_is_refused_for_ktx2_and_dds_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["o.ktx2", "o.dds"] {
        let out = dir.path().join(name);
        let r = parvo(&[
            "mip",
            "builtin:checker:257",
            "-o",
            s(&out),
            "--rounding",
            "up",
        ]);
        assert_eq!(r.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains("floor(size / 2^k)"), "{name}: {err}");
        assert!(!out.exists(), "{name}");
    }
    // EXR has a rounding mode of its own and takes it.
    let out = dir.path().join("o.exr");
    let r = parvo(&[
        "mip",
        "builtin:checker:257",
        "-o",
        s(&out),
        "--rounding",
        "up",
    ]);
    assert!(r.status.success());
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert_eq!((l.levels[1].width(), l.levels[1].height()), (129, 129));
}
