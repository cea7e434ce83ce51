//! The fuzz targets' inputs replayed in the ordinary test build: every seed
//! of `fuzz/seeds/TARGET`, every kept crash of `fuzz/artifacts/TARGET` (a
//! developer's own fuzzing run; git ignores the folder) and a fixed set of
//! blind mutations of each seed, through the target's body
//! (`fuzz/bodies/TARGET.rs`, the same file the libFuzzer binary wraps).
//!
//! This is what the CI fuzz smoke did (seeds, then a few thousand
//! mutations per target) without its own instrumented build of the
//! library: the test build has overflow checks and debug assertions on,
//! as the fuzz build has. The mutations are not coverage-guided; real
//! fuzzing stays `fuzz/run.sh TARGET SECONDS`.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// Mutated inputs per target, spread over its seeds (the old smoke ran
/// 3,000 libFuzzer executions per target, seeds included).
pub const MUTANTS_PER_TARGET: usize = 3000;

/// The files of `dir`, sorted by name; none if it does not exist.
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .map(|e| e.expect("read fuzz directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

/// xorshift64*: the mutations are the same on every run.
struct Xs(u64);
impl Xs {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// One to four of libFuzzer's simplest mutations: flip a bit, set a byte
/// to a random or boundary value, insert or erase bytes, copy a chunk over
/// another, truncate.
fn mutate(seed: &[u8], rng: &mut Xs) -> Vec<u8> {
    let mut d = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        match rng.below(6) {
            0 if !d.is_empty() => {
                let i = rng.below(d.len());
                d[i] ^= 1 << rng.below(8);
            }
            1 if !d.is_empty() => {
                let i = rng.below(d.len());
                const EDGE: [u8; 6] = [0, 1, 0x7f, 0x80, 0xfe, 0xff];
                d[i] = if rng.below(2) == 0 {
                    EDGE[rng.below(EDGE.len())]
                } else {
                    rng.next() as u8
                };
            }
            2 => {
                let i = rng.below(d.len() + 1);
                d.insert(i, rng.next() as u8);
            }
            3 if d.len() > 1 => {
                let i = rng.below(d.len());
                let n = 1 + rng.below((d.len() - i).min(16));
                d.drain(i..i + n);
            }
            4 if d.len() > 2 => {
                let n = 1 + rng.below(d.len() / 2);
                let (from, to) = (rng.below(d.len() - n + 1), rng.below(d.len() - n + 1));
                let chunk = d[from..from + n].to_vec();
                d[to..to + n].copy_from_slice(&chunk);
            }
            5 if !d.is_empty() => d.truncate(rng.below(d.len())),
            _ => {}
        }
    }
    d
}

/// Runs `body` on `data`; a panic fails the test naming the input, and the
/// input is kept under `target/fuzz-replay/TARGET/` so it can become a
/// seed and a regression test.
fn run_one(target: &str, what: &str, data: &[u8], body: fn(&[u8])) {
    if catch_unwind(AssertUnwindSafe(|| body(data))).is_err() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = root.join("target/fuzz-replay").join(target);
        let _ = std::fs::create_dir_all(&dir);
        let kept = dir.join(what.replace('/', "_"));
        let _ = std::fs::write(&kept, data);
        panic!(
            "fuzz target {target}: {what} panicked (input kept in {})",
            kept.display()
        );
    }
}

/// Replays fuzz target `target` through `body`: its seeds, its kept
/// artifacts and [`MUTANTS_PER_TARGET`] mutations of the seeds. Returns
/// how many inputs ran.
pub fn replay(target: &str, body: fn(&[u8])) -> usize {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let seeds = files(&root.join("seeds").join(target));
    assert!(!seeds.is_empty(), "fuzz/seeds/{target} has no seed");
    let artifacts = files(&root.join("artifacts").join(target));
    let mut ran = 0;
    let mut inputs = Vec::new();
    for p in seeds.iter().chain(&artifacts) {
        let data = std::fs::read(p).expect("read fuzz input");
        let name = p
            .strip_prefix(&root)
            .unwrap_or(p)
            .to_string_lossy()
            .into_owned();
        run_one(target, &name, &data, body);
        ran += 1;
        inputs.push((name, data));
    }
    // The seeds' mutations, round-robin, from a seed fixed per target.
    let fnv = target.bytes().fold(0xCBF2_9CE4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01B3)
    });
    let mut rng = Xs(fnv | 1);
    for k in 0..MUTANTS_PER_TARGET {
        let (name, data) = &inputs[k % seeds.len()];
        let m = mutate(data, &mut rng);
        run_one(target, &format!("{name}.mutant{k}"), &m, body);
        ran += 1;
    }
    ran
}
