//! A prefetching texture unit after Igehy, Eldridge and Proudfoot
//! ("Prefetching in a texture cache architecture", Graphics Hardware
//! 1998): the cache's tags are looked up when a fragment enters the unit,
//! its missing lines are requested from memory at once, and the fragment
//! waits in a FIFO until its data is back; a deeper FIFO lets more
//! requests be in flight, so more of the memory latency is hidden.
//!
//! # The model
//! Time is counted in cycles. Fragments (a pixel's query, or a 2×2
//! quad's four) arrive in raster order and the unit filters at most one
//! per cycle. A FIFO of depth `D` holds fragments whose tags were looked
//! up and that wait for the filter; with the one being filtered, at most
//! `D + 1` fragments are in the unit. For fragment `i`:
//!
//! - it enters (tag lookup) at `enter_i = max(enter_{i−1} + 1,
//!   leave_{i−D−1})`: one fragment per cycle, and only when there is room;
//! - its lines are looked up in the tags in order, each line once (a
//!   line it already requested that the tags now hit is that request);
//!   each line the tags miss is requested from memory at
//!   `max(enter_i, previous request + B)` (`B` cycles per line request:
//!   the memory's bandwidth) and arrives `L` cycles later (the latency);
//! - it reaches the filter at `start_i = max(enter_i, leave_{i−1})` and
//!   leaves at `leave_i = max(start_i, ready_i) + 1`, where `ready_i` is
//!   the latest arrival of any line it reads (missed by it, or missed by
//!   an earlier fragment and still on its way).
//!
//! The tags see every fragment's lines in raster order, whatever the
//! timing, so hits and misses are those of the plain cache model: this is
//! the point of the paper's architecture, whose reorder buffer and
//! in-order data cache keep a prefetched line from displacing one that an
//! earlier fragment still needs. The model takes the cache's outcomes per
//! fragment ([`Prefetch::fragment`]) and adds the times.
//!
//! Reported ([`PrefetchStats`]): the cycles of the frame and the cycles
//! lost to waiting for memory (`cycles − fragments`); the fragments that
//! waited at the head of the FIFO; the stall-free hit rate (line requests
//! whose data was present when their fragment reached the filter); and,
//! against a blocking cache (`D = 0`: a fragment is looked up only when
//! the one before it has left, so every miss costs the whole latency), the
//! share of its lost cycles that the FIFO recovers.
//!
//! Two properties follow from the definitions and are tested
//! (`tests/core/cache_report/cache_quads_prefetch.rs`, with a hand-worked trace): with
//! `D = 0` the stall-free hit rate is the cache's hit rate (for `L ≥ 1`);
//! and every time above is a non-decreasing function of earlier times in
//! which a deeper FIFO only ever makes `leave_{i−D−1}` an earlier leave,
//! so a deeper FIFO never takes more cycles.

use crate::error::{Error, Result};

/// The timing parameters of [`Prefetch`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Timing {
    /// FIFO depth `D` in fragments (0: a blocking cache).
    pub depth: u32,
    /// Memory latency `L` in cycles.
    pub latency: u32,
    /// Cycles between line requests `B` (1: a line per cycle).
    pub request_cycles: u32,
}

impl Timing {
    /// Check the parameters: a request interval of at least 1 and a
    /// latency up to a million cycles.
    pub fn validate(&self) -> Result<()> {
        if self.request_cycles == 0 {
            return Err(Error::InvalidOption(
                "the memory needs at least one cycle per line request".into(),
            ));
        }
        if self.latency > 1_000_000 {
            return Err(Error::InvalidOption(format!(
                "a memory latency of {} cycles is more than the million the model takes",
                self.latency
            )));
        }
        if self.depth > 1 << 20 {
            return Err(Error::InvalidOption(format!(
                "a FIFO of {} fragments is more than the 2^20 the model takes",
                self.depth
            )));
        }
        Ok(())
    }
}

/// What [`Prefetch`] measured over a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PrefetchStats {
    /// The parameters.
    pub timing: Timing,
    /// Fragments.
    pub fragments: u64,
    /// Line requests: per fragment, each line once (again if it missed
    /// again), see [`Prefetch::fragment`].
    pub requests: u64,
    /// Requests the tags missed (lines fetched from memory).
    pub misses: u64,
    /// Cycles until the last fragment left.
    pub cycles: u64,
    /// Fragments that waited for memory at the head of the FIFO.
    pub stalled_fragments: u64,
    /// Requests whose line was present when their fragment reached the
    /// filter.
    pub stall_free_requests: u64,
    /// Cycles of the same frame through a blocking cache (`D = 0`, same
    /// latency and bandwidth).
    pub blocking_cycles: u64,
}

impl PrefetchStats {
    /// Cycles lost to waiting for memory: cycles beyond one per fragment.
    pub fn stall_cycles(&self) -> u64 {
        self.cycles.saturating_sub(self.fragments)
    }

    /// [`PrefetchStats::stall_cycles`] of the blocking cache.
    pub fn blocking_stall_cycles(&self) -> u64 {
        self.blocking_cycles.saturating_sub(self.fragments)
    }

    /// Stall-free requests per request (1 when there were none).
    pub fn stall_free_hit_rate(&self) -> f64 {
        if self.requests == 0 {
            1.0
        } else {
            self.stall_free_requests as f64 / self.requests as f64
        }
    }

    /// The share of the blocking cache's lost cycles this FIFO recovers
    /// (1 when the blocking cache lost none).
    pub fn latency_hidden(&self) -> f64 {
        let b = self.blocking_stall_cycles();
        if b == 0 {
            1.0
        } else {
            1.0 - self.stall_cycles() as f64 / b as f64
        }
    }

