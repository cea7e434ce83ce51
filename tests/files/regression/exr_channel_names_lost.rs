//! Issue 18 #6: EXR channels `N.X,N.Y,N.Z` or `X,Y,Z` loaded as one grey
//! channel (N.Y); a `U,V` flow map came out as `Y,A` with V treated as
//! premultiplied alpha. Channels now load by OpenImageIO's conventions
//! (X, Y, Z order in a layer that has them; alpha only when named A), EXR
//! output keeps their names, stderr says what was mapped to what, and
//! `--channels` picks explicitly.

use super::util::{ok, parvo, s, write_exr};

fn exr_channel_names(path: &std::path::Path) -> Vec<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0]
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect()
}

#[test]
fn normal_channels_load_as_three_data_channels_and_keep_their_names() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("n.exr");
    let n = 4 * 4;
    write_exr(
        &src,
        &[
            ("N.X", vec![0.1; n]),
            ("N.Y", vec![0.2; n]),
            ("N.Z", vec![0.9; n]),
        ],
        4,
        4,
    );
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().channels(), 3);
    assert_eq!(l.info.channel_names, ["N.X", "N.Y", "N.Z"]);
    assert_eq!(&l.base().to_linear()[..3], &[0.1, 0.2, 0.9]);
    let out = dir.path().join("o.exr");
    let r = parvo(&["mip", s(&src), "-o", s(&out)]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("channels N.X,N.Y,N.Z read as R,G,B"), "{err}");
    assert_eq!(exr_channel_names(&out), ["N.X", "N.Y", "N.Z"]);
    // Plain X, Y, Z keep X, Y, Z order (not alphabetical-with-Y-first).
    let src = dir.path().join("xyz.exr");
    write_exr(
        &src,
        &[
            ("X", vec![1.0; n]),
            ("Y", vec![2.0; n]),
            ("Z", vec![3.0; n]),
        ],
        4,
        4,
    );
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.info.channel_names, ["X", "Y", "Z"]);
    assert_eq!(&l.base().to_linear()[..3], &[1.0, 2.0, 3.0]);
}

#[test]
fn a_uv_flow_map_is_two_data_channels_not_grey_and_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("flow.exr");
    // V = 0 where U is large: as premultiplied alpha it would zero U.
    let u: Vec<f32> = (0..16).map(|i| i as f32 / 15.0).collect();
    let v: Vec<f32> = (0..16)
        .map(|i| if i % 2 == 0 { 0.0 } else { 0.5 })
        .collect();
    write_exr(&src, &[("U", u.clone()), ("V", v.clone())], 4, 4);
    let l = parvo::io::load(s(&src), &parvo::io::Limits::default()).unwrap();
    let f = l.base().format();
    assert_eq!((f.channels, f.has_alpha()), (2, false));
    let out = dir.path().join("flow_mip.exr");
    ok(&parvo(&["mip", s(&src), "-o", s(&out), "--type", "f32"]));
    assert_eq!(exr_channel_names(&out), ["U", "V"]);
    let m = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    // Level 1 texel (0, 0) is the plain mean of U and of V over texels
    // (0,0), (1,0), (0,1), (1,1): no alpha weighting.
    let idx = [0usize, 1, 4, 5];
    let mu = idx.iter().map(|&i| u[i]).sum::<f32>() / 4.0;
    let mv = idx.iter().map(|&i| v[i]).sum::<f32>() / 4.0;
    let l1 = m.levels[1].to_linear();
    assert!(
        (l1[0] - mu).abs() < 1e-6 && (l1[1] - mv).abs() < 1e-6,
        "{l1:?}"
    );
}

#[test]
fn channels_option_picks_and_orders_and_a_lone_channel_keeps_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("n.exr");
    write_exr(
        &src,
        &[
            ("N.X", vec![0.1; 4]),
            ("N.Y", vec![0.2; 4]),
            ("N.Z", vec![0.9; 4]),
        ],
        2,
        2,
    );
    let out = dir.path().join("z.exr");
    ok(&parvo(&[
        "mip",
        s(&src),
        "-o",
        s(&out),
        "--channels",
        "N.Z",
    ]));
    assert_eq!(exr_channel_names(&out), ["N.Z"]);
    let r = parvo(&["mip", s(&src), "-o", s(&out), "--channels", "N.W"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("no channel `N.W`"));
    // A single Y stays Y.
    let src = dir.path().join("y.exr");
    write_exr(&src, &[("Y", vec![0.5; 4])], 2, 2);
    ok(&parvo(&["mip", s(&src), "-o", s(&out)]));
    assert_eq!(exr_channel_names(&out), ["Y"]);
}
