//! Issue 27, finding 10: a file that says nothing about its colour
//! encoding (a PNG without colour chunks, e.g. a 16-bit grey height map) is
//! read as sRGB, as OpenImageIO reads it — but only BC4 output said so:
//! DDS/KTX2/EXR outputs changed 48059 to 32567 without a word. `sample`,
//! `render`, `tradeoff` and `cachesim` had no `--color`, so a 16-bit data
//! PNG could not be sampled as data; and `sample` printed NaN for a KTX2
//! holding NaN texels where `mip` refuses the file.

use parvo::io::{self, OutputKind, SaveOptions};
use parvo::{ChannelType, ColorSpace, Format, Rounding, Texture};

use super::util::{ok, parvo, parvo_stdin, s};

/// An 8×8 16-bit grey PNG with no colour chunk, every value `v`.
fn grey16(path: &std::path::Path, v: u16) {
    image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_pixel(8, 8, image::Luma([v]))
        .save(path)
        .unwrap();
}

#[test]
fn an_assumed_colour_space_is_said_once_for_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("height.png");
    grey16(&input, 48059);
    for out in ["h.exr", "h.ktx2", "h.dds", "h_{level}.png"] {
        let o = parvo(&["mip", s(&input), "-o", s(&dir.path().join(out))]);
        ok(&o);
        let err = String::from_utf8_lossy(&o.stderr);
        // The assumption (colour), or, for an output that keeps one
        // channel, that it holds data (issue 53): said once, with the flag.
        let said = err
            .matches("does not say how its values encode colour")
            .count()
            + err
                .matches("holds data: the file's stored codes are kept")
                .count();
        assert_eq!(said, 1, "{out}: {err}");
        assert!(err.contains("--color"), "{out}: {err}");
        // Told the file is data, nothing is assumed and nothing said.
        let o = parvo(&[
            "mip",
            s(&input),
            "-o",
            s(&dir.path().join(out)),
            "--color",
            "linear",
        ]);
        ok(&o);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("encode colour"), "{out}: {err}");
    }
}

#[test]
fn sampling_commands_take_color_and_say_the_assumption() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("height.png");
    grey16(&input, 48059);
    let q = "0.5 0.5 0 0 0 0\n";
    let auto = parvo_stdin(&["sample", s(&input)], q);
    let data = parvo_stdin(&["sample", s(&input), "--color", "linear"], q);
    let v = |o: &std::process::Output| -> f64 {
        ok(o).split_whitespace().next().unwrap().parse().unwrap()
    };
    // As data: the code itself; as sRGB: its decoded value.
    assert!((v(&data) - 48059.0 / 65535.0).abs() < 1e-6, "{}", v(&data));
    let c = 48059.0f64 / 65535.0;
    let srgb = ((c + 0.055) / 1.055).powf(2.4);
    assert!((v(&auto) - srgb).abs() < 1e-5, "{}", v(&auto));
    assert!(String::from_utf8_lossy(&auto.stderr).contains("encode colour"));
    assert!(!String::from_utf8_lossy(&data.stderr).contains("encode colour"));
    // The other sampling commands take the same flags.
    for cmd in ["render", "tradeoff", "cachesim"] {
        let o = parvo(&[cmd, "--help"]);
        let help = ok(&o);
        assert!(
            help.contains("--color") && help.contains("--fixnan"),
            "{cmd}"
        );
    }
    let out = dir.path().join("r.png");
    ok(&parvo(&[
        "render",
        "--texture",
        s(&input),
        "--color",
        "linear",
        "--size",
        "32x24",
        "-o",
        s(&out),
    ]));
}

#[test]
fn sample_refuses_nan_texels_as_mip_does() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nan.ktx2");
    let f = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let mut v = vec![0.25f32; 16];
    v[5] = f32::NAN;
    let t = Texture::from_f32(4, 4, f, v).unwrap();
    io::save(
        &[t],
        Rounding::Down,
        &path,
        OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap();
    let q = "0.3 0.3 0 0 0 0\n";
    let o = parvo_stdin(&["sample", s(&path), "--filter", "nearest"], q);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("non-finite") && err.contains("--fixnan"),
        "{err}"
    );
    let mip = parvo(&["mip", s(&path), "-o", s(&dir.path().join("m.exr"))]);
    assert_eq!(mip.status.code(), Some(1));
    let o = parvo_stdin(
        &[
            "sample",
            s(&path),
            "--filter",
            "nearest",
            "--fixnan",
            "black",
        ],
        q,
    );
    let out = ok(&o);
    let x: f64 = out.split_whitespace().next().unwrap().parse().unwrap();
    assert!(x.is_finite(), "{out}");
}
