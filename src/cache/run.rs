//! Driving the cache model from a scene: every pixel's query is filtered by
//! a sampler whose texel reads become byte addresses of a chain layout, in
//! raster order, and the addresses are simulated in that order.
//!
//! Sampling runs in chunks of pixels, on as many threads as rayon's pool
//! has; each chunk's addresses are recorded, and the chunks are fed to the
//! simulator in raster order by one of those threads, which samples chunks
//! too while the next one to simulate is not ready (sampling and
//! simulation overlap, `par::produce_consume`). The recorded form
//! ([`Trace`]) packs an access into one `u64`: the address in the low 56
//! bits, the mip level (or [`SAT_LEVEL`] for a summed-area-table entry) in
//! the top 8.

use std::io::{BufRead, Write};

use rayon::prelude::*;

use super::isotropic::{AddressOnly, BlockSink};
use super::layout::{ChainLayout, Lanes};
use super::prefetch::{Prefetch, PrefetchStats, Timing};
use super::sim::{AddressSpace, CacheConfig, Outcome, Policy, Simulator, Stats};
use crate::error::{Error, Result};
use crate::sample::{Query, Sampler, TexelSink};
use crate::scene::{Frame, RasterOrder, Scene, View};

/// The level tag of a summed-area-table entry read.
pub const SAT_LEVEL: u32 = 255;
const ADDRESS_BITS: u32 = 56;
const ADDRESS_MASK: u64 = (1 << ADDRESS_BITS) - 1;

/// Pixels per sampling chunk.
const CHUNK: usize = 8192;

/// Queries made and traced at a time within a chunk (a multiple of the
/// 8 that `AddressOnly::trace_all` plans together).
const QUERY_BATCH: usize = 256;

/// Pack an address and its level.
#[inline]
pub fn pack(address: u64, level: u32) -> u64 {
    (address & ADDRESS_MASK) | ((level.min(SAT_LEVEL) as u64) << ADDRESS_BITS)
}

/// Unpack an access: (address, level).
#[inline]
pub fn unpack(a: u64) -> (u64, u32) {
    (a & ADDRESS_MASK, (a >> ADDRESS_BITS) as u32)
}

/// A sink that turns texel and table-entry reads into packed addresses.
/// Table-entry reads are recorded only when the layout has the table
/// ([`ChainLayout::for_sampler`] lays it out for a `sat` sampler).
pub struct AddressSink<'a> {
    layout: &'a ChainLayout,
    /// The packed accesses so far.
    pub out: Vec<u64>,
}

impl<'a> AddressSink<'a> {
    /// An empty sink over `layout`.
    pub fn new(layout: &'a ChainLayout) -> Self {
        AddressSink {
            layout,
            out: Vec::new(),
        }
    }
}

impl TexelSink for AddressSink<'_> {
    #[inline]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        self.out.push(pack(self.layout.address(level, x, y), level));
    }
    #[inline]
    fn sat_entry(&mut self, x: u32, y: u32) {
        // A layout without the table has no address for the entry: the
        // read is not recorded (`SceneSetup::simulate` refuses that pair).
        if let Some(a) = self.layout.sat_address(x, y) {
            self.out.push(pack(a, SAT_LEVEL));
        }
    }
}

/// How the [`Recorder`] may keep reads as fewer entries: lines of
/// `1 << shift` bytes, and a window of the last `window` distinct lines
/// (see [`Window`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Merge {
    shift: u32,
    window: usize,
}

/// The longest window a [`Merge`] uses.
const MAX_WINDOW: usize = 4;

/// The last few distinct lines one layout's reads touched, most recent
/// first, for [`Recorder`].
///
/// Every line in the window was read since the oldest of them was, so at
/// most `window` distinct lines were read since any of them was last read:
/// in an LRU cache of at least `window` ways (and in the fully associative
/// shadow, which is larger) each is still present, and a read of one of
/// them is a hit. A hit changes no counts but the hits, only the recency
/// order of the lines read; so such reads are counted (`pending`) instead
/// of recorded, and before the next read of a line outside the window the
/// lines read meanwhile are recorded once each, least recent first (the
/// lines of the window not read meanwhile are older than all of them):
/// the cache then holds its lines in the order the full sequence leaves.
/// With a window of one this is the merging of consecutive reads of one
/// line, which is a hit that changes nothing under every policy.
#[derive(Clone, Copy, Debug, Default)]
struct Window {
    len: usize,
    line: [u64; MAX_WINDOW],
    /// The packed access recorded for the line (its first read).
    entry: [u64; MAX_WINDOW],
    /// Reads of the line since it was last recorded.
    pending: [u32; MAX_WINDOW],
}

