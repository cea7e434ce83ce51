//! `parvo info`: describe texture files — ours and other tools' (a
//! maketx-made EXR reads with all its levels).
//!
//! The file is decoded completely (every level), so `info` also verifies
//! that it reads; each level's size and per-channel mean are printed.

use std::process::ExitCode;

use parvo::ImageKind;
use parvo::io::{self, Limits, Loaded};

/// Arguments of `parvo info`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Describe texture files: format, size, channels, type, levels, tiling, wrap modes, metadata",
    long_about = "Describe texture files: format, size, channels, type, every mip level's size (and \
    per-channel mean, which proves the level decodes), tiling, wrap modes and metadata.\n\n\
    Exit codes: 0 every file read; 1 some file failed; 2 usage error."
)]
pub struct InfoArgs {
    /// Texture files (EXR, KTX2, DDS, PNG, JPEG, TIFF, HDR) or builtin:NAME[:SIZE].
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,

    /// Print one JSON object per file.
    #[arg(long)]
    json: bool,

    /// Largest accepted width in texels.
    #[arg(long, default_value_t = Limits::default().max_width, value_name = "N")]
    max_width: u32,

    /// Largest accepted height in texels.
    #[arg(long, default_value_t = Limits::default().max_height, value_name = "N")]
    max_height: u32,

    /// Largest decoded size, e.g. 4G, 512M, 1000000.
    #[arg(long, default_value = "4G", value_name = "BYTES", value_parser = super::args::parse_bytes)]
    max_alloc: u64,
}

pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let limits = Limits {
        max_width: args.max_width,
        max_height: args.max_height,
        max_alloc: args.max_alloc,
    };
    // Decoder panics are reported as per-file errors by the library.
    std::panic::set_hook(Box::new(|_| {}));
    let mut failed = false;
    for file in &args.files {
        // Environment maps are described, not refused (nothing is built
        // from them here).
        let options = io::LoadOptions {
            environment: io::EnvironmentMaps::Describe,
            ..Default::default()
        };
        match io::load_with(file, &limits, &options) {
            Ok(l) => {
                if args.json {
                    println!("{}", json(file, &l));
                } else {
                    print!("{}", text(file, &l));
                }
            }
            Err(e) => {
                failed = true;
                eprintln!("parvo: {file}: {}", super::words::words(&e));
                if args.json {
                    // One object per file, failed ones included (as `mip
                    // --json` does), so a script sees every file.
                    println!(
                        "{}",
                        serde_json::json!({"file": file, "status": "failed", "error": super::words::words(&e)})
                    );
                }
            }
        }
    }
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn means(t: &parvo::Texture) -> Vec<f64> {
    let ch = t.channels();
    let lin = t.to_linear();
    let mut sum = vec![0f64; ch];
    for px in lin.chunks_exact(ch) {
        for (s, &v) in sum.iter_mut().zip(px) {
            *s += v as f64;
        }
    }
    let n = t.texel_count().max(1) as f64;
    sum.into_iter().map(|s| s / n).collect()
}

fn text(file: &str, l: &Loaded) -> String {
    use std::fmt::Write;
    let b = l.base();
    let f = b.format();
    let i = &l.info;
    let mut s = String::new();
    let _ = writeln!(s, "{file}");
    let mut desc = i.format.name().to_string();
    if let Some((tw, th)) = i.tile {
        let _ = write!(desc, ", tiled {tw}x{th}");
    }
    if i.own_mips {
        let _ = write!(desc, ", mip-mapped (rounding {})", i.rounding);
    }
    let _ = writeln!(s, "  format:     {desc}");
    let _ = writeln!(s, "  size:       {}x{}", b.width(), b.height());
    let _ = writeln!(
        s,
        "  channels:   {} ({})",
        f.channels,
        i.channel_names.join(",")
    );
    let _ = writeln!(
        s,
        "  type:       {} {}{}",
        f.channel_type,
        f.color_space,
        if f.has_alpha() {
            format!(", {} alpha", f.alpha)
        } else {
            String::new()
        }
    );
    let _ = writeln!(s, "  kind:       {}", kind_text(i));
    let _ = writeln!(s, "  levels:     {}", l.levels.len());
    for (k, t) in l.levels.iter().enumerate() {
        let m: Vec<String> = means(t).iter().map(|v| format!("{v:.4}")).collect();
        let _ = writeln!(
            s,
            "    {k:>2}: {}x{}  mean {}",
            t.width(),
            t.height(),
            m.join(" ")
        );
    }
    let _ = writeln!(
        s,
        "  wrap modes: {}",
        i.wrap
            .map(|w| format!("{},{}", w.u.oiio_name(), w.v.oiio_name()))
            .unwrap_or_else(|| "(not recorded)".into())
    );
    for n in &i.notes {
        let _ = writeln!(s, "  note:       {}", super::words::words(n));
    }
    if !i.attributes.is_empty() {
        let _ = writeln!(s, "  metadata:");
        for (k, v) in &i.attributes {
            let _ = writeln!(s, "    {k}: {v}");
        }
    }
    s
}

/// The image kind in words: what the container says (array, cube map)
/// or the environment the file records (OpenEXR, maketx).
fn kind_text(i: &io::SourceInfo) -> String {
    match i.environment {
        Some(io::Environment::LatLong) => ImageKind::LatLong.describe(),
        Some(io::Environment::Cube) => {
            "cube map (OpenEXR strip: six faces stacked, +x -x +y -y +z -z from the top)".into()
        }
        None if i.one_d => i.kind.describe().replacen("2-D", "1-D", 1),
        None => i.kind.describe(),
    }
}

/// The image kind as `--json` names it: `2d`, `array`, `cube`,
/// `cube-array`, `latlong`.
fn kind_id(i: &io::SourceInfo) -> &'static str {
    match (i.environment, i.kind) {
        (Some(io::Environment::LatLong), _) | (None, ImageKind::LatLong) => "latlong",
        (Some(io::Environment::Cube), _) | (None, ImageKind::Cube) => "cube",
        (None, ImageKind::Array { .. }) => "array",
        (None, ImageKind::CubeArray { .. }) => "cube-array",
        (None, ImageKind::Plain) => "2d",
    }
}

fn json(file: &str, l: &Loaded) -> String {
    let b = l.base();
    let f = b.format();
    let i = &l.info;
    serde_json::json!({
        "file": file,
        "status": "ok",
        "format": i.format.name(),
        "width": b.width(),
        "height": b.height(),
        "channels": f.channels,
        "channel_names": i.channel_names,
        "type": f.channel_type.name(),
        "color": f.color_space.to_string(),
        "alpha": f.alpha.to_string(),
        "tile": i.tile.map(|(w, h)| [w, h]),
        "rounding": i.rounding.to_string(),
        "kind": kind_id(i),
        "images": 1 + l.images.len(),
        "levels": l.levels.iter().map(|t| serde_json::json!({
            "width": t.width(),
            "height": t.height(),
            "mean": means(t),
        })).collect::<Vec<_>>(),
        "wrapmodes": i.wrap.map(|w| format!("{},{}", w.u.oiio_name(), w.v.oiio_name())),
        "attributes": i.attributes.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
        "notes": i.notes.iter().map(super::words::words).collect::<Vec<_>>(),
    })
    .to_string()
}