    /// `fragments / cycles`: the share of the unit's peak rate (one
    /// fragment per cycle) reached.
    pub fn efficiency(&self) -> f64 {
        if self.cycles == 0 {
            1.0
        } else {
            self.fragments as f64 / self.cycles as f64
        }
    }
}

/// One FIFO depth's clock.
struct Clock {
    depth: usize,
    /// `leave` of the last `depth + 1` fragments, a ring indexed by
    /// fragment number.
    leaves: Vec<u64>,
    enter: u64,
    leave: u64,
    last_request: Option<u64>,
    /// Arrival cycle of each line's latest fetch (0: long ago).
    arrival: Vec<u64>,
    stalled: u64,
    stall_free: u64,
}

impl Clock {
    fn new(depth: u32, lines: usize) -> Self {
        Clock {
            depth: depth as usize,
            leaves: vec![0; depth as usize + 1],
            enter: 0,
            leave: 0,
            last_request: None,
            arrival: vec![0; lines],
            stalled: 0,
            stall_free: 0,
        }
    }

    /// Fragment number `n` reading `lines` (line, missed by the tags).
    fn fragment(&mut self, n: u64, lines: &[(u64, bool)], latency: u64, interval: u64) {
        let slot = (n % (self.depth as u64 + 1)) as usize;
        // leave_{n−D−1} is the entry this fragment's slot still holds.
        let room = if n > self.depth as u64 {
            self.leaves[slot]
        } else {
            0
        };
        let enter = if n == 0 {
            room
        } else {
            (self.enter + 1).max(room)
        };
        let start = enter.max(self.leave);
        let mut ready = 0u64;
        for &(line, missed) in lines {
            let Some(at) = self.arrival.get_mut(line as usize) else {
                continue;
            };
            if missed {
                let request = match self.last_request {
                    Some(r) => enter.max(r + interval),
                    None => enter,
                };
                self.last_request = Some(request);
                *at = request + latency;
            }
            if *at <= start {
                self.stall_free += 1;
            }
            ready = ready.max(*at);
        }
        if ready > start {
            self.stalled += 1;
        }
        self.enter = enter;
        self.leave = start.max(ready) + 1;
        self.leaves[slot] = self.leave;
    }
}

/// The prefetching unit at one or more FIFO depths (one pass over the
/// cache's outcomes), and the blocking cache beside them.
pub struct Prefetch {
    timings: Vec<Timing>,
    clocks: Vec<Clock>,
    blocking: Clock,
    fragments: u64,
    requests: u64,
    misses: u64,
    /// The current fragment's requests.
    scratch: Vec<(u64, bool)>,
}

impl Prefetch {
    /// The model at each of `timings` (and a blocking cache of the first
    /// one's latency and bandwidth) over line numbers below `lines`.
    /// Times per line are kept in a table of `lines` entries, allocated
    /// zeroed: only the pages of lines the frame reads are touched.
    pub fn new(timings: &[Timing], lines: u64) -> Result<Self> {
        let first = timings
            .first()
            .ok_or_else(|| Error::InvalidOption("the prefetch model needs a FIFO depth".into()))?;
        for t in timings {
            t.validate()?;
            if (t.latency, t.request_cycles) != (first.latency, first.request_cycles) {
                return Err(Error::InvalidOption(
                    "the FIFO depths of one prefetch run share one latency and bandwidth".into(),
                ));
            }
        }
        let lines = usize::try_from(lines)
            .ok()
            .filter(|&n| n <= 1 << 30)
            .ok_or_else(|| {
                Error::InvalidOption(format!(
                    "{lines} cache lines is more than the prefetch model's 2^30"
                ))
            })?;
        Ok(Prefetch {
            timings: timings.to_vec(),
            clocks: timings.iter().map(|t| Clock::new(t.depth, lines)).collect(),
            blocking: Clock::new(0, lines),
            fragments: 0,
            requests: 0,
            misses: 0,
            scratch: Vec::new(),
        })
    }

    /// The next fragment in raster order: the lines it reads in order,
    /// each with whether the cache's tags missed it. A line the fragment
    /// already requested that the tags now hit is that same request (its
    /// data comes with it), not another one; a line missed again (evicted
    /// in between) is a new request. Lines at or above the table's size
    /// are ignored.
    pub fn fragment(&mut self, lines: &[(u64, bool)]) {
        let (latency, interval) = (
            self.timings[0].latency as u64,
            self.timings[0].request_cycles as u64,
        );
        let mut requests = std::mem::take(&mut self.scratch);
        requests.clear();
        for &(line, missed) in lines {
            if missed || !requests.iter().any(|r: &(u64, bool)| r.0 == line) {
                requests.push((line, missed));
            }
        }
        let n = self.fragments;
        for c in &mut self.clocks {
            c.fragment(n, &requests, latency, interval);
        }
        self.blocking.fragment(n, &requests, latency, interval);
        self.fragments += 1;
        self.requests += requests.len() as u64;
        self.misses += requests.iter().filter(|l| l.1).count() as u64;
        self.scratch = requests;
    }

    /// The statistics per timing, in the order given.
    pub fn stats(&self) -> Vec<PrefetchStats> {
        self.timings
            .iter()
            .zip(&self.clocks)
            .map(|(t, c)| PrefetchStats {
                timing: *t,
                fragments: self.fragments,
                requests: self.requests,
                misses: self.misses,
                cycles: c.leave,
                stalled_fragments: c.stalled,
                stall_free_requests: c.stall_free,
                blocking_cycles: self.blocking.leave,
            })
            .collect()
    }
}