impl Window {
    /// Record the lines with pending reads, least recent first.
    #[inline(always)]
    fn flush(&mut self, out: &mut Vec<u64>, counts: &mut Vec<u32>) {
        for p in (0..self.len).rev() {
            if self.pending[p] > 0 {
                out.push(self.entry[p]);
                counts.push(self.pending[p]);
                self.pending[p] = 0;
            }
        }
    }

    /// Make position `p` the most recent.
    #[inline(always)]
    fn raise(&mut self, p: usize) {
        let (l, e, n) = (self.line[p], self.entry[p], self.pending[p]);
        for k in (0..p).rev() {
            self.line[k + 1] = self.line[k];
            self.entry[k + 1] = self.entry[k];
            self.pending[k + 1] = self.pending[k];
        }
        (self.line[0], self.entry[0], self.pending[0]) = (l, e, n);
    }

    /// A line just recorded (nothing pending), the least recent line
    /// leaving a full window of `size`.
    #[inline(always)]
    fn insert(&mut self, line: u64, entry: u64, size: usize) {
        self.len = (self.len + 1).min(size);
        self.raise(self.len - 1);
        (self.line[0], self.entry[0], self.pending[0]) = (line, entry, 0);
    }
}

/// One layout's recording in a [`Recorder`]: the packed accesses, their
/// counts (when merging) and the window.
#[derive(Debug, Default)]
struct Track {
    out: Vec<u64>,
    counts: Vec<u32>,
    window: Window,
}

impl Track {
    /// `n` reads of the line of packed access `a` (`mergeable`: a texel,
    /// not a table entry) under `merge`.
    #[inline(always)]
    fn put(&mut self, merge: Option<Merge>, a: u64, n: u32, mergeable: bool) {
        let Some(m) = merge else {
            self.out.push(a);
            return;
        };
        let w = &mut self.window;
        let line = a >> m.shift;
        if mergeable && w.len > 0 {
            if w.line[0] == line {
                // Nothing pending: the line's entry is the last one.
                match self.counts.last_mut() {
                    Some(c) if w.pending[0] == 0 => *c += n,
                    _ => w.pending[0] += n,
                }
                return;
            }
            if let Some(p) = (1..w.len).find(|&p| w.line[p] == line) {
                w.raise(p);
                w.pending[0] += n;
                return;
            }
        }
        w.flush(&mut self.out, &mut self.counts);
        self.out.push(a);
        self.counts.push(n);
        if mergeable {
            w.insert(line, a, m.window);
        } else {
            // A read outside the window's reckoning: start it afresh.
            w.len = 0;
        }
    }
}

/// The recording sink of a traced frame: each read's address in every
/// layout (a sweep traces its frame once for all of them), and, when
/// `merge` is set, reads of lines in the window of the last few distinct
/// lines kept as counts on fewer entries (see [`Window`]): the simulator
/// then takes those reads as the hits they are without looking them up.
/// `ONE` is the common case of one layout, compiled without the loop.
struct Recorder<'a, const ONE: bool> {
    layouts: &'a [&'a ChainLayout],
    merge: Option<Merge>,
    /// The first layout's track, held here (the hot case of one layout
    /// reaches it without a load through a vector), then the others'.
    first: Track,
    rest: Vec<Track>,
    /// The layout as 8-lane tables (`ONE` only, where it has them).
    lanes: Option<Lanes>,
}

impl<'a, const ONE: bool> Recorder<'a, ONE> {
    /// A recorder into `reuse`'s vectors (emptied) when given, else into
    /// new ones of `reserve` entries.
    fn new(
        layouts: &'a [&'a ChainLayout],
        merge: Option<Merge>,
        reserve: usize,
        reuse: Option<Buffers>,
    ) -> Self {
        let n = layouts.len();
        let (mut out, mut counts) = reuse.map_or_else(Default::default, |b| (b.out, b.counts));
        out.resize_with(n, || Vec::with_capacity(reserve));
        counts.resize_with(n, || {
            Vec::with_capacity(if merge.is_some() { reserve } else { 0 })
        });
        let mut tracks = out
            .into_iter()
            .zip(counts)
            .take(n)
            .map(|(mut out, mut counts)| {
                out.clear();
                counts.clear();
                Track {
                    out,
                    counts,
                    window: Window::default(),
                }
            });
        let first = tracks.next().unwrap_or_default();
        Recorder {
            layouts,
            merge,
            first,
            rest: tracks.collect(),
            lanes: if ONE { layouts[0].lanes() } else { None },
        }
    }

    /// `n` reads of the line of packed access `a` in layout `i`
    /// (`mergeable`: a texel, not a table entry).
    #[inline(always)]
    fn put(&mut self, i: usize, a: u64, n: u32, mergeable: bool) {
        let track = if i == 0 {
            &mut self.first
        } else {
            &mut self.rest[i - 1]
        };
        track.put(self.merge, a, n, mergeable);
    }

    /// Reads recorded so far (without merging).
    fn len(&self) -> usize {
        self.first.out.len()
    }

    /// The entries and counts, every pending read recorded.
    fn finish(self) -> (Vec<Vec<u64>>, Vec<Vec<u32>>) {
        let merging = self.merge.is_some();
        let (mut outs, mut counts) = (Vec::new(), Vec::new());
        for mut t in std::iter::once(self.first).chain(self.rest) {
            if merging {
                t.window.flush(&mut t.out, &mut t.counts);
                counts.push(t.counts);
            }
            outs.push(t.out);
        }
        (outs, counts)
    }
}

