//! Every `parvo mip` flag on every image kind: honoured (a check of what
//! the flag does on the written file or the report), or refused with a
//! message that names it. The kinds: a 2-D image, a cube map from a
//! vertical strip (`--env cube`), a cube map from six face files, a KTX2
//! 2-D array, and a lat-long map (`--env latlong`). The table below is
//! the test; it also writes itself, with the messages the refusals
//! printed, to `target/mip-flags-by-kind.md` (the table of issue 51's
//! note).

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::cli_common;

use parvo::io::{self, EnvironmentMaps, LoadOptions, OutputKind, SaveOptions};
use parvo::mip::Rounding;
use parvo::{ChannelType, ColorSpace, Format, ImageKind, Texture};

/// Faces, layers and the 2-D image are `N`×`N`, the lat-long map
/// `2N`×`N`: not powers of two, so that `--resize-to pow2` shows.
const N: u32 = 20;

/// The kinds, as the columns.
const KINDS: [&str; 5] = [
    "2-D",
    "cube (strip)",
    "cube (6 files)",
    "KTX2 array",
    "lat-long",
];

/// What a flag does to one kind.
#[derive(Clone, Copy, Debug)]
enum Want {
    /// Exit 0, and the check holds.
    Ok(Check),
    /// A non-zero exit, stderr holding this text.
    No(&'static str),
}

/// What an honoured flag shows.
#[derive(Clone, Copy, Debug)]
enum Check {
    /// The output's bytes differ from the run without the flag (the
    /// setting reached the output: its texels, or its fingerprint).
    Differs,
    /// The output's bytes are the run without the flag's.
    Same,
    /// The output holds this many levels.
    Levels(usize),
    /// The output's channel type.
    Type(ChannelType),
    /// The output holds BC7 blocks.
    Bc7,
    /// The KTX2 output's supercompression scheme.
    Scheme(u32),
    /// No output written.
    Absent,
    /// One JSON object on stdout, of this `kind`.
    Json(&'static str),
    /// A stats line on stdout.
    Stats,
    /// A second run says the output is up to date.
    UpToDate,
    /// The output's level 0 is this wide.
    Width(u32),
    /// The output holds an image of this kind (`ImageKind::id`).
    Kind(&'static str),
    /// This file was written beside the output.
    Writes(&'static str),
}

use Check::*;
use Want::{No, Ok as Yes};

/// One row: the flag's arguments, the output's extension (`ktx2` is
/// each kind's usual container: OpenEXR for a lat-long map, unless the
/// row asks for another environment), and the outcome on each kind.
struct Row {
    args: &'static [&'static str],
    ext: &'static str,
    /// Arguments both this run and its baseline take (e.g. a resize
    /// that makes the faces fit an OpenEXR strip).
    both: &'static [&'static str],
    want: [Want; 5],
}

const fn row(args: &'static [&'static str], ext: &'static str, want: [Want; 5]) -> Row {
    Row {
        args,
        ext,
        both: &[],
        want,
    }
}

/// The table. `--env` in a row replaces the kind's own.
fn table() -> Vec<Row> {
    const EXR: &[&str] = &["--resize-to", "pow2"];
    let all = |c| [Yes(c); 5];
    let mut rows = vec![
        row(&["--dry-run"], "ktx2", all(Absent)),
        row(&["--json"], "ktx2", {
            [
                Yes(Json("2d")),
                Yes(Json("cube")),
                Yes(Json("cube")),
                Yes(Json("array")),
                Yes(Json("latlong")),
            ]
        }),
        row(&["--stats"], "ktx2", all(Stats)),
        row(&["--update"], "ktx2", all(UpToDate)),
        row(
            &["--levels", "3"],
            "ktx2",
            [
                Yes(Levels(3)),
                Yes(Levels(3)),
                Yes(Levels(3)),
                Yes(Levels(3)),
                No("full chain"),
            ],
        ),
        row(&["--type", "f32"], "ktx2", all(Type(ChannelType::F32))),
        row(&["--resize-to", "pow2"], "ktx2", {
            [
                Yes(Width(16)),
                Yes(Width(16)),
                Yes(Width(16)),
                Yes(Width(16)),
                Yes(Width(32)),
            ]
        }),
        row(
            &["--filter", "kaiser"],
            "ktx2",
            [
                Yes(Differs),
                Yes(Differs),
                Yes(Differs),
                Yes(Differs),
                No("--filter"),
            ],
        ),
        row(&["--color", "linear"], "ktx2", all(Differs)),
        row(&["--alpha", "premultiplied"], "ktx2", all(Differs)),
        row(
            &["--alpha-coverage", "0.5"],
            "ktx2",
            [
                Yes(Differs),
                Yes(Differs),
                Yes(Differs),
                Yes(Differs),
                No("--alpha-coverage"),
            ],
        ),
        row(
            &["--normal-map"],
            "ktx2",
            [
                Yes(Differs),
                No("--normal-map"),
                No("--normal-map"),
                Yes(Differs),
                No("--normal-map"),
            ],
        ),
        row(
            &[
                "--normal-map",
                "--roughness",
                "0.3",
                "--roughness-out",
                "ROUGH.ktx2",
            ],
            "ktx2",
            [
                Yes(Writes("ROUGH.ktx2")),
                No("--roughness"),
                No("--roughness"),
                No("--roughness"),
                No("--roughness"),
            ],
        ),
        row(
            &["--wrap", "clamp"],
            "ktx2",
            [
                Yes(Differs),
                No("--wrap"),
                No("--wrap"),
                Yes(Differs),
                No("--wrap"),
            ],
        ),
        row(&["--fixnan", "black"], "ktx2", all(Differs)),
        row(
            &["--rounding", "up"],
            "ktx2",
            [
                No("--rounding up"),
                No("--rounding up"),
                No("--rounding up"),
                No("--rounding up"),
                No("--rounding"),
            ],
        ),
        row(
            &["--zstd", "3"],
            "ktx2",
            [
                Yes(Scheme(2)),
                Yes(Scheme(2)),
                Yes(Scheme(2)),
                Yes(Scheme(2)),
                No("--zstd"),
            ],
        ),
        row(
            &["--zlib", "3"],
            "ktx2",
            [
                Yes(Scheme(3)),
                Yes(Scheme(3)),
                Yes(Scheme(3)),
                Yes(Scheme(3)),
                No("--zlib"),
            ],
        ),
        row(&["-j", "1"], "ktx2", all(Same)),
        row(&["--no-auto-orient"], "ktx2", all(Same)),
        row(&["--max-width", "8"], "ktx2", [No("--max-width"); 5]),
        row(&["--subimage", "1"], "ktx2", [No("--subimage"); 5]),
        row(&["--channels", "R,G,B"], "ktx2", [No("--channels"); 5]),
        row(&["--max-height", "8"], "ktx2", [No("--max-height"); 5]),
        row(&["--max-alloc", "100"], "ktx2", [No("--max-alloc"); 5]),
        Row {
            both: EXR,
            ..row(
                &["--tile", "32"],
                "exr",
                [
                    Yes(Differs),
                    Yes(Differs),
                    Yes(Differs),
                    No("cannot store a 2-D array"),
                    Yes(Differs),
                ],
            )
        },
        Row {
            both: EXR,
            ..row(
                &["--compression", "piz"],
                "exr",
                [
                    Yes(Differs),
                    Yes(Differs),
                    Yes(Differs),
                    No("cannot store a 2-D array"),
                    Yes(Differs),
                ],
            )
        },
        row(
            &["--env", "latlong"],
            "exr",
            [
                Yes(Kind("latlong")),
                Yes(Kind("latlong")),
                Yes(Kind("latlong")),
                No("cannot become"),
                Yes(Kind("latlong")),
            ],
        ),
        row(
            &["--env", "cube"],
            "ktx2",
            [
                No("a cube map comes from"),
                Yes(Kind("cube")),
                Yes(Kind("cube")),
                No("cannot become"),
                Yes(Kind("cube")),
            ],
        ),
        row(
            &["--env", "cube", "--face-size", "8"],
            "ktx2",
            [
                No("a cube map comes from"),
                No("--face-size"),
                No("--face-size"),
                No("cannot become"),
                Yes(Width(8)),
            ],
        ),
        row(
            &[
                "--env",
                "cube",
                "--prefilter",
                "ggx",
                "--prefilter-samples",
                "4",
            ],
            "ktx2",
            [
                No("a cube map comes from"),
                Yes(Type(ChannelType::F16)),
                Yes(Type(ChannelType::F16)),
                No("cannot become"),
                Yes(Type(ChannelType::F16)),
            ],
        ),
        row(
            &["--irradiance", "IRR.ktx2"],
            "ktx2",
            [
                No("--irradiance"),
                Yes(Writes("IRR.ktx2")),
                Yes(Writes("IRR.ktx2")),
                No("--irradiance"),
                Yes(Writes("IRR.ktx2")),
            ],
        ),
        row(
            &["--no-edge-fixup"],
            "ktx2",
            [
                No("--no-edge-fixup"),
                Yes(Differs),
                Yes(Differs),
                No("--no-edge-fixup"),
                No("--no-edge-fixup"),
            ],
        ),
    ];
    if cfg!(feature = "encode") {
        rows.push(Row {
            both: &["--compress", "bc7"],
            ..row(
                &["--quality", "fast"],
                "ktx2",
                [
                    Yes(Differs),
                    Yes(Differs),
                    Yes(Differs),
                    Yes(Differs),
                    No("--compress"),
                ],
            )
        });
        rows.push(row(
            &["--compress", "bc7"],
            "ktx2",
            [Yes(Bc7), Yes(Bc7), Yes(Bc7), Yes(Bc7), No("--compress")],
        ));
        rows.push(row(
            &["--compress", "bc7"],
            "dds",
            [
                Yes(Bc7),
                Yes(Bc7),
                Yes(Bc7),
                Yes(Bc7),
                No("DDS cannot store a lat-long"),
            ],
        ));
    }
    rows
}

/// xorshift, fixed seed.
fn noise(seed: u64, n: usize) -> Vec<u8> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect()
}

