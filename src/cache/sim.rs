//! The texel cache simulator (SPEC.md, "Texel cache model").
//!
//! A cache of SIZE bytes, lines of L bytes, W ways: `sets = SIZE/(L·W)`,
//! the line of address `a` is `⌊a/L⌋` and its set `⌊a/L⌋ mod sets`. An
//! access of B bytes touches lines `⌊a/L⌋ … ⌊(a+B−1)/L⌋`, each counting
//! one hit or one miss. Replacement is `lru`, `fifo` (hits do not reorder)
//! or `random` (a seeded xorshift; a new line takes a free way first, then
//! the way the generator picks). With sectors (`--sector S`) a line is
//! allocated whole but only the sectors an access touches are fetched; a
//! touched line whose sectors are all present is a hit.
//!
//! Misses are split into three classes (Hill & Smith 1989, Dinero IV's
//! `-ccc`): cold if what is missing was never accessed before; capacity if
//! a fully associative LRU cache with the same number of lines (run
//! alongside, fed every access) also misses; conflict otherwise. The
//! shadow cache is this same simulator with one set.
//!
//! Three stores, chosen by associativity: up to 16 ways, each set's tags
//! sit in one short array (recency order for LRU, slot order otherwise)
//! and a lookup is a scan of W tags; above that a line → way index (an
//! open-addressing table sized by the cache, small enough to stay in the
//! processor's cache) and per-set queues of use stamps make every access
//! O(1) amortised; and a fully associative LRU cache of 32 ways or more
//! (the 3C shadow) keeps its 16 most recent lines in front of such a
//! store, compared at once. A plain model ([`super::reference`]) is tested
//! against all three, access by access.

use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// Replacement policy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Policy {
    /// Least recently used.
    #[default]
    Lru,
    /// First in, first out: hits do not reorder.
    Fifo,
    /// A seeded pseudo-random way.
    Random,
}

impl fmt::Display for Policy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Policy::Lru => "lru",
            Policy::Fifo => "fifo",
            Policy::Random => "random",
        })
    }
}

impl FromStr for Policy {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "lru" => Ok(Policy::Lru),
            "fifo" => Ok(Policy::Fifo),
            "random" => Ok(Policy::Random),
            _ => Err(Error::parse(
                "replacement policy",
                s,
                "expected lru, fifo or random",
            )),
        }
    }
}

/// Parse a byte size: `16384`, `16K`, `16KiB`, `16KB`, `4M`, `1G`.
pub fn parse_size(s: &str) -> Result<u64> {
    let t = s.trim();
    let bad = || {
        Error::parse(
            "byte size",
            s,
            "expected a number with an optional K, M or G (16384, 16K, 16KiB, 4M)",
        )
    };
    let lower = t.to_ascii_lowercase();
    let (num, mul) = [
        ("kib", 1u64 << 10),
        ("mib", 1 << 20),
        ("gib", 1 << 30),
        ("kb", 1 << 10),
        ("mb", 1 << 20),
        ("gb", 1 << 30),
        ("k", 1 << 10),
        ("m", 1 << 20),
        ("g", 1 << 30),
    ]
    .iter()
    .find_map(|(suf, m)| lower.strip_suffix(suf).map(|n| (n.trim().to_string(), *m)))
    .unwrap_or((lower.clone(), 1));
    num.parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(mul))
        .ok_or_else(bad)
}

/// A cache configuration: `SIZE:LINE:WAYS[:POLICY]`, plus sectors and the
/// random policy's seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CacheConfig {
    /// Capacity in bytes.
    pub size: u64,
    /// Line size in bytes (a power of two).
    pub line: u64,
    /// Associativity: 1 direct mapped, `size / line` fully associative.
    pub ways: u64,
    /// Replacement policy.
    pub policy: Policy,
    /// Sector size in bytes (a power of two dividing the line, at most 32
    /// sectors per line), or `None` for whole-line fills.
    pub sector: Option<u64>,
    /// Seed of the random policy.
    pub seed: u64,
}

impl CacheConfig {
    /// A cache with the given geometry, LRU, no sectors.
    pub fn new(size: u64, line: u64, ways: u64) -> Self {
        CacheConfig {
            size,
            line,
            ways,
            policy: Policy::Lru,
            sector: None,
            seed: 0x5eed,
        }
    }

    /// Number of lines.
    pub fn lines(&self) -> u64 {
        self.size / self.line
    }

    /// Number of sets.
    pub fn sets(&self) -> u64 {
        self.size / (self.line * self.ways)
    }

    /// The fully associative LRU cache of the same lines (the 3C shadow).
    pub fn fully_associative(&self) -> Self {
        CacheConfig {
            ways: self.lines(),
            policy: Policy::Lru,
            ..*self
        }
    }