impl<const ONE: bool> BlockSink for Recorder<'_, ONE> {
    /// With one layout that works out a block's addresses together, one
    /// entry for the four reads when the lowest and the highest (the
    /// first and the last) share a merged line.
    #[inline(always)]
    fn block(&mut self, level: u32, x: u32, y: u32) {
        if ONE && let Some(a) = self.layouts[0].block_addresses(level, x, y) {
            self.block_at(level, a);
            return;
        }
        self.texel(level, x, y);
        self.texel(level, x + 1, y);
        self.texel(level, x, y + 1);
        self.texel(level, x + 1, y + 1);
    }

    fn lanes(&self) -> Option<&Lanes> {
        self.lanes.as_ref()
    }

    #[inline(always)]
    fn texel_at(&mut self, level: u32, a: u64) {
        self.put(0, pack(a, level), 1, true);
    }

    #[inline(always)]
    fn block_at(&mut self, level: u32, a: [u64; 4]) {
        let packed = a.map(|a| pack(a, level));
        let line = |k: usize, m: Merge| packed[k] >> m.shift;
        match self.merge {
            Some(m) if line(0, m) == line(3, m) => {
                self.put(0, packed[0], 4, true);
            }
            // Two lines, a row (or a column) of the block in each: reads
            // A A B B (or A B A B) are two of A, then two of B. With a
            // window of two or more lines the second read of A in A B A B
            // is a hit (B cannot have evicted it) and leaves A and B in
            // the same recency order as A A B B does; a window of one
            // (FIFO, random, direct-mapped) is left the reads as they are.
            Some(m)
                if m.window >= 2
                    && ((line(0, m) == line(1, m) && line(2, m) == line(3, m))
                        || (line(0, m) == line(2, m) && line(1, m) == line(3, m))) =>
            {
                let other = if line(0, m) == line(1, m) { 2 } else { 1 };
                self.put(0, packed[0], 2, true);
                self.put(0, packed[other], 2, true);
            }
            _ => {
                // Four calls written out: as an array iterator the loop
                // was compiled out of line (15 % of the run).
                let [a, b, c, d] = packed;
                self.put(0, a, 1, true);
                self.put(0, b, 1, true);
                self.put(0, c, 1, true);
                self.put(0, d, 1, true);
            }
        }
    }
}

impl<const ONE: bool> TexelSink for Recorder<'_, ONE> {
    #[inline(always)]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        if ONE {
            let a = pack(self.layouts[0].address(level, x, y), level);
            self.put(0, a, 1, true);
        } else {
            for i in 0..self.layouts.len() {
                let a = pack(self.layouts[i].address(level, x, y), level);
                self.put(i, a, 1, true);
            }
        }
    }
    #[inline]
    fn sat_entry(&mut self, x: u32, y: u32) {
        for i in 0..self.layouts.len() {
            if let Some(a) = self.layouts[i].sat_address(x, y) {
                self.put(i, pack(a, SAT_LEVEL), 1, false);
            }
        }
    }
}

/// What a run models of the texture unit beside the cache.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Model {
    /// Issue the frame by 2×2 quads ([`RasterOrder::quads`]): the texel
    /// reads of a quad's pixels are one group, whose requests to one
    /// cache line merge into one ([`Simulator::access_group`]).
    pub quads: bool,
    /// The prefetching unit's timings ([`Prefetch`]; all with one latency
    /// and bandwidth), empty for none.
    pub prefetch: Vec<Timing>,
}

