//! Peer corpus: Pillow's `exif_imagemagick_orientation.png` keeps EXIF
//! orientation 3 where ImageMagick puts EXIF in a PNG: a `Raw profile type
//! exif` text chunk (tEXt, zTXt or iTXt) whose text is `\nexif\n<length>\n`
//! and the block in hex. OpenImageIO reports it and Pillow applies it;
//! parvo, which applies the `eXIf` chunk's orientation, ignored this form
//! without a word. It is now read like `eXIf` (the same note, the same
//! `--no-auto-orient`), and when both are present `eXIf` decides, as in
//! OpenImageIO, which reads it last.

use std::path::Path;

use super::util::{ok, parvo, png_u16, s};
use parvo::io::{Limits, LoadOptions, load, load_with};
use parvo::texel::Texels;

/// An EXIF block (TIFF header, one IFD) holding one Orientation tag, in
/// the byte order `big` says.
fn exif(orientation: u16, big: bool) -> Vec<u8> {
    let u16b = |v: u16| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let u32b = |v: u32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let mut b = if big {
        b"MM\0*".to_vec()
    } else {
        b"II*\0".to_vec()
    };
    b.extend(u32b(8));
    b.extend(u16b(1));
    b.extend(u16b(0x0112));
    b.extend(u16b(3));
    b.extend(u32b(1));
    b.extend(u16b(orientation));
    b.extend([0, 0]);
    b.extend(u32b(0));
    b
}

/// ImageMagick's text for an EXIF block: the `Exif\0\0` marker, the
/// length, and lower-case hex in lines of 72 digits (as its `png.c`
/// writes raw profiles).
fn raw_profile(block: &[u8]) -> String {
    let mut data = b"Exif\0\0".to_vec();
    data.extend_from_slice(block);
    let hex: String = data.iter().map(|b| format!("{b:02x}")).collect();
    let lines: Vec<&str> = hex
        .as_bytes()
        .chunks(72)
        .map(|c| std::str::from_utf8(c).unwrap())
        .collect();
    format!("\nexif\n{:8}\n{}\n", data.len(), lines.join("\n"))
}

const W: u32 = 5;
const H: u32 = 3;

/// Stored texel values: 1..=15, row-major, so every texel is told apart.
fn stored() -> Vec<u8> {
    (1..=(W * H) as u8).map(|v| v * 16).collect()
}

enum Text {
    Plain,
    Compressed,
    International,
}

fn write_png(path: &Path, text: Option<(Text, String)>, exif_chunk: Option<Vec<u8>>) {
    let mut info = png::Info::with_size(W, H);
    info.color_type = png::ColorType::Grayscale;
    info.bit_depth = png::BitDepth::Eight;
    info.exif_metadata = exif_chunk.map(Into::into);
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::with_info(std::io::BufWriter::new(file), info).unwrap();
    let key = "Raw profile type exif".to_string();
    match text {
        Some((Text::Plain, t)) => enc.add_text_chunk(key, t).unwrap(),
        Some((Text::Compressed, t)) => enc.add_ztxt_chunk(key, t).unwrap(),
        Some((Text::International, t)) => enc.add_itxt_chunk(key, t).unwrap(),
        None => {}
    }
    let mut w = enc.write_header().unwrap();
    w.write_image_data(&stored()).unwrap();
}

/// The stored grey texels turned by EXIF orientation `code`, computed
/// from the orientation's definition (where the stored row 0 and column 0
/// go), with the displayed size.
fn turned(code: u16) -> ((u32, u32), Vec<u8>) {
    let v = stored();
    let (w, h) = (W as usize, H as usize);
    let at = |x: usize, y: usize| v[y * w + x];
    match code {
        // 180°: displayed (x, y) is stored (w-1-x, h-1-y).
        3 => (
            (W, H),
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| at(w - 1 - x, h - 1 - y))
                .collect(),
        ),
        // 90° clockwise for display: the stored left column becomes the
        // top row, read bottom to top.
        6 => (
            (H, W),
            (0..w)
                .flat_map(|y| (0..h).map(move |x| (x, y)))
                .map(|(x, y)| at(y, h - 1 - x))
                .collect(),
        ),
        _ => ((W, H), v),
    }
}