    /// Check the rules a cache must follow; the error names the one broken.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidOption(format!("cache {self}: {m}")));
        if self.size == 0 || self.line == 0 || self.ways == 0 {
            return bad("size, line size and ways must all be at least 1".into());
        }
        if !self.line.is_power_of_two() {
            return bad(format!("the line size {} is not a power of two", self.line));
        }
        let Some(set_bytes) = self.line.checked_mul(self.ways) else {
            return bad("line × ways overflows 64 bits".into());
        };
        if !self.size.is_multiple_of(set_bytes) {
            return bad(format!(
                "the size {} is not a multiple of line × ways = {set_bytes}",
                self.size
            ));
        }
        if self.lines() > 1 << 28 {
            return bad(format!("{} lines is more than 2^28", self.lines()));
        }
        if let Some(s) = self.sector
            && (s == 0
                || !s.is_power_of_two()
                || !self.line.is_multiple_of(s)
                || self.line / s > 32)
        {
            return bad(format!(
                "the sector size {s} must be a power of two dividing the line into at most 32 sectors"
            ));
        }
        Ok(())
    }
}

impl fmt::Display for CacheConfig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let size = |n: u64| {
            if n >= 1 << 20 && n.is_multiple_of(1 << 20) {
                format!("{}M", n >> 20)
            } else if n >= 1 << 10 && n.is_multiple_of(1 << 10) {
                format!("{}K", n >> 10)
            } else {
                n.to_string()
            }
        };
        write!(
            f,
            "{}:{}:{}:{}",
            size(self.size),
            self.line,
            self.ways,
            self.policy
        )?;
        if let Some(s) = self.sector {
            write!(f, " (sectors of {s})")?;
        }
        Ok(())
    }
}

impl FromStr for CacheConfig {
    type Err = Error;
    /// `SIZE:LINE:WAYS[:POLICY]`; WAYS may be `full`.
    fn from_str(s: &str) -> Result<Self> {
        let parts: Vec<&str> = s.trim().split(':').collect();
        if !(3..=4).contains(&parts.len()) {
            return Err(Error::parse(
                "cache",
                s,
                "expected SIZE:LINE:WAYS[:POLICY], e.g. 16K:64:4 or 16K:64:4:fifo",
            ));
        }
        let size = parse_size(parts[0])?;
        let line = parse_size(parts[1])?;
        let ways = if parts[2].eq_ignore_ascii_case("full") {
            size.checked_div(line).unwrap_or(0)
        } else {
            parts[2].parse::<u64>().map_err(|_| {
                Error::parse(
                    "cache",
                    s,
                    format!("ways `{}` is not a number or `full`", parts[2]),
                )
            })?
        };
        let mut c = CacheConfig::new(size, line, ways);
        if let Some(p) = parts.get(3) {
            c.policy = p.parse()?;
        }
        c.validate()?;
        Ok(c)
    }
}

/// How a touched line was counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// Present (with every touched sector).
    Hit,
    /// Missing, never accessed before.
    Cold,
    /// Missing; a fully associative LRU cache of the same size misses too.
    Capacity,
    /// Missing only because of the mapping.
    Conflict,
    /// Missing (when misses are not classified).
    Miss,
}

/// Counters of a run (or of one mip level of it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Touched lines (one per line an access spans).
    pub accesses: u64,
    /// Hits.
    pub hits: u64,
    /// Misses.
    pub misses: u64,
    /// Cold misses.
    pub cold: u64,
    /// Capacity misses.
    pub capacity: u64,
    /// Conflict misses.
    pub conflict: u64,
    /// Bytes fetched from the next level (lines, or missing sectors).
    pub bytes_fetched: u64,
    /// Distinct lines touched (the working set, in lines).
    pub lines_touched: u64,
}

impl Counters {
    /// Hits per access (0 when there were none).
    pub fn hit_rate(&self) -> f64 {
        if self.accesses == 0 {
            0.0
        } else {
            self.hits as f64 / self.accesses as f64
        }
    }

    fn add(&mut self, o: Outcome, fetched: u64) {
        self.accesses += 1;
        match o {
            Outcome::Hit => self.hits += 1,
            other => {
                self.misses += 1;
                self.bytes_fetched += fetched;
                match other {
                    Outcome::Cold => self.cold += 1,
                    Outcome::Capacity => self.capacity += 1,
                    Outcome::Conflict => self.conflict += 1,
                    _ => {}
                }
            }
        }
    }
}

/// A fast hasher for line numbers (a multiply and a shift; keys are not
/// adversarial).
#[derive(Clone, Copy, Default)]
struct LineHasher(u64);

impl std::hash::Hasher for LineHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (v ^ (v >> 29))
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(31);
    }
}