/// What a scene run needs: the sampler (its filter), the chain's layout,
/// the scene and how its pixels are visited.
pub struct SceneSetup<'a> {
    /// The sampler whose reads are simulated.
    pub sampler: &'a Sampler,
    /// Addresses of the chain (and of the summed-area table, for `sat`).
    pub layout: &'a ChainLayout,
    /// The scene.
    pub scene: Scene,
    /// The frame.
    pub frame: Frame,
    /// The raster order.
    pub order: RasterOrder,
}

impl SceneSetup<'_> {
    /// Bytes of one access of the given level tag.
    pub fn access_bytes(&self, level: u32) -> u64 {
        if level == SAT_LEVEL {
            self.layout.sat_entry().unwrap_or(self.layout.texel())
        } else {
            self.layout.texel()
        }
    }

    /// The queries of the pixels that show texture, in raster order.
    pub fn queries(&self) -> Vec<Query> {
        let view = self.scene.view(self.frame, self.tex());
        self.order
            .pixel_list(self.frame)
            .par_chunks(CHUNK)
            .flat_map_iter(|c| {
                c.iter()
                    .filter_map(|&(x, y)| view.query(x, y))
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    fn tex(&self) -> (u32, u32) {
        self.sampler.chain().level_size(0).unwrap_or((1, 1))
    }

    fn tracer<'b>(&'b self, layouts: &'b [&'b ChainLayout], issue: Issue) -> Tracer<'b> {
        Tracer {
            sampler: self.sampler,
            address_only: AddressOnly::new(self.sampler),
            layouts,
            view: self.scene.view(self.frame, self.tex()),
            frame: self.frame,
            order: self.order,
            issue,
        }
    }

    /// Every access of the frame, in raster order (for replaying one trace
    /// under many caches). A `sat` sampler's table reads are missing
    /// unless the layout has the table (see [`AddressSink`]).
    pub fn record(&self) -> Trace {
        let layouts = [self.layout];
        let tracer = self.tracer(&layouts, Issue::Stream);
        let list = tracer.unit_list();
        let n = tracer.unit_count(list.as_deref());
        let chunks: Vec<Chunk> = (0..(n as usize).div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| tracer.produce_chunk(list.as_deref(), c, None, None))
            .collect();
        let n = chunks.iter().map(|c| c.accesses[0].len()).sum();
        let mut accesses = Vec::with_capacity(n);
        for c in &chunks {
            accesses.extend_from_slice(&c.accesses[0]);
        }
        Trace {
            accesses,
            pixels: chunks.iter().map(|c| c.pixels).sum(),
            texel_bytes: self.layout.texel(),
            sat_bytes: self.layout.sat_entry().unwrap_or(self.layout.texel()),
        }
    }

    /// Simulate the frame under `l1` (and `l2`), read by read, with
    /// sampling and simulation overlapped; `each` sees every packed access
    /// in order, `progress(done, total)` counts pixels visited. A `sat`
    /// sampler needs a layout with its table ([`ChainLayout::for_sampler`]).
    pub fn simulate(
        &self,
        l1: &CacheConfig,
        l2: Option<&CacheConfig>,
        each: &mut dyn FnMut(u64) -> Result<()>,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<RunStats> {
        self.run(l1, l2, &Model::default(), Some(each), progress)
    }

    /// [`SceneSetup::simulate`] under `model` (quads, prefetching);
    /// `each`, when given, sees every packed texel read in order (before
    /// quads merge them); `progress(done, total)` counts the pixels or
    /// quads visited.
    pub fn run(
        &self,
        l1: &CacheConfig,
        l2: Option<&CacheConfig>,
        model: &Model,
        each: Option<&mut dyn FnMut(u64) -> Result<()>>,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<RunStats> {
        if self.sampler.sat().is_some() && self.layout.sat_entry().is_none() {
            return Err(Error::InvalidOption(
                "the sampler reads a summed-area table the cache layout does not lay out".into(),
            ));
        }
        let layouts = [self.layout];
        let tracer = self.tracer(&layouts, Issue::of(model));
        let jobs = [Job {
            layout: 0,
            l1: *l1,
            l2: l2.copied(),
        }];
        let mut runs = tracer.simulate(&jobs, model, each, progress)?;
        runs.pop()
            .ok_or_else(|| Error::InvalidOption("no cache to simulate".into()))
    }

    /// The frame traced once for every layout of `layouts` (this setup's
    /// own layout aside) and simulated under every job of `jobs`, on all
    /// of rayon's threads while the next pixels are sampled: the runs in
    /// the order of `jobs`. `progress(done, total)` counts the pixels or
    /// quads visited. A `sat` sampler needs layouts with its table.
    pub fn run_jobs(
        &self,
        layouts: &[&ChainLayout],
        jobs: &[Job],
        model: &Model,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<Vec<RunStats>> {
        if self.sampler.sat().is_some() && layouts.iter().any(|l| l.sat_entry().is_none()) {
            return Err(Error::InvalidOption(
                "the sampler reads a summed-area table a cache layout does not lay out".into(),
            ));
        }
        if jobs.iter().any(|j| j.layout >= layouts.len()) {
            return Err(Error::InvalidOption(
                "a simulation names a layout the frame is not traced for".into(),
            ));
        }
        self.tracer(layouts, Issue::of(model))
            .simulate(jobs, model, None, progress)
    }
}

/// One simulation of a frame traced by [`SceneSetup::run_jobs`]: which of
/// its layouts, and the caches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Job {
    /// Index into the layouts the frame is traced for.
    pub layout: usize,
    /// The first-level cache.
    pub l1: CacheConfig,
    /// The second-level cache.
    pub l2: Option<CacheConfig>,
}

/// How the tracer issues the frame's reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Issue {
    /// Pixels in slices, no fragment boundaries (the plain cache model).
    Stream,
    /// Pixel by pixel, each one fragment (the prefetch model needs them).
    Pixels,
    /// 2×2 quads, each one fragment.
    Quads,
}

