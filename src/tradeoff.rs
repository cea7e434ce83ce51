//! The trade-off report: what each filter costs and how far it is from
//! the truth, on a texture and a scene — speed (ns per pixel, one thread,
//! the untraced fast path), memory traffic (texels read, bytes from memory
//! through a cache), accuracy against the reference image (PSNR, RMSE,
//! maximum error) and flicker (two frames a small camera move apart).
//!
//! [`run`] takes a [`TextureStore`] and plain [`Settings`] and returns a
//! [`Report`] of one [`Row`] per filter (and per filter on the chain
//! block-compressed, when asked). It writes nothing: the images it renders
//! (the reference, each filter's frame) are handed to a callback as they
//! are made, so a caller can save them without the report holding every
//! frame; progress goes to another callback. Only what the filters need
//! is built (the store's [`Built`] in the report says what).
//!
//! ```
//! use parvo::scene::{Frame, Scene};
//! use parvo::store::TextureStore;
//! use parvo::{MipOptions, SamplerOptions, builtin, tradeoff};
//!
//! let store = TextureStore::new(builtin::load("builtin:checker:64")?, MipOptions::default());
//! let filters = vec![SamplerOptions::from_name("bilinear")?, SamplerOptions::from_name("trilinear")?];
//! let mut settings = tradeoff::Settings::new("plane".parse::<Scene>()?, Frame::new(32, 24), filters)?;
//! settings.runs = 1;
//! let report = tradeoff::run(&store, &settings, &|_| {}, &mut |_| Ok::<(), parvo::Error>(()))?;
//! assert_eq!(report.rows.len(), 2);
//! assert!(report.rows[1].psnr_db > 10.0);
//! # Ok::<(), parvo::Error>(())
//! ```

use std::time::Instant;

use crate::cache::layout::{ChainLayout, Layout};
use crate::cache::run::SceneSetup;
use crate::cache::sim::CacheConfig;
use crate::compress::{BlockFormat, Quality};
use crate::error::{Error, Result};
use crate::sample::{Query, Sampler, SamplerOptions, TexelSink};
use crate::scene::metrics::{error_scale, flicker, scores};
use crate::scene::reference::Reference;
use crate::scene::render::{Image, ns_per_query, queries, render};
use crate::scene::{Frame, RasterOrder, Scene};
use crate::store::{Built, TextureStore};
use crate::texture::Texture;

/// The cache the traffic figures use by default.
pub const DEFAULT_CACHE: &str = "16K:64:4";
/// The chain's memory layout the traffic figures use by default.
pub const DEFAULT_LAYOUT: &str = "tiled:4x4";
/// The raster order the traffic figures use by default.
pub const DEFAULT_ORDER: &str = "tiled:8";
/// The camera move between the flicker frames by default, pixels.
pub const FLICKER_SHIFT: (f64, f64) = (0.25, 0.0);
/// Side of the square tiles the working set is counted in, texels.
pub const TILE: u32 = 64;

/// What to measure.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The scene.
    pub scene: Scene,
    /// The frame.
    pub frame: Frame,
    /// The filters, one row each (their wrap mode is the store's).
    pub filters: Vec<SamplerOptions>,
    /// How the reference image is computed.
    pub reference: Reference,
    /// Timing runs per filter (the median is reported; at least 1).
    pub runs: usize,
    /// Also measure every filter on the chain block-compressed to this
    /// format with this encoder effort (needs the `encode` feature).
    pub compress: Option<(BlockFormat, Quality)>,
    /// The cache of the traffic figures.
    pub cache: CacheConfig,
    /// The chain's memory layout of the traffic figures.
    pub layout: Layout,
    /// The raster order of the traffic figures.
    pub order: RasterOrder,
    /// The camera move between the two flicker frames, pixels.
    pub flicker_shift: (f64, f64),
}

