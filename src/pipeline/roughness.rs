//! The normal and roughness chains of a normal map with a roughness
//! output ([`super::RoughnessSettings`]).

use super::{RoughnessSettings, RoughnessSource, Settings};
use crate::error::{Error, Result};
use crate::io;
use crate::mip::roughness::BaseRoughness;
use crate::mip::{self, MipOptions};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

/// The normal chain (encoded as `out`) and, unless packed into its
/// alpha, the roughness chain encoded for its own output.
pub(crate) fn build_roughness(
    base: &Texture,
    r: &RoughnessSettings,
    s: &Settings,
    options: &MipOptions,
    out: Format,
    progress: &mut dyn FnMut(mip::Progress),
) -> Result<(Vec<Texture>, Option<Vec<Texture>>)> {
    let map;
    let base_rough = match &r.base {
        RoughnessSource::Constant(a) => BaseRoughness::Constant(*a),
        RoughnessSource::Map(name) => {
            map = io::load_with(name, &s.limits, &s.load)?.into_base();
            BaseRoughness::Map(&map)
        }
    };
    let opts = MipOptions {
        normal_map: false,
        alpha_store: None,
        ..*options
    };
    let chain = mip::roughness::build(base, r.channels, base_rough, r.specular, &opts, progress)?;
    let narrow = |f: Format, ch: u8| Format {
        channels: ch,
        alpha: AlphaMode::None,
        ..f
    };
    let mut normals = Vec::with_capacity(chain.normals.len());
    for (n, sp) in chain.normals.iter().zip(&chain.specular) {
        let v = if r.pack_alpha {
            let (Texels::F32(nv), Texels::F32(sv)) = (n.texels(), sp.texels()) else {
                return Err(Error::InvalidOption("roughness chains are f32".into()));
            };
            let packed: Vec<f32> = nv
                .chunks_exact(3)
                .zip(sv)
                .flat_map(|(n, a)| [n[0], n[1], n[2], *a])
                .collect();
            let f =
                Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
            Texture::from_f32(n.width(), n.height(), f, packed)?
        } else {
            n.clone()
        };
        let ch = v.format().channels;
        let enc = mip::normal::encode(&v, narrow(out, ch))?;
        normals.push(if out.channels != ch {
            enc.expand_channels(out.channels)?
        } else {
            enc
        });
    }
    let rough = match &r.output {
        None => None,
        Some((_, kind)) => {
            let ty = match s.out_type {
                Some(t) if kind.supports(t) => t,
                _ => kind.data_type(out.channel_type),
            };
            let f =
                kind.storable(Format::new(1, ty, ColorSpace::Linear).with_alpha(AlphaMode::None));
            Some(
                chain
                    .specular
                    .into_iter()
                    .map(|l| mip::band::convert_level(l, f))
                    .collect::<Result<Vec<_>>>()?,
            )
        }
    };
    Ok((normals, rough))
}
