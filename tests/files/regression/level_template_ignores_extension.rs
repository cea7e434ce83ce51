//! Issue 18, smaller points: `-o 'lv_{level}.exr'` silently wrote PNG files
//! named `.exr`; and re-running into `NAME_{level}.png` with a shorter
//! chain left the higher levels of the earlier run behind.

use super::util::{ok, parvo, s};

#[test]
fn a_level_template_must_name_png() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["lv_{level}.exr", "lv_{level}.ktx2", "lv_{level}"] {
        let r = parvo(&["mip", "builtin:checker:8", "-o", s(&dir.path().join(name))]);
        assert_eq!(r.status.code(), Some(2), "{name}");
        assert!(
            String::from_utf8_lossy(&r.stderr).contains("must end in .png"),
            "{name}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_shorter_rerun_removes_the_stale_levels_parvo_wrote_and_only_those() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lv_{level}.png");
    ok(&parvo(&["mip", "builtin:checker:64", "-o", s(&out)])); // 7 levels
    assert!(dir.path().join("lv_6.png").exists());
    // Someone else's file at a level name past the new chain.
    image::save_buffer(
        dir.path().join("lv_5.png"),
        &[1, 2, 3],
        1,
        1,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let r = parvo(&["mip", "builtin:checker:64", "-o", s(&out), "--levels", "3"]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    for k in 0..3 {
        assert!(dir.path().join(format!("lv_{k}.png")).exists());
    }
    for k in [3, 4, 6] {
        assert!(
            !dir.path().join(format!("lv_{k}.png")).exists(),
            "level {k} stale"
        );
    }
    assert!(dir.path().join("lv_5.png").exists(), "not parvo's: kept");
    assert!(err.contains("removed 3 stale level file(s)"), "{err}");
    assert!(err.contains("left alone (not written by parvo)"), "{err}");
}