impl Settings {
    /// `filters` on `scene` in `frame` with the defaults: the gaussian
    /// reference, 5 timing runs, no compression, [`DEFAULT_CACHE`],
    /// [`DEFAULT_LAYOUT`], [`DEFAULT_ORDER`], [`FLICKER_SHIFT`].
    pub fn new(scene: Scene, frame: Frame, filters: Vec<SamplerOptions>) -> Result<Self> {
        Ok(Settings {
            scene,
            frame,
            filters,
            reference: Reference::default(),
            runs: 5,
            compress: None,
            cache: DEFAULT_CACHE.parse()?,
            layout: DEFAULT_LAYOUT.parse()?,
            order: DEFAULT_ORDER.parse()?,
            flicker_shift: FLICKER_SHIFT,
        })
    }
}

/// The tiles of one level a filter's frame reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelTiles {
    /// Mip level.
    pub level: usize,
    /// [`TILE`]-sided tiles read at least once.
    pub touched: usize,
    /// Tiles of the level.
    pub tiles: usize,
}

impl LevelTiles {
    /// The fraction of the level's tiles read.
    pub fn fraction(&self) -> f64 {
        self.touched as f64 / self.tiles.max(1) as f64
    }
}

/// One filter's measurements.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The filter's report name; `NAME+bc7` and so on for the
    /// block-compressed chain.
    pub name: String,
    /// What the chain stores: its texel format, or the block format.
    pub stored: String,
    /// Median wall time per pixel (one thread, untraced), nanoseconds.
    pub ns_per_pixel: f64,
    /// Texel (or table-entry) reads per pixel.
    pub texels_per_pixel: f64,
    /// Bytes from memory per pixel through the settings' cache.
    pub bytes_per_pixel: f64,
    /// PSNR against the reference, dB (infinite when equal).
    pub psnr_db: f64,
    /// RMSE against the reference.
    pub rmse: f64,
    /// Largest absolute error of any channel.
    pub max_error: f64,
    /// Flicker: the RMS change between the two frames minus the
    /// reference's.
    pub flicker: f64,
    /// The 99th-percentile per-pixel error ([`error_scale`]), the scale of
    /// an error map.
    pub error_scale: f64,
    /// Per level, the tiles the frame reads.
    pub working_set: Vec<LevelTiles>,
}

/// The report.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Pixels that show texture.
    pub pixels: usize,
    /// Level 0's size.
    pub texture_size: (u32, u32),
    /// Seconds the first reference frame took.
    pub reference_seconds: f64,
    /// What the store built for the filters.
    pub built: Built,
    /// One row per filter, then one per filter on the compressed chain.
    pub rows: Vec<Row>,
}

/// A step of [`run`], for a progress display.
#[derive(Clone, Copy, Debug)]
pub enum Progress<'a> {
    /// A phase starts: `reference`, `timing`, a filter's name, `BC7
    /// encode` …
    Step(&'a str),
    /// One unit of [`progress_total`] is done (a reference row, a plain
    /// filter's row).
    Advance,
}

/// The units of [`Progress::Advance`] a run of `settings` reports: two
/// reference frames of rows and one per filter.
pub fn progress_total(settings: &Settings) -> u64 {
    settings.frame.height as u64 * 2 + settings.filters.len() as u64
}

/// An image [`run`] made, handed over as soon as it exists.
pub enum Rendered<'a> {
    /// The reference frame.
    Reference(&'a Image),
    /// One row's frame.
    Filter {
        /// The row (its name, its error scale).
        row: &'a Row,
        /// The frame the filter rendered.
        image: &'a Image,
        /// The reference frame.
        reference: &'a Image,
        /// The sampler that rendered it (for level-tint images).
        sampler: &'a Sampler,
        /// Every pixel's query (row-major).
        queries: &'a [Option<Query>],
    },
}