impl Issue {
    fn of(model: &Model) -> Self {
        if model.quads {
            Issue::Quads
        } else if !model.prefetch.is_empty() {
            Issue::Pixels
        } else {
            Issue::Stream
        }
    }
}

/// The vectors of a consumed [`Chunk`], for the next one to record into.
struct Buffers {
    out: Vec<Vec<u64>>,
    counts: Vec<Vec<u32>>,
}

/// A sampled piece of the frame: per layout the packed accesses, the end
/// of each fragment in them (empty for [`Issue::Stream`]), the pixels
/// that issued a query and the pixels or quads visited.
struct Chunk {
    accesses: Vec<Vec<u64>>,
    /// Per layout, the reads each access stands for (see [`Recorder`]),
    /// empty when every access is one read.
    counts: Vec<Vec<u32>>,
    ends: Vec<usize>,
    pixels: u64,
    units: u64,
}

/// Traces a frame: its pixels (or quads) in raster order, each query
/// filtered by the sampler and its reads recorded in every layout.
struct Tracer<'a> {
    sampler: &'a Sampler,
    /// The sampler's reads without its texels, when it is isotropic.
    address_only: Option<AddressOnly>,
    layouts: &'a [&'a ChainLayout],
    view: View,
    frame: Frame,
    order: RasterOrder,
    issue: Issue,
}

