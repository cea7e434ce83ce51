//! Found by the peer corpus (issue 27): image-tiff's
//! `extra_bits_rgb_8b.tiff`, RGB plus one sample that `ExtraSamples` 0
//! declares data, lost its fourth channel (the `tiff` crate returns RGB
//! without a sample it does not take for alpha); OpenImageIO and
//! image-tiff read four channels. The README says ExtraSamples 0 is data.

use super::util::{RawIfd, Rng, parvo, s, write_raw_tiff};

#[test]
fn rgb_with_a_data_sample_reads_four_channels_of_data() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rgbx.tif");
    let (w, h) = (13u32, 7u32);
    let mut rng = Rng(0x7ee5);
    let px: Vec<u8> = (0..w * h * 4).map(|_| rng.next() as u8).collect();
    write_raw_tiff(
        &path,
        &[RawIfd {
            entries: vec![
                (256, 4, vec![w]),
                (257, 4, vec![h]),
                (258, 3, vec![8, 8, 8, 8]),
                (262, 3, vec![2]),
                (277, 3, vec![4]),
                (278, 4, vec![h]),
                (338, 3, vec![0]),
            ],
            chunks: vec![px.clone()],
            tiled: false,
        }],
        None,
    );
    let loaded = parvo::io::load(s(&path), &Default::default()).unwrap();
    let t = loaded.base();
    let f = t.format();
    assert_eq!(f.channels, 4, "{f}");
    assert!(!f.has_alpha(), "the fourth channel is data: {f}");
    let parvo::Texels::U8(v) = t.texels() else {
        panic!("u8 expected, got {f}");
    };
    assert_eq!(v, &px);
    // The CLI says nothing about a channel not read.
    let o = parvo(&["info", s(&path)]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("not read"));
}
