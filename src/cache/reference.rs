//! The plain cache model: obviously correct, slow, and the reference the
//! fast simulator ([`super::sim`]) is tested against access by access.
//!
//! Each set is a `Vec` of `(line, sectors)`: for LRU in recency order
//! (most recent first), for FIFO in insertion order (oldest first), for
//! random in way order (a free way first, then the way the shared xorshift
//! picks). The 3C shadow is the same model with one set and LRU; the lines
//! ever touched are a `HashMap`.

use std::collections::HashMap;

use super::sim::{CacheConfig, Outcome, Policy, xorshift};

/// One level of the plain model.
pub struct PlainCache {
    config: CacheConfig,
    sets: Vec<Vec<(u64, u32)>>,
    rng: u64,
}

impl PlainCache {
    /// An empty cache.
    pub fn new(config: &CacheConfig) -> Self {
        PlainCache {
            config: *config,
            sets: vec![Vec::new(); config.sets() as usize],
            rng: config.seed | 1,
        }
    }

    /// Touch `line` wanting sectors `want`; the sectors that were missing.
    pub fn touch(&mut self, line: u64, want: u32) -> u32 {
        let ways = self.config.ways as usize;
        let set = &mut self.sets[(line % self.config.sets()) as usize];
        if let Some(i) = set.iter().position(|e| e.0 == line) {
            let missing = want & !set[i].1;
            set[i].1 |= want;
            if self.config.policy == Policy::Lru {
                let e = set.remove(i);
                set.insert(0, e);
            }
            return missing;
        }
        match self.config.policy {
            Policy::Lru => {
                set.insert(0, (line, want));
                set.truncate(ways);
            }
            Policy::Fifo => {
                if set.len() == ways {
                    set.remove(0);
                }
                set.push((line, want));
            }
            Policy::Random => {
                if set.len() < ways {
                    set.push((line, want));
                } else {
                    let victim = (xorshift(&mut self.rng) % ways as u64) as usize;
                    set[victim] = (line, want);
                }
            }
        }
        want
    }
}

/// The plain model with the 3C classification: what [`super::sim::Simulator`]
/// computes, written the slow way.
pub struct PlainSimulator {
    l1: PlainCache,
    shadow: PlainCache,
    touched: HashMap<u64, u32>,
    line: u64,
    sector: u64,
}

impl PlainSimulator {
    /// A plain simulator of `config`.
    pub fn new(config: &CacheConfig) -> Self {
        PlainSimulator {
            l1: PlainCache::new(config),
            shadow: PlainCache::new(&config.fully_associative()),
            touched: HashMap::new(),
            line: config.line,
            sector: config.sector.unwrap_or(config.line),
        }
    }

    /// The (line, outcome) of every line an access of `bytes` at `address`
    /// touches, in order.
    pub fn access(&mut self, address: u64, bytes: u64) -> Vec<(u64, Outcome)> {
        let end = address + bytes.max(1) - 1;
        let mut out = Vec::new();
        for line in address / self.line..=end / self.line {
            let base = line * self.line;
            let mut want = 0u32;
            for byte in address.max(base)..=end.min(base + self.line - 1) {
                want |= 1 << ((byte - base) / self.sector);
            }
            let missing = self.l1.touch(line, want);
            let before = self.touched.get(&line).copied().unwrap_or(0);
            self.touched.insert(line, before | want);
            let shadow_missing = self.shadow.touch(line, want);
            let o = if missing == 0 {
                Outcome::Hit
            } else if missing & before != missing {
                Outcome::Cold
            } else if shadow_missing == 0 {
                Outcome::Conflict
            } else {
                Outcome::Capacity
            };
            out.push((line, o));
        }
        out
    }
}