impl Tracer<'_> {
    /// The pixels, or quads, in raster order, when the order needs the
    /// list; `None` when each chunk works out its own
    /// ([`Tracer::units_in`]): the list of a 1080p frame is 16 MiB that
    /// one thread would fill, every page faulted in, before any sampling.
    fn unit_list(&self) -> Option<Vec<(u32, u32)>> {
        match self.issue {
            Issue::Quads => Some(self.order.quads(self.frame)),
            _ if self.order.has_ranges() => None,
            _ => Some(self.order.pixel_list(self.frame)),
        }
    }

    /// How many units [`Tracer::unit_list`] has (or would have).
    fn unit_count(&self, list: Option<&[(u32, u32)]>) -> u64 {
        list.map_or(self.frame.pixels(), |l| l.len() as u64)
    }

    /// Units `start .. start + len`: a slice of `list`, or worked out
    /// into `buf` when there is none.
    fn units_in<'u>(
        &self,
        list: Option<&'u [(u32, u32)]>,
        start: u64,
        len: usize,
        buf: &'u mut Vec<(u32, u32)>,
    ) -> &'u [(u32, u32)] {
        match list {
            Some(l) => &l[start as usize..start as usize + len],
            None => {
                buf.clear();
                self.order.pixel_range(self.frame, start, len, buf);
                buf
            }
        }
    }

    /// Chunk `c` of the frame's units, sampled; `merge`: see
    /// [`Recorder`]; `reuse`: the vectors of a consumed chunk, to record
    /// into.
    fn produce_chunk(
        &self,
        list: Option<&[(u32, u32)]>,
        c: usize,
        merge: Option<Merge>,
        reuse: Option<Buffers>,
    ) -> Chunk {
        let start = (c * CHUNK) as u64;
        let len = CHUNK.min((self.unit_count(list) - start) as usize);
        let mut buf = Vec::new();
        let units = self.units_in(list, start, len, &mut buf);
        self.produce(units, merge, reuse)
    }

    /// Sample `units` (pixels or quads); `merge`: see [`Recorder`];
    /// `reuse`: the vectors of a consumed chunk, to record into.
    fn produce(&self, units: &[(u32, u32)], merge: Option<Merge>, reuse: Option<Buffers>) -> Chunk {
        // About eight reads per pixel (trilinear) to start with.
        let reserve = units.len() * if self.issue == Issue::Quads { 32 } else { 8 };
        let layouts = self.layouts;
        if layouts.len() == 1 {
            self.produce_into(units, Recorder::<true>::new(layouts, merge, reserve, reuse))
        } else {
            self.produce_into(
                units,
                Recorder::<false>::new(layouts, merge, reserve, reuse),
            )
        }
    }

    fn produce_into<const ONE: bool>(
        &self,
        units: &[(u32, u32)],
        mut sink: Recorder<'_, ONE>,
    ) -> Chunk {
        let mut ends = Vec::new();
        let mut colours = Vec::new();
        let mut pixels = 0u64;
        match self.issue {
            Issue::Stream => {
                // A few hundred queries at a time in one small vector: a
                // chunk's 8192 (192 KiB, a fresh mapping of the allocator
                // each time, faulted in page by page) would be written
                // and read back through the cache hierarchy.
                let mut qs: Vec<Query> = Vec::with_capacity(QUERY_BATCH);
                for part in units.chunks(QUERY_BATCH) {
                    qs.clear();
                    qs.extend(part.iter().filter_map(|&(x, y)| self.view.query(x, y)));
                    self.trace(&qs, &mut colours, &mut sink);
                    pixels += qs.len() as u64;
                }
            }
            Issue::Pixels => {
                for &(x, y) in units {
                    if let Some(q) = self.view.query(x, y) {
                        self.trace(std::slice::from_ref(&q), &mut colours, &mut sink);
                        ends.push(sink.len());
                        pixels += 1;
                    }
                }
            }
            Issue::Quads => {
                let (w, h) = (self.frame.width, self.frame.height);
                let mut qs = Vec::with_capacity(4);
                for &(qx, qy) in units {
                    qs.clear();
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let (x, y) = (2 * qx + dx, 2 * qy + dy);
                        if x < w && y < h {
                            qs.extend(self.view.query(x, y));
                        }
                    }
                    if !qs.is_empty() {
                        self.trace(&qs, &mut colours, &mut sink);
                        ends.push(sink.len());
                        pixels += qs.len() as u64;
                    }
                }
            }
        }
        let (accesses, counts) = sink.finish();
        Chunk {
            accesses,
            counts,
            ends,
            pixels,
            units: units.len() as u64,
        }
    }

    /// Report the reads of `qs` to `sink`: address only when the sampler
    /// is isotropic, else by sampling (into `colours`, resized).
    #[inline]
    fn trace<S: BlockSink>(&self, qs: &[Query], colours: &mut Vec<[f32; 4]>, sink: &mut S) {
        if let Some(a) = &self.address_only {
            a.trace_all(qs, sink);
            return;
        }
        colours.resize(qs.len(), [0.0; 4]);
        // Sampling cannot fail for a valid sampler and matching lengths.
        let _ = self
            .sampler
            .sample_slice_traced(qs, &mut colours[..qs.len()], sink);
    }

    /// How reads may be kept as fewer entries for `jobs` (see
    /// [`Recorder`]): lines of the smallest line of their first levels,
    /// when a texel read lies within one line and no cache has sectors
    /// (whose repeats may want other sectors), and the reads are neither
    /// written out nor grouped into fragments; a window of as many lines
    /// as the fewest ways when every first level is LRU (up to
    /// [`MAX_WINDOW`]), else of one line (only consecutive reads of a line
    /// merge: a hit to the line just read changes no policy's state).
    fn merge(&self, jobs: &[Job], writing: bool) -> Option<Merge> {
        let line = jobs.iter().map(|j| j.l1.line).min()?;
        let texel = self.layouts.iter().map(|l| l.texel()).max()?;
        let plain = jobs.iter().all(|j| j.l1.sector.is_none());
        let lru = jobs.iter().all(|j| j.l1.policy == Policy::Lru);
        let ways = jobs.iter().map(|j| j.l1.ways).min()?;
        (self.issue == Issue::Stream && !writing && plain && texel <= line).then(|| Merge {
            shift: line.trailing_zeros(),
            window: if lru {
                (ways as usize).clamp(1, MAX_WINDOW)
            } else {
                1
            },
        })
    }

    /// Sample the frame chunk by chunk, on as many threads as rayon's pool
    /// has (this one among them), and feed the chunks to every job's
    /// simulator in order, here (the jobs in parallel on the pool).
    fn simulate(
        &self,
        jobs: &[Job],
        model: &Model,
        mut each: Option<&mut dyn FnMut(u64) -> Result<()>>,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<Vec<RunStats>> {
        let mut consumers = jobs
            .iter()
            .map(|j| Consumer::new(j, self.layouts[j.layout], model))
            .collect::<Result<Vec<_>>>()?;
        let merge = self.merge(jobs, each.is_some());
        let list = self.unit_list();
        let total = self.unit_count(list.as_deref());
        let mut done = 0u64;
        let chunks = (total as usize).div_ceil(CHUNK);
        // Chunks sampled ahead of the simulation: fewer when each read is
        // kept in several layouts.
        let ahead = if self.layouts.len() > 1 { 4 } else { 16 };
        let spare = std::sync::Mutex::new(Vec::<Buffers>::new());
        // Sampling overlaps simulation, unless this is a pool thread: see
        // crate::par.
        crate::par::produce_consume(
            chunks,
            ahead,
            |c| {
                let reuse = spare.lock().ok().and_then(|mut v| v.pop());
                self.produce_chunk(list.as_deref(), c, merge, reuse)
            },
            |_, chunk| -> Result<()> {
                if let [one] = consumers.as_mut_slice() {
                    one.consume(&chunk, &mut each)?;
                } else {
                    consumers
                        .par_iter_mut()
                        .try_for_each(|k| k.consume(&chunk, &mut None))?;
                }
                done += chunk.units;
                progress(done, total);
                // The next chunks record into these vectors: no new pages
                // to fault in and zero for every chunk.
                if let Ok(mut v) = spare.lock() {
                    v.push(Buffers {
                        out: chunk.accesses,
                        counts: chunk.counts,
                    });
                }
                Ok(())
            },
        )?;
        Ok(consumers.into_iter().map(Consumer::finish).collect())
    }
}

