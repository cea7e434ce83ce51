//! Address-only chains: what the cache model needs of a texture is its
//! level sizes, its texel format and the memory layout, not its texels.
//!
//! Which texels a nearest, bilinear, trilinear, anisotropic, EWA or
//! supersampling lookup reads follows from the query, the level sizes and
//! the sampler's options alone; only the `sat` filter reads a table built
//! from the values ([`reads_depend_on_values`]). For the others a
//! stand-in chain ([`stand_in`]) is filtered instead of the texture: the
//! same level sizes and format, all zero, allocated zeroed and never
//! written, so a page of it is mapped only when a filter reads it (and
//! then the system's shared zero page; the isotropic filters read none,
//! see [`super::isotropic`]). A 4096² RGBA8 texture's 85 MiB chain is
//! then neither generated nor mip-mapped, and no page a filter does not
//! read is touched. `tests/core/cache_report/cache_fast_paths.rs` checks that every such
//! filter's trace of a stand-in equals its trace of the texture, for
//! textures of several formats.

use std::sync::Arc;

use super::layout::{ChainLayout, Layout};
use crate::compress::BlockFormat;
use crate::error::Result;
use crate::mip::{self, MipChain, MipOptions};
use crate::sample::{Method, Sampler, SamplerOptions};
use crate::texel::Format;
use crate::texture::Texture;

/// Whether the texels a sampler with `options` reads depend on the
/// texture's values (the `sat` filter's table is built from them, and its
/// entry size chosen by them); when not, a [`stand_in`] gives the same
/// reads.
pub fn reads_depend_on_values(options: &SamplerOptions) -> bool {
    options.method == Method::Sat
}

/// The stand-in of a texture of `format` whose levels have the sizes
/// [`mip::level_sizes`] gives a `width × height` level 0 under `options`:
/// those levels, every texel zero and no page of them written.
pub fn stand_in(width: u32, height: u32, format: Format, options: &MipOptions) -> Result<MipChain> {
    let levels = mip::level_sizes(width, height, options.rounding, options.max_levels)
        .into_iter()
        .map(|(w, h)| Texture::new(w, h, format))
        .collect::<Result<Vec<_>>>()?;
    MipChain::from_levels(levels, *options)
}

/// A texture as a cache run reads it: the chain its samplers filter (the
/// texture itself, or a [`stand_in`] of it) and the block format it is
/// stored in.
#[derive(Clone, Debug)]
pub struct CacheTexture {
    /// The chain the samplers filter.
    pub chain: Arc<MipChain>,
    /// The block format the texture's levels are stored in, if any.
    pub blocks: Option<BlockFormat>,
    /// Whether `chain` is a stand-in (see the module docs).
    pub stand_in: bool,
}

impl CacheTexture {
    /// A loaded chain (`blocks`: the block format its file stores).
    pub fn loaded(chain: Arc<MipChain>, blocks: Option<BlockFormat>) -> Self {
        CacheTexture {
            chain,
            blocks,
            stand_in: false,
        }
    }

    /// The built-in texture `name` (`builtin:KIND[:SIZE]`) without its
    /// texels: a [`stand_in`] of its size and format, with the chain
    /// options a built-in texture is loaded with (the defaults). (The
    /// format is read off a one-texel instance of the same kind: a
    /// built-in's format does not depend on its size.)
    pub fn builtin(name: &str) -> Result<Self> {
        let (kind, size) = crate::builtin::parse(name)?;
        let format = crate::builtin::generate(kind, 1)?.format();
        let (w, h) = crate::builtin::dimensions(kind, size);
        Ok(CacheTexture {
            chain: Arc::new(stand_in(w, h, format, &MipOptions::default())?),
            blocks: None,
            stand_in: true,
        })
    }

    /// The texel format as stored.
    pub fn format(&self) -> Format {
        self.chain.levels()[0].format()
    }

    /// The layout `sampler` (a sampler of [`CacheTexture::chain`]) reads:
    /// the levels, with the texel (or block) size of their format, and the
    /// summed-area table after them for `sat`.
    pub fn layout(&self, sampler: &Sampler, layout: Layout) -> ChainLayout {
        ChainLayout::for_sampler_stored(&self.chain, sampler, layout, self.blocks)
    }
}