type LineMap<V> = HashMap<u64, V, std::hash::BuildHasherDefault<LineHasher>>;

/// The lines an address space can hold: dense tables when it is bounded
/// (scene mode knows it), hash maps for arbitrary traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AddressSpace {
    /// Addresses below this many bytes.
    Bounded(u64),
    /// Any 64-bit address.
    Any,
}

/// line → slot of a store with more than 16 ways: open addressing with
/// linear probing in a table of two to four times as many entries as the
/// store has slots, and backward-shift deletion. It is sized by the cache,
/// not by the address space, so that it stays in the processor's cache
/// (12 KiB for the 256 lines of a 16 KiB cache's 3C shadow): a lookup is a
/// multiplication and one or two probes.
struct Index {
    keys: Vec<u64>,
    /// The slot of each entry; [`NONE`] marks a free entry.
    values: Vec<u32>,
    shift: u32,
    mask: usize,
}

const NONE: u32 = u32::MAX;

impl Index {
    fn new(slots: usize) -> Self {
        let factor = if slots <= 1 << 16 { 4 } else { 2 };
        let n = (slots * factor).next_power_of_two().max(16);
        Index {
            keys: vec![0; n],
            values: vec![NONE; n],
            shift: 64 - n.trailing_zeros(),
            mask: n - 1,
        }
    }
    #[inline(always)]
    fn home(&self, line: u64) -> usize {
        (line.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }
    /// The entry holding `line`, or the free entry where it would go.
    #[inline(always)]
    fn find(&self, line: u64) -> usize {
        let mut i = self.home(line);
        while self.values[i] != NONE && self.keys[i] != line {
            i = (i + 1) & self.mask;
        }
        i
    }
    #[inline]
    fn get(&self, line: u64) -> u32 {
        self.values[self.find(line)]
    }
    #[inline]
    fn set(&mut self, line: u64, value: u32) {
        let mut i = self.find(line);
        if value != NONE {
            self.keys[i] = line;
            self.values[i] = value;
            return;
        }
        if self.values[i] == NONE {
            return;
        }
        // Backward shift: move later entries of the probe run into the
        // hole unless their home lies cyclically in (hole, entry].
        let mut j = i;
        loop {
            j = (j + 1) & self.mask;
            if self.values[j] == NONE {
                break;
            }
            let k = self.home(self.keys[j]);
            let stays = if i <= j {
                i < k && k <= j
            } else {
                i < k || k <= j
            };
            if !stays {
                self.keys[i] = self.keys[j];
                self.values[i] = self.values[j];
                i = j;
            }
        }
        self.values[i] = NONE;
    }
}

const EMPTY: u64 = u64::MAX;

/// One cache level (no classification, no statistics).
struct Cache {
    sets: u64,
    set_mask: Option<u64>,
    ways: usize,
    policy: Policy,
    rng: u64,
    store: Store,
}

enum Store {
    /// Up to 16 ways: per set `ways` tags (LRU: most recent first; others:
    /// slot order) with their sector masks; `fill` is the number of valid
    /// ways (and, for FIFO, `ptr` the next victim).
    Small {
        tags: Vec<u64>,
        masks: Vec<u32>,
        fill: Vec<u8>,
        ptr: Vec<u8>,
    },
    /// More ways: slots `set·ways ..`, a line → slot index, and per set a
    /// circular list (head = most recent / newest) for LRU and FIFO.
    Large {
        index: Index,
        line: Vec<u64>,
        mask: Vec<u32>,
        /// When each slot was last used (LRU) or filled (FIFO).
        stamp: Vec<u64>,
        /// Per set, (slot, stamp) in the order of use: an entry whose
        /// stamp is still its slot's is live, the others are stale (the
        /// slot was used again later). The first live entry is the least
        /// recent (oldest) slot. A hit is a stamp and a push, no list to
        /// relink; stale entries are skipped when a victim is sought and
        /// dropped when the queue grows past four per way.
        queue: Vec<Queue>,
        clock: u64,
        fill: Vec<u32>,
    },
    /// Fully associative LRU of [`Front::MIN_WAYS`] ways or more (the 3C
    /// shadow): see [`Front`].
    Front(Box<Front>),
}

impl Cache {
    fn new(c: &CacheConfig) -> Self {
        let sets = c.sets();
        let ways = c.ways as usize;
        let slots = c.lines() as usize;
        let store = if ways <= 16 {
            Store::Small {
                tags: vec![EMPTY; slots],
                masks: vec![0; slots],
                fill: vec![0; sets as usize],
                ptr: vec![0; sets as usize],
            }
        } else if sets == 1 && c.policy == Policy::Lru && ways >= Front::MIN_WAYS {
            Store::Front(Box::new(Front::new(ways)))
        } else {
            Store::Large {
                index: Index::new(slots),
                line: vec![EMPTY; slots],
                mask: vec![0; slots],
                stamp: vec![0; slots],
                queue: vec![Queue::default(); sets as usize],
                clock: 0,
                fill: vec![0; sets as usize],
            }
        };
        Cache {
            sets,
            set_mask: sets.is_power_of_two().then(|| sets - 1),
            ways,
            policy: c.policy,
            rng: c.seed | 1,
            store,
        }
    }

