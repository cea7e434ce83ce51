//! Driving the cache model from a scene: every pixel's query is filtered by
//! a sampler whose texel reads become byte addresses of a chain layout, in
//! raster order, and the addresses are simulated in that order.
//!
//! Sampling runs on rayon in chunks of pixels; each chunk's addresses are
//! recorded, and the chunks are fed to the simulator in raster order on
//! another thread while the next chunks are sampled (sampling and
//! simulation overlap). The recorded form ([`Trace`]) packs an access into
//! one `u64`: the address in the low 56 bits, the mip level (or
//! [`SAT_LEVEL`] for a summed-area-table entry) in the top 8.

use std::io::{BufRead, Write};

use rayon::prelude::*;

use super::layout::ChainLayout;
use super::sim::{AddressSpace, CacheConfig, Simulator, Stats};
use crate::error::{Error, Result};
use crate::sample::{Query, Sampler, TexelSink};
use crate::scene::{Frame, RasterOrder, Scene};

/// The level tag of a summed-area-table entry read.
pub const SAT_LEVEL: u32 = 255;
const ADDRESS_BITS: u32 = 56;
const ADDRESS_MASK: u64 = (1 << ADDRESS_BITS) - 1;

/// Pixels per sampling chunk.
const CHUNK: usize = 8192;

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
        let tex = self.sampler.chain().level_size(0).unwrap_or((1, 1));
        let frame = self.frame;
        let scene = self.scene;
        let pixels: Vec<(u32, u32)> = self.order.pixels(frame).collect();
        pixels
            .par_chunks(CHUNK)
            .flat_map_iter(|c| {
                c.iter()
                    .filter_map(|&(x, y)| scene.query(frame, tex, x, y))
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    fn chunk_trace(&self, queries: &[Query]) -> Vec<u64> {
        let mut sink = AddressSink::new(self.layout);
        sink.out.reserve(queries.len() * 8);
        let mut colours = vec![[0f32; 4]; queries.len()];
        // Sampling cannot fail for a valid sampler and matching lengths.
        let _ = self
            .sampler
            .sample_slice_traced(queries, &mut colours, &mut sink);
        sink.out
    }

    /// Every access of the frame, in raster order (for sweeps, which replay
    /// one trace under many caches). A `sat` sampler's table reads are
    /// missing unless the layout has the table (see [`AddressSink`]).
    pub fn record(&self) -> Trace {
        let queries = self.queries();
        let chunks: Vec<Vec<u64>> = queries
            .par_chunks(CHUNK)
            .map(|c| self.chunk_trace(c))
            .collect();
        let mut accesses = Vec::with_capacity(chunks.iter().map(Vec::len).sum());
        for c in chunks {
            accesses.extend_from_slice(&c);
        }
        Trace {
            accesses,
            pixels: queries.len() as u64,
            texel_bytes: self.layout.texel(),
            sat_bytes: self.layout.sat_entry().unwrap_or(self.layout.texel()),
        }
    }

    /// Simulate the frame under `l1` (and `l2`) with sampling and
    /// simulation overlapped; `each` sees every packed access in order
    /// (for `--trace-out`), `progress(done, total)` counts pixels. A `sat`
    /// sampler needs a layout with its table
    /// ([`ChainLayout::for_sampler`]).
    pub fn simulate(
        &self,
        l1: &CacheConfig,
        l2: Option<&CacheConfig>,
        each: &mut dyn FnMut(u64) -> Result<()>,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<RunStats> {
        if self.sampler.sat().is_some() && self.layout.sat_entry().is_none() {
            return Err(Error::InvalidOption(
                "the sampler reads a summed-area table the cache layout does not lay out".into(),
            ));
        }
        let queries = self.queries();
        let total = queries.len() as u64;
        let mut sim = Simulator::new(
            l1,
            l2,
            AddressSpace::Bounded(self.layout.total_bytes()),
            true,
        )?;
        let nlevels = self.layout.levels() as u32;
        let texel = self.layout.texel();
        let sat = self.layout.sat_entry().unwrap_or(texel);
        let mut reads = 0u64;
        let groups: Vec<&[Query]> = queries.chunks(CHUNK * 8).collect();
        // Sampling (on the pool) overlaps simulation (here), unless this
        // is a pool thread: see crate::par.
        let result = crate::par::produce_consume(
            &groups,
            2,
            |_, g| -> Vec<Vec<u64>> { g.par_chunks(CHUNK).map(|c| self.chunk_trace(c)).collect() },
            |gi, traces| -> Result<()> {
                for t in &traces {
                    for &a in t {
                        let (addr, level) = unpack(a);
                        let (bytes, index) = if level == SAT_LEVEL {
                            (sat, nlevels)
                        } else {
                            (texel, level)
                        };
                        sim.access(addr, bytes, index);
                        each(a)?;
                    }
                    reads += t.len() as u64;
                }
                progress(((gi + 1) * CHUNK * 8).min(total as usize) as u64, total);
                Ok(())
            },
        );
        result?;
        Ok(RunStats {
            stats: sim.into_stats(),
            pixels: total,
            reads,
        })
    }
}

/// Statistics of a scene run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunStats {
    /// The cache counters.
    pub stats: Stats,
    /// Pixels that issued a query.
    pub pixels: u64,
    /// Texel (or table-entry) reads.
    pub reads: u64,
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
        Ok(RunStats {
            stats: sim.into_stats(),
            pixels: self.pixels,
            reads: self.accesses.len() as u64,
        })
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