/// An sRGB RGBA8 image whose alpha varies (so alpha coverage and
/// association show).
fn rgba(w: u32, h: u32, seed: u64) -> Texture {
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    Texture::from_u8(w, h, f, noise(seed, (w * h * 4) as usize)).unwrap()
}

fn png(t: &Texture, path: &Path) {
    io::png_levels::save(std::slice::from_ref(t), path).unwrap();
}

/// The inputs of each kind, written into `dir`: the arguments that name
/// them (and their `--env`).
fn inputs(dir: &Path) -> Vec<(Vec<String>, Option<&'static str>)> {
    let s = |p: PathBuf| p.to_string_lossy().into_owned();
    png(&rgba(N, N, 1), &dir.join("flat.png"));
    png(&rgba(N, 6 * N, 2), &dir.join("strip.png"));
    let faces: Vec<String> = (0..6)
        .map(|f| {
            let p = dir.join(format!("face{f}.png"));
            png(&rgba(N, N, 10 + f), &p);
            s(p)
        })
        .collect();
    let layers: Vec<Vec<Texture>> = (0..3).map(|l| vec![rgba(N, N, 20 + l)]).collect();
    let refs: Vec<&[Texture]> = layers.iter().map(Vec::as_slice).collect();
    io::save_images(
        &refs,
        ImageKind::Array { layers: 3 },
        Rounding::Down,
        &dir.join("array.ktx2"),
        OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap();
    png(&rgba(2 * N, N, 3), &dir.join("latlong.png"));
    vec![
        (vec![s(dir.join("flat.png"))], None),
        (vec![s(dir.join("strip.png"))], Some("cube")),
        (faces, Some("cube")),
        (vec![s(dir.join("array.ktx2"))], None),
        (vec![s(dir.join("latlong.png"))], Some("latlong")),
    ]
}

/// The arguments of one run: the kind's inputs and `--env` (unless the
/// row gives its own), `extra`, and `-o out`.
fn args(
    kind: &(Vec<String>, Option<&'static str>),
    extra: &[&str],
    dir: &Path,
    out: &Path,
) -> Vec<String> {
    let mut a = vec!["mip".to_string()];
    a.extend(kind.0.iter().cloned());
    if let Some(e) = kind.1
        && !extra.contains(&"--env")
    {
        a.extend(["--env".to_string(), e.to_string()]);
    }
    for x in extra {
        // Names of files beside the output.
        a.push(if x.contains("IRR") || x.contains("ROUGH") {
            dir.join(x).to_string_lossy().into_owned()
        } else {
            x.to_string()
        });
    }
    a.extend(["-o".to_string(), out.to_string_lossy().into_owned()]);
    a
}

fn run(args: &[String]) -> Output {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    cli_common::parvo(&a)
}

fn load(path: &Path) -> io::Loaded {
    let options = LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..LoadOptions::default()
    };
    io::load_with(&path.to_string_lossy(), &io::Limits::default(), &options)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether `check` holds for a run `o` that wrote `out` (`base`: the
/// baseline run's output bytes); `Err` says what was seen.
fn holds(
    check: Check,
    o: &Output,
    out: &Path,
    base: &[u8],
    again: &dyn Fn() -> Output,
    dir: &Path,
) -> Result<(), String> {
    let stdout = String::from_utf8_lossy(&o.stdout);
    let bytes = || std::fs::read(out).map_err(|e| format!("{}: {e}", out.display()));
    let yes = |b: bool, seen: String| if b { Ok(()) } else { Err(seen) };
    match check {
        Differs => yes(
            bytes()? != base,
            "the same bytes as without the flag".into(),
        ),
        Same => yes(bytes()? == base, "other bytes than without the flag".into()),
        Levels(n) => {
            let l = load(out);
            yes(l.levels.len() == n, format!("{} levels", l.levels.len()))
        }
        Type(t) => {
            let l = load(out);
            let got = l.base().channel_type();
            yes(got == t, format!("{got}"))
        }
        Bc7 => {
            let l = load(out);
            yes(
                l.info.blocks == Some(parvo::compress::BlockFormat::Bc7),
                format!("{:?}", l.info.blocks),
            )
        }
        Scheme(n) => {
            let b = bytes()?;
            let got = u32::from_le_bytes(b[44..48].try_into().unwrap());
            yes(got == n, format!("scheme {got}"))
        }
        Absent => yes(!out.exists(), format!("{} written", out.display())),
        Json(kind) => {
            let lines: Vec<&str> = stdout.lines().collect();
            let v: serde_json::Value = serde_json::from_str(lines.first().unwrap_or(&""))
                .map_err(|e| format!("{e}: {stdout}"))?;
            yes(
                lines.len() == 1 && v["kind"] == kind && v["status"] == "written",
                stdout.to_string(),
            )
        }
        Stats => yes(stdout.contains("stats: read"), stdout.to_string()),
        UpToDate => {
            let second = again();
            let text = String::from_utf8_lossy(&second.stdout).into_owned();
            yes(text.contains("(up to date)"), text)
        }
        Width(w) => {
            let got = load(out).base().width();
            yes(got == w, format!("{got} wide"))
        }
        Kind(k) => {
            let l = load(out);
            let got = if l.info.environment == Some(io::Environment::LatLong) {
                "latlong"
            } else {
                l.info.kind.id()
            };
            // An OpenEXR cube is its strip: told by its envmap.
            let got = if l.info.environment == Some(io::Environment::Cube) {
                "cube"
            } else {
                got
            };
            yes(got == k, got.to_string())
        }
        Writes(name) => {
            let p = dir.join(name);
            yes(p.is_file(), format!("no {}", p.display()))
        }
    }
}

#[test]
fn every_flag_is_honoured_or_refused_for_every_kind() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let kinds = inputs(dir);
    let mut failures = Vec::new();
    let mut md = format!(
        "| flag | output | {} |\n|---|---|{}\n",
        KINDS.join(" | "),
        "---|".repeat(KINDS.len())
    );
    for (r, row) in table().iter().enumerate() {
        let mut cells = Vec::new();
        for (k, kind) in kinds.iter().enumerate() {
            let ext =
                if kind.1 == Some("latlong") && row.ext == "ktx2" && !row.args.contains(&"--env") {
                    "exr"
                } else {
                    row.ext
                };
            let out = dir.join(format!("out{r}_{k}.{ext}"));
            let base_out = dir.join(format!("base{r}_{k}.{ext}"));
            let _ = std::fs::remove_file(dir.join("IRR.ktx2"));
            let _ = std::fs::remove_file(dir.join("ROUGH.ktx2"));
            let base_args = args(kind, row.both, dir, &base_out);
            let mut extra: Vec<&str> = row.both.to_vec();
            extra.extend(row.args);
            let run_args = args(kind, &extra, dir, &out);
            let o = run(&run_args);
            let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
            let cell = match row.want[k] {
                Yes(check) => {
                    let base = if matches!(check, Differs | Same) {
                        let b = run(&base_args);
                        assert!(
                            b.status.success(),
                            "{base_args:?}: {}",
                            String::from_utf8_lossy(&b.stderr)
                        );
                        std::fs::read(&base_out).unwrap()
                    } else {
                        Vec::new()
                    };
                    let again = || run(&run_args);
                    let verdict = if o.status.success() {
                        holds(check, &o, &out, &base, &again, dir)
                    } else {
                        Err(format!("exit {:?}: {stderr}", o.status.code()))
                    };
                    if let Err(seen) = &verdict {
                        failures.push(format!(
                            "{} on {}: wanted {check:?}, saw {seen}",
                            row.args.join(" "),
                            KINDS[k]
                        ));
                    }
                    format!("honoured ({check:?})")
                }
                No(text) => {
                    let line = stderr.lines().next().unwrap_or("").trim().to_string();
                    if o.status.success() || !stderr.contains(text) {
                        failures.push(format!(
                            "{} on {}: wanted a refusal naming `{text}`, saw exit {:?}: {stderr}",
                            row.args.join(" "),
                            KINDS[k],
                            o.status.code()
                        ));
                    }
                    // The message without the temporary paths.
                    let dir_text = dir.to_string_lossy().into_owned();
                    format!("refused: {}", line.replace(&dir_text, "…"))
                }
            };
            cells.push(cell.replace('|', "\\|"));
        }
        md += &format!(
            "| `{}` | .{} | {} |\n",
            row.args
                .join(" ")
                .replace("IRR", "irr")
                .replace("ROUGH", "rough"),
            row.ext,
            cells.join(" | ")
        );
    }
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    let _ = std::fs::create_dir_all(&target);
    let _ = std::fs::write(target.join("mip-flags-by-kind.md"), &md);
    assert!(failures.is_empty(), "{}\n\n{md}", failures.join("\n"));
}