    #[inline]
    fn set_of(&self, line: u64) -> u64 {
        match self.set_mask {
            Some(m) => line & m,
            None => line % self.sets,
        }
    }

    /// Touch `line` wanting the sectors in `want`; returns the sectors that
    /// were missing (0 = hit) and the line's sectors present afterwards.
    #[inline(always)]
    fn touch(&mut self, line: u64, want: u32) -> (u32, u32) {
        let set = self.set_of(line) as usize;
        let ways = self.ways;
        let policy = self.policy;
        let rng = &mut self.rng;
        match &mut self.store {
            Store::Small {
                tags,
                masks,
                fill,
                ptr,
            } => {
                let base = set * ways;
                let n = fill[set] as usize;
                let row = &mut tags[base..base + ways];
                let mrow = &mut masks[base..base + ways];
                if let Some(i) = row[..n].iter().position(|&t| t == line) {
                    let missing = want & !mrow[i];
                    mrow[i] |= want;
                    let after = mrow[i];
                    if policy == Policy::Lru && i > 0 {
                        move_to_front(row, mrow, i);
                    }
                    return (missing, after);
                }
                if policy == Policy::Lru {
                    // Insert as most recent; the last way (least recent)
                    // falls off when the set is full.
                    let k = n.min(ways - 1);
                    row[k] = line;
                    mrow[k] = want;
                    move_to_front(row, mrow, k);
                } else {
                    let slot = if n < ways {
                        n
                    } else if policy == Policy::Fifo {
                        let p = ptr[set] as usize;
                        ptr[set] = ((p + 1) % ways) as u8;
                        p
                    } else {
                        (xorshift(rng) % ways as u64) as usize
                    };
                    row[slot] = line;
                    mrow[slot] = want;
                }
                if n < ways {
                    fill[set] += 1;
                }
                (want, want)
            }
            Store::Front(f) => f.touch(line, want),
            Store::Large { .. } => self.touch_large(line, want, set),
        }
    }
    /// [`Cache::touch`] for more than 16 ways (kept out of line: the hot
    /// small-set path stays small where it is inlined).
    #[inline(never)]
    fn touch_large(&mut self, line: u64, want: u32, set: usize) -> (u32, u32) {
        let ways = self.ways;
        let policy = self.policy;
        let rng = &mut self.rng;
        let Store::Large {
            index,
            line: lines,
            mask,
            stamp,
            queue,
            clock,
            fill,
        } = &mut self.store
        else {
            unreachable!("touch_large on a small store")
        };
        let queue = &mut queue[set];
        let s = index.get(line);
        if s != NONE {
            let s = s as usize;
            let missing = want & !mask[s];
            mask[s] |= want;
            // Already the most recent: nothing to reorder.
            if policy == Policy::Lru && queue.last() != Some((s as u32, stamp[s])) {
                *clock += 1;
                stamp[s] = *clock;
                queue.push((s as u32, *clock), ways, stamp);
            }
            return (missing, mask[s]);
        }
        let n = fill[set] as usize;
        let slot = if n < ways {
            fill[set] += 1;
            set * ways + n
        } else if policy == Policy::Random {
            let victim = set * ways + (xorshift(rng) % ways as u64) as usize;
            index.set(lines[victim], NONE);
            victim
        } else {
            let victim = queue.pop_oldest(stamp);
            index.set(lines[victim], NONE);
            victim
        };
        lines[slot] = line;
        mask[slot] = want;
        index.set(line, slot as u32);
        if policy != Policy::Random {
            *clock += 1;
            stamp[slot] = *clock;
            queue.push((slot as u32, *clock), ways, stamp);
        }
        (want, want)
    }
}

/// A fully associative LRU cache split in two by recency: the
/// [`Front::LEN`] most recent lines in a short array that a lookup
/// compares at once (their order kept by stamps: the least recent has the
/// smallest), and the rest, in the order they left the front, in a
/// store like [`Store::Large`]'s (index, stamps, queue) of the other ways.
///
/// Lines leave the front least recent first, so the back's order of
/// arrival is their recency order, and front and back together hold the
/// `ways` most recent lines in LRU order: the same cache, hit for hit.
/// Most reads of a texture's trace are of lines read a few lines ago
/// (in the 1080p trilinear plane, 7 in 8 of the reads the recorder keeps
/// are within the 16 most recent lines): those cost a compare of 16 tags
/// and a stamp, where the one store of all ways costs a hash probe, a
/// stamp and a queue entry (that must later be compacted).
struct Front {
    /// The front: lines ([`EMPTY`] while not full), their low 32 bits
    /// (compared four to a register), sectors, stamps.
    line: [u64; Front::LEN],
    low: [u32; Front::LEN],
    mask: [u32; Front::LEN],
    stamp: [u64; Front::LEN],
    len: usize,
    clock: u64,
    /// The back: `ways - LEN` slots (see `Store::Large`; a stamp of 0
    /// marks a slot whose line moved to the front).
    index: Index,
    back_line: Vec<u64>,
    back_mask: Vec<u32>,
    back_stamp: Vec<u64>,
    queue: Queue,
    /// Slots never used, and slots freed by a line moving to the front.
    fill: usize,
    free: Vec<u32>,
}

impl Front {
    const LEN: usize = 16;
    /// Ways at which the split pays (a back at least as long as the front).
    const MIN_WAYS: usize = 2 * Front::LEN;