/// Measure every filter of `settings` on the texture in `store`; see the
/// module docs. `progress` sees the steps, `images` every image made (its
/// error stops the run).
pub fn run<E: From<Error>>(
    store: &TextureStore,
    settings: &Settings,
    progress: &(dyn Fn(Progress<'_>) + Sync),
    images: &mut dyn FnMut(Rendered<'_>) -> std::result::Result<(), E>,
) -> std::result::Result<Report, E> {
    if settings.filters.is_empty() {
        return Err(
            Error::InvalidOption("the trade-off report needs at least one filter".into()).into(),
        );
    }
    let wrap = store.options().wrap;
    let base = store.base();
    let tex = (base.width(), base.height());
    let frame = settings.frame;
    let scene = &settings.scene;

    // The reference, twice (the flicker frames).
    progress(Progress::Step("reference"));
    let ref_sampler = store.reference_sampler(wrap)?;
    let t0 = Instant::now();
    let tick = |_| progress(Progress::Advance);
    let reference = &settings.reference;
    let ref0 = reference.render(scene, frame, (0.0, 0.0), &ref_sampler, &tick);
    let reference_seconds = t0.elapsed().as_secs_f64();
    let ref1 = reference.render(scene, frame, settings.flicker_shift, &ref_sampler, &tick);
    images(Rendered::Reference(&ref0))?;
    let q0 = queries(scene, frame, tex, (0.0, 0.0));
    let q1 = queries(scene, frame, tex, settings.flicker_shift);
    let dense: Vec<Query> = q0.iter().flatten().copied().collect();
    if dense.is_empty() {
        return Err(Error::InvalidOption(format!(
            "scene {scene} shows no texture in a {frame} frame"
        ))
        .into());
    }
    let env = RowEnv {
        settings,
        ref0: &ref0,
        ref1: &ref1,
        q0: &q0,
        q1: &q1,
        dense: &dense,
    };
    let mut rows = Vec::new();
    let stored = match store.stored_blocks() {
        Some(b) => b.name().to_string(),
        None => base.format().to_string(),
    };
    env.rows(store, None, &stored, progress, images, &mut rows)?;
    if let Some((bf, quality)) = settings.compress {
        progress(Progress::Step(&format!("{bf} encode")));
        let (decoded, stored) = compressed_chain(store, bf, quality)?;
        let cstore = TextureStore::from_levels(decoded, *store.options());
        env.rows(&cstore, Some(bf), &stored, progress, images, &mut rows)?;
    }
    Ok(Report {
        pixels: dense.len(),
        texture_size: tex,
        reference_seconds,
        built: store.built(),
        rows,
    })
}

/// Marks the tiles of each level a run reads.
struct TileSink {
    sizes: Vec<(u32, u32)>,
    tiles: Vec<Vec<bool>>,
}

impl TileSink {
    fn new(sampler: &Sampler) -> Self {
        let n = sampler.chain().len();
        let sizes: Vec<(u32, u32)> = (0..n)
            .map(|k| sampler.chain().level_size(k).unwrap_or((1, 1)))
            .collect();
        let tiles = sizes
            .iter()
            .map(|&(w, h)| vec![false; (w.div_ceil(TILE) * h.div_ceil(TILE)) as usize])
            .collect();
        TileSink { sizes, tiles }
    }

    fn levels(&self) -> Vec<LevelTiles> {
        self.tiles
            .iter()
            .enumerate()
            .map(|(level, t)| LevelTiles {
                level,
                touched: t.iter().filter(|&&b| b).count(),
                tiles: t.len(),
            })
            .collect()
    }
}

impl TexelSink for TileSink {
    #[inline]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        let k = level as usize;
        let w = self.sizes[k].0.div_ceil(TILE);
        self.tiles[k][((y / TILE) * w + x / TILE) as usize] = true;
    }
}

/// What every row's measurement shares.
struct RowEnv<'a> {
    settings: &'a Settings,
    ref0: &'a Image,
    ref1: &'a Image,
    q0: &'a [Option<Query>],
    q1: &'a [Option<Query>],
    dense: &'a [Query],
}

impl RowEnv<'_> {
    /// The rows of every filter on the chain of `store`: `compressed` names
    /// the block format the store's levels were decoded from (the rows are
    /// then named `NAME+bc7` …, their traffic counts blocks, and they
    /// report no progress units).
    fn rows<E: From<Error>>(
        &self,
        store: &TextureStore,
        compressed: Option<BlockFormat>,
        stored: &str,
        progress: &(dyn Fn(Progress<'_>) + Sync),
        images: &mut dyn FnMut(Rendered<'_>) -> std::result::Result<(), E>,
        rows: &mut Vec<Row>,
    ) -> std::result::Result<(), E> {
        let s = self.settings;
        let mut samplers = Vec::new();
        for options in &s.filters {
            let name = options.name();
            let mut options = *options;
            options.wrap = store.options().wrap;
            samplers.push((name, options, store.sampler(options)?));
        }
        if compressed.is_none() {
            progress(Progress::Step("timing"));
        }
        let timed: Vec<&Sampler> = samplers.iter().map(|(_, _, s)| s).collect();
        let timings = ns_per_query(&timed, self.dense, s.runs);
        let tag = compressed.map(|bf| bf.name().to_ascii_lowercase().replace("_uf16", ""));
        for ((name, options, sampler), ns) in samplers.iter().zip(&timings) {
            let name = match &tag {
                Some(t) => format!("{name}+{t}"),
                None => name.clone(),
            };
            progress(Progress::Step(&name));
            let chain = store.chain_for(options)?;
            let blocks = compressed.or(store.stored_blocks());
            let cl = ChainLayout::for_sampler_stored(chain, sampler, s.layout, blocks);
            self.row(name, stored.to_string(), sampler, &cl, *ns, images, rows)?;
            if compressed.is_none() {
                progress(Progress::Advance);
            }
        }
        Ok(())
    }

    /// Render, score and simulate one filter, hand its frame over and add
    /// its row.
    #[allow(clippy::too_many_arguments)]
    fn row<E: From<Error>>(
        &self,
        name: String,
        stored: String,
        sampler: &Sampler,
        cl: &ChainLayout,
        ns: f64,
        images: &mut dyn FnMut(Rendered<'_>) -> std::result::Result<(), E>,
        rows: &mut Vec<Row>,
    ) -> std::result::Result<(), E> {
        let s = self.settings;
        let img0 = render(sampler, self.q0);
        let img1 = render(sampler, self.q1);
        let sc = scores(self.ref0, &img0);
        let fl = flicker((&img0, &img1), (self.ref0, self.ref1));
        let setup = SceneSetup {
            sampler,
            layout: cl,
            scene: s.scene,
            frame: s.frame,
            order: s.order,
        };
        let run = setup.simulate(&s.cache, None, &mut |_| Ok(()), &|_, _| {})?;
        let mut tiles = TileSink::new(sampler);
        let mut out = vec![[0f32; 4]; self.dense.len()];
        sampler.sample_slice_traced(self.dense, &mut out, &mut tiles)?;
        let pixels = run.pixels.max(1) as f64;
        let row = Row {
            name,
            stored,
            ns_per_pixel: ns,
            texels_per_pixel: run.reads as f64 / pixels,
            bytes_per_pixel: run.stats.bytes_from_memory() as f64 / pixels,
            psnr_db: sc.psnr_db,
            rmse: sc.rmse,
            max_error: sc.max_error,
            flicker: fl,
            error_scale: error_scale(&img0, self.ref0),
            working_set: tiles.levels(),
        };
        images(Rendered::Filter {
            row: &row,
            image: &img0,
            reference: self.ref0,
            sampler,
            queries: self.q0,
        })?;
        rows.push(row);
        Ok(())
    }
}

/// The store's full chain block-compressed and decoded again, and the
/// stored format's name.
fn compressed_chain(
    store: &TextureStore,
    bf: BlockFormat,
    quality: Quality,
) -> Result<(Vec<Texture>, String)> {
    #[cfg(feature = "encode")]
    {
        let levels = store.chain()?.levels();
        let (decoded, _) = crate::compress::round_trip(levels, bf, quality)?;
        let srgb = decoded[0].format().color_space == crate::texel::ColorSpace::Srgb;
        Ok((decoded, format!("{bf}{}", if srgb { "_SRGB" } else { "" })))
    }
    #[cfg(not(feature = "encode"))]
    {
        let _ = (store, quality);
        Err(Error::InvalidOption(format!(
            "{bf}: this parvo was built without the `encode` feature"
        )))
    }
}