/// One job's simulator fed a traced frame, with its prefetch model.
struct Consumer {
    layout: usize,
    sim: Simulator,
    texel: u64,
    sat: u64,
    levels: u32,
    quads: bool,
    prefetch: Option<Prefetch>,
    /// The current fragment's requests: (line, missed).
    lines: Vec<(u64, bool)>,
    reads: u64,
    pixels: u64,
    fragments: u64,
}

impl Consumer {
    fn new(job: &Job, layout: &ChainLayout, model: &Model) -> Result<Self> {
        let space = AddressSpace::Bounded(layout.total_bytes());
        let prefetch = match model.prefetch.as_slice() {
            [] => None,
            t => {
                let lines = (layout.total_bytes() >> job.l1.line.trailing_zeros()) + 1;
                Some(Prefetch::new(t, lines)?)
            }
        };
        Ok(Consumer {
            layout: job.layout,
            sim: Simulator::new(&job.l1, job.l2.as_ref(), space, true)?,
            texel: layout.texel(),
            sat: layout.sat_entry().unwrap_or(layout.texel()),
            levels: layout.levels() as u32,
            quads: model.quads,
            prefetch,
            lines: Vec::new(),
            reads: 0,
            pixels: 0,
            fragments: 0,
        })
    }

    /// (address, bytes, level counter) of a packed access.
    #[inline(always)]
    fn decode(&self) -> impl Fn(u64) -> (u64, u64, u32) + use<> {
        let (texel, sat, levels) = (self.texel, self.sat, self.levels);
        move |a| {
            let (addr, level) = unpack(a);
            if level == SAT_LEVEL {
                (addr, sat, levels)
            } else {
                (addr, texel, level)
            }
        }
    }

    fn consume(
        &mut self,
        c: &Chunk,
        each: &mut Option<&mut dyn FnMut(u64) -> Result<()>>,
    ) -> Result<()> {
        let acc = &c.accesses[self.layout];
        self.pixels += c.pixels;
        if let Some(counts) = c.counts.get(self.layout) {
            // Merged repeats (see `Recorder`): no reads written, no
            // fragments.
            self.fragments += c.pixels;
            let decode = self.decode();
            for (&a, &n) in acc.iter().zip(counts) {
                let (addr, bytes, level) = decode(a);
                self.sim.access(addr, bytes, level);
                // `n - 1` may be 0: adding it saves a branch on data.
                self.sim.repeat_hits(level, n as u64 - 1);
                self.reads += n as u64;
            }
            return Ok(());
        }
        self.reads += acc.len() as u64;
        if let Some(each) = each {
            for &a in acc {
                each(a)?;
            }
        }
        if c.ends.is_empty() {
            self.fragments += c.pixels;
            let decode = self.decode();
            for &a in acc {
                let (addr, bytes, level) = decode(a);
                self.sim.access(addr, bytes, level);
            }
            return Ok(());
        }
        let mut from = 0;
        for &end in &c.ends {
            let fragment = &acc[from..end];
            from = end;
            self.fragment(fragment);
        }
        self.fragments += c.ends.len() as u64;
        Ok(())
    }

