//! `parvo sample` end to end, on built-in textures.

use std::process::Output;

use crate::cli_common;

/// `parvo sample ARGS` with `stdin` as its input.
fn run(args: &[&str], stdin: &str) -> Output {
    let all: Vec<&str> = std::iter::once("sample")
        .chain(args.iter().copied())
        .collect();
    cli_common::parvo_with_input(&all, stdin)
}

fn lines(o: &Output) -> Vec<Vec<f32>> {
    String::from_utf8(o.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| l.split(' ').map(|t| t.parse().unwrap()).collect())
        .collect()
}

#[test]
fn one_line_per_query_in_order_with_one_value_per_channel() {
    let input = "# header comment\n0.5 0.5 0 0 0 0\n\n0.1,0.2,0.01,0,0,0.01 # trailing\nnan inf 1e30 0 0 -inf\n0.3\t0.3 0 0 0 0\n";
    let o = run(&["builtin:checker:64", "--filter", "bilinear"], input);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = lines(&o);
    assert_eq!(v.len(), 4);
    assert!(
        v.iter()
            .all(|l| l.len() == 4 && l.iter().all(|x| x.is_finite()))
    );
    // The checker is sRGB: texel centre of a white square is linear 1.0,
    // of a red one the decoded linear value of code 180.
    let o = run(
        &["builtin:checker:64", "--filter", "nearest"],
        "0.01 0.01 0 0 0 0\n0.2 0.01 0 0 0 0\n",
    );
    let v = lines(&o);
    assert_eq!(v[0], vec![1.0, 1.0, 1.0, 1.0]);
    assert_eq!(v[1][0], parvo::texel::srgb::decode_u8(180));
    assert_eq!(v[1][3], 1.0);
}

#[test]
fn output_matches_the_library_bit_for_bit() {
    use parvo::sample::{Query, Sampler, SamplerOptions};
    let chain = parvo::mip::build(
        parvo::builtin::load("builtin:zoneplate:128").unwrap(),
        &parvo::MipOptions::default(),
    )
    .unwrap();
    let qs = [
        Query::new(0.13, 0.77, 0.02, 0.001, -0.003, 0.05),
        Query::new(-3.5, 9.25, 0.0, 0.0, 0.0, 0.0),
        Query::new(0.5, 0.5, 0.3, 0.3, -0.01, 0.01),
    ];
    let input: String = qs
        .iter()
        .map(|q| {
            format!(
                "{} {} {} {} {} {}\n",
                q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy
            )
        })
        .collect();
    for (args, o) in [
        (
            vec!["--filter", "aniso", "--max-aniso", "8"],
            SamplerOptions::aniso(8),
        ),
        (vec!["--filter", "ewa"], SamplerOptions::ewa()),
        (
            vec![
                "--filter",
                "trilinear",
                "--lod-bias",
                "-0.5",
                "--wrap",
                "mirror,clamp",
            ],
            SamplerOptions {
                lod_bias: -0.5,
                wrap: "mirror,clamp".parse().unwrap(),
                ..SamplerOptions::trilinear()
            },
        ),
        (
            vec![
                "--filter",
                "bilinear",
                "--mip",
                "none",
                "--wrap",
                "border",
                "--border",
                "0.25,0.5,0.75,1",
            ],
            SamplerOptions {
                mip: parvo::sample::MipMode::None,
                wrap: "border".parse().unwrap(),
                border: [0.25, 0.5, 0.75, 1.0],
                ..SamplerOptions::bilinear()
            },
        ),
    ] {
        let mut a = vec!["builtin:zoneplate:128"];
        a.extend(args.iter());
        let out = run(&a, &input);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s = Sampler::new(&chain, o).unwrap();
        let want: Vec<Vec<f32>> = qs.iter().map(|q| s.sample(q).to_vec()).collect();
        assert_eq!(lines(&out), want, "{args:?}");
    }
}