    fn new(ways: usize) -> Self {
        let back = ways - Front::LEN;
        Front {
            line: [EMPTY; Front::LEN],
            low: [EMPTY as u32; Front::LEN],
            mask: [0; Front::LEN],
            stamp: [0; Front::LEN],
            len: 0,
            clock: 0,
            index: Index::new(back),
            back_line: vec![EMPTY; back],
            back_mask: vec![0; back],
            back_stamp: vec![0; back],
            queue: Queue::default(),
            fill: 0,
            free: Vec::new(),
        }
    }

    /// [`Cache::touch`].
    #[inline(always)]
    fn touch(&mut self, line: u64, want: u32) -> (u32, u32) {
        // The low halves all compared at once (which one hits is data,
        // a loop's exit would be mispredicted); the candidates, almost
        // always none or the one, checked whole.
        let mut m = equal_lanes(&self.low, line as u32);
        let i = loop {
            if m == 0 {
                return self.touch_back(line, want);
            }
            let i = m.trailing_zeros() as usize;
            if self.line[i] == line {
                break i;
            }
            m &= m - 1;
        };
        let missing = want & !self.mask[i];
        self.mask[i] |= want;
        self.clock += 1;
        self.stamp[i] = self.clock;
        (missing, self.mask[i])
    }

    /// A line not in the front: taken from the back if there (a hit),
    /// and made the front's most recent; the front's least recent line
    /// moves to the back as its most recent.
    #[inline(never)]
    fn touch_back(&mut self, line: u64, want: u32) -> (u32, u32) {
        let s = self.index.get(line);
        let had = if s == NONE {
            0
        } else {
            let s = s as usize;
            self.index.set(line, NONE);
            self.back_line[s] = EMPTY;
            self.back_stamp[s] = 0;
            self.free.push(s as u32);
            self.back_mask[s]
        };
        let i = if self.len < Front::LEN {
            self.len += 1;
            self.len - 1
        } else {
            let mut v = 0;
            for k in 1..Front::LEN {
                if self.stamp[k] < self.stamp[v] {
                    v = k;
                }
            }
            self.demote(self.line[v], self.mask[v]);
            v
        };
        self.clock += 1;
        (self.line[i], self.low[i]) = (line, line as u32);
        (self.mask[i], self.stamp[i]) = (had | want, self.clock);
        (want & !had, had | want)
    }

    /// Put a line that leaves the front into the back as its most
    /// recent, evicting the back's least recent when it is full.
    fn demote(&mut self, line: u64, mask: u32) {
        let ways = self.back_line.len();
        let slot = if let Some(s) = self.free.pop() {
            s as usize
        } else if self.fill < ways {
            self.fill += 1;
            self.fill - 1
        } else {
            // Full, no slot freed: every slot has a live queue entry.
            let v = self.queue.pop_oldest(&self.back_stamp);
            self.index.set(self.back_line[v], NONE);
            v
        };
        self.back_line[slot] = line;
        self.back_mask[slot] = mask;
        self.index.set(line, slot as u32);
        self.clock += 1;
        self.back_stamp[slot] = self.clock;
        self.queue
            .push((slot as u32, self.clock), ways, &self.back_stamp);
    }
}

/// Bit `i` set where `v[i] == x`: four SSE2 compares (every x86-64 has
/// SSE2), a loop elsewhere.
#[inline(always)]
fn equal_lanes(v: &[u32; 16], x: u32) -> u32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            __m128i, _mm_castsi128_ps, _mm_cmpeq_epi32, _mm_loadu_si128, _mm_movemask_ps,
            _mm_set1_epi32,
        };
        #[allow(unsafe_code)]
        // SAFETY: SSE and SSE2 are part of x86-64, so every CPU this
        // runs on has the intrinsics; each `part` is four readable `u32`s,
        // exactly one unaligned 16-byte load.
        unsafe {
            let key = _mm_set1_epi32(x as i32);
            let mut m = 0u32;
            for (k, part) in v.chunks_exact(4).enumerate() {
                let lanes = _mm_loadu_si128(part.as_ptr().cast::<__m128i>());
                let eq = _mm_castsi128_ps(_mm_cmpeq_epi32(lanes, key));
                m |= (_mm_movemask_ps(eq) as u32) << (4 * k);
            }
            m
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let mut m = 0u32;
        for (i, &l) in v.iter().enumerate() {
            m |= ((l == x) as u32) << i;
        }
        m
    }
}