    /// One fragment's reads: through the cache (merged per line for a
    /// quad), then the prefetch model.
    fn fragment(&mut self, reads: &[u64]) {
        let mut lines = std::mem::take(&mut self.lines);
        lines.clear();
        let mut note = |line: u64, o: Outcome| lines.push((line, o != Outcome::Hit));
        let decode = self.decode();
        if self.quads {
            self.sim
                .access_group(reads.iter().map(|&a| decode(a)), &mut note);
        } else {
            for &a in reads {
                let (addr, bytes, level) = decode(a);
                self.sim.access_with(addr, bytes, level, &mut note);
            }
        }
        if let Some(p) = &mut self.prefetch {
            p.fragment(&lines);
        }
        self.lines = lines;
    }

    fn finish(self) -> RunStats {
        RunStats {
            stats: self.sim.into_stats(),
            pixels: self.pixels,
            reads: self.reads,
            quads: self.quads.then_some(self.fragments),
            prefetch: self.prefetch.map_or_else(Vec::new, |p| p.stats()),
        }
    }
}

/// Statistics of a scene run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunStats {
    /// The cache counters (its accesses are the line requests: per texel
    /// read, or per line per quad with [`Model::quads`]).
    pub stats: Stats,
    /// Pixels that issued a query.
    pub pixels: u64,
    /// Texel (or table-entry) reads.
    pub reads: u64,
    /// Quads that issued a query, when the frame was issued by quads.
    pub quads: Option<u64>,
    /// The prefetch model's statistics, one per timing of the
    /// [`Model`].
    pub prefetch: Vec<PrefetchStats>,
}

impl RunStats {
    /// A run's statistics from its counters alone (no quads, no
    /// prefetching).
    pub fn plain(stats: Stats, pixels: u64, reads: u64) -> Self {
        RunStats {
            stats,
            pixels,
            reads,
            quads: None,
            prefetch: Vec::new(),
        }
    }
}

/// A recorded frame: packed accesses in raster order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Trace {
    /// Packed accesses (see [`pack`]).
    pub accesses: Vec<u64>,
    /// Pixels that issued a query.
    pub pixels: u64,
    /// Bytes of a texel access.
    pub texel_bytes: u64,
    /// Bytes of a summed-area-table entry access.
    pub sat_bytes: u64,
}

impl Trace {
    /// Simulate the trace under `l1` (and `l2`); `levels` is the chain's
    /// level count (table entries are counted as level `levels`).
    pub fn simulate(
        &self,
        l1: &CacheConfig,
        l2: Option<&CacheConfig>,
        space: AddressSpace,
        levels: u32,
    ) -> Result<RunStats> {
        let mut sim = Simulator::new(l1, l2, space, true)?;
        for &a in &self.accesses {
            let (addr, level) = unpack(a);
            if level == SAT_LEVEL {
                sim.access(addr, self.sat_bytes, levels);
            } else {
                sim.access(addr, self.texel_bytes, level);
            }
        }
        Ok(RunStats::plain(
            sim.into_stats(),
            self.pixels,
            self.accesses.len() as u64,
        ))
    }
}

/// Write one access per line (decimal byte address), SPEC.md's trace
/// format, after a `#` header.
pub fn write_trace_line(out: &mut impl Write, address: u64) -> std::io::Result<()> {
    writeln!(out, "{address}")
}

/// Read SPEC.md's trace format line by line (streaming: memory stays
/// bounded for any length): a decimal or `0x`-hex byte address per line,
/// `#` starts a comment, blank lines are skipped. `each(address)` is called
/// in order; a malformed line is an error naming its line number.
pub fn read_trace(input: impl BufRead, each: &mut dyn FnMut(u64)) -> Result<u64> {
    let mut n = 0u64;
    for (i, line) in input.lines().enumerate() {
        let line = line.map_err(|e| Error::Decode {
            format: "address trace",
            reason: format!("line {}: {e}", i + 1),
        })?;
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let parsed = match body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
            Some(hex) => u64::from_str_radix(hex, 16),
            None => body.parse::<u64>(),
        };
        let a = parsed.map_err(|_| Error::Decode {
            format: "address trace",
            reason: format!(
                "line {}: `{body}` is not a byte address (decimal or 0x-hex)",
                i + 1
            ),
        })?;
        each(a);
        n += 1;
    }
    Ok(n)
}
