//! [`TextureStore`]: one texture and the structures built from it, each
//! built on first use, so a run models only what its filters require.
//!
//! A filter that reads only level 0 (mip mode `none`, the summed-area
//! table, the reference image) never causes the mip chain to be built; a
//! run without `sat` never builds a summed-area table. [`TextureStore::built`]
//! reports what was built and how many bytes it holds (what a texture
//! streamer would have to keep resident).

use std::sync::{Arc, OnceLock};

use crate::error::Result;
use crate::mip::{self, MipChain, MipOptions};
use crate::sample::{Method, MipMode, Sampler, SamplerOptions, TexelFilter};
use crate::sat::SatSampler;
use crate::texture::Texture;

/// What a store has built so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Built {
    /// Mip levels made from level 0 (0 when only level 0 was read).
    pub mip_levels: u32,
    /// Bytes of those levels (stored format).
    pub mip_bytes: u64,
    /// Whether a summed-area table was built.
    pub sat: bool,
    /// Bytes of the summed-area table.
    pub sat_bytes: u64,
}

/// One texture and its lazily built mip chain and summed-area table.
pub struct TextureStore {
    base: Texture,
    own_levels: Option<Vec<Texture>>,
    options: MipOptions,
    level0: OnceLock<Result<MipChain, String>>,
    /// The block format the file stored its levels in, if any.
    blocks: Option<crate::compress::BlockFormat>,
    chain: OnceLock<Result<MipChain, String>>,
    sat: OnceLock<Result<Arc<SatSampler>, String>>,
}

impl TextureStore {
    /// A store of `base`, whose chain (when a filter needs one) is built
    /// with `options`.
    pub fn new(base: Texture, options: MipOptions) -> Self {
        TextureStore {
            base,
            own_levels: None,
            options,
            level0: OnceLock::new(),
            blocks: None,
            chain: OnceLock::new(),
            sat: OnceLock::new(),
        }
    }

    /// A store of a file's levels: its own mip levels are the chain (none
    /// are built), level 0 alone otherwise.
    pub fn from_levels(mut levels: Vec<Texture>, options: MipOptions) -> Self {
        let base = levels.remove(0);
        let mut s = TextureStore::new(base, options);
        if !levels.is_empty() {
            s.own_levels = Some(levels);
        }
        s
    }

    /// A store of the texture `name` (a file or a `builtin:` name, see
    /// [`crate::io::load`]) under `limits`: the file's own mip levels are
    /// the chain, and its wrap mode (repeat when it records none) is the
    /// one mips are built and filters sample with.
    /// Non-finite float values are refused
    /// ([`crate::io::LoadOptions::for_sampling`]).
    #[cfg(feature = "io")]
    pub fn load(name: &str, limits: &crate::io::Limits) -> Result<Self> {
        let loaded = crate::io::load_with(name, limits, &crate::io::LoadOptions::for_sampling())?;
        Ok(Self::from_loaded(loaded))
    }

    /// A store of a loaded file (see [`TextureStore::load`]).
    #[cfg(feature = "io")]
    pub fn from_loaded(loaded: crate::io::Loaded) -> Self {
        let options = loaded.chain_options();
        let mut s = Self::from_levels(loaded.levels, options);
        s.blocks = loaded.info.blocks;
        s
    }

    /// The block format of a block-compressed file the store was loaded
    /// from (its levels are decoded; memory traffic counts whole blocks).
    pub fn stored_blocks(&self) -> Option<crate::compress::BlockFormat> {
        self.blocks
    }

    /// The options the chain is built with (its wrap mode is the
    /// texture's).
    pub fn options(&self) -> &MipOptions {
        &self.options
    }

    /// Level 0.
    pub fn base(&self) -> &Texture {
        &self.base
    }

    /// Level 0 alone as a chain (made on first call; a single level
    /// always forms a chain, but the check is `from_levels`'s).
    fn level0(&self) -> Result<&MipChain> {
        let r = self.level0.get_or_init(|| {
            MipChain::from_levels(vec![self.base.clone()], self.options).map_err(|e| e.to_string())
        });
        r.as_ref()
            .map_err(|e| crate::Error::InvalidOption(e.clone()))
    }

    /// The full mip chain (built on first call).
    pub fn chain(&self) -> Result<&MipChain> {
        let r = self.chain.get_or_init(|| {
            let r = match &self.own_levels {
                Some(own) => {
                    let mut all = vec![self.base.clone()];
                    all.extend(own.iter().cloned());
                    MipChain::from_levels(all, self.options)
                }
                None => mip::build(self.base.clone(), &self.options),
            };
            r.map_err(|e| e.to_string())
        });
        r.as_ref()
            .map_err(|e| crate::Error::InvalidOption(e.clone()))
    }

    /// The summed-area-table sampler for `options`: one table per store
    /// (built on first call), addressed with this call's wrap modes and
    /// border colour (the table itself does not depend on them).
    fn sat(&self, options: &SamplerOptions) -> Result<Arc<SatSampler>> {
        let r = self.sat.get_or_init(|| {
            SatSampler::new(&self.base, options.wrap, options.border)
                .map(Arc::new)
                .map_err(|e| e.to_string())
        });
        let table = r.clone().map_err(crate::Error::InvalidOption)?;
        Ok(Arc::new(
            table.with_addressing(options.wrap, options.border),
        ))
    }

    /// Whether a filter with `options` reads levels above 0.
    pub fn needs_mips(options: &SamplerOptions) -> bool {
        match options.method {
            Method::Sat | Method::Supersample => false,
            _ => options.mip != MipMode::None,
        }
    }

    /// The chain a filter with `options` reads: the full chain for
    /// mip-mapped filters, level 0 alone otherwise (built on first use).
    pub fn chain_for(&self, options: &SamplerOptions) -> Result<&MipChain> {
        if Self::needs_mips(options) {
            self.chain()
        } else {
            self.level0()
        }
    }

    /// A sampler for `options`, building what it needs: the chain for
    /// mip-mapped filters, the summed-area table for `sat`, nothing for
    /// level-0 filters.
    pub fn sampler(&self, options: SamplerOptions) -> Result<Sampler> {
        if options.method == Method::Sat {
            return Sampler::with_sat(self.level0()?, options, self.sat(&options)?);
        }
        Sampler::new(self.chain_for(&options)?, options)
    }

    /// The reference image's sampler: bilinear on level 0.
    pub fn reference_sampler(&self, wrap: crate::Wrap) -> Result<Sampler> {
        let o = SamplerOptions {
            mag: TexelFilter::Linear,
            min: TexelFilter::Linear,
            mip: MipMode::None,
            wrap,
            ..SamplerOptions::default()
        };
        Sampler::new(self.level0()?, o)
    }

    /// What has been built so far.
    pub fn built(&self) -> Built {
        let mut b = Built::default();
        if self.own_levels.is_none()
            && let Some(Ok(c)) = self.chain.get()
        {
            b.mip_levels = c.len() as u32 - 1;
            b.mip_bytes = c.levels()[1..].iter().map(|l| l.byte_len() as u64).sum();
        }
        if let Some(Ok(s)) = self.sat.get() {
            b.sat = true;
            b.sat_bytes = s.table().memory_bytes() as u64;
        }
        b
    }
}