/// One set's (slot, stamp) entries in the order of use, from `head` on
/// (see `Store::Large`).
#[derive(Clone, Debug, Default)]
struct Queue {
    entries: Vec<(u32, u64)>,
    head: usize,
}

impl Queue {
    #[inline(always)]
    fn last(&self) -> Option<(u32, u64)> {
        self.entries.last().copied()
    }

    /// Append an entry; past four entries per way (and a few) in the
    /// queue, or as many popped ones before it, keep only the live ones
    /// (in order): the memory stays within a few entries per way.
    #[inline(always)]
    fn push(&mut self, e: (u32, u64), ways: usize, stamp: &[u64]) {
        self.entries.push(e);
        let limit = 4 * ways + 16;
        if self.entries.len() - self.head > limit || self.head > limit {
            self.compact(stamp);
        }
    }

    #[inline(never)]
    fn compact(&mut self, stamp: &[u64]) {
        let mut j = 0;
        for i in self.head..self.entries.len() {
            let (k, t) = self.entries[i];
            if stamp[k as usize] == t {
                self.entries[j] = (k, t);
                j += 1;
            }
        }
        self.entries.truncate(j);
        self.head = 0;
    }

    /// Remove and return the oldest live slot. A full set has a live
    /// entry per slot; an empty queue (which a full set never has) gives
    /// slot 0 rather than a panic.
    #[inline(always)]
    fn pop_oldest(&mut self, stamp: &[u64]) -> usize {
        while let Some(&(k, t)) = self.entries.get(self.head) {
            self.head += 1;
            if stamp[k as usize] == t {
                return k as usize;
            }
        }
        0
    }
}

/// Move way `i` of a short recency-ordered set to the front (an element
/// loop: `rotate_right` calls `memmove`, which costs more than the move
/// for at most 16 ways).
#[inline(always)]
fn move_to_front(tags: &mut [u64], masks: &mut [u32], i: usize) {
    let (t, m) = (tags[i], masks[i]);
    let mut j = i;
    while j > 0 {
        tags[j] = tags[j - 1];
        masks[j] = masks[j - 1];
        j -= 1;
    }
    tags[0] = t;
    masks[0] = m;
}

/// xorshift64*: the random policy's generator (the plain model uses the
/// same one, so both pick the same ways).
#[inline]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    let mut x = *state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *state = x;
    x.wrapping_mul(0x2545_F491_4F6C_DD1D)
}

/// Lines (and sectors) ever touched: the cold-miss test and the working set.
enum Touched {
    Dense(Vec<u32>),
    Hash(LineMap<u32>),
}

impl Touched {
    fn new(space: AddressSpace, line_shift: u32) -> Self {
        match space {
            AddressSpace::Bounded(b) if (b >> line_shift) < (1 << 28) => {
                Touched::Dense(vec![0; ((b >> line_shift) + 1) as usize])
            }
            _ => Touched::Hash(LineMap::default()),
        }
    }
    /// Mark `mask`'s sectors of `line`; returns (sectors touched before,
    /// whether the line is new).
    #[inline]
    fn mark(&mut self, line: u64, mask: u32) -> (u32, bool) {
        let slot = match self {
            Touched::Dense(v) => match v.get_mut(line as usize) {
                Some(x) => x,
                None => return (0, true),
            },
            Touched::Hash(m) => m.entry(line).or_insert(0),
        };
        let before = *slot;
        *slot |= mask;
        (before, before == 0)
    }
}

/// Statistics of a simulation.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// First-level totals.
    pub total: Counters,
    /// First-level counters per mip level (index = level).
    pub per_level: Vec<Counters>,
    /// Second-level totals, when there is one (it sees the first level's
    /// fetches as reads).
    pub l2: Option<Counters>,
}

impl Stats {
    /// Bytes that reach memory: the last level's fetches.
    pub fn bytes_from_memory(&self) -> u64 {
        self.l2.as_ref().unwrap_or(&self.total).bytes_fetched
    }
}

