//! Issue 27, finding 11: batch ergonomics. An `--out-dir` that did not
//! exist was an error (it is made); a directory given as input was refused
//! (its images are the inputs); the summary line under `--update` and
//! `--dry-run` named a BC7 output "RGB u8 srgb" (the encoder's input, not
//! what the file holds); `--resize-to multiple-of-4` still warned that
//! WebGL refuses level 1 (WebGL's rule since revision 6 of
//! WEBGL_compressed_texture_s3tc: `width << level` a multiple of 4, which
//! every level of a multiple-of-4 level 0 meets).

use super::util::{ok, parvo, s};

fn photo(path: &std::path::Path, w: u32, h: u32) {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb([(x * 7) as u8, (y * 5) as u8, 90]))
        .save(path)
        .unwrap();
}

#[test]
fn a_missing_out_dir_is_made_and_a_directory_input_is_its_images() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    photo(&src.join("b.png"), 20, 12);
    photo(&src.join("a.PNG"), 16, 16);
    std::fs::write(src.join("notes.txt"), "not an image").unwrap();
    std::fs::create_dir(src.join("sub")).unwrap();
    photo(&src.join("sub/c.png"), 8, 8);
    let out = dir.path().join("new/deeper");
    let o = parvo(&["mip", s(&src), "--out-dir", s(&out), "--ext", "ktx2"]);
    let stdout = ok(&o);
    assert!(
        out.join("a.ktx2").is_file() && out.join("b.ktx2").is_file(),
        "{stdout}"
    );
    // Not the text file, not the subdirectory's image.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
    // A dry run makes nothing.
    let dry = dir.path().join("dry");
    ok(&parvo(&["mip", s(&src), "--out-dir", s(&dry), "--dry-run"]));
    assert!(!dry.exists());
    // A directory without images is a usage error that says so.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let o = parvo(&["mip", s(&empty), "--out-dir", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds no image"));
}

#[test]
fn up_to_date_and_dry_run_name_the_block_format_stored() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("p.png");
    photo(&input, 32, 32);
    let out = dir.path().join("o");
    let args = [
        "mip",
        s(&input),
        "--out-dir",
        s(&out),
        "--ext",
        "ktx2",
        "--compress",
        "bc7",
    ];
    let first = ok(&parvo(&args));
    assert!(first.contains("BC7_SRGB"), "{first}");
    for extra in ["--update", "--dry-run"] {
        let mut a = args.to_vec();
        a.push(extra);
        let line = ok(&parvo(&a));
        assert!(line.contains("BC7_SRGB"), "{extra}: {line}");
        assert!(!line.contains("u8"), "{extra}: {line}");
    }
}

#[test]
fn multiple_of_4_level_0_is_not_warned_about_webgl() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("p.png");
    // 1001x998: level 0 becomes 1004x1000, level 1 502x500.
    photo(&input, 1001, 998);
    let o = parvo(&[
        "mip",
        s(&input),
        "-o",
        s(&dir.path().join("o.dds")),
        "--compress",
        "bc1",
        "--resize-to",
        "multiple-of-4",
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("WebGL"), "{err}");
    // Without the resize, level 0 itself is not whole blocks: said.
    let o = parvo(&[
        "mip",
        s(&input),
        "-o",
        s(&dir.path().join("p.dds")),
        "--compress",
        "bc1",
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("WebGL") && err.contains("level 0"), "{err}");
}