#[test]
fn a_malformed_line_is_an_error_naming_its_line_number() {
    let o = run(
        &["builtin:checker:16"],
        "0 0 0 0 0 0\n# ok\n0.5 0.5 0 0 0\n0 0 0 0 0 0\n",
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("stdin line 3: expected 6 numbers, got 5"),
        "{err}"
    );
    // The line before the bad one was answered.
    assert_eq!(lines(&o).len(), 1);
    let o = run(&["builtin:checker:16"], "0 0 0 zero 0 0\n");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("stdin line 1: `zero` is not a number"));
}

#[test]
fn usage_errors_exit_with_2() {
    for args in [
        vec!["builtin:checker:16", "--filter", "blurry"],
        vec!["builtin:checker:16", "--max-aniso", "0"],
        vec!["builtin:checker:16", "--wrap", "sideways"],
        vec!["builtin:checker:16", "--border", "1,2"],
        vec!["builtin:checker:16", "--lod-min", "3", "--lod-max", "1"],
    ] {
        let o = run(&args, "");
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    // A missing file: a clear error naming it, exit 1.
    let o = run(&["no-such-file.exr"], "");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no-such-file.exr"));
}

#[test]
fn empty_input_gives_empty_output() {
    let o = run(
        &[
            "builtin:checker:16",
            "--filter",
            "supersample",
            "--supersample",
            "4",
        ],
        "",
    );
    assert!(o.status.success());
    assert!(o.stdout.is_empty());
}

#[test]
fn sat_filter_averages_the_footprint_box() {
    // builtin:checker:16 has 2x2-texel squares; a footprint of exactly one
    // square aligned to it averages to that square's colour, and a 4x4
    // texel box centred on a corner averages the two colours equally.
    let tex = parvo::builtin::load("builtin:checker:16").unwrap();
    let lin = tex.to_linear();
    let px = |x: usize, y: usize| lin[(y * 16 + x) * 4];
    let q1 = "0.0625 0.0625 0.125 0 0 0.125\n"; // centre (1,1) texels, box [0,2)^2
    let q2 = "0.125 0.125 0.25 0 0 0.25\n"; // box [0,4)^2
    let o = run(
        &["builtin:checker:16", "--filter", "sat"],
        &format!("{q1}{q2}"),
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let out = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<Vec<f32>> = out
        .lines()
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    let want1 = (px(0, 0) + px(1, 0) + px(0, 1) + px(1, 1)) / 4.0;
    let want2: f32 = (0..4)
        .flat_map(|y| (0..4).map(move |x| (x, y)))
        .map(|(x, y)| px(x, y))
        .sum::<f32>()
        / 16.0;
    assert!(
        (lines[0][0] - want1).abs() < 1e-6,
        "{} vs {want1}",
        lines[0][0]
    );
    assert!(
        (lines[1][0] - want2).abs() < 1e-6,
        "{} vs {want2}",
        lines[1][0]
    );
}

#[test]
fn a_mip_mapped_exr_written_by_parvo_mip_samples_like_its_source() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("checker.exr");
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["mip", "builtin:checker:16", "-o"])
        .arg(&exr)
        .status()
        .unwrap();
    assert!(st.success());
    // Trilinear at several footprints reads the file's own levels; the EXR
    // holds linear half floats of the same sRGB checker, its levels built
    // in f32 (the built-in's levels are 8-bit sRGB, within one code).
    let queries = "0.3 0.7 0 0 0 0\n0.3 0.7 0.125 0 0 0.125\n0.5 0.5 0.25 0 0 0.25\n";
    let a = run(&["builtin:checker:16", "--filter", "trilinear"], queries);
    let b = run(&[exr.to_str().unwrap(), "--filter", "trilinear"], queries);
    assert_eq!(
        b.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&b.stderr)
    );
    let parse = |o: &std::process::Output| -> Vec<f32> {
        String::from_utf8_lossy(&o.stdout)
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (a, b) = (parse(&a), parse(&b));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 0.01, "{x} vs {y}");
    }
}