/// A cache (with an optional second level) and its statistics.
pub struct Simulator {
    l1: Cache,
    shadow: Option<Cache>,
    touched: Touched,
    l2: Option<Cache>,
    l2_line_shift: u32,
    l2_sector_shift: u32,
    l2_sectors: u32,
    line_shift: u32,
    sector_shift: u32,
    sector_bytes: u64,
    stats: Stats,
    /// The line of the last access and the sectors it holds in the cache
    /// and in the shadow: a repeat needing no more is a hit that changes
    /// no state (it is most recent in both already).
    last_line: u64,
    last_mask: u32,
    /// [`Simulator::access_group`]'s lines: (line, sectors, level).
    group: Vec<(u64, u32, u32)>,
}

impl Simulator {
    /// A simulator of `l1` (and `l2`) over `space`; `classify` runs the
    /// fully associative shadow that splits misses into the 3C classes.
    pub fn new(
        l1: &CacheConfig,
        l2: Option<&CacheConfig>,
        space: AddressSpace,
        classify: bool,
    ) -> Result<Self> {
        l1.validate()?;
        if let Some(c) = l2 {
            c.validate()?;
        }
        let line_shift = l1.line.trailing_zeros();
        let sector = l1.sector.unwrap_or(l1.line);
        Ok(Simulator {
            l1: Cache::new(l1),
            shadow: classify.then(|| Cache::new(&l1.fully_associative())),
            touched: Touched::new(space, line_shift),
            l2: l2.map(Cache::new),
            l2_line_shift: l2.map_or(0, |c| c.line.trailing_zeros()),
            l2_sector_shift: l2.map_or(0, |c| c.sector.unwrap_or(c.line).trailing_zeros()),
            l2_sectors: l2.map_or(1, |c| c.sector.map_or(1, |s| (c.line / s) as u32)),
            line_shift,
            sector_shift: sector.trailing_zeros(),
            sector_bytes: sector,
            stats: Stats {
                l2: l2.map(|_| Counters::default()),
                ..Stats::default()
            },
            last_line: u64::MAX,
            last_mask: 0,
            group: Vec::new(),
        })
    }

    /// The statistics so far (the hot path counts accesses and misses per
    /// level only; hits and the totals are filled in here).
    pub fn stats(&self) -> Stats {
        let mut s = self.stats.clone();
        let mut total = Counters::default();
        for c in &mut s.per_level {
            c.hits = c.accesses - c.misses;
            total.accesses += c.accesses;
            total.hits += c.hits;
            total.misses += c.misses;
            total.cold += c.cold;
            total.capacity += c.capacity;
            total.conflict += c.conflict;
            total.bytes_fetched += c.bytes_fetched;
            total.lines_touched += c.lines_touched;
        }
        s.total = total;
        if let Some(l2) = &mut s.l2 {
            l2.hits = l2.accesses - l2.misses;
        }
        s
    }

    /// Consume into the statistics.
    pub fn into_stats(self) -> Stats {
        self.stats()
    }

    /// An access of `bytes` bytes at `address` (a texel of mip level
    /// `level`, for the per-level counters).
    #[inline]
    pub fn access(&mut self, address: u64, bytes: u64, level: u32) {
        self.access_inner(address, bytes, level, |_, _| {});
    }

    /// `n` more accesses of the line the last access touched, at `level`:
    /// hits that change nothing (the line is most recent in the cache and
    /// in the shadow). Only for a last access that touched one line and
    /// wanted all of its sectors, as a texel read of a cache without
    /// sectors does (the fast path of [`Simulator::access`] for a repeat).
    #[inline]
    pub(crate) fn repeat_hits(&mut self, level: u32, n: u64) {
        // The access before made the level's counters.
        self.stats.per_level[level as usize].accesses += n;
    }

    /// [`Simulator::access`], calling `each(line, outcome)` for every line
    /// the access touches (tests compare these sequences).
    pub fn access_with(
        &mut self,
        address: u64,
        bytes: u64,
        level: u32,
        each: &mut dyn FnMut(u64, Outcome),
    ) {
        self.access_inner(address, bytes, level, each);
    }

    #[inline(always)]
    fn access_inner(
        &mut self,
        address: u64,
        bytes: u64,
        level: u32,
        mut each: impl FnMut(u64, Outcome),
    ) {
        self.level_counters(level);
        let end = address.saturating_add(bytes.max(1) - 1);
        let (first, last) = (address >> self.line_shift, end >> self.line_shift);
        if first == last && self.sector_shift == self.line_shift {
            // The common case: one line, no sectors.
            let o = self.touch_line(first, 1, level);
            each(first, o);
            return;
        }
        for line in first..=last {
            let want = self.sectors(address, end, line);
            let o = self.touch_line(line, want, level);
            each(line, o);
        }
    }

