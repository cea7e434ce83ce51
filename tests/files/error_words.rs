//! Every error a user can reach is one line in parvo's words (issue 53):
//! the file, what is wrong in the format's terms, what to do — never a
//! dependency's message alone, never a path twice.
//!
//! The errors walked: `parvo info` and `parvo mip` on every file the peer
//! corpus (`tests/data/peer/manifest.json`) expects refused; `parvo info`
//! on the fuzz seeds and kept artifacts of the decoders, and on every
//! corpus file cut short (at half, at 64 bytes, one byte short) and with
//! bytes overwritten; and the command-line misuses a user makes (a
//! missing file, a directory, an output nobody can write, an unknown
//! extension, an option out of range). Each error line must start with
//! `parvo: `, name each path at most once, and hold none of the phrases
//! the libraries use ([`LIBRARY_PHRASES`]). `cargo test --test files
//! error_words -- --nocapture` prints every distinct message (numbers as
//! N, paths as FILE).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::cli_common::parvo;

/// Words of the libraries parvo reads with (and of Rust itself) that must
/// never reach a user: each names where it comes from.
const LIBRARY_PHRASES: &[(&str, &str)] = &[
    ("os error", "std::io's error code"),
    ("one one of", "zune-jpeg's wording"),
    ("set_limits", "the tiff crate's advice about its own API"),
    ("reference to missing bytes", "the exr crate"),
    ("not supported yet", "the exr crate"),
    ("invalid: ", "the exr crate's Display prefix"),
    ("Unknown frame descriptor", "zstd"),
    ("Decode Error", "the tiff crate's generic error"),
    ("Format error", "the image crate"),
    ("failed to fill whole buffer", "std::io's read_exact"),
    ("InsufficientInput", "a Rust enum variant"),
    ("UnexpectedEof", "a Rust enum variant"),
    ("ChunkType", "the png crate's type name"),
    ("error decoding", "a decoder's own prefix"),
    ("Some(", "Rust Debug output"),
    ("None", "Rust Debug output"),
    ("{", "Rust Debug output"),
    ("}", "Rust Debug output"),
    ("panicked", "a panic"),
    ("RUST_BACKTRACE", "a panic"),
    ("internal error", "a bug"),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The errors seen, by message (numbers as N, paths as FILE), with where
/// each came from; and the problems found.
#[derive(Default)]
struct Walk {
    messages: BTreeMap<String, Vec<String>>,
    problems: Vec<String>,
}

impl Walk {
    /// Run `parvo args`; when it fails, judge its error line. `paths` are
    /// the paths the command names (each may appear once).
    fn run(&mut self, what: &str, args: &[&str], paths: &[&str]) {
        let o = parvo(args);
        if o.status.success() {
            return;
        }
        let err = String::from_utf8_lossy(&o.stderr);
        let Some(line) = err.lines().rev().find(|l| !l.trim().is_empty()) else {
            self.problems
                .push(format!("{what}: fails with nothing on stderr"));
            return;
        };
        let mut found = Vec::new();
        // 1: the input or the work failed; 2: the command line was wrong.
        if !matches!(o.status.code(), Some(1 | 2)) {
            found.push(format!("exit status {:?}", o.status.code()));
        }
        if !line.starts_with("parvo: ") {
            found.push("does not start with `parvo: `".into());
        }
        // parvo's own output-name placeholders are braces too.
        let judged = ["{level}", "{face}", "{layer}"]
            .iter()
            .fold(line.to_string(), |t, p| t.replace(p, ""));
        for (phrase, source) in LIBRARY_PHRASES {
            if judged.contains(phrase) {
                found.push(format!("holds `{phrase}` ({source})"));
            }
        }
        let mut text = line.to_string();
        for p in paths.iter().filter(|p| !p.is_empty()) {
            let n = text.matches(p).count();
            if n > 1 {
                found.push(format!("names `{p}` {n} times"));
            }
            text = text.replace(p, "FILE");
        }
        if !found.is_empty() {
            self.problems
                .push(format!("{what}: {}: {line}", found.join("; ")));
        }
        self.messages
            .entry(numbers_as_n(&text))
            .or_default()
            .push(what.to_string());
    }
}

/// `text` with each number that stands on its own (not inside a name such
/// as KTX2 or BC7) written N, so messages that differ only in numbers
/// are one.
fn numbers_as_n(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut prev: Option<char> = None;
    let mut in_number = false;
    for c in text.chars() {
        let starts =
            c.is_ascii_digit() && !prev.is_some_and(|p| p.is_ascii_alphanumeric() || p == '_');
        if starts {
            in_number = true;
            out.push('N');
        } else if !(in_number && (c.is_ascii_digit() || c == '.')) {
            in_number = false;
            out.push(c);
        }
        prev = Some(c);
    }
    out
}

fn manifest() -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(root().join("tests/data/peer/manifest.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["files"].as_array().unwrap().clone()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_reachable_error_is_one_line_in_parvos_words() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.exr");
    let mut walk = Walk::default();
    let entries = manifest();
    let peer = root().join("tests/data/peer");
    // The corpus's refusals, through both commands.
    for e in entries.iter().filter(|e| e["expect"] == "refuse") {
        let f = peer.join(e["file"].as_str().unwrap());
        let opts: Vec<String> = e["options"]
            .as_array()
            .map(|a| a.iter().map(|o| o.as_str().unwrap().to_string()).collect())
            .unwrap_or_default();
        let name = e["file"].as_str().unwrap();
        walk.run(&format!("info {name}"), &["info", s(&f)], &[s(&f)]);
        let mut args = vec!["mip", s(&f)];
        args.extend(opts.iter().map(String::as_str));
        args.extend(["-o", s(&out)]);
        walk.run(&format!("mip {name}"), &args, &[s(&f), s(&out)]);
    }
    // The decoders' fuzz seeds and kept artifacts.
    for sub in ["seeds", "artifacts"] {
        let d = root().join("fuzz").join(sub).join("decode_and_mip");
        let Ok(list) = std::fs::read_dir(&d) else {
            continue;
        };
        let mut list: Vec<PathBuf> = list.map(|e| e.unwrap().path()).collect();
        list.sort();
        for f in list {
            walk.run(
                &format!("info fuzz {}", f.display()),
                &["info", s(&f)],
                &[s(&f)],
            );
        }
    }
    // Every corpus file cut short and overwritten.
    let mut files: Vec<&str> = entries
        .iter()
        .map(|e| e["file"].as_str().unwrap())
        .collect();
    files.sort();
    files.dedup();
    for name in files {
        let data = std::fs::read(peer.join(name)).unwrap();
        let base = Path::new(name).file_name().unwrap().to_str().unwrap();
        let mut xored = data.clone();
        let step = (data.len() / 7).max(1);
        for i in (16..data.len()).step_by(step) {
            xored[i] ^= 0x5A;
        }
        let variants = [
            ("half", data[..data.len() / 2].to_vec()),
            ("64", data[..data.len().min(64)].to_vec()),
            ("short", data[..data.len().saturating_sub(1)].to_vec()),
            ("xor", xored),
        ];
        for (tag, bytes) in variants {
            let f = dir.path().join(format!("{tag}-{base}"));
            std::fs::write(&f, bytes).unwrap();
            walk.run(&format!("info {name} ({tag})"), &["info", s(&f)], &[s(&f)]);
        }
    }
    // A user's slips on the command line.
    let png = peer.join("pillow/hopper.png");
    let missing = dir.path().join("missing.png");
    let nowhere = dir.path().join("no/such/dir/out.exr");
    let odd = dir.path().join("out.unknown");
    let frame = dir.path().join("no/such/dir/frame.png");
    let cases: Vec<(&str, Vec<&str>, Vec<&str>)> = vec![
        (
            "info of a missing file",
            vec!["info", s(&missing)],
            vec![s(&missing)],
        ),
        (
            "info of a directory",
            vec!["info", s(dir.path())],
            vec![s(dir.path())],
        ),
        (
            "mip of a missing file",
            vec!["mip", s(&missing), "-o", s(&out)],
            vec![s(&missing), s(&out)],
        ),
        (
            "mip into a missing directory",
            vec!["mip", s(&png), "-o", s(&nowhere)],
            vec![s(&png), s(&nowhere)],
        ),
        (
            "mip to an unknown extension",
            vec!["mip", s(&png), "-o", s(&odd)],
            vec![s(&png), s(&odd)],
        ),
        (
            "mip --levels 0",
            vec!["mip", s(&png), "--levels", "0", "-o", s(&out)],
            vec![s(&png), s(&out)],
        ),
        (
            "render into a missing directory",
            vec!["render", "-o", s(&frame)],
            vec![s(&frame)],
        ),
    ];
    for (what, args, paths) in &cases {
        walk.run(what, args, paths);
    }
    let mut listed: Vec<(&String, &Vec<String>)> = walk.messages.iter().collect();
    listed.sort_by_key(|(_, from)| std::cmp::Reverse(from.len()));
    println!("{} distinct error messages:", listed.len());
    for (m, from) in &listed {
        println!("{:5}  {m}", from.len());
    }
    assert!(walk.messages.len() > 20, "the walk reached too few errors");
    assert!(
        walk.problems.is_empty(),
        "{} errors not in parvo's words:\n{}",
        walk.problems.len(),
        walk.problems.join("\n")
    );
}
