//! Texel tracing: every filter reports each texel it reads.
//!
//! The samplers are generic over a [`TexelSink`]. [`NoTrace`] has an empty,
//! always-inlined method, so `Sampler::sample` (which uses it) compiles to
//! the same code as an untraced sampler would; the `sample` benchmark
//! compares it against a counting sink. [`TexelRecorder`] keeps every read
//! in order (what the cache simulator replays); [`TexelCounter`] only
//! counts them (tests use it to bound the work per query).
//!
//! Reads of the border colour (`ClampToBorder` outside the level) touch no
//! texel memory and are not reported.

/// Receives every texel a filter reads, in read order.
pub trait TexelSink {
    /// False only for a sink that ignores every read ([`NoTrace`]): the
    /// samplers may then take paths that do not report reads one by one.
    /// Default: true.
    const TRACES: bool = true;
    /// Texel `(x, y)` of mip level `level` was read (`x`, `y` in range).
    fn texel(&mut self, level: u32, x: u32, y: u32);
    /// Entry `(x, y)` of the summed-area table was read (0 ≤ x ≤ width,
    /// 0 ≤ y ≤ height: the table has one more row and column than the
    /// level). Default: ignored.
    #[inline(always)]
    fn sat_entry(&mut self, _x: u32, _y: u32) {}
}

impl<S: TexelSink + ?Sized> TexelSink for &mut S {
    const TRACES: bool = S::TRACES;
    #[inline(always)]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        (**self).texel(level, x, y);
    }
    #[inline(always)]
    fn sat_entry(&mut self, x: u32, y: u32) {
        (**self).sat_entry(x, y);
    }
}

/// [`TexelSink`]'s calls behind a trait object (the trait itself has a
/// constant, so it cannot be one).
pub(crate) trait DynSink {
    fn texel_dyn(&mut self, level: u32, x: u32, y: u32);
    fn sat_entry_dyn(&mut self, x: u32, y: u32);
}

impl<S: TexelSink> DynSink for S {
    #[inline]
    fn texel_dyn(&mut self, level: u32, x: u32, y: u32) {
        self.texel(level, x, y);
    }
    #[inline]
    fn sat_entry_dyn(&mut self, x: u32, y: u32) {
        self.sat_entry(x, y);
    }
}

/// Any tracing sink as one type: the samplers' kernels are compiled for
/// two sinks, [`NoTrace`] and this, instead of once per sink type (the
/// cache simulator alone has four). A traced read costs one indirect call,
/// small beside what a sink does with it (a cache lookup, a push).
pub(crate) struct Erased<'a>(pub &'a mut dyn DynSink);

impl TexelSink for Erased<'_> {
    #[inline(always)]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        self.0.texel_dyn(level, x, y);
    }
    #[inline(always)]
    fn sat_entry(&mut self, x: u32, y: u32) {
        self.0.sat_entry_dyn(x, y);
    }
}

/// The sink that ignores everything (compiles away).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoTrace;

impl TexelSink for NoTrace {
    const TRACES: bool = false;
    #[inline(always)]
    fn texel(&mut self, _level: u32, _x: u32, _y: u32) {}
}

/// One texel read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TexelRead {
    /// Mip level (0 = full resolution).
    pub level: u32,
    /// Column within the level.
    pub x: u32,
    /// Row within the level.
    pub y: u32,
}

/// Records every read in order.
#[derive(Clone, Debug, Default)]
pub struct TexelRecorder {
    /// The reads so far.
    pub reads: Vec<TexelRead>,
}

impl TexelRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }
}

impl TexelSink for TexelRecorder {
    #[inline]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        self.reads.push(TexelRead { level, x, y });
    }
}

/// Counts reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TexelCounter {
    /// Texels read so far.
    pub count: u64,
}

impl TexelSink for TexelCounter {
    #[inline(always)]
    fn texel(&mut self, _level: u32, _x: u32, _y: u32) {
        self.count += 1;
    }
}
