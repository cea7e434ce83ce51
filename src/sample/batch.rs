//! Slices of queries: serial, traced, and parallel (rayon).
//!
//! The parallel version splits the slice into chunks of [`CHUNK`] queries
//! (large enough that scheduling costs nothing next to the lookups, small
//! enough to balance the expensive EWA queries) and runs the same loop as
//! the serial one on each. Output order always matches input order.

use rayon::prelude::*;

use crate::error::{Error, Result};

use super::{Query, Sampler};
use crate::trace::{NoTrace, TexelSink};

/// Queries per parallel task.
pub const CHUNK: usize = 1024;

fn check_len(q: usize, o: usize) -> Result<()> {
    if q == o {
        Ok(())
    } else {
        Err(Error::InvalidOption(format!(
            "{q} queries but room for {o} colours"
        )))
    }
}

impl Sampler {
    /// Sample every query into `out` on the calling thread.
    pub fn sample_slice(&self, queries: &[Query], out: &mut [[f32; 4]]) -> Result<()> {
        self.sample_slice_traced(queries, out, &mut NoTrace)
    }

    /// [`Sampler::sample_slice`], reporting every texel read to `sink` in
    /// query order.
    pub fn sample_slice_traced<S: TexelSink>(
        &self,
        queries: &[Query],
        out: &mut [[f32; 4]],
        sink: &mut S,
    ) -> Result<()> {
        check_len(queries.len(), out.len())?;
        self.run(queries, out, sink);
        Ok(())
    }

    /// Sample every query into `out` on all of rayon's threads.
    pub fn sample_batch(&self, queries: &[Query], out: &mut [[f32; 4]]) -> Result<()> {
        check_len(queries.len(), out.len())?;
        queries
            .par_chunks(CHUNK)
            .zip(out.par_chunks_mut(CHUNK))
            .for_each(|(q, o)| self.run(q, o, &mut NoTrace));
        Ok(())
    }

    /// [`Sampler::sample_batch`] with one sink per parallel chunk, made by
    /// `make_sink(first_query_index)` and returned with that index, in
    /// query order, so traces can be merged or replayed per chunk.
    pub fn sample_batch_traced<S, F>(
        &self,
        queries: &[Query],
        out: &mut [[f32; 4]],
        make_sink: F,
    ) -> Result<Vec<(usize, S)>>
    where
        S: TexelSink + Send,
        F: Fn(usize) -> S + Sync,
    {
        check_len(queries.len(), out.len())?;
        Ok(queries
            .par_chunks(CHUNK)
            .zip(out.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(k, (q, o))| {
                let start = k * CHUNK;
                let mut sink = make_sink(start);
                self.run(q, o, &mut sink);
                (start, sink)
            })
            .collect())
    }
}