    /// Make sure level `level` has counters.
    #[inline(always)]
    fn level_counters(&mut self, level: u32) {
        if (level as usize) >= self.stats.per_level.len() {
            self.stats
                .per_level
                .resize(level as usize + 1, Counters::default());
        }
    }

    /// The sectors of `line` that bytes `address ..= end` touch.
    #[inline(always)]
    fn sectors(&self, address: u64, end: u64, line: u64) -> u32 {
        if self.sector_shift == self.line_shift {
            return 1;
        }
        let line_mask = (1u64 << self.line_shift) - 1;
        let base = line << self.line_shift;
        let lo = address.max(base) - base;
        let hi = end.min(base + line_mask) - base;
        let (s0, s1) = (lo >> self.sector_shift, hi >> self.sector_shift);
        (((1u64 << (s1 + 1)) - 1) as u32) & !(((1u64 << s0) - 1) as u32)
    }

    /// Accesses read together (a 2×2 quad's texel reads), each `(address,
    /// bytes, level)`: every line they touch is requested once, in the
    /// order first touched, wanting every sector any of them touches, and
    /// counted at the level of the access that first touched it;
    /// `each(line, outcome)` is called per request.
    pub fn access_group(
        &mut self,
        accesses: impl IntoIterator<Item = (u64, u64, u32)>,
        mut each: impl FnMut(u64, Outcome),
    ) {
        let mut group = std::mem::take(&mut self.group);
        group.clear();
        for (address, bytes, level) in accesses {
            let end = address.saturating_add(bytes.max(1) - 1);
            for line in (address >> self.line_shift)..=(end >> self.line_shift) {
                let want = self.sectors(address, end, line);
                // Most repeats are of the line just added.
                match group.iter_mut().rev().find(|g| g.0 == line) {
                    Some(g) => g.1 |= want,
                    None => group.push((line, want, level)),
                }
            }
        }
        for &(line, want, level) in &group {
            self.level_counters(level);
            let o = self.touch_line(line, want, level);
            each(line, o);
        }
        self.group = group;
    }

    #[inline(always)]
    fn touch_line(&mut self, line: u64, want: u32, level: u32) -> Outcome {
        if line == self.last_line && want & !self.last_mask == 0 {
            self.stats.per_level[level as usize].accesses += 1;
            return Outcome::Hit;
        }
        let (missing, held) = self.l1.touch(line, want);
        let shadow = self.shadow.as_mut().map(|s| s.touch(line, want));
        self.last_line = line;
        self.last_mask = held & shadow.map_or(u32::MAX, |s| s.1);
        if missing == 0 {
            self.stats.per_level[level as usize].accesses += 1;
            return Outcome::Hit;
        }
        // Only a miss can touch something for the first time.
        let (before, new_line) = self.touched.mark(line, want);
        let outcome = match shadow {
            None => Outcome::Miss,
            Some(_) if missing & before != missing => Outcome::Cold,
            Some((0, _)) => Outcome::Conflict,
            Some(_) => Outcome::Capacity,
        };
        let fetched = missing.count_ones() as u64 * self.sector_bytes;
        let lv = &mut self.stats.per_level[level as usize];
        lv.add(outcome, fetched);
        if new_line {
            lv.lines_touched += 1;
        }
        self.fetch_l2(line, missing);
        outcome
    }

    /// The second level sees each missing sector run of the first as a read.
    fn fetch_l2(&mut self, line: u64, missing: u32) {
        // `new` sets the second level and its counters together.
        let (Some(l2), Some(c)) = (self.l2.as_mut(), self.stats.l2.as_mut()) else {
            return;
        };
        let mut m = missing;
        while m != 0 {
            let s = m.trailing_zeros() as u64;
            m &= m - 1;
            let addr = (line << self.line_shift) + (s << self.sector_shift);
            let end = addr + self.sector_bytes - 1;
            for l in (addr >> self.l2_line_shift)..=(end >> self.l2_line_shift) {
                let base = l << self.l2_line_shift;
                let lo = addr.max(base) - base;
                let hi = end.min(base + (1u64 << self.l2_line_shift) - 1) - base;
                let (s0, s1) = (lo >> self.l2_sector_shift, hi >> self.l2_sector_shift);
                let want = (((1u64 << (s1 + 1)) - 1) as u32) & !(((1u64 << s0) - 1) as u32);
                let want = want & (((1u64 << self.l2_sectors) - 1) as u32);
                let (miss, _) = l2.touch(l, want);
                let o = if miss == 0 {
                    Outcome::Hit
                } else {
                    Outcome::Miss
                };
                c.add(o, miss.count_ones() as u64 * (1u64 << self.l2_sector_shift));
            }
        }
    }
}
