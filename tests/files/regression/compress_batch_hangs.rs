//! Issue 27, finding 1: `parvo mip a.png b.png c.png --out-dir o --ext dds
//! --compress bc1` never returned when the inputs were at least as many as
//! the threads: each pool thread slept in a progress-polling loop while the
//! encode it waited for was queued behind it. Every batch of 1–5 inputs ×
//! `-j 1..4` × every compressor × every block container must finish; a run
//! that does not finish within its deadline is killed and fails the test
//! (it does not hang it).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::util::{bin, s};

/// Runs parvo with `args`; `Err` with what is known when it exits
/// non-zero or is still running after `limit` (then it is killed).
fn run_bounded(args: &[&str], limit: Duration) -> Result<(), String> {
    let mut child = Command::new(bin())
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let t = Instant::now();
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            if status.success() {
                return Ok(());
            }
            let mut err = String::new();
            use std::io::Read;
            if let Some(mut e) = child.stderr.take() {
                let _ = e.read_to_string(&mut err);
            }
            return Err(format!("exit {:?}: {err}", status.code()));
        }
        if t.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {limit:?}: killed (a hang)"));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn write_input(path: &Path, seed: u32) {
    // An awkward size (not a multiple of 4) with alpha, so every
    // compressor pads blocks and keeps or drops channels.
    let (w, h) = (37u32, 22u32);
    let mut x = seed.wrapping_mul(2654435761).wrapping_add(1);
    let img = image::RgbaImage::from_fn(w, h, |_, _| {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        image::Rgba(x.to_le_bytes())
    });
    img.save(path).unwrap();
}

#[test]
fn compress_batches_finish_for_every_thread_count_and_compressor() {
    let dir = tempfile::tempdir().unwrap();
    let inputs: Vec<String> = (0..5)
        .map(|i| {
            let p = dir.path().join(format!("in{i}.png"));
            write_input(&p, i);
            s(&p).to_string()
        })
        .collect();
    let mut failures = Vec::new();
    for bc in ["bc1", "bc3", "bc4", "bc5", "bc6h", "bc7"] {
        for (c, (ext, extra)) in [("dds", None), ("ktx2", None), ("ktx2", Some("--zstd=3"))]
            .into_iter()
            .enumerate()
        {
            for n in 1..=5 {
                for j in 1..=4 {
                    let out = dir.path().join(format!("o_{bc}_{c}_{n}_{j}"));
                    std::fs::create_dir(&out).unwrap();
                    let j = j.to_string();
                    let mut args = vec!["mip"];
                    args.extend(inputs[..n].iter().map(String::as_str));
                    args.extend([
                        "--out-dir",
                        s(&out),
                        "--ext",
                        ext,
                        "--compress",
                        bc,
                        "-j",
                        &j,
                    ]);
                    args.extend(extra);
                    if let Err(e) = run_bounded(&args, Duration::from_secs(60)) {
                        failures.push(format!("{}: {e}", args.join(" ")));
                        continue;
                    }
                    for i in 0..n {
                        let o = out.join(format!("in{i}.{ext}"));
                        if !o.is_file() {
                            failures.push(format!("{}: {} missing", args.join(" "), o.display()));
                        }
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