fn grey(t: &parvo::texture::Texture) -> Vec<u8> {
    match t.texels() {
        Texels::U8(v) => v.clone(),
        other => panic!("8-bit grey expected, not {other:?}"),
    }
}

#[test]
fn every_text_chunk_form_and_byte_order_is_applied() {
    let dir = tempfile::tempdir().unwrap();
    for (k, (form, big)) in [
        (Text::Plain, true),
        (Text::Compressed, false),
        (Text::International, true),
    ]
    .into_iter()
    .enumerate()
    {
        let p = dir.path().join(format!("t{k}.png"));
        write_png(&p, Some((form, raw_profile(&exif(6, big)))), None);
        let l = load(s(&p), &Limits::default()).unwrap();
        let ((w, h), want) = turned(6);
        assert_eq!((l.base().width(), l.base().height()), (w, h), "form {k}");
        assert_eq!(grey(l.base()), want, "form {k}");
        assert_eq!(l.info.attribute("Orientation"), Some("6"));
        assert!(
            l.info
                .notes
                .iter()
                .any(|n| n.contains("EXIF orientation 6 applied")),
            "{:?}",
            l.info.notes
        );
        let kept = load_with(
            s(&p),
            &Limits::default(),
            &LoadOptions {
                auto_orient: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(grey(kept.base()), stored(), "--no-auto-orient, form {k}");
    }
}

#[test]
fn exif_chunk_decides_over_the_text_form() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("both.png");
    write_png(
        &p,
        Some((Text::Plain, raw_profile(&exif(6, false)))),
        Some(exif(3, false)),
    );
    let l = load(s(&p), &Limits::default()).unwrap();
    let ((w, h), want) = turned(3);
    assert_eq!((l.base().width(), l.base().height()), (w, h));
    assert_eq!(grey(l.base()), want);
}

#[test]
fn a_text_that_is_not_exif_is_said_and_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.png");
    write_png(
        &p,
        Some((Text::Plain, "\nexif\n      12\nnot hex at all\n".into())),
        None,
    );
    let l = load(s(&p), &Limits::default()).unwrap();
    assert_eq!(grey(l.base()), stored());
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("Raw profile type exif")),
        "{:?}",
        l.info.notes
    );
}

/// The peer file: its stored texels as the `png` crate decodes them
/// (nothing turned), against `parvo mip`'s level 0 turned 180° with the
/// note on stderr, and kept as stored with `--no-auto-orient`.
#[test]
fn pillow_imagemagick_file_is_turned_180_degrees() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer/pillow/exif_imagemagick_orientation.png");
    let mut r = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()))
        .read_info()
        .unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let frame = r.next_frame(&mut buf).unwrap();
    assert_eq!(frame.color_type, png::ColorType::Rgb);
    assert_eq!(frame.bit_depth, png::BitDepth::Eight);
    let (w, h) = (frame.width as usize, frame.height as usize);
    let px = |x: usize, y: usize| &buf[(y * w + x) * 3..(y * w + x) * 3 + 3];
    let want: Vec<u16> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| px(w - 1 - x, h - 1 - y).to_vec())
        .map(|v| v as u16 * 257)
        .collect();
    let stored: Vec<u16> = buf[..w * h * 3].iter().map(|&v| v as u16 * 257).collect();
    assert_ne!(want, stored, "the picture is not symmetric under 180°");

    let dir = tempfile::tempdir().unwrap();
    let tpl = dir.path().join("l_{level}.png");
    let out = parvo(&["mip", s(&path), "-o", s(&tpl)]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("EXIF orientation 3 applied"), "{err}");
    let (lw, lh, ch, v) = png_u16(&dir.path().join("l_0.png"));
    assert_eq!((lw as usize, lh as usize, ch), (w, h, 3));
    assert!(v == want, "level 0 is not the stored picture turned 180°");

    let keep = dir.path().join("k_{level}.png");
    let out = parvo(&["mip", s(&path), "--no-auto-orient", "-o", s(&keep)]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("EXIF orientation 3 not applied"));
    let (_, _, _, v) = png_u16(&dir.path().join("k_0.png"));
    assert!(
        v == stored,
        "--no-auto-orient: level 0 is not the stored picture"
    );
}
